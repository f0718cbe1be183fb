#include "applications/quad/quad_quality.h"

#include "polycube/parallel.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

namespace polycube {

namespace {
constexpr double kDegrees = 57.29577951308232;

// Quad q's corners, the surface's normal for it and whether it is flipped or degenerate (edges
// or area at most the given ones).
struct QuadCheck {
  Eigen::Vector3d p[4];
  Eigen::Vector3d normal;
  bool flipped = false;
  bool degenerate = false;
};
QuadCheck check_quad(const QuadMesh& quads, int q, const SurfaceProjector& reference, double min_length, double min_area) {
  QuadCheck c;
  for (int k = 0; k < 4; ++k) c.p[k] = quads.V.row(quads.Q(q, k));
  c.normal = quad_surface_normal(reference, c.p);
  const Eigen::Vector3d diagonal_cross = (c.p[2] - c.p[0]).cross(c.p[3] - c.p[1]);
  c.flipped = diagonal_cross.dot(c.normal) <= 0;
  double shortest = INFINITY;
  for (int k = 0; k < 4; ++k) shortest = std::min(shortest, (c.p[(k + 1) % 4] - c.p[k]).norm());
  c.degenerate = shortest <= min_length || diagonal_cross.norm() / 2 <= min_area;
  return c;
}
}  // namespace

Eigen::Vector3d quad_surface_normal(const SurfaceProjector& surface, const Eigen::Vector3d corners[4]) {
  return quad_surface_normal(surface, surface.closest((corners[0] + corners[1] + corners[2] + corners[3]) / 4));
}

std::vector<int> bad_quads(const QuadMesh& quads, const SurfaceProjector& reference, const QuadQualityOptions& options) {
  const double diagonal = bounding_box(reference.surface().V).diagonal();
  const double min_length = options.degenerate_tolerance * diagonal;
  const double min_area = min_length * diagonal;
  std::vector<char> bad(quads.num_quads(), 0);
  parallel_range(quads.num_quads(), options.threads, [&](int q) {
    const QuadCheck c = check_quad(quads, q, reference, min_length, min_area);
    bad[q] = c.flipped || c.degenerate;
  });
  std::vector<int> out;
  for (int q = 0; q < quads.num_quads(); ++q)
    if (bad[q]) out.push_back(q);
  return out;
}

QuadQuality measure_quads(const QuadMesh& quads, const SurfaceProjector& reference, const std::vector<int>& corners,
                          const QuadQualityOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  QuadQuality r;
  r.quads = quads.num_quads();
  r.vertices = quads.num_vertices();
  r.topology = quad_topology(quads);
  if (r.topology.closed_manifold() && r.topology.components == 1) r.genus = r.topology.genus();
  r.diagonal = bounding_box(reference.surface().V).diagonal();

  const std::set<int> corner_set(corners.begin(), corners.end());
  for (int v = 0; v < r.vertices; ++v) {
    const bool irregular = r.topology.valence[v] != 4 && r.topology.valence[v] != 0;
    r.irregular_vertices += irregular;
    if (irregular && corner_set.count(v)) ++r.irregular_at_corners;
  }
  for (int c : corner_set) r.corners_irregular += c >= 0 && c < r.vertices && r.topology.valence[c] != 4;

  std::vector<double> deviation;
  deviation.reserve(4 * r.quads);
  const double min_length = options.degenerate_tolerance * r.diagonal;
  const double min_area = options.degenerate_tolerance * r.diagonal * r.diagonal;
  double aspect_sum = 0;
  // The closest points (the slow part) on the threads, then everything summed in order.
  std::vector<double> vertex_distance(r.vertices, 0);
  parallel_range(r.vertices, options.threads, [&](int v) {
    if (r.topology.valence[v] > 0) vertex_distance[v] = reference.closest(quads.V.row(v).transpose()).distance;
  });
  for (double d : vertex_distance) r.max_distance_to_surface = std::max(r.max_distance_to_surface, d);
  std::vector<QuadCheck> checks(r.quads);
  parallel_range(r.quads, options.threads, [&](int q) { checks[q] = check_quad(quads, q, reference, min_length, min_area); });
  for (int q = 0; q < r.quads; ++q) {
    const QuadCheck& c = checks[q];
    const Eigen::Vector3d* p = c.p;
    r.flipped_quads += c.flipped;
    r.degenerate_quads += c.degenerate;
    double shortest = INFINITY, longest = 0;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d next = p[(k + 1) % 4] - p[k], previous = p[(k + 3) % 4] - p[k];
      shortest = std::min(shortest, next.norm());
      longest = std::max(longest, next.norm());
      const double angle = std::atan2(next.cross(previous).norm(), next.dot(previous)) * kDegrees;
      deviation.push_back(std::abs(angle - 90));
      r.sharp_corners += sharp_corner(next, previous, options.sharp_degrees);
      if (next.cross(previous).dot(c.normal) <= 0) ++r.inverted_corners;
    }
    const double aspect = shortest > 0 ? longest / shortest : INFINITY;
    aspect_sum += aspect;
    r.aspect_ratio_max = std::max(r.aspect_ratio_max, aspect);
  }
  if (!deviation.empty()) {
    double sum = 0;
    for (double d : deviation) sum += d;
    r.angle_deviation_mean = sum / deviation.size();
    r.aspect_ratio_mean = aspect_sum / r.quads;
    const size_t k95 = std::min(deviation.size() - 1, static_cast<size_t>(std::ceil(0.95 * deviation.size())) - 1);
    std::nth_element(deviation.begin(), deviation.begin() + k95, deviation.end());
    r.angle_deviation_p95 = deviation[k95];
    r.angle_deviation_max = *std::max_element(deviation.begin(), deviation.end());
  }

  if (options.hausdorff && r.quads > 0) {
    HausdorffOptions sampling = options.sampling;
    sampling.threads = options.threads;
    const HausdorffDistance d = hausdorff_distance(triangulate_quads(quads), reference.sampled(), sampling);
    r.hausdorff_measured = true;
    r.hausdorff = d.hausdorff;
    r.hausdorff_percent = r.diagonal > 0 ? 100 * d.hausdorff / r.diagonal : 0;
    r.quads_to_model = d.a_to_b;
    r.model_to_quads = d.b_to_a;
    r.farthest_on_quads = d.a_farthest;
    r.farthest_on_model = d.b_farthest;
    r.mean_distance = (d.mean_a_to_b + d.mean_b_to_a) / 2;
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace polycube
