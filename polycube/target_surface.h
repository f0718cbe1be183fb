// Internal (CGAL; include only from engine .cpp files): closest points on the surface a map's
// images should lie on, with the faces' area vectors the orientation test needs, and the audit's
// judgement of one image triangle. Shared by the audit (map_audit.cpp), the refinement of P's
// sampling (map_refinement.cpp), the smoothing's guard (map_smoothing.cpp) and the last
// untangling (image_untangle.cpp), which must judge exactly as the audit does. Faces tied for
// closest are all taken (tied_faces), so no verdict depends on how the tree breaks ties.
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

  // A target face closest to p, the search started from `seed` (a face near p, or -1: only a
  // hint; faces of zero area are never returned).
  int closest_face(const Eigen::Vector3d& p, int seed) const;

  // Appends to `faces` the target faces other than f tied with it for closest to p: with q the
  // point of f closest to p, when q lies within `tolerance` of an edge of f, every face passing
  // within `tolerance` of q (q being a point of those faces too, they are as near to p). A q
  // inside f, farther than the tolerance from its edges, gets none (another sheet of the target
  // that close is taken as absent, and a face elsewhere within rounding of p's distance to f
  // as not there: a tie no frame makes likelier).
  void tied_faces(const Eigen::Vector3d& p, int f, double tolerance, std::vector<int>& faces) const;

  // Whether face f has an area (faces without are not in the tree and never closest).
  bool has_area(int f) const { return tree_index_[f] >= 0; }

  // Corner k of target face f.
  Eigen::Vector3d corner(int f, int k) const { return target_.V.row(target_.F(f, k)).transpose(); }

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
  std::vector<int> faces_;       // target face of each tree triangle
  std::vector<int> tree_index_;  // per target face: its tree triangle (-1: zero area)
  double area_ = 0, diagonal_ = 0;
  triangle_tree::Tree tree_;
};

}  // namespace polycube
