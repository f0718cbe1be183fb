// slice_mesh: the refined mesh is the same surface (area, volume, topology), every face lies in
// one slab, every piece's Euler characteristic, genus and boundary loops agree with a direct
// count, and the pieces add up to the mesh.
#include "polycube/slice.h"

#include "formats/mesh_io.h"
#include "polycube/errors.h"
#include "polycube/mesh_topology.h"
#include "polycube/validate.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace polycube {
namespace {

// n planes evenly spread over the open z range of the mesh.
std::vector<double> even_planes(const TriMesh& mesh, int n) {
  const BoundingBox box = bounding_box(mesh.V);
  std::vector<double> planes;
  for (int k = 1; k <= n; ++k) planes.push_back(box.min.z() + box.extent().z() * k / (n + 1));
  return planes;
}

Eigen::MatrixX3i rows(const Eigen::MatrixX3i& F, const std::vector<int>& faces) {
  Eigen::MatrixX3i out(faces.size(), 3);
  for (size_t k = 0; k < faces.size(); ++k) out.row(k) = F.row(faces[k]);
  return out;
}

void expect_valid_slicing(const TriMesh& mesh, const SlicedMesh& s) {
  const TriMesh& R = s.mesh;
  const int nv = mesh.num_vertices();
  ASSERT_EQ(s.input_vertices, nv);
  ASSERT_GE(R.num_vertices(), nv);
  EXPECT_EQ(R.V.topRows(nv), mesh.V) << "input vertices must not move";
  // Planes: sorted, inside the range, through no input vertex; new vertices exactly on one.
  EXPECT_TRUE(std::is_sorted(s.planes.begin(), s.planes.end()));
  std::set<double> plane_set(s.planes.begin(), s.planes.end());
  EXPECT_EQ(plane_set.size(), s.planes.size());
  for (int v = 0; v < nv; ++v) EXPECT_EQ(plane_set.count(mesh.V(v, 2)), 0u);
  for (int v = nv; v < R.num_vertices(); ++v) EXPECT_EQ(plane_set.count(R.V(v, 2)), 1u) << "vertex " << v;
  // Same surface: area, volume, topology, orientation.
  EXPECT_NEAR(surface_area(R), surface_area(mesh), 1e-9 * surface_area(mesh));
  EXPECT_NEAR(signed_volume(R), signed_volume(mesh), 1e-9 * std::abs(signed_volume(mesh)));
  EXPECT_EQ(euler_characteristic(R.F, R.num_vertices()), euler_characteristic(mesh.F, nv));
  EXPECT_TRUE(boundary_loops(R.F).empty());
  EXPECT_EQ(count_nonmanifold_vertices(R.F, R.num_vertices()), 0);
  // Each refined face lies in its input face's plane and has positive area.
  const double extent = bounding_box(mesh.V).extent().maxCoeff();
  ASSERT_EQ(s.face_origin.size(), R.num_faces());
  ASSERT_EQ(s.face_piece.size(), R.num_faces());
  for (int f = 0; f < R.num_faces(); ++f) {
    const int o = s.face_origin[f];
    const Eigen::Vector3d a = mesh.V.row(mesh.F(o, 0)), b = mesh.V.row(mesh.F(o, 1)), c = mesh.V.row(mesh.F(o, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    const Eigen::Vector3d p = R.V.row(R.F(f, 0)), q = R.V.row(R.F(f, 1)), r = R.V.row(R.F(f, 2));
    for (const Eigen::Vector3d& x : {p, q, r}) EXPECT_LT(std::abs(n.dot(x - a)), 1e-9 * extent);
    const Eigen::Vector3d m = (q - p).cross(r - p);
    EXPECT_GT(m.norm(), 1e-14 * extent * extent) << "degenerate face " << f;
    EXPECT_GT(m.dot(n), 0) << "face " << f << " flipped";
  }
  // Pieces.
  int euler_sum = 0;
  std::vector<int> seen(R.num_faces(), 0);
  for (size_t p = 0; p < s.pieces.size(); ++p) {
    SCOPED_TRACE("piece " + std::to_string(p));
    const Piece& piece = s.pieces[p];
    ASSERT_FALSE(piece.faces.empty());
    EXPECT_TRUE(std::is_sorted(piece.faces.begin(), piece.faces.end()));
    for (int f : piece.faces) {
      EXPECT_EQ(s.face_piece[f], static_cast<int>(p));
      ++seen[f];
      // Inside its slab.
      for (int i = 0; i < 3; ++i) {
        const double z = R.V(R.F(f, i), 2);
        if (piece.plane_below >= 0) {
          EXPECT_GE(z, s.planes[piece.plane_below]);
        }
        if (piece.plane_above >= 0) {
          EXPECT_LE(z, s.planes[piece.plane_above]);
        }
      }
    }
    const int np = static_cast<int>(s.planes.size());
    if (piece.plane_below >= 0 && piece.plane_above >= 0) {
      EXPECT_EQ(piece.plane_above, piece.plane_below + 1);
    }
    if (piece.plane_below < 0) {
      EXPECT_EQ(piece.plane_above, np > 0 ? 0 : -1);
    }
    if (piece.plane_above < 0) {
      EXPECT_EQ(piece.plane_below, np - 1);
    }
    const Eigen::MatrixX3i PF = rows(R.F, piece.faces);
    EXPECT_EQ(connected_components(PF, R.num_vertices()), 1);
    EXPECT_EQ(piece.euler, euler_characteristic(PF, R.num_vertices()));
    EXPECT_EQ(piece.genus, genus(PF, R.num_vertices()));
    EXPECT_EQ(piece.boundary_loops.size(), boundary_loops(PF).size());
    euler_sum += piece.euler;
    // Loops: on one of the two planes of the piece, following boundary edges of the piece.
    ASSERT_EQ(piece.loop_plane.size(), piece.boundary_loops.size());
    std::set<std::pair<int, int>> directed;
    for (int f : piece.faces)
      for (int i = 0; i < 3; ++i) directed.insert({R.F(f, i), R.F(f, (i + 1) % 3)});
    size_t loop_edges = 0;
    for (size_t l = 0; l < piece.boundary_loops.size(); ++l) {
      const auto& loop = piece.boundary_loops[l];
      const int plane = piece.loop_plane[l];
      EXPECT_TRUE(plane == piece.plane_below || plane == piece.plane_above);
      EXPECT_GE(loop.size(), 3u);
      for (size_t k = 0; k < loop.size(); ++k) {
        const int a = loop[k], b = loop[(k + 1) % loop.size()];
        EXPECT_EQ(R.V(a, 2), s.planes[plane]);
        EXPECT_TRUE(directed.count({a, b})) << "loop edge not in the piece";
        EXPECT_FALSE(directed.count({b, a})) << "loop edge not on the boundary";
      }
      loop_edges += loop.size();
    }
    size_t boundary_edges = 0;
    for (const auto& [a, b] : directed) boundary_edges += !directed.count({b, a});
    EXPECT_EQ(loop_edges, boundary_edges);
  }
  for (int f = 0; f < R.num_faces(); ++f) EXPECT_EQ(seen[f], 1);
  EXPECT_EQ(euler_sum, euler_characteristic(mesh.F, nv));
}

TEST(Slice, SphereIntoCapsAndBands) {
  const TriMesh sphere = test::make_sphere(3);
  const SlicedMesh s = slice_mesh(sphere, even_planes(sphere, 5));
  expect_valid_slicing(sphere, s);
  ASSERT_EQ(s.pieces.size(), 6u);
  for (size_t p = 0; p < s.pieces.size(); ++p) {
    EXPECT_EQ(s.pieces[p].genus, 0);
    EXPECT_EQ(s.pieces[p].boundary_loops.size(), p == 0 || p == 5 ? 1u : 2u);
    EXPECT_EQ(s.pieces[p].plane_below, static_cast<int>(p) - 1);
    EXPECT_EQ(s.pieces[p].plane_above, p == 5 ? -1 : static_cast<int>(p));
  }
}

TEST(Slice, TestMeshesKeepTheirSurfaceAndTopology) {
  for (const std::string name : {"rotor.off", "joint.off", "eight.off", "helmet.off", "anchor.off", "couplingdown.off", "knot.off"}) {
    SCOPED_TRACE(name);
    const TriMesh mesh = test::load_test_mesh(name);
    for (int n : {1, 9, 40}) expect_valid_slicing(mesh, slice_mesh(mesh, even_planes(mesh, n)));
  }
}

TEST(Slice, TrianglesCrossedByManyPlanes) {
  // The icosahedron: every face crossed by several of 30 planes.
  const TriMesh ico = test::make_sphere(0);
  const SlicedMesh s = slice_mesh(ico, even_planes(ico, 30));
  expect_valid_slicing(ico, s);
  EXPECT_EQ(s.pieces.size(), 31u);
  EXPECT_GT(s.mesh.num_faces(), 10 * ico.num_faces());
}

TEST(Slice, FlatTorusCutThroughItsMiddle) {
  // Axis along z: a plane through the middle gives two annuli; the tube's equator vertices lie
  // exactly on that plane, so it is moved off them first.
  const TriMesh torus = test::make_torus(2.0, 0.5, 24, 12);
  const SlicedMesh s = slice_mesh(torus, {0.0});
  expect_valid_slicing(torus, s);
  EXPECT_EQ(s.nudged_planes, 1);
  ASSERT_EQ(s.planes.size(), 1u);
  EXPECT_NE(s.planes[0], 0.0);
  ASSERT_EQ(s.pieces.size(), 2u);
  for (const Piece& piece : s.pieces) {
    EXPECT_EQ(piece.genus, 0);
    EXPECT_EQ(piece.boundary_loops.size(), 2u);
  }
}

TEST(Slice, PlanesAreSortedDeduplicatedAndKeptInRange) {
  const TriMesh mesh = test::load_test_mesh("joint.off");
  const BoundingBox box = bounding_box(mesh.V);
  const double mid = box.min.z() + 0.37 * box.extent().z(), top = box.min.z() + 0.81 * box.extent().z();
  const SlicedMesh s = slice_mesh(mesh, {top, mid, mid, box.max.z() + 1, box.min.z() - 1, box.max.z(),
                                         std::numeric_limits<double>::quiet_NaN()});
  expect_valid_slicing(mesh, s);
  ASSERT_EQ(s.planes.size(), 2u);
  EXPECT_EQ(s.planes[0], mid);
  EXPECT_EQ(s.planes[1], top);
  const SlicedMesh none = slice_mesh(mesh, {});
  expect_valid_slicing(mesh, none);
  ASSERT_EQ(none.pieces.size(), 1u);
  EXPECT_EQ(none.pieces[0].genus, 2);
  EXPECT_EQ(none.mesh.F, mesh.F);
}

TEST(Slice, PlanesThroughVerticesAreMovedOffThem) {
  const TriMesh mesh = test::load_test_mesh("helmet.off");
  std::vector<double> planes;
  for (int v = 7; v < mesh.num_vertices(); v += 61) planes.push_back(mesh.V(v, 2));
  const SlicedMesh s = slice_mesh(mesh, planes);
  expect_valid_slicing(mesh, s);
  EXPECT_GT(s.nudged_planes, 0);
}

TEST(Slice, RejectsOpenMeshes) { EXPECT_THROW(slice_mesh(test::open_cylinder(), {0.5}), MeshError); }

}  // namespace
}  // namespace polycube
