// Simplification of a plane's finished quadtree approximation Q_i, once every slab passes. The
// repairs subdivide cells along whole contours, down to levels far finer than d_a asks for, and
// every subdivided stretch of a contour becomes a staircase of tiny steps, each step polycube
// corners; and neighbouring planes' staircases differ by a cell here and there, each difference
// a horizontal face with its corners. Merging sibling leaves back (coarsen_section) and letting
// Q_i follow its neighbours (snap_section), where accuracy, topology and the slab checks allow,
// removes both.
#pragma once

#include "polycube/contour_sections.h"
#include "polycube/quadtree_section.h"

#include <functional>
#include <vector>

namespace polycube {

// Per face of the section: area(Q_f Δ R_f) / area(R_f) for the solid faces, 0 for the others —
// QuadtreeSection::region_error, for any leaves (only mixed leaves count, as there).
std::vector<double> region_errors(const PlaneSection& section, const std::vector<QuadLeaf>& leaves);

// The other conditions a simplified labelling must meet (the stacking checks of the plane's two
// slabs): returns true when `leaves` are acceptable; otherwise may set implicated[l] for the
// leaves whose change should be undone (implicated has one entry per leaf, all zero on entry).
using CoarseningCheck = std::function<bool(const std::vector<QuadLeaf>& leaves, std::vector<char>& implicated)>;

// What a simplification did.
//   leaves        the simplified leaves (cover the unit square)
//   merges        sibling groups merged into their parent (coarsen_section), leaves relabelled
//                 (snap_section)
//   undone        changes tried and undone because a check failed
struct CoarsenedSection {
  std::vector<QuadLeaf> leaves;
  int merges = 0;
  int undone = 0;
};

// Merges groups of four sibling leaves into their parent, deepest level first, labelling the
// parent with the face covering most of its area — never above the cells of the d_a refinement
// (QuadLeaf::accuracy_level), so the result is at least as fine as §3.2's approximation
// everywhere and only the repairs' excess subdivisions are undone, and never into a cell
// coarser than coarsest_level (a bound on how far the coarsening may move a boundary). A merge
// is kept only if
//   - every solid region's area difference area(Q_r Δ R_r) / area(R_r) stays within
//     max(da, its difference before coarsening) (same measure as approximate_section);
//   - the labelling keeps the topology of the contours (check_section_topology);
//   - `check` accepts the result;
// merges the checks implicate are undone and the rest tried again. Merges of siblings labelled
// alike change no label and are kept without checks. Merges of a child whose face a repair
// imposed (a mixed leaf whose face is not its largest) are not tried. The input must be a valid
// labelling (QuadtreeSection::valid) accepted by `check`; then so is the output.
CoarsenedSection coarsen_section(const PlaneSection& section, const std::vector<QuadLeaf>& leaves, double da,
                                 int coarsest_level, const CoarseningCheck& check);

// A neighbouring plane for snap_section: its section and leaves (leaves null: none, the empty set
// beyond the first or last plane).
struct SnapNeighbour {
  const PlaneSection* section = nullptr;
  const std::vector<QuadLeaf>* leaves = nullptr;
};

// Relabels the mixed leaves finer than coarsest_level under which the neighbouring plane's Q (the
// one below if follow_below, else the one above) is all solid or all empty, and this plane's is
// not, with a face of that kind present in them — where that removes polycube corners at the
// levels below and above this plane: Q_i follows its neighbour where d_a allows, no horizontal
// faces and no steps between them there. A relabelled leaf moves Q's boundary by up to its
// side, a merge of coarsen_section by about half of its side: hence one level finer. Same
// limits and checks as coarsen_section; `merges` counts the relabelled leaves.
CoarsenedSection snap_section(const PlaneSection& section, const std::vector<QuadLeaf>& leaves, double da,
                              int coarsest_level, const SnapNeighbour& below, const SnapNeighbour& above,
                              bool follow_below, const CoarseningCheck& check);

}  // namespace polycube
