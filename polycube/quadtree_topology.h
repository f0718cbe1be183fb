// The topology conditions a quadtree labelling must meet so that every contour of the plane has
// exactly one boundary loop of Q_i (see QuadtreeSection::valid).
#pragma once

#include "polycube/contour_sections.h"
#include "polycube/quadtree_section.h"

#include <string>
#include <utility>
#include <vector>

namespace polycube {

// Checks the labelling of `leaves` (covering the unit square; cells not covered count as the
// outside): every face of the arrangement has a non-empty 4-connected cell set, the outside one
// connected to the border; cells of faces no contour separates never touch, not even at a
// corner; and no grid vertex has solid and empty cells alternating around it. Returns a
// description of the first violation, empty if none; mark gets one entry per leaf, set for the
// leaves whose subdivision may repair a violation.
std::string check_section_topology(const PlaneSection& section, const std::vector<QuadLeaf>& leaves,
                                   std::vector<char>& mark);

// Where subdivision cannot repair the labelling (a sliver thinner than the deepest cells, two
// contours closer than that), local relabellings that can: at a vertex with a face on two
// diagonal cells only, the off-diagonal cell with most of that face's true area joins it; a
// cell touching a face it may not touch takes the face between them; and when that changes
// nothing, the stray components of a face (all but its largest) take their neighbours' face.
// Returns (leaf index, new face) pairs, empty when nothing applies.
std::vector<std::pair<int, int>> section_topology_relabels(const PlaneSection& section,
                                                           const std::vector<QuadLeaf>& leaves);

}  // namespace polycube
