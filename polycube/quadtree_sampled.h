// A cross-section sampled on a fine uniform grid: the reference an infinitely refined quadtree
// tends to. The stacking repairs compare against it to tell defects that subdivision can repair
// (the quadtree lost an overlap the contours have) from defects only a new plane can (the
// contours of consecutive planes themselves overlap differently from how the model connects).
#pragma once

#include "polycube/contour_sections.h"
#include "polycube/quadtree_section.h"

#include <vector>

namespace polycube {

// Labels the cells of the grid of `resolution` cells along the longer side of the bounding box
// of the plane's contours (rounded up to a power of two, at most 2^kQuadGridBits over the unit
// square) with the face of the plane's arrangement containing their centre, by scanlines; then
// merges 2x2 blocks of one face, so leaves are fine only along the contours. Cells outside the
// bounding box are not listed (they are outside, face 0). mixed is false for all leaves.
std::vector<QuadLeaf> sample_section(const CrossSections& sections, int plane, int resolution = 512);

}  // namespace polycube
