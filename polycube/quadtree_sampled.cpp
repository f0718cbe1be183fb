#include "polycube/quadtree_sampled.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace polycube {

namespace {

struct Sampler {
  int level = 0;                // pixel level
  int64_t px0 = 0, py0 = 0;     // first pixel of the labelled range
  int width = 0, height = 0;    // labelled range
  std::vector<int> face;        // width * height
  std::vector<QuadLeaf> leaves;

  int label(int64_t px, int64_t py) const {
    if (px < px0 || py < py0 || px >= px0 + width || py >= py0 + height) return 0;
    return face[(py - py0) * width + (px - px0)];
  }

  // Returns the face if the cell is uniform (and leaves it to the caller), -1 otherwise (its
  // uniform children have been emitted).
  int build(int l, int64_t ix, int64_t iy) {
    const int64_t shift = level - l;
    const int64_t x0 = ix << shift, y0 = iy << shift, x1 = (ix + 1) << shift, y1 = (iy + 1) << shift;
    if (x1 <= px0 || y1 <= py0 || x0 >= px0 + width || y0 >= py0 + height) return 0;
    if (l == level) return label(ix, iy);
    int faces[4];
    bool uniform = true;
    for (int q = 0; q < 4; ++q) {
      faces[q] = build(l + 1, 2 * ix + (q & 1), 2 * iy + (q >> 1));
      uniform = uniform && faces[q] >= 0 && faces[q] == faces[0];
    }
    if (uniform) return faces[0];
    for (int q = 0; q < 4; ++q)
      if (faces[q] >= 0) emit(l + 1, 2 * ix + (q & 1), 2 * iy + (q >> 1), faces[q]);
    return -1;
  }

  void emit(int l, int64_t ix, int64_t iy, int f) {
    QuadLeaf leaf;
    leaf.cell = {l, static_cast<int>(ix), static_cast<int>(iy)};
    leaf.face = f;
    leaves.push_back(leaf);
  }
};

}  // namespace

std::vector<QuadLeaf> sample_section(const CrossSections& sections, int plane, int resolution) {
  const PlaneSection& section = sections.planes[plane];
  if (section.contours.empty()) return {};
  Eigen::Vector2d lo = sections.contours[section.contours[0]].points.front(), hi = lo;
  for (int c : section.contours)
    for (const Eigen::Vector2d& p : sections.contours[c].points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  lo = lo.cwiseMax(Eigen::Vector2d::Zero());
  hi = hi.cwiseMin(Eigen::Vector2d::Ones());
  const double side = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1.0 / kQuadGridSize});
  Sampler s;
  s.level = std::clamp(static_cast<int>(std::ceil(std::log2(std::max(1, resolution) / side))), 0, kQuadGridBits);
  const double cells = std::ldexp(1.0, s.level);
  s.px0 = static_cast<int64_t>(std::floor(lo.x() * cells));
  s.py0 = static_cast<int64_t>(std::floor(lo.y() * cells));
  const int64_t px1 = std::min<int64_t>(static_cast<int64_t>(std::ceil(hi.x() * cells)), static_cast<int64_t>(cells));
  const int64_t py1 = std::min<int64_t>(static_cast<int64_t>(std::ceil(hi.y() * cells)), static_cast<int64_t>(cells));
  s.width = static_cast<int>(std::max<int64_t>(1, px1 - s.px0));
  s.height = static_cast<int>(std::max<int64_t>(1, py1 - s.py0));
  s.face.assign(static_cast<size_t>(s.width) * s.height, 0);

  // Scanlines through pixel centres; deeper contours overwrite, so each pixel ends with the
  // face just inside the innermost contour around it.
  std::vector<int> order(section.contours.begin(), section.contours.end());
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return sections.contours[a].depth < sections.contours[b].depth; });
  std::vector<std::vector<double>> crossings(s.height);
  for (int c : order) {
    const SectionContour& contour = sections.contours[c];
    for (auto& row : crossings) row.clear();
    const size_t n = contour.points.size();
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d& a = contour.points[i];
      const Eigen::Vector2d& b = contour.points[(i + 1) % n];
      if (a.y() == b.y()) continue;
      // Rows whose centre y = (row + 0.5) / cells lies in [min, max) of the edge.
      const double y_lo = std::min(a.y(), b.y()) * cells - 0.5, y_hi = std::max(a.y(), b.y()) * cells - 0.5;
      const int64_t first = std::max<int64_t>(s.py0, static_cast<int64_t>(std::ceil(y_lo)));
      const int64_t last = std::min<int64_t>(s.py0 + s.height - 1, static_cast<int64_t>(std::ceil(y_hi)) - 1);
      for (int64_t row = first; row <= last; ++row) {
        const double y = (row + 0.5) / cells;
        crossings[row - s.py0].push_back(a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y()));
      }
    }
    for (int row = 0; row < s.height; ++row) {
      std::vector<double>& xs = crossings[row];
      if (xs.size() < 2) continue;
      std::sort(xs.begin(), xs.end());
      for (size_t k = 0; k + 1 < xs.size(); k += 2) {
        const int64_t from = std::max<int64_t>(s.px0, static_cast<int64_t>(std::ceil(xs[k] * cells - 0.5)));
        const int64_t to = std::min<int64_t>(s.px0 + s.width - 1, static_cast<int64_t>(std::floor(xs[k + 1] * cells - 0.5)));
        for (int64_t px = from; px <= to; ++px) s.face[row * s.width + (px - s.px0)] = contour.local + 1;
      }
    }
  }

  const int f = s.build(0, 0, 0);
  if (f >= 0) s.emit(0, 0, 0, f);
  return std::move(s.leaves);
}

}  // namespace polycube
