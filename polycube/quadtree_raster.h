// The common refinement of one or more quadtrees as a rectilinear grid: the grid lines are the
// leaf sides of all of them, so every grid cell lies in exactly one leaf of each. Checks and
// surface extraction run on this grid with plain array code.
#pragma once

#include "polycube/quadtree_section.h"

#include <vector>

namespace polycube {

// Grid over the unit square with one padding ring of empty cells around it: cell (cx, cy) for
// cx in -1..nx, cy in -1..ny; the padding cells have leaf -1.
//   xs, ys  grid lines in quadtree units, ascending, from 0 to kQuadGridSize
//   leaf    per section: nx*ny leaf indices, row-major (cy * nx + cx)
struct QuadRaster {
  std::vector<int> xs;
  std::vector<int> ys;
  std::vector<std::vector<int>> leaf;

  int nx() const { return static_cast<int>(xs.size()) - 1; }
  int ny() const { return static_cast<int>(ys.size()) - 1; }
  bool inside(int cx, int cy) const { return cx >= 0 && cy >= 0 && cx < nx() && cy < ny(); }
  // Leaf of section s at cell (cx, cy), -1 in the padding.
  int leaf_at(int s, int cx, int cy) const { return inside(cx, cy) ? leaf[s][cy * nx() + cx] : -1; }
};

// Rasterizes the leaf sets (each covering the unit square) on their common grid.
QuadRaster rasterize(const std::vector<const std::vector<QuadLeaf>*>& sections);

// Grid cells (nx × ny per leaf set) rasterize has filled on this thread so far: the work of the
// sections' and slabs' checks, which rasterize every time, measured without a clock (the same on
// every machine and run). build_polycube budgets it (PolycubeOptions::max_rasterized_cells).
long long& rasterized_cells();

// The faces of section s's leaves (its leaf list) on the raster's cells with the padding ring:
// element (cy + 1) * (nx + 2) + cx + 1 for cell (cx, cy), face 0 (outside) in the padding. For
// checks that look up neighbouring cells many times.
std::vector<int> padded_faces(const QuadRaster& raster, int s, const std::vector<QuadLeaf>& leaves);

}  // namespace polycube
