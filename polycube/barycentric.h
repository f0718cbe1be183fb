// Barycentric coordinates in a triangle, shared by the map's point location, its overlay and its
// smoothing.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>

namespace polycube {

inline double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Of p in the 2D triangle (a, b, c), which must have non-zero area.
inline Eigen::Vector3d barycentric2(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                                    const Eigen::Vector2d& p) {
  const double area2 = cross2(b - a, c - a);
  return Eigen::Vector3d(cross2(b - p, c - p), cross2(c - p, a - p), cross2(a - p, b - p)) / area2;
}

// Of x projected onto the plane of the 3D triangle (a, b, c); -infinity for a degenerate triangle.
inline Eigen::Vector3d barycentric3(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                    const Eigen::Vector3d& x) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double nn = n.squaredNorm();
  if (!(nn > 0)) return Eigen::Vector3d::Constant(-INFINITY);
  const double wa = (c - b).cross(x - b).dot(n) / nn;
  const double wb = (a - c).cross(x - c).dot(n) / nn;
  return {wa, wb, 1 - wa - wb};
}

// Negative coordinates set to 0 and the rest renormalised (the centroid when none is left).
inline Eigen::Vector3d clamp_bary(Eigen::Vector3d w) {
  w = w.cwiseMax(0.0);
  const double s = w.sum();
  return s > 0 ? Eigen::Vector3d(w / s) : Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3);
}

}  // namespace polycube
