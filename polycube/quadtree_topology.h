// The topology conditions a quadtree labelling must meet so that every contour of the plane has
// exactly one boundary loop of Q_i (see QuadtreeSection::valid).
#pragma once

#include "polycube/contour_sections.h"
#include "polycube/quadtree_section.h"

#include <string>
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

}  // namespace polycube
