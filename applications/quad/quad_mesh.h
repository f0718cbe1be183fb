// The all-quad mesh the quad application produces, and the combinatorial checks every stage of it
// (and its tests) rely on: closed, 2-manifold, consistently oriented, valences.
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace polycube {

// A quad mesh.
//   V  #V by 3 vertex positions
//   Q  #Q by 4 vertex indices per quad, counter-clockwise seen from outside
struct QuadMesh {
  Eigen::MatrixX3d V;
  Eigen::MatrixX4i Q;

  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_quads() const { return static_cast<int>(Q.rows()); }
};

// Combinatorics of a quad mesh, counted (never thrown) so that callers can report everything.
//   edges               undirected edges
//   boundary_edges      edges with one quad
//   nonmanifold_edges   edges with more than two quads
//   misoriented_edges   edges with two quads that traverse it in the same direction
//   nonmanifold_vertices  vertices whose quads do not form one fan (disk) around them
//   unreferenced_vertices
//   components          connected components of the quads (sharing a vertex connects)
//   euler               V - E + F over referenced vertices
//   valence             #V: quads around each vertex (0 for unreferenced ones)
struct QuadTopology {
  int edges = 0;
  int boundary_edges = 0;
  int nonmanifold_edges = 0;
  int misoriented_edges = 0;
  int nonmanifold_vertices = 0;
  int unreferenced_vertices = 0;
  int components = 0;
  int euler = 0;
  Eigen::VectorXi valence;

  // Closed, edge- and vertex-manifold, consistently oriented, no unreferenced vertex.
  bool closed_manifold() const {
    return boundary_edges == 0 && nonmanifold_edges == 0 && misoriented_edges == 0 && nonmanifold_vertices == 0 &&
           unreferenced_vertices == 0;
  }
  // (2 - euler) / 2 for a closed connected orientable surface.
  int genus() const { return (2 - euler) / 2; }
};

// Throws std::invalid_argument for an index outside 0..#V-1 or a quad with a repeated corner.
QuadTopology quad_topology(const QuadMesh& mesh);

// Undirected edges, #E by 2 with E(e,0) < E(e,1), sorted.
Eigen::MatrixX2i quad_edges(const Eigen::MatrixX4i& Q);

// Vertices adjacent to each vertex along quad edges, ascending.
std::vector<std::vector<int>> vertex_neighbours(const Eigen::MatrixX4i& Q, int num_vertices);

// Quads around each vertex.
std::vector<std::vector<int>> vertex_quads(const Eigen::MatrixX4i& Q, int num_vertices);

// Two triangles per quad, split along the shorter diagonal (the split that keeps a folded quad
// closest to its surface), for distance measurements and triangle-only tools.
TriMesh triangulate_quads(const QuadMesh& mesh);

// The corners (0..3) of quad q's two triangles as triangulate_quads splits it (positions from
// mesh.V): along the diagonal 0-2 when it is not longer than 1-3, else along 1-3.
std::array<std::array<int, 3>, 2> quad_triangle_corners(const QuadMesh& mesh, int q);

// The quads as polygon lists, for write_polygon_mesh.
std::vector<std::vector<int>> quad_polygons(const QuadMesh& mesh);

}  // namespace polycube
