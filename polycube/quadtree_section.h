// The axis-aligned (rectilinear) approximation Q_i of one cross-section by a quadtree (§3.2):
// starting from the unit square, cells the contours cross are subdivided until the normalised
// area difference of every region is at most d_a (or a maximum level), then further wherever
// the cells' labels would not have the topology of the contours.
#pragma once

#include "polycube/contour_sections.h"

#include <string>
#include <utility>
#include <vector>

namespace polycube {

// Cells live on a global dyadic grid over the normalised unit square [0,1]^2: integer
// coordinates in units of 2^-kQuadGridBits, so all planes share grid lines.
constexpr int kQuadGridBits = 20;
constexpr int kQuadGridSize = 1 << kQuadGridBits;

// A square of the grid: [ix, ix+1) x [iy, iy+1) in units of 2^-level.
struct QuadCell {
  int level = 0;
  int ix = 0;
  int iy = 0;

  int size() const { return kQuadGridSize >> level; }  // side in grid units
  int x0() const { return ix * size(); }
  int y0() const { return iy * size(); }
  int x1() const { return (ix + 1) * size(); }
  int y1() const { return (iy + 1) * size(); }
  bool operator<(const QuadCell& o) const {
    return level != o.level ? level < o.level : ix != o.ix ? ix < o.ix : iy < o.iy;
  }
  bool operator==(const QuadCell& o) const { return level == o.level && ix == o.ix && iy == o.iy; }
};

// A leaf of the quadtree.
//   face        the face of the plane's arrangement (PlaneSection) the cell is assigned to: the
//               face covering most of its area; Q_i is the union of cells with a solid face
//   mixed       contours cross the cell
//   face_areas  for mixed cells: (face, area in normalised units) of every face present
//   accuracy_level  level of the leaf of the d_a refinement that contains the cell: deeper leaves
//               come from the topology and stacking repairs
struct QuadLeaf {
  QuadCell cell;
  int face = 0;
  bool mixed = false;
  std::vector<std::pair<int, double>> face_areas;
  int accuracy_level = 0;

  double area_of(int f) const {
    for (const auto& [g, a] : face_areas)
      if (g == f) return a;
    return 0;
  }
};

struct QuadtreeOptions {
  // Largest normalised area difference area(Q_r Δ R_r) / area(R_r) per region r (§3.2's d_a;
  // the paper measures area(p \ c) only, the symmetric difference also bounds what is missing).
  double da = 0.3;
  // Deepest level the d_a refinement subdivides to (§3.2's maximal subdivision level).
  int max_level = 10;
  // Thin parts (0: not looked for): a leaf labelled with another face than a solid face f that
  // covers more than a twentieth of it is split while it is wider than feature_distance (unit
  // square units) and no leaf labelled f touches it, or wider than 4 × feature_distance when one
  // does. A tail or a fin that d_a drops (its area is small beside its region's) keeps cells of
  // its own where it reaches farther than about feature_distance from its region's cells.
  double feature_distance = 0;
  // Deepest level topology repairs may subdivide to (at most kQuadGridBits).
  int max_repair_level = 18;
  // Topology repair rounds at most.
  int max_repair_rounds = 64;
  // Most leaves the topology repairs may grow the tree to.
  int max_leaves = 40000;
};

// The approximation of one plane.
//   leaves           cover the unit square
//   region_error     per face: area(Q_f Δ R_f) / area(R_f) for solid faces, 0 for the others
//   *_splits         subdivisions made for d_a (and feature_distance: feature_splits of them),
//                    because they were requested, for topology
//   topology_relabels  cells relabelled where subdivision could not repair the topology
//   deepest_level    of any leaf
//   valid            the labelling has the topology of the contours: every face of the
//                    arrangement has a non-empty 4-connected cell set (the outside one connected
//                    to the border), cells of faces that no contour separates never touch (not
//                    even at a corner), and no vertex has solid and empty cells alternating
//                    around it; then every contour has exactly one boundary loop of Q_i
//   problem          why not, when not valid
struct QuadtreeSection {
  std::vector<QuadLeaf> leaves;
  std::vector<double> region_error;
  int accuracy_splits = 0;
  int feature_splits = 0;  // of them, for QuadtreeOptions::feature_distance
  int forced_splits = 0;
  int topology_splits = 0;
  int topology_relabels = 0;
  int deepest_level = 0;
  bool valid = false;
  std::string problem;
};

// Changes the stacking repairs ask for on top of the approximation.
//   splits  cells to subdivide (with all their ancestors)
//   labels  cells whose leaves (the cell, or the leaves inside it) get the given face instead of
//           the one covering most of their area ("grow or shrink cells")
struct QuadtreeEdits {
  std::vector<QuadCell> splits;
  std::vector<std::pair<QuadCell, int>> labels;
};

// Builds Q for plane `plane` of `sections`: d_a refinement, then the edits, then subdivision
// wherever the topology conditions fail. Never throws for geometry; `valid` says whether the
// topology conditions hold within the level limits.
QuadtreeSection approximate_section(const CrossSections& sections, int plane, const QuadtreeEdits& edits = {},
                                    const QuadtreeOptions& options = {});

}  // namespace polycube
