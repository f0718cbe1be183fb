// The common refinement of one or more quadtrees as a rectilinear grid: the grid lines are the
// leaf sides of all of them, so every grid cell lies in exactly one leaf of each. The surface
// extraction and the coarsening's three-plane check run on this grid with plain array code. The
// section and slab checks are defined on it too, but run on the leaves (LeafLocator,
// tile_corners): the grid has (lines)² cells, so a few deep leaves make it huge.
#pragma once

#include "polycube/disjoint_sets.h"
#include "polycube/quadtree_section.h"

#include <array>
#include <cstdint>
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

// Grid cells (nx × ny per leaf set) of the common grids rasterize has filled or the section and
// slab checks have charged (charge_raster_cells: they run on the leaves) on this thread so far:
// the checks' work measured without a clock (the same on every machine and run), in the unit it
// had when they filled the grid. build_polycube budgets it (PolycubeOptions::max_rasterized_cells).
long long& rasterized_cells();

// The grid lines of the leaf sets' common grid, as rasterize gives them (QuadRaster::xs, ys).
void grid_lines(const std::vector<const std::vector<QuadLeaf>*>& sections, std::vector<int>& xs, std::vector<int>& ys);

// Adds to rasterized_cells() the cells rasterize would fill for `sets` leaf sets with these grid
// lines, without filling them: checks that look leaves up directly (LeafLocator) charge the work
// the budget was set in, so a budget stops a build at the same point with or without the raster.
void charge_raster_cells(const std::vector<int>& xs, const std::vector<int>& ys, int sets);

// Point location among the leaves of one quadtree, without a raster. The places no leaf covers
// get filler tiles of the outside face (0), numbered after the leaves, so leaves and fillers
// tile the unit square. The leaves must not overlap; the locator keeps a reference to them.
class LeafLocator {
 public:
  explicit LeafLocator(const std::vector<QuadLeaf>& leaves);

  // Leaves, then fillers.
  int size() const { return static_cast<int>(leaves_.size() + fillers_.size()); }
  const QuadCell& cell(int t) const { return t < leaves() ? leaves_[t].cell : fillers_[t - leaves()]; }
  int face(int t) const { return t < leaves() ? leaves_[t].face : 0; }
  int leaves() const { return static_cast<int>(leaves_.size()); }
  // The tile holding the unit square of the finest grid [ux, ux + 1) x [uy, uy + 1); -1 outside
  // the unit square.
  int at(int ux, int uy) const;
  // The tile holding the finest unit square at grid point (x, y) in direction (sx, sy), each -1
  // or +1.
  int beside(int x, int y, int sx, int sy) const { return at(sx < 0 ? x - 1 : x, sy < 0 ? y - 1 : y); }
  // What a cell of the unit square is: a tile (its index), kSubdivided (tiles lie inside it) or
  // kInside (it lies inside a tile).
  static constexpr int kSubdivided = -1, kInside = -2;
  int find(const QuadCell& cell) const;

 private:
  static constexpr int kInner = kSubdivided;  // a cell the tiles subdivide
  static uint64_t key(const QuadCell& c) {
    return (static_cast<uint64_t>(c.level) << 42) | (static_cast<uint64_t>(c.ix) << 21) | static_cast<uint64_t>(c.iy);
  }
  // Open addressing with linear probing, cell key -> value: the checks look cells up millions
  // of times.
  class CellTable {
   public:
    // Inserts key -> value if the key is absent; returns whether it was.
    bool insert(uint64_t key, int value);
    void assign(uint64_t key, int value);
    const int* find(uint64_t key) const;  // null when absent

   private:
    static constexpr uint64_t kEmpty = ~uint64_t{0};
    size_t slot(uint64_t key) const;
    void grow();
    std::vector<uint64_t> keys_;
    std::vector<int> values_;
    size_t size_ = 0;
    int bits_ = 0;
  };
  const std::vector<QuadLeaf>& leaves_;
  std::vector<QuadCell> fillers_;
  CellTable nodes_;  // every tile and every cell above one: tile index or kInner
  int deepest_ = 0;
};

// A corner of a tile and the four tiles around it (SW, SE, NE, NW; -1 outside the unit square).
// Two tiles that touch meet at a corner of one of them, and every vertex of the common grid that
// is no tile corner lies inside a tile or inside a side two tiles share: conditions on touching
// cells are checked on these.
struct TileCorner {
  int x = 0;
  int y = 0;
  std::array<int, 4> around{};
};

// Every tile corner once, bottom to top, then left to right (the order of a raster scan).
std::vector<TileCorner> tile_corners(const LeafLocator& tiles);

// The components of the tiles where `joined(s, t)` holds for tiles that share an edge (the
// tiles on the two sides of a line at a corner), the tiles on the border of the unit square
// where `open(t)` holds joining element tiles.size(), which stands for the padding ring.
template <typename Joined, typename Open>
DisjointSets tile_components(const LeafLocator& tiles, const std::vector<TileCorner>& corners, const Joined& joined,
                             const Open& open) {
  const int nt = tiles.size();
  DisjointSets sets(nt + 1);
  for (const TileCorner& corner : corners)
    for (int k = 0; k < 4; ++k) {
      const int s = corner.around[k], t = corner.around[(k + 1) % 4];
      if (s >= 0 && t >= 0 && s != t && joined(s, t)) sets.unite(s, t);
    }
  for (int t = 0; t < nt; ++t) {
    const QuadCell& c = tiles.cell(t);
    if (open(t) && (c.x0() == 0 || c.y0() == 0 || c.x1() == kQuadGridSize || c.y1() == kQuadGridSize))
      sets.unite(t, nt);
  }
  return sets;
}

// The side two tiles share from a corner to the right (the tiles below and above it) or
// upwards (left and right of it), up to the next tile corner on it: x (y) of its far end. The
// two tiles are equal where there is no side; -1 outside the unit square.
struct TileSide {
  int from = 0;  // the tile below (left)
  int to = 0;    // the tile above (right)
  int end = 0;
};
TileSide side_from(const LeafLocator& tiles, const TileCorner& corner, bool upwards);

// The faces of section s's leaves (its leaf list) on the raster's cells with the padding ring:
// element (cy + 1) * (nx + 2) + cx + 1 for cell (cx, cy), face 0 (outside) in the padding. For
// checks that look up neighbouring cells many times.
std::vector<int> padded_faces(const QuadRaster& raster, int s, const std::vector<QuadLeaf>& leaves);

}  // namespace polycube
