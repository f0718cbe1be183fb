// The closest point of a triangle in space to a point (Ericson, Real-Time Collision Detection,
// 5.1.5), with its barycentric coordinates: for local projections onto meshes and distances to
// single triangles, where an AABB tree would be overkill.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>

namespace polycube {

struct TriangleClosest {
  Eigen::Vector3d point;
  Eigen::Vector3d bary;  // of point in (a, b, c), each >= 0, summing to 1
};

inline TriangleClosest closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                           const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  if (ab.cross(ac).squaredNorm() == 0) {
    // A degenerate triangle (corners on a line, or equal): the nearest point of its sides (the
    // regions below assume an area; with two equal corners they divided 0 by 0 or took the
    // wrong side).
    const auto on_side = [&p](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
      const Eigen::Vector3d e = v - u;
      const double length = e.squaredNorm();
      return length > 0 ? std::clamp((p - u).dot(e) / length, 0.0, 1.0) : 0.0;
    };
    const double t_ab = on_side(a, b), t_bc = on_side(b, c), t_ca = on_side(c, a);
    TriangleClosest best{a + t_ab * ab, {1 - t_ab, t_ab, 0}};
    const TriangleClosest from_bc{b + t_bc * (c - b), {0, 1 - t_bc, t_bc}};
    const TriangleClosest from_ca{c + t_ca * (a - c), {t_ca, 0, 1 - t_ca}};
    if ((from_bc.point - p).squaredNorm() < (best.point - p).squaredNorm()) best = from_bc;
    if ((from_ca.point - p).squaredNorm() < (best.point - p).squaredNorm()) best = from_ca;
    return best;
  }
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {a, {1, 0, 0}};
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {b, {0, 1, 0}};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {a + v * ab, {1 - v, v, 0}};
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {c, {0, 0, 1}};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {a + w * ac, {1 - w, 0, w}};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + w * (c - b), {0, 1 - w, w}};
  }
  const double denom = 1 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {a + ab * v + ac * w, {1 - v - w, v, w}};
}

}  // namespace polycube
