// The multi-hole disk D_{M_i} of §3.3 (Fig. 5): a piece laid out in the plane with its uniform
// flat metric. The outer loop becomes the unit circle, every other loop a circle inside it. The
// next step (§3.4) uses it to parametrise the boundary and to place the cuts between the circles.
#pragma once

#include "polycube/flat_metric.h"
#include "polycube/mesh.h"

#include <Eigen/Core>

#include <vector>

namespace polycube {

// The layout and how good it is.
//   uv            #V(piece) by 2 positions of the piece's vertices
//   inserted_uv   positions of the vertices flat_metric inserted (FlatMetric::inserted_vertices,
//                 vertex ids #V(piece) + row), which lie on the boundary circles
//   centres, radii  per loop (in the order of FlatMetric::loops): the circle fitted to the
//                 loop's vertices (least squares on the distance); the outer one is centred at
//                 the origin with radius 1, its loop's first vertex on the positive x axis
//   outer_loop    index of the outer loop
//   max_roundness_error  over all loops: max |distance to the centre − radius| / radius
//   layout_error  max over the edges of the intrinsic triangulation of | laid-out length − metric
//                 length |, in units of the outer radius (accumulated rounding of the layout)
//   flipped_triangles  triangles of the intrinsic triangulation (the one the metric lives on)
//                 with signed area <= 0 at the laid-out positions: 0 for an embedding
//   flipped_input_triangles  triangles of the piece's own connectivity with signed area <= 0
//                 when drawn with straight edges at the laid-out positions (the intrinsic
//                 triangulation is an embedding; the input's need not be — e.g. slivers along a
//                 loop whose apex falls outside the chord once the loop is a circle)
//   min_circle_gap  smallest distance between two circles (or between an inner circle and the
//                 outer one), relative to the outer radius: how far the holes are from touching
//                 (can be slightly negative for coarse loops: the region is bounded by the
//                 inscribed polygons, and circles bulge past each other's chords)
//   min_radius    smallest circle radius (1 without holes). A tube of length h and
//                 circumference c in the piece becomes a hole of radius about e^{−2πh/c}: the
//                 layout loses relative precision around holes below ~1e-12
struct CircleDomain {
  Eigen::MatrixX2d uv;
  Eigen::MatrixX2d inserted_uv;
  std::vector<Eigen::Vector2d> centres;
  std::vector<double> radii;
  int outer_loop = 0;
  double max_roundness_error = 0;
  double layout_error = 0;
  int flipped_triangles = 0;
  int flipped_input_triangles = 0;
  double min_circle_gap = 0;
  double min_radius = 1;
};

// Lays out the intrinsic triangulation of `metric` (computed by flat_metric(piece, ...)) in the
// plane by unfolding its triangles breadth-first from the face deepest inside, so the rounding
// error grows with the square root of the face count only. Each vertex keeps the position of its
// first placement. Then the similarity taking the outer loop's circle to the unit circle, its
// first vertex to (1, 0).
//   piece   the mesh flat_metric was given (for its face list and vertex count)
// Throws std::invalid_argument if metric does not belong to piece, AlgorithmError if the
// triangulation is not connected.
CircleDomain circle_domain(const TriMesh& piece, const FlatMetric& metric);

}  // namespace polycube
