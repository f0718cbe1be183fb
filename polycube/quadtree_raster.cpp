#include "polycube/quadtree_raster.h"

#include <algorithm>

namespace polycube {

long long& rasterized_cells() {
  thread_local long long cells = 0;
  return cells;
}

QuadRaster rasterize(const std::vector<const std::vector<QuadLeaf>*>& sections) {
  QuadRaster raster;
  for (const auto* leaves : sections)
    for (const QuadLeaf& leaf : *leaves) {
      raster.xs.push_back(leaf.cell.x0());
      raster.xs.push_back(leaf.cell.x1());
      raster.ys.push_back(leaf.cell.y0());
      raster.ys.push_back(leaf.cell.y1());
    }
  raster.xs.push_back(0);
  raster.xs.push_back(kQuadGridSize);
  raster.ys.push_back(0);
  raster.ys.push_back(kQuadGridSize);
  for (auto* lines : {&raster.xs, &raster.ys}) {
    std::sort(lines->begin(), lines->end());
    lines->erase(std::unique(lines->begin(), lines->end()), lines->end());
  }
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
