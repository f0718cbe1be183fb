// Point location in a planar triangulation (a piece's disk embedding): a uniform grid of buckets
// over the bounding box, each listing the triangles whose bounding box meets it.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace polycube {

class DiskLocator {
 public:
  DiskLocator() = default;
  // uv: #V by 2 positions; F: #F by 3 faces (counter-clockwise).
  DiskLocator(const Eigen::MatrixX2d& uv, const Eigen::MatrixX3i& F);

  // The face containing q and q's barycentric coordinates in it. Points outside every face (by
  // rounding, on the boundary) get the face whose smallest barycentric coordinate is largest,
  // with the coordinates clamped to >= 0 and renormalised. Returns -1 only for an empty mesh.
  int locate(const Eigen::Vector2d& q, Eigen::Vector3d& bary) const;

 private:
  Eigen::Vector3d barycentric(int f, const Eigen::Vector2d& q) const;

  const Eigen::MatrixX2d* uv_ = nullptr;
  const Eigen::MatrixX3i* F_ = nullptr;
  Eigen::Vector2d min_ = Eigen::Vector2d::Zero();
  double cell_size_ = 1;
  int nx_ = 0, ny_ = 0;
  std::vector<int> start_;  // CSR buckets
  std::vector<int> faces_;
};

}  // namespace polycube
