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

void charge_raster_cells(const std::vector<int>& xs, const std::vector<int>& ys, int sets) {
  rasterized_cells() += static_cast<long long>(xs.size() - 1) * static_cast<long long>(ys.size() - 1) * sets;
}

size_t LeafLocator::CellTable::slot(uint64_t key) const {
  return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> (64 - bits_));
}

void LeafLocator::CellTable::grow() {
  std::vector<uint64_t> keys = std::move(keys_);
  std::vector<int> values = std::move(values_);
  bits_ = std::max(bits_ + 1, 4);
  keys_.assign(size_t{1} << bits_, kEmpty);
  values_.assign(size_t{1} << bits_, 0);
  size_ = 0;
  for (size_t i = 0; i < keys.size(); ++i)
    if (keys[i] != kEmpty) insert(keys[i], values[i]);
}

bool LeafLocator::CellTable::insert(uint64_t key, int value) {
  if (2 * (size_ + 1) > keys_.size()) grow();
  const size_t mask = keys_.size() - 1;
  for (size_t i = slot(key);; i = (i + 1) & mask) {
    if (keys_[i] == key) return false;
    if (keys_[i] == kEmpty) {
      keys_[i] = key;
      values_[i] = value;
      ++size_;
      return true;
    }
  }
}

void LeafLocator::CellTable::assign(uint64_t key, int value) {
  if (!insert(key, value)) values_[find(key) - values_.data()] = value;
}

const int* LeafLocator::CellTable::find(uint64_t key) const {
  if (keys_.empty()) return nullptr;
  const size_t mask = keys_.size() - 1;
  for (size_t i = slot(key);; i = (i + 1) & mask) {
    if (keys_[i] == key) return &values_[i];
    if (keys_[i] == kEmpty) return nullptr;
  }
}

LeafLocator::LeafLocator(const std::vector<QuadLeaf>& leaves) : leaves_(leaves) {
  for (int l = 0; l < static_cast<int>(leaves.size()); ++l) {
    QuadCell c = leaves[l].cell;
    deepest_ = std::max(deepest_, c.level);
    nodes_.assign(key(c), l);
    while (c.level > 0) {
      c = {c.level - 1, c.ix >> 1, c.iy >> 1};
      if (!nodes_.insert(key(c), kInner)) break;
    }
  }
  // Fillers: the children no tile is in, under every subdivided cell.
  auto add_filler = [&](const QuadCell& c) {
    nodes_.assign(key(c), size());
    fillers_.push_back(c);
  };
  if (!nodes_.find(key({}))) add_filler({});
  std::vector<QuadCell> inner;
  if (*nodes_.find(key({})) == kInner) inner.push_back({});
  while (!inner.empty()) {
    const QuadCell c = inner.back();
    inner.pop_back();
    for (int q = 0; q < 4; ++q) {
      const QuadCell child{c.level + 1, 2 * c.ix + (q & 1), 2 * c.iy + (q >> 1)};
      const int* found = nodes_.find(key(child));
      if (!found) add_filler(child);
      else if (*found == kInner) inner.push_back(child);
    }
  }
}

int LeafLocator::at(int ux, int uy) const {
  if (ux < 0 || uy < 0 || ux >= kQuadGridSize || uy >= kQuadGridSize) return -1;
  // The cells holding the unit square exist down to its tile's level: search that level.
  int lo = 0, hi = deepest_, tile = *nodes_.find(key({}));
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2, shift = kQuadGridBits - mid;
    const int* found = nodes_.find(key({mid, ux >> shift, uy >> shift}));
    if (!found) {
      hi = mid - 1;
    } else {
      lo = mid;
      tile = *found;
    }
  }
  return tile;
}

int LeafLocator::find(const QuadCell& cell) const {
  const int* found = nodes_.find(key(cell));
  return found ? *found : kInside;
}

std::vector<TileCorner> tile_corners(const LeafLocator& tiles) {
  std::vector<uint64_t> points;  // y << 32 | x: sorted as (y, x)
  points.reserve(4 * static_cast<size_t>(tiles.size()));
  for (int t = 0; t < tiles.size(); ++t) {
    const QuadCell& c = tiles.cell(t);
    for (int y : {c.y0(), c.y1()})
      for (int x : {c.x0(), c.x1()}) points.push_back(static_cast<uint64_t>(y) << 32 | static_cast<uint64_t>(x));
  }
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  std::vector<TileCorner> corners(points.size());
  for (size_t p = 0; p < points.size(); ++p) {
    const int y = static_cast<int>(points[p] >> 32), x = static_cast<int>(points[p] & 0xffffffffu);
    corners[p] = {x, y,
                  {tiles.beside(x, y, -1, -1), tiles.beside(x, y, 1, -1), tiles.beside(x, y, 1, 1),
                   tiles.beside(x, y, -1, 1)}};
  }
  return corners;
}

TileSide side_from(const LeafLocator& tiles, const TileCorner& corner, bool upwards) {
  TileSide side;
  side.from = upwards ? corner.around[3] : corner.around[1];
  side.to = corner.around[2];
  side.end = kQuadGridSize;
  for (int t : {side.from, side.to})
    if (t >= 0) side.end = std::min(side.end, upwards ? tiles.cell(t).y1() : tiles.cell(t).x1());
  return side;
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
