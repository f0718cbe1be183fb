// Combinatorial structure of triangle meshes: edges, boundary loops, components, Euler
// characteristic and genus. Works on any index triple list (also non-manifold ones) so that
// validation can count problems before rejecting them.
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace polycube {

// Undirected edges of a triangle list and their incidences.
//   E     #E by 2 vertex indices, E(e,0) < E(e,1), sorted lexicographically
//   FE    #F by 3: FE(f,i) is the edge from F(f,i) to F(f,(i+1)%3)
//   EF    #E by 2: the first two faces on each edge (-1 where fewer)
//   face_count  #E: how many faces use each edge (1 boundary, 2 manifold, >2 non-manifold)
struct EdgeMap {
  Eigen::MatrixX2i E;
  Eigen::MatrixX3i FE;
  Eigen::MatrixX2i EF;
  Eigen::VectorXi face_count;

  int num_edges() const { return static_cast<int>(E.rows()); }
};

EdgeMap build_edge_map(const Eigen::MatrixX3i& F);

// Lists in one array (compressed rows): the items of key k are items[begin[k] .. begin[k + 1]),
// in the order the (key, item) pairs were given.
struct CompressedLists {
  std::vector<int> begin, items;
  CompressedLists() = default;
  // pairs: (key in 0..keys-1, item).
  CompressedLists(int keys, const std::vector<std::pair<int, int>>& pairs);
  const int* first(int k) const { return items.data() + begin[k]; }
  const int* last(int k) const { return items.data() + begin[k + 1]; }
  int count(int k) const { return begin[k + 1] - begin[k]; }
};

// The faces round each vertex, in increasing order.
CompressedLists vertex_faces(const Eigen::MatrixX3i& F, int num_vertices);

// How the faces meet along the edges: edges with one face (boundary), with more than two
// (non-manifold), and with two faces running through them in the same direction (inconsistently
// oriented). All zero for a closed, edge-manifold, consistently oriented mesh.
struct EdgeDefects {
  int boundary = 0;
  int nonmanifold = 0;
  int misoriented = 0;
};

// edges = build_edge_map(F).
EdgeDefects edge_defects(const Eigen::MatrixX3i& F, const EdgeMap& edges);

// Boundary loops of an edge-manifold mesh as ordered vertex cycles, each following the
// orientation of its faces. Edges used by one face only are boundary edges. Where boundary
// vertices are not manifold, loops are still closed but their split at such vertices is arbitrary.
std::vector<std::vector<int>> boundary_loops(const Eigen::MatrixX3i& F);

// Connected components of the faces (faces sharing a vertex are connected).
// Returns the component count; face_component (if given) gets #F component ids in 0..count-1,
// numbered in order of first face.
int connected_components(const Eigen::MatrixX3i& F, int num_vertices, Eigen::VectorXi* face_component = nullptr);

// Vertices whose incident faces do not form a single fan (disk or half-disk) around them.
// Only meaningful where every edge has at most two faces.
int count_nonmanifold_vertices(const Eigen::MatrixX3i& F, int num_vertices);

// Number of vertex indices in 0..num_vertices-1 used by no face.
int count_unreferenced_vertices(const Eigen::MatrixX3i& F, int num_vertices);

// V - E + F counting only vertices referenced by F.
int euler_characteristic(const Eigen::MatrixX3i& F, int num_vertices);

// Genus of an orientable 2-manifold with boundary: sum over components of (2 - chi_c - b_c) / 2.
int genus(const Eigen::MatrixX3i& F, int num_vertices);

}  // namespace polycube
