// The point of the plane where the smallest of a few affine functions is largest: the linear
// programme max t s.t. a_k + g_k · q >= t, solved by enumerating its candidate vertices. Used for
// the point of a vertex's tangent plane where the smallest signed area of its fan is largest (the
// smoothing's kernel point, the last untangling's widest fan point): each signed area is affine in
// the vertex's position.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace polycube {

struct MaxMinPoint {
  Eigen::Vector2d q = Eigen::Vector2d::Zero();
  double value = 0;  // min_k (a_k + g_k · q)
};

// Over the square |q.x|, |q.y| <= radius (radius = +infinity: the whole plane), starting from q = 0:
// the candidates are the square's corners, the points of its sides where two functions are equal,
// and the points where three are (the last alone when the plane is unbounded); the best is
// returned (q = 0 when none is better). a and g have the same size.
inline MaxMinPoint max_min_affine(const std::vector<double>& a, const std::vector<Eigen::Vector2d>& g,
                                  double radius = std::numeric_limits<double>::infinity()) {
  const size_t n = a.size();
  auto smallest = [&](const Eigen::Vector2d& q) {
    double m = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < n; ++k) m = std::min(m, a[k] + g[k].dot(q));
    return m;
  };
  MaxMinPoint best;
  best.value = smallest(best.q);
  const bool bounded = std::isfinite(radius);
  auto consider = [&](const Eigen::Vector2d& q) {
    if (!q.allFinite()) return;
    if (bounded && (std::abs(q.x()) > radius * (1 + 1e-12) || std::abs(q.y()) > radius * (1 + 1e-12))) return;
    if (const double m = smallest(q); m > best.value) best = {q, m};
  };
  if (bounded) {
    for (int sx : {-1, 1})
      for (int sy : {-1, 1}) consider(Eigen::Vector2d(sx * radius, sy * radius));
    for (size_t i = 0; i < n; ++i)
      for (size_t j = i + 1; j < n; ++j) {
        // (g_i - g_j) · q = a_j - a_i on a side x = ±radius or y = ±radius
        const Eigen::Vector2d d = g[i] - g[j];
        const double e = a[j] - a[i];
        for (int side : {-1, 1}) {
          if (d.y() != 0) consider(Eigen::Vector2d(side * radius, (e - d.x() * side * radius) / d.y()));
          if (d.x() != 0) consider(Eigen::Vector2d((e - d.y() * side * radius) / d.x(), side * radius));
        }
      }
  }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
      for (size_t k = j + 1; k < n; ++k) {
        // a_i + g_i q = a_j + g_j q = a_k + g_k q
        Eigen::Matrix2d A;
        A.row(0) = (g[i] - g[j]).transpose();
        A.row(1) = (g[i] - g[k]).transpose();
        const double det = A.determinant();
        if (!(std::abs(det) > 1e-300)) continue;
        consider(A.inverse() * Eigen::Vector2d(a[j] - a[i], a[k] - a[i]));
      }
  return best;
}

}  // namespace polycube
