// Internal (CGAL; include only from engine .cpp files): closest points on the surface a map's
// images should lie on, with the faces' area vectors the orientation test needs, and the audit's
// judgement of one image triangle. Shared by the audit (map_audit.cpp), the refinement of P's
// sampling (map_refinement.cpp) and the last untangling (image_untangle.cpp), which must find the
// same closest faces (the same tree over the same triangles breaks every tie the same way).
#pragma once

#include "polycube/mesh.h"
#include "polycube/triangle_tree.h"

#include <Eigen/Core>

#include <cmath>
#include <utility>
#include <vector>

namespace polycube {

class TargetSurface {
 public:
  // Faces of exactly zero area are left out of the tree (their points lie on a neighbour's edge
  // in a closed mesh, and they have no normal). Throws std::invalid_argument("<what>: target has
  // zero area") when no face is left.
  TargetSurface(const TriMesh& target, const char* what);
  TargetSurface(const TargetSurface&) = delete;
  TargetSurface& operator=(const TargetSurface&) = delete;

  // Closest target face to p and the distance to it.
  std::pair<int, double> closest(const Eigen::Vector3d& p) const;

  // Closest point of the target to p and its face.
  std::pair<Eigen::Vector3d, int> project(const Eigen::Vector3d& p) const;

  // Per target face: twice the area times the outward unit normal.
  const std::vector<Eigen::Vector3d>& area_vectors() const { return area_vectors_; }

  // The target's area (Σ face areas) and bounding-box diagonal.
  double area() const { return area_; }
  double diagonal() const { return diagonal_; }

  // The audit's verdict on the image triangle (a, b, c) whose corners' closest faces are fa, fb,
  // fc: 0 good, 1 flipped (image_orientation.h), 2 degenerate (area <= kAuditDegenerateArea ×
  // the target's).
  int judge(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, int fa, int fb, int fc) const;

 private:
  TriMesh target_;
  std::vector<Eigen::Vector3d> area_vectors_;
  std::vector<triangle_tree::Triangle> triangles_;
  std::vector<int> faces_;  // target face of each tree triangle
  double area_ = 0, diagonal_ = 0;
  triangle_tree::Tree tree_;
};

}  // namespace polycube
