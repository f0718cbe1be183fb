#include "polycube/target_surface.h"

#include "polycube/image_orientation.h"
#include "polycube/map_audit.h"

#include <Eigen/Geometry>

#include <stdexcept>
#include <string>

namespace polycube {

using namespace triangle_tree;

TargetSurface::TargetSurface(const TriMesh& target, const char* what) : target_(target) {
  triangles_.reserve(target.num_faces());
  for (int f = 0; f < target.num_faces(); ++f) {
    const Eigen::Vector3d a = target.V.row(target.F(f, 0)).transpose();
    area_vectors_.push_back((target.V.row(target.F(f, 1)).transpose() - a).cross(target.V.row(target.F(f, 2)).transpose() - a));
    area_ += 0.5 * area_vectors_.back().norm();
    if (area_vectors_.back().squaredNorm() == 0) continue;
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
  const auto corner = [this](int f, int k) -> Eigen::Vector3d { return target_.V.row(target_.F(f, k)); };
  const auto nearest = [this](const Eigen::Vector3d& p, int) { return closest(p).first; };
  return image_triangle_flipped(a, b, c, fa, fb, fc, area_vectors_, nearest, corner, kInFaceTolerance * diagonal_) ? 1 : 0;
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
