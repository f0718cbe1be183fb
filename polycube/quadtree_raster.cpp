#include "polycube/quadtree_raster.h"

#include <algorithm>

namespace polycube {

long long& rasterized_cells() {
  thread_local long long cells = 0;
  return cells;
}

void grid_lines(const std::vector<const std::vector<QuadLeaf>*>& sections, std::vector<int>& xs, std::vector<int>& ys) {
  xs = {0, kQuadGridSize};
  ys = {0, kQuadGridSize};
  for (const auto* leaves : sections)
    for (const QuadLeaf& leaf : *leaves) {
      xs.push_back(leaf.cell.x0());
      xs.push_back(leaf.cell.x1());
      ys.push_back(leaf.cell.y0());
      ys.push_back(leaf.cell.y1());
    }
  for (auto* lines : {&xs, &ys}) {
    std::sort(lines->begin(), lines->end());
    lines->erase(std::unique(lines->begin(), lines->end()), lines->end());
  }
}

QuadRaster rasterize(const std::vector<const std::vector<QuadLeaf>*>& sections) {
  QuadRaster raster;
  grid_lines(sections, raster.xs, raster.ys);
  const int nx = raster.nx(), ny = raster.ny();
  auto index_of = [](const std::vector<int>& lines, int value) {
    return static_cast<int>(std::lower_bound(lines.begin(), lines.end(), value) - lines.begin());
  };
  raster.leaf.resize(sections.size());
  rasterized_cells() += static_cast<long long>(nx) * ny * static_cast<long long>(sections.size());
  for (size_t s = 0; s < sections.size(); ++s) {
    std::vector<int>& cells = raster.leaf[s];
    cells.assign(static_cast<size_t>(nx) * ny, -1);
    const std::vector<QuadLeaf>& leaves = *sections[s];
    for (size_t l = 0; l < leaves.size(); ++l) {
      const QuadCell& c = leaves[l].cell;
      const int cx0 = index_of(raster.xs, c.x0()), cx1 = index_of(raster.xs, c.x1());
      const int cy0 = index_of(raster.ys, c.y0()), cy1 = index_of(raster.ys, c.y1());
      for (int cy = cy0; cy < cy1; ++cy)
        std::fill(cells.begin() + static_cast<size_t>(cy) * nx + cx0, cells.begin() + static_cast<size_t>(cy) * nx + cx1,
                  static_cast<int>(l));
    }
  }
  return raster;
}

void charge_raster_cells(const std::vector<const std::vector<QuadLeaf>*>& sections) {
  std::vector<int> xs, ys;
  grid_lines(sections, xs, ys);
  rasterized_cells() += static_cast<long long>(xs.size() - 1) * static_cast<long long>(ys.size() - 1) *
                        static_cast<long long>(sections.size());
}

LeafLocator::LeafLocator(const std::vector<QuadLeaf>& leaves) : leaves_(leaves) {
  nodes_.reserve(2 * leaves.size() + 1);
  for (int l = 0; l < static_cast<int>(leaves.size()); ++l) {
    QuadCell c = leaves[l].cell;
    deepest_ = std::max(deepest_, c.level);
    nodes_[key(c)] = l;
    while (c.level > 0) {
      c = {c.level - 1, c.ix >> 1, c.iy >> 1};
      if (!nodes_.emplace(key(c), kInner).second) break;
    }
  }
  // Fillers: the children no tile is in, under every subdivided cell.
  auto add_filler = [&](const QuadCell& c) {
    nodes_[key(c)] = size();
    fillers_.push_back(c);
  };
  if (nodes_.find(key({})) == nodes_.end()) add_filler({});
  std::vector<QuadCell> inner;
  if (nodes_.at(key({})) == kInner) inner.push_back({});
  while (!inner.empty()) {
    const QuadCell c = inner.back();
    inner.pop_back();
    for (int q = 0; q < 4; ++q) {
      const QuadCell child{c.level + 1, 2 * c.ix + (q & 1), 2 * c.iy + (q >> 1)};
      const auto it = nodes_.find(key(child));
      if (it == nodes_.end()) add_filler(child);
      else if (it->second == kInner) inner.push_back(child);
    }
  }
}

int LeafLocator::at(int ux, int uy) const {
  if (ux < 0 || uy < 0 || ux >= kQuadGridSize || uy >= kQuadGridSize) return -1;
  // The cells holding the unit square exist down to its tile's level: search that level.
  int lo = 0, hi = deepest_, tile = nodes_.at(key({}));
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2, shift = kQuadGridBits - mid;
    const auto it = nodes_.find(key({mid, ux >> shift, uy >> shift}));
    if (it == nodes_.end()) {
      hi = mid - 1;
    } else {
      lo = mid;
      tile = it->second;
    }
  }
  return tile;
}

int LeafLocator::find(const QuadCell& cell) const {
  const auto it = nodes_.find(key(cell));
  return it == nodes_.end() ? kInside : it->second;
}

std::vector<TileCorner> tile_corners(const LeafLocator& tiles) {
  std::vector<std::pair<int, int>> points;  // (y, x)
  points.reserve(4 * static_cast<size_t>(tiles.size()));
  for (int t = 0; t < tiles.size(); ++t) {
    const QuadCell& c = tiles.cell(t);
    for (int y : {c.y0(), c.y1()})
      for (int x : {c.x0(), c.x1()}) points.emplace_back(y, x);
  }
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  std::vector<TileCorner> corners(points.size());
  for (size_t p = 0; p < points.size(); ++p) {
    const auto [y, x] = points[p];
    corners[p] = {x, y,
                  {tiles.beside(x, y, -1, -1), tiles.beside(x, y, 1, -1), tiles.beside(x, y, 1, 1),
                   tiles.beside(x, y, -1, 1)}};
  }
  return corners;
}

std::vector<int> padded_faces(const QuadRaster& raster, int s, const std::vector<QuadLeaf>& leaves) {
  const int nx = raster.nx(), ny = raster.ny(), row = nx + 2;
  std::vector<int> faces(static_cast<size_t>(row) * (ny + 2), 0);
  for (int cy = 0; cy < ny; ++cy) {
    const int* leaf = raster.leaf[s].data() + static_cast<size_t>(cy) * nx;
    int* face = faces.data() + static_cast<size_t>(cy + 1) * row + 1;
    for (int cx = 0; cx < nx; ++cx) face[cx] = leaf[cx] < 0 ? 0 : leaves[leaf[cx]].face;
  }
  return faces;
}

}  // namespace polycube
