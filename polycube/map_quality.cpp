#include "polycube/map_quality.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace polycube {

namespace {

// Triangles at or below this fraction of their mesh's total area are degenerate (metrics.md).
constexpr double kDegenerateArea = 1e-14;

// Value at sorted position ceil(p·n) - 1 (nearest rank); values is non-empty and gets reordered.
double nearest_rank(std::vector<double>& values, double p) {
  const auto n = static_cast<double>(values.size());
  const auto rank = static_cast<size_t>(std::max(0.0, std::ceil(p * n) - 1));
  const auto it = values.begin() + static_cast<std::ptrdiff_t>(std::min(rank, values.size() - 1));
  std::nth_element(values.begin(), it, values.end());
  return *it;
}

Eigen::Vector3d row(const Eigen::MatrixX3d& X, int i) { return X.row(i).transpose(); }

}  // namespace

double triangle_angle_distortion(const Eigen::Vector3d p[3], const Eigen::Vector3d q[3]) {
  const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
  const double image_area = 0.5 * (q[1] - q[0]).cross(q[2] - q[0]).norm();
  if (!(area > 0 && image_area > 0)) return std::numeric_limits<double>::infinity();
  // cot(angle at p_c) = (e·e') / (2 A(T)) for the two edges e, e' leaving p_c.
  double energy = 0;
  for (int c = 0; c < 3; ++c) {
    const int a = (c + 1) % 3, b = (c + 2) % 3;
    energy += (p[a] - p[c]).dot(p[b] - p[c]) * (q[b] - q[a]).squaredNorm();
  }
  return energy / (2 * area) / (4 * image_area);
}

DistortionStats map_distortion(const TriMesh& domain, const Eigen::MatrixX3d& image) {
  const int nv = domain.num_vertices(), nf = domain.num_faces();
  if (nf == 0) throw std::invalid_argument("map_distortion: domain has no faces");
  if (image.rows() != nv)
    throw std::invalid_argument("map_distortion: image has " + std::to_string(image.rows()) + " rows, domain has " +
                                std::to_string(nv) + " vertices");
  if (domain.F.minCoeff() < 0 || domain.F.maxCoeff() >= nv)
    throw std::invalid_argument("map_distortion: face index out of range [0, " + std::to_string(nv) + ")");
  if (!domain.V.allFinite()) throw std::invalid_argument("map_distortion: domain has non-finite vertices");

  // Unnormalised areas of T and T'; image triangles with a non-finite vertex get NaN.
  std::vector<double> area(nf), image_area(nf);
  double total = 0, total_image = 0;
  for (int f = 0; f < nf; ++f) {
    const int i = domain.F(f, 0), j = domain.F(f, 1), k = domain.F(f, 2);
    area[f] = 0.5 * (row(domain.V, j) - row(domain.V, i)).cross(row(domain.V, k) - row(domain.V, i)).norm();
    total += area[f];
    const bool finite = image.row(i).allFinite() && image.row(j).allFinite() && image.row(k).allFinite();
    image_area[f] = finite ? 0.5 * (row(image, j) - row(image, i)).cross(row(image, k) - row(image, i)).norm()
                           : std::numeric_limits<double>::quiet_NaN();
    if (finite) total_image += image_area[f];
  }
  if (!(total > 0)) throw std::invalid_argument("map_distortion: domain has zero area");

  DistortionStats stats;
  stats.triangles = nf;
  std::vector<double> angle, area_change;
  angle.reserve(nf);
  area_change.reserve(nf);
  double weight_sum = 0, angle_sum = 0, area_sum = 0;
  for (int f = 0; f < nf; ++f) {
    const bool domain_degenerate = area[f] <= kDegenerateArea * total;
    // NaN (non-finite vertex) fails the comparison and counts as degenerate.
    const bool image_degenerate = !(image_area[f] > kDegenerateArea * total_image);
    stats.degenerate_domain += domain_degenerate;
    stats.degenerate_image += image_degenerate;
    if (domain_degenerate || image_degenerate) continue;

    // T = (p0, p1, p2) on the domain, T' = (q0, q1, q2) its image; edge i is opposite vertex i.
    const Eigen::Vector3d p[3] = {row(domain.V, domain.F(f, 0)), row(domain.V, domain.F(f, 1)),
                                  row(domain.V, domain.F(f, 2))};
    const Eigen::Vector3d q[3] = {row(image, domain.F(f, 0)), row(image, domain.F(f, 1)), row(image, domain.F(f, 2))};
    // Both cotangents and the ratio a'²/A(T') are scale-invariant, so the normalisation does not
    // change ε_angle.
    const double eps_angle = triangle_angle_distortion(p, q);
    const double ratio = (area[f] / total) / (image_area[f] / total_image);
    const double eps_area = 0.5 * (ratio + 1 / ratio);
    const double weight = image_area[f] / total_image;

    weight_sum += weight;
    angle_sum += weight * eps_angle;
    area_sum += weight * eps_area;
    angle.push_back(eps_angle);
    area_change.push_back(eps_area);
  }

  if (angle.empty()) {
    const double inf = std::numeric_limits<double>::infinity();
    stats.eps_angle = stats.eps_area = inf;
    stats.angle_p50 = stats.angle_p95 = stats.angle_max = inf;
    stats.area_p50 = stats.area_p95 = stats.area_max = inf;
    return stats;
  }
  stats.eps_angle = angle_sum / weight_sum;
  stats.eps_area = area_sum / weight_sum;
  stats.angle_max = *std::max_element(angle.begin(), angle.end());
  stats.area_max = *std::max_element(area_change.begin(), area_change.end());
  stats.angle_p50 = nearest_rank(angle, 0.5);
  stats.angle_p95 = nearest_rank(angle, 0.95);
  stats.area_p50 = nearest_rank(area_change, 0.5);
  stats.area_p95 = nearest_rank(area_change, 0.95);
  return stats;
}

}  // namespace polycube
