#include "polycube/target_surface.h"

#include "polycube/closest_point.h"
#include "polycube/image_orientation.h"
#include "polycube/map_audit.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <iterator>
#include <stdexcept>
#include <string>

namespace polycube {

using namespace triangle_tree;

TargetSurface::TargetSurface(const TriMesh& target, const char* what) : target_(target), tree_index_(target.num_faces(), -1) {
  triangles_.reserve(target.num_faces());
  for (int f = 0; f < target.num_faces(); ++f) {
    const Eigen::Vector3d a = target.V.row(target.F(f, 0)).transpose();
    area_vectors_.push_back((target.V.row(target.F(f, 1)).transpose() - a).cross(target.V.row(target.F(f, 2)).transpose() - a));
    area_ += 0.5 * area_vectors_.back().norm();
    if (area_vectors_.back().squaredNorm() == 0) continue;
    tree_index_[f] = static_cast<int>(triangles_.size());
    triangles_.emplace_back(point(target, target.F(f, 0)), point(target, target.F(f, 1)), point(target, target.F(f, 2)));
    faces_.push_back(f);
  }
  if (triangles_.empty()) throw std::invalid_argument(std::string(what) + ": target has zero area");
  tree_.rebuild(triangles_.begin(), triangles_.end());
  tree_.accelerate_distance_queries();
  diagonal_ = bounding_box(target.V).diagonal();
}

int TargetSurface::judge(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, int fa, int fb, int fc) const {
  if (0.5 * (b - a).cross(c - a).norm() <= kAuditDegenerateArea * area_) return 2;
  const double in_face = kInFaceTolerance * diagonal_;
  const auto corners = [this](int f, int k) { return corner(f, k); };
  const auto nearest = [this](const Eigen::Vector3d& p, int seed) { return closest_face(p, seed); };
  const auto tied = [this, in_face](const Eigen::Vector3d& p, int f, std::vector<int>& faces) { tied_faces(p, f, in_face, faces); };
  return image_triangle_flipped(a, b, c, fa, fb, fc, area_vectors_, nearest, tied, corners, in_face) ? 1 : 0;
}

int TargetSurface::closest_face(const Eigen::Vector3d& p, int seed) const {
  if (seed < 0 || seed >= static_cast<int>(tree_index_.size()) || tree_index_[seed] < 0) return closest(p).first;
  const Point q(p.x(), p.y(), p.z());
  const auto seeded = triangles_.begin() + tree_index_[seed];
  const Eigen::Vector3d h = closest_on_triangle(p, corner(seed, 0), corner(seed, 1), corner(seed, 2)).point;
  const auto found = tree_.closest_point_and_primitive(q, Tree::Point_and_primitive_id(Point(h.x(), h.y(), h.z()), seeded)).second;
  return faces_[static_cast<size_t>(found - triangles_.begin())];
}

void TargetSurface::tied_faces(const Eigen::Vector3d& p, int f, double tolerance, std::vector<int>& faces) const {
  const Eigen::Vector3d a = corner(f, 0), b = corner(f, 1), c = corner(f, 2);
  const Eigen::Vector3d q = closest_on_triangle(p, a, b, c).point;
  // p's closest point q on f, farther than the tolerance from f's edges, lies on no other face
  // (the target is closed and free of self-intersections; another sheet that close counts as
  // none): the common case, answered without a search.
  auto off_edge = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    const Eigen::Vector3d e = v - u;
    const double t = std::clamp((q - u).dot(e) / e.squaredNorm(), 0.0, 1.0);
    return (u + t * e - q).norm() > tolerance;
  };
  if (off_edge(a, b) && off_edge(b, c) && off_edge(c, a)) return;
  // On an edge or a vertex of f: every face through q (within the tolerance) is as close to p,
  // q being a point of it and the closest point of the target. (Searched round q, not within
  // p's distance round p: a chord's centroid or grid point can lie far off P's overlay, whose
  // cells are tiny, and the untangling judges thousands of them: on cow's exact sampling the
  // untangling of the model's chords took 12 s, 2.4 s this way.)
  const double reach = tolerance;
  const CGAL::Bbox_3 box(q.x() - reach, q.y() - reach, q.z() - reach, q.x() + reach, q.y() + reach, q.z() + reach);
  thread_local std::vector<Tree::Primitive_id> hits;
  hits.clear();
  tree_.all_intersected_primitives(box, std::back_inserter(hits));
  for (const auto& hit : hits) {
    const int g = faces_[static_cast<size_t>(hit - triangles_.begin())];
    if (g != f && (closest_on_triangle(q, corner(g, 0), corner(g, 1), corner(g, 2)).point - q).norm() <= reach) faces.push_back(g);
  }
}

std::pair<int, double> TargetSurface::closest(const Eigen::Vector3d& p) const {
  const auto [q, face] = project(p);
  return {face, (q - p).norm()};
}

std::pair<Eigen::Vector3d, int> TargetSurface::project(const Eigen::Vector3d& p) const {
  const Point query(p.x(), p.y(), p.z());
  const auto [point, id] = tree_.closest_point_and_primitive(query);
  return {Eigen::Vector3d(point.x(), point.y(), point.z()), faces_[static_cast<size_t>(id - triangles_.begin())]};
}

}  // namespace polycube
