// Internal (CGAL; include only from engine .cpp files): the AABB tree types over a mesh's
// triangles that the distance measures and the audit use for closest points.
#pragma once

#include "polycube/mesh.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <vector>

namespace polycube::triangle_tree {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;

// CGAL's projection of p onto triangle t (Kernel's Construct_projected_point_3, CGAL 5.5), the
// same arithmetic step for step in doubles, so the same bits, without the kernel's generic
// constructions (planes, lines, vectors through functors), which were the largest single cost of
// the untangling and of the quads' relaxation. Its steps: p projected onto t's plane; if that
// point lies outside an edge whose span holds it, its projection onto the edge's line; else, if
// outside, the nearest corner; else the point itself. A degenerate triangle goes to CGAL.
inline Point projected_point(const Triangle& t, const Point& p) {
  const double t0x = t[0].x(), t0y = t[0].y(), t0z = t[0].z();
  const double t1x = t[1].x(), t1y = t[1].y(), t1z = t[1].z();
  const double t2x = t[2].x(), t2y = t[2].y(), t2z = t[2].z();
  // The supporting plane ax + by + cz + d = 0 (plane_from_pointsC3).
  const double rpx = t0x - t2x, rpy = t0y - t2y, rpz = t0z - t2z;
  const double rqx = t1x - t2x, rqy = t1y - t2y, rqz = t1z - t2z;
  const double a = rpy * rqz - rqy * rpz, b = rpz * rqx - rqz * rpx, c = rpx * rqy - rqx * rpy;
  const double d = -a * t2x - b * t2y - c * t2z;
  if (a == 0 && b == 0 && c == 0) return Kernel().construct_projected_point_3_object()(t, p);
  // p projected onto it (projection_planeC3).
  const double lambda = (a * p.x() + b * p.y() + c * p.z() + d) / (a * a + b * b + c * c);
  const double qx = p.x() - lambda * a, qy = p.y() - lambda * b, qz = p.z() - lambda * c;
  // The edges (p1, p2) in turn: q outside it (turning against the normal) and within its span:
  // q projected onto its line.
  bool outside = false;
  const auto edge = [&](double p1x, double p1y, double p1z, double p2x, double p2y, double p2z, Point& result) {
    const double ux = p2x - p1x, uy = p2y - p1y, uz = p2z - p1z;
    const double sx = qx - p1x, sy = qy - p1y, sz = qz - p1z;
    const double vx = uy * sz - uz * sy, vy = uz * sx - ux * sz, vz = ux * sy - uy * sx;
    if (vx * a + vy * b + vz * c < 0) {
      if (sx * ux + sy * uy + sz * uz >= 0 && (qx - p2x) * (p1x - p2x) + (qy - p2y) * (p1y - p2y) + (qz - p2z) * (p1z - p2z) >= 0) {
        const double along = (ux * sx + uy * sy + uz * sz) / (ux * ux + uy * uy + uz * uz);
        result = Point(p1x + along * ux, p1y + along * uy, p1z + along * uz);
        return true;
      }
      outside = true;
    }
    return false;
  };
  Point result;
  if (edge(t0x, t0y, t0z, t1x, t1y, t1z, result) || edge(t1x, t1y, t1z, t2x, t2y, t2z, result) ||
      edge(t2x, t2y, t2z, t0x, t0y, t0z, result))
    return result;
  if (!outside) return Point(qx, qy, qz);
  // The corner nearest q, the first of equals (nearest_point_3).
  const auto squared = [&](double x, double y, double z) { return (qx - x) * (qx - x) + (qy - y) * (qy - y) + (qz - z) * (qz - z); };
  const double d0 = squared(t0x, t0y, t0z), d1 = squared(t1x, t1y, t1z), d2 = squared(t2x, t2y, t2z);
  if (d1 >= d0 && d2 >= d0) return t[0];
  if (d2 >= d1) return t[1];
  return t[2];
}

// CGAL's AABB traits with the two tests a closest-point search repeats at every node and leaf in
// plain doubles: a leaf's closest point by projected_point, and whether a box comes within the
// current closest distance by the squared distance to the box (CGAL builds a sphere). The same
// comparisons in the same order as CGAL's, so the same answers bit for bit. Everything else is
// CGAL's.
template <class Primitive>
class ClosestPointTraits : public CGAL::AABB_traits<Kernel, Primitive> {
  using Base = CGAL::AABB_traits<Kernel, Primitive>;

 public:
  class Closest_point {
   public:
    explicit Closest_point(const ClosestPointTraits& traits) : traits_(traits) {}
    // The projection of p onto primitive's triangle, or bound when that is farther from p.
    Point operator()(const Point& p, const Primitive& primitive, const Point& bound) const {
      const Point q = projected_point(CGAL::internal::Primitive_helper<Base>::get_datum(primitive, traits_), p);
      return CGAL::squared_distance(p, q) > CGAL::squared_distance(p, bound) ? bound : q;
    }

   private:
    const ClosestPointTraits& traits_;
  };
  class Compare_distance {
   public:
    // SMALLER when the box comes within p's distance to bound (its inside counting as distance 0).
    CGAL::Comparison_result operator()(const Point& p, const CGAL::Bbox_3& box, const Point& bound) const {
      double gap = 0;
      for (int i = 0; i < 3; ++i) {
        if (p[i] < box.min(i)) {
          const double d = box.min(i) - p[i];
          gap += d * d;
        } else if (p[i] > box.max(i)) {
          const double d = p[i] - box.max(i);
          gap += d * d;
        }
      }
      return gap <= CGAL::squared_distance(p, bound) ? CGAL::SMALLER : CGAL::LARGER;
    }
  };
  Closest_point closest_point_object() const { return Closest_point(*this); }
  Compare_distance compare_distance_object() const { return Compare_distance(); }
};

using Primitive = CGAL::AABB_triangle_primitive<Kernel, Iterator>;
using Tree = CGAL::AABB_tree<ClosestPointTraits<Primitive>>;

inline Point point(const TriMesh& mesh, int v) { return Point(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)); }

// One CGAL triangle per face, in face order (a tree built on them reports face ids as iterator
// offsets).
inline std::vector<Triangle> triangles_of(const TriMesh& mesh) {
  std::vector<Triangle> triangles;
  triangles.reserve(mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) triangles.emplace_back(point(mesh, mesh.F(f, 0)), point(mesh, mesh.F(f, 1)), point(mesh, mesh.F(f, 2)));
  return triangles;
}

}  // namespace polycube::triangle_tree
