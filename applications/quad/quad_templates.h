// Local refinement of the quad grid by templates, the last resort of the quad application's
// refinement (issue 7's Hausdorff bound). Halving chord parts (PolycubeGridOptions::refine_rounds)
// keeps every vertex regular but adds a line of quads along a whole chord for each place; where
// the map squeezes a part of M into a small part of P (a head, a horn, a groove of a coarse CAD
// part) the budget runs out before the lines get there. The templates refine only the quads at
// the places, with a conforming transition round them, at the price of irregular vertices off
// P's corners.
//
// 3-refinement by marked vertices (Schneiders 1996): every edge with one marked end gets a point a
// third of the way from it, every edge with two marked ends two points at thirds, so neighbouring
// quads agree on their shared edge; then per quad, by its marked corners:
//   none                kept
//   one                 3 quads (a corner third of the quad and two round it; new vertex of
//                       valence 3, the opposite corner gains a quad)
//   two along an edge   7 quads (three along the marked edge, four above them)
//   all four            9 quads (a 3 × 3 split)
// Two opposite or three marked corners mark the fourth (and so on until none is left), so these
// cases are all there are. Points are placed on P by the quads' bilinear parameters (every grid
// quad is flat on one face of P), so the grid stays on P.
#pragma once

#include "applications/quad/polycube_grid.h"
#include "polycube/polycube_map.h"

#include <Eigen/Core>

#include <functional>
#include <vector>

namespace polycube {

// The grid refined where `marked` (per vertex of grid.mesh) is set, after the closure above.
//   on_polycube  a point of P (position on P up to rounding) as a surface point of P's mesh, for
//                the new vertices' PolycubeGrid::on_polycube
// Old vertices keep their indices (the new ones follow), corners stay corners; every quad's
// quad_axis and quad_cell are its parent's, quad_refined_by is -1 everywhere; the layout, levels
// and chord figures are the input grid's. Throws std::invalid_argument when marked's size is not
// the vertex count. parents: when given, per quad of the result, the quad of grid it splits.
PolycubeGrid refine_grid_by_templates(const PolycubeGrid& grid, std::vector<char> marked,
                                      const std::function<SurfacePoint(const Eigen::Vector3d&)>& on_polycube,
                                      std::vector<int>* parents = nullptr);

// The closure alone: marked with the fourth corner of every quad with two opposite or three
// marked corners added, until no such quad is left.
std::vector<char> close_template_marks(const Eigen::MatrixX4i& Q, std::vector<char> marked);

}  // namespace polycube
