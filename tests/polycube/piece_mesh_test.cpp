// extract_piece: the local mesh is the piece (same triangles, same positions, same Euler
// characteristic), its loops are exactly its boundary loops, and the maps lead back to the
// sliced mesh.
#include "polycube/piece_mesh.h"

#include "polycube/mesh_topology.h"
#include "polycube/topology.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace polycube {
namespace {

// Directed edges (a, b) of a set of vertex cycles.
std::set<std::pair<int, int>> cycle_edges(const std::vector<std::vector<int>>& loops) {
  std::set<std::pair<int, int>> edges;
  for (const auto& loop : loops)
    for (size_t k = 0; k < loop.size(); ++k) edges.emplace(loop[k], loop[(k + 1) % loop.size()]);
  return edges;
}

TEST(PieceMesh, PiecesOfSlicedTestMeshes) {
  for (const std::string name : {"double-torus-example.off", "helmet.off", "rotor.off"}) {
    SCOPED_TRACE(name);
    const TopologyResult topo = analyse_topology(test::load_test_mesh(name));
    const SlicedMesh& s = topo.sliced;
    int faces = 0;
    for (int p = 0; p < static_cast<int>(s.pieces.size()); ++p) {
      SCOPED_TRACE("piece " + std::to_string(p));
      const Piece& piece = s.pieces[p];
      const PieceMesh local = extract_piece(s, p);
      const TriMesh& m = local.mesh;
      ASSERT_EQ(m.num_faces(), static_cast<int>(piece.faces.size()));
      ASSERT_EQ(m.num_vertices(), static_cast<int>(local.vertex_to_global.size()));
      EXPECT_EQ(local.face_to_global, piece.faces);
      EXPECT_EQ(count_unreferenced_vertices(m.F, m.num_vertices()), 0);
      for (int f = 0; f < m.num_faces(); ++f)
        for (int i = 0; i < 3; ++i) EXPECT_EQ(local.vertex_to_global[m.F(f, i)], s.mesh.F(piece.faces[f], i));
      for (int v = 0; v < m.num_vertices(); ++v) EXPECT_EQ(m.V.row(v), s.mesh.V.row(local.vertex_to_global[v]));
      EXPECT_EQ(euler_characteristic(m.F, m.num_vertices()), piece.euler);
      EXPECT_EQ(genus(m.F, m.num_vertices()), 0);
      // Loops: the piece's loops in local ids, and exactly the boundary of the local mesh.
      ASSERT_EQ(local.loops.size(), piece.boundary_loops.size());
      for (size_t l = 0; l < local.loops.size(); ++l) {
        ASSERT_EQ(local.loops[l].size(), piece.boundary_loops[l].size());
        for (size_t k = 0; k < local.loops[l].size(); ++k)
          EXPECT_EQ(local.vertex_to_global[local.loops[l][k]], piece.boundary_loops[l][k]);
      }
      EXPECT_EQ(cycle_edges(local.loops), cycle_edges(boundary_loops(m.F)));
      EXPECT_EQ(local.loop_plane, piece.loop_plane);
      faces += m.num_faces();
    }
    EXPECT_EQ(faces, s.mesh.num_faces());
  }
}

TEST(PieceMesh, RejectsBadPieceIndex) {
  const TopologyResult topo = analyse_topology(test::load_test_mesh("sphere.off"));
  EXPECT_THROW(extract_piece(topo.sliced, -1), std::out_of_range);
  EXPECT_THROW(extract_piece(topo.sliced, static_cast<int>(topo.sliced.pieces.size())), std::out_of_range);
}

}  // namespace
}  // namespace polycube
