#include "polycube/disk_locator.h"

#include <algorithm>
#include <cmath>

namespace polycube {

DiskLocator::DiskLocator(const Eigen::MatrixX2d& uv, const Eigen::MatrixX3i& F) : uv_(&uv), F_(&F) {
  const int nf = static_cast<int>(F.rows());
  if (nf == 0) return;
  min_ = uv.colwise().minCoeff().transpose();
  const Eigen::Vector2d max = uv.colwise().maxCoeff().transpose();
  const Eigen::Vector2d extent = (max - min_).cwiseMax(1e-12);
  cell_size_ = std::sqrt(extent.x() * extent.y() / std::max(1, nf)) * 1.5;
  nx_ = std::clamp(static_cast<int>(std::ceil(extent.x() / cell_size_)), 1, 4096);
  ny_ = std::clamp(static_cast<int>(std::ceil(extent.y() / cell_size_)), 1, 4096);
  cell_size_ = std::max(extent.x() / nx_, extent.y() / ny_) * (1 + 1e-9);
  std::vector<int> count(nx_ * ny_ + 1, 0);
  auto for_cells = [&](int f, auto&& visit) {
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    for (int i = 0; i < 3; ++i) {
      x0 = std::min(x0, uv(F(f, i), 0));
      x1 = std::max(x1, uv(F(f, i), 0));
      y0 = std::min(y0, uv(F(f, i), 1));
      y1 = std::max(y1, uv(F(f, i), 1));
    }
    const int i0 = std::clamp(static_cast<int>((x0 - min_.x()) / cell_size_), 0, nx_ - 1);
    const int i1 = std::clamp(static_cast<int>((x1 - min_.x()) / cell_size_), 0, nx_ - 1);
    const int j0 = std::clamp(static_cast<int>((y0 - min_.y()) / cell_size_), 0, ny_ - 1);
    const int j1 = std::clamp(static_cast<int>((y1 - min_.y()) / cell_size_), 0, ny_ - 1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) visit(j * nx_ + i);
  };
  for (int f = 0; f < nf; ++f) for_cells(f, [&](int c) { ++count[c + 1]; });
  for (int c = 0; c < nx_ * ny_; ++c) count[c + 1] += count[c];
  start_ = count;
  faces_.resize(count.back());
  for (int f = 0; f < nf; ++f) for_cells(f, [&](int c) { faces_[count[c]++] = f; });
}

Eigen::Vector3d DiskLocator::barycentric(int f, const Eigen::Vector2d& q) const {
  const Eigen::Vector2d a = uv_->row((*F_)(f, 0)), b = uv_->row((*F_)(f, 1)), c = uv_->row((*F_)(f, 2));
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) { return u.x() * v.y() - u.y() * v.x(); };
  const double area = cross(b - a, c - a);
  if (!(std::abs(area) > 0)) return Eigen::Vector3d(-INFINITY, -INFINITY, -INFINITY);
  const double wa = cross(b - q, c - q) / area, wb = cross(c - q, a - q) / area;
  return {wa, wb, 1 - wa - wb};
}

int DiskLocator::locate(const Eigen::Vector2d& q, Eigen::Vector3d& bary) const {
  if (faces_.empty()) return -1;
  int best = -1;
  double best_min = -INFINITY;
  Eigen::Vector3d best_bary = Eigen::Vector3d::Zero();
  auto scan = [&](int c) {
    for (int k = start_[c]; k < start_[c + 1]; ++k) {
      const Eigen::Vector3d w = barycentric(faces_[k], q);
      const double m = w.minCoeff();
      if (m > best_min) {
        best_min = m;
        best = faces_[k];
        best_bary = w;
      }
    }
  };
  const int ci = std::clamp(static_cast<int>((q.x() - min_.x()) / cell_size_), 0, nx_ - 1);
  const int cj = std::clamp(static_cast<int>((q.y() - min_.y()) / cell_size_), 0, ny_ - 1);
  scan(cj * nx_ + ci);
  // Outside every face of the bucket (on the boundary by rounding, or a sparse bucket): widen.
  for (int ring = 1; best_min < -1e-12 && ring <= std::max(nx_, ny_); ++ring) {
    for (int j = cj - ring; j <= cj + ring; ++j)
      for (int i = ci - ring; i <= ci + ring; ++i) {
        if (i < 0 || j < 0 || i >= nx_ || j >= ny_) continue;
        if (std::max(std::abs(i - ci), std::abs(j - cj)) != ring) continue;
        scan(j * nx_ + i);
      }
    if (ring >= 2 && best_min > -1e-6) break;
  }
  bary = best_bary.cwiseMax(0.0);
  const double sum = bary.sum();
  bary = sum > 0 ? Eigen::Vector3d(bary / sum) : Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3);
  return best;
}

}  // namespace polycube
