// Intrinsic Delaunay triangulation of a closed triangle mesh: the same vertices and the same
// metric (edge lengths of the input), re-triangulated by intrinsic edge flips until every edge is
// locally Delaunay. Its cotangent Laplacian has only non-negative weights, so discrete harmonic
// functions on it satisfy the maximum principle (used for the harmonic function of §3.1, eq. 1).
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

namespace polycube {

struct IntrinsicDelaunayOptions {
  // Edges with cot(alpha) + cot(beta) below -tolerance are flipped; the tolerance keeps
  // (nearly) cocircular quads, such as the rectangles of a grid, from flipping back and forth.
  double tolerance = 1e-10;
  // Upper bound on flips, as a multiple of the edge count (the Delaunay flip algorithm
  // terminates on its own; this only bounds the work on pathological inputs). 0 disables flips
  // and returns the input triangulation with its Euclidean edge lengths.
  double max_flips_per_edge = 50;
};

// A triangulation of the input surface on the input vertices. Because flips can join the same
// two vertices by several edges, connectivity is given by face adjacency, not by vertex pairs.
//   F              #F by 3 vertex ids, counter-clockwise like the input; no face repeats a vertex
//   adjacent       #F by 3: adjacent(f,i) is the face across edge i of f, the edge from F(f,i) to
//                  F(f,(i+1)%3)
//   adjacent_edge  #F by 3: the index of that same edge inside adjacent(f,i), so that
//                  F(adjacent(f,i), adjacent_edge(f,i)) == F(f,(i+1)%3)
//                  (surfaces with boundary, e.g. from flat_metric: both -1 across a boundary edge;
//                  intrinsic_delaunay itself only takes closed meshes)
//   length         #F by 3 intrinsic length of edge i of f, in the units of the input
struct IntrinsicTriangulation {
  Eigen::MatrixX3i F;
  Eigen::MatrixX3i adjacent;
  Eigen::MatrixX3i adjacent_edge;
  Eigen::MatrixX3d length;
  int flips = 0;
  // Edges still non-Delaunay because flipping them would make an edge from a vertex to itself
  // (the link of a vertex must stay a cycle of other vertices for PL Morse theory) or leave a
  // vertex with only two edges, or because the flip bound was reached. Rare: such edges occur
  // next to vertices of very small cone angle (spikes), e.g. 1 on femur.off.
  int non_delaunay_edges = 0;
  // Smallest cot(alpha) + cot(beta) over all edges after flipping (>= -tolerance when every
  // edge is Delaunay).
  double min_cotan_sum = 0;
};

// Flips the edges of `mesh` intrinsically (lengths only, vertices never move) until every edge
// satisfies cot(alpha) + cot(beta) >= -tolerance, processing edges from a stack.
//   mesh  closed, edge-manifold, consistently oriented triangle mesh without zero-length edges
// Throws MeshError if an edge does not have exactly two faces traversing it in opposite
// directions, or if an edge has zero length.
IntrinsicTriangulation intrinsic_delaunay(const TriMesh& mesh, const IntrinsicDelaunayOptions& options = {});

}  // namespace polycube
