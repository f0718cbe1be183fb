// How good a quad remesh is (issue 7's report): topology, irregular vertices, right angles,
// flipped or degenerate quads, and distance to the surface it stands for.
#pragma once

#include "applications/quad/quad_mesh.h"
#include "applications/quad/surface_projector.h"
#include "polycube/polycube_distance.h"

#include <cmath>
#include <vector>

namespace polycube {

struct QuadQualityOptions {
  // Measure the Hausdorff distance (sampling; the slowest part).
  bool hausdorff = true;
  HausdorffOptions sampling;
  // A quad is degenerate when its area or an edge is below this times the reference's diagonal
  // (squared for the area).
  double degenerate_tolerance = 1e-10;
  // A corner is sharp when its angle is this many degrees or more from 90° either way (below 30°
  // or above 150° by default: a scaled Jacobian below 0.5 there).
  double sharp_degrees = 60;
  // Threads for the closest points and the Hausdorff samples (0: one per hardware thread); the
  // figures do not depend on it.
  int threads = 0;
};

// Everything measured (angles in degrees, lengths in input units).
//   quads, vertices; topology of the quads
//   genus                   (2 - euler) / 2 of a closed connected result, else -1
//   irregular_vertices      valence != 4
//   irregular_at_corners    of those, how many are in the given corner list
//   corners_irregular       corners given that are irregular (= corners count when the map keeps them)
//   angle_deviation_*       |corner angle - 90°| over all quad corners: mean, 95th percentile, max
//   aspect_ratio_*          longest / shortest edge per quad: mean, max
//   flipped_quads           quads whose normal (cross product of the diagonals) points against
//                           quad_surface_normal (the criterion smooth_quads keeps)
//   inverted_corners        quad corners whose two edges turn against it (non-convex or folded
//                           quads)
//   sharp_corners           quad corners more than sharp_degrees from 90° (nearly shut or flat)
//   degenerate_quads        zero area or zero-length edge
//   max_distance_to_surface largest vertex distance to the reference surface
//   hausdorff               sampled two-sided distance between the triangulated quads and the
//                           reference (0 when not measured), hausdorff_percent of its diagonal
//   quads_to_model, model_to_quads  the two one-sided distances (largest), and
//   farthest_on_quads, farthest_on_model  where each occurs (to find what the quads miss)
//   mean_distance           mean sample distance, both directions together
//   diagonal                of the reference's bounding box
struct QuadQuality {
  int quads = 0;
  int vertices = 0;
  QuadTopology topology;
  int genus = -1;
  int irregular_vertices = 0;
  int irregular_at_corners = 0;
  int corners_irregular = 0;
  double angle_deviation_mean = 0;
  double angle_deviation_p95 = 0;
  double angle_deviation_max = 0;
  double aspect_ratio_mean = 0;
  double aspect_ratio_max = 0;
  int flipped_quads = 0;
  int inverted_corners = 0;
  int sharp_corners = 0;
  int degenerate_quads = 0;
  double max_distance_to_surface = 0;
  bool hausdorff_measured = false;
  double hausdorff = 0;
  double hausdorff_percent = 0;
  double quads_to_model = 0;
  double model_to_quads = 0;
  Eigen::Vector3d farthest_on_quads = Eigen::Vector3d::Zero();
  Eigen::Vector3d farthest_on_model = Eigen::Vector3d::Zero();
  double mean_distance = 0;
  double diagonal = 0;
  double seconds = 0;
};

// The surface's normal for a quad: that of the triangle closest to the quad's centre (a face
// normal, so a quad on one face of a polycube gets exactly that face's normal).
Eigen::Vector3d quad_surface_normal(const SurfaceProjector& surface, const Eigen::Vector3d corners[4]);
// The same from a closest-point query already made for the centre (centre: the closest hit to
// the mean of the corners), so callers can pass search hints.
inline Eigen::Vector3d quad_surface_normal(const SurfaceProjector& surface, const SurfaceHit& centre) {
  return surface.face_normal(centre.face);
}

// Whether the corner between edges a and b (from the corner to its two neighbours) is sharp: its
// angle more than sharp_degrees from 90° either way (measure_quads' sharp_corners; false for an
// edge of length 0 or sharp_degrees <= 0).
inline bool sharp_corner(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double sharp_degrees) {
  const double lengths = a.norm() * b.norm();
  return sharp_degrees > 0 && lengths > 0 && std::abs(a.dot(b)) > std::sin(sharp_degrees * M_PI / 180) * lengths;
}

// The quads measure_quads counts as flipped or degenerate, by index.
std::vector<int> bad_quads(const QuadMesh& quads, const SurfaceProjector& reference, const QuadQualityOptions& options = {});

// Measures quads against the surface they approximate.
//   corners  vertex indices expected to be irregular (the polycube's corners), may be empty
// Throws std::invalid_argument for a bad quad index.
QuadQuality measure_quads(const QuadMesh& quads, const SurfaceProjector& reference, const std::vector<int>& corners,
                          const QuadQualityOptions& options = {});

}  // namespace polycube
