// The last resort for quads that stay flipped or degenerate after the untangling: each is
// removed by a diagonal collapse (its two opposite corners merged into one vertex), which keeps
// the mesh all-quad, closed and of the same genus, at the price of irregular vertices off the
// polycube's corners (the merged vertex gets the two valences less 2, the quad's two other
// corners one quad fewer each).
//
// A tiny quad folded over its neighbours (femur: a quad 0.3 % of the diagonal wide, turned against
// every quad round it and against the model) cannot be unfolded by moving vertices on a crumpled
// surface; collapsed, with the quads round it moved, it leaves none flipped.
#pragma once

#include "applications/quad/polycube_grid.h"
#include "applications/quad/quad_mesh.h"
#include "applications/quad/quad_quality.h"
#include "applications/quad/quad_smooth.h"
#include "applications/quad/surface_projector.h"

#include <vector>

namespace polycube {

//   collapsed             quads removed
//   bad_before, bad_after flipped or degenerate quads (bad_quads) before and after
//   irregular_added       irregular vertices (valence != 4) after minus before: the net change,
//                         negative when a neighbour's collapse makes irregular corners regular
struct QuadCollapseResult {
  int collapsed = 0;
  int bad_before = 0, bad_after = 0;
  int irregular_added = 0;
};

// Collapses bad quads (bad_quads(quads, model, quality)) while that lowers their count, at most
// 64. A quad's diagonal is collapsed only when the mesh stays a 2-manifold: no vertex other than
// the quad's own lies in quads round both merged corners, and neither of the quad's other corners
// has fewer than 4 quads (it would be left with 2). The merged vertex stays on a polycube corner
// when one of the two is one (never both); else it goes to the model's closest point to the
// diagonal's middle or to either corner's place. The place with the fewest bad quads round it
// (within 4 rings of the quad) is taken if that is fewer than before; when no place is, the
// quads within 2 rings of the merged vertex are untangled (untangle_quads with `untangle`'s
// vertex moves, no patches; the rest held) from each place in turn, at most 24 times per call.
// When no collapse of the bad quad itself lowers them, the same for each quad sharing an edge
// with it (a valence-3 vertex beside a bad quad can bar its own diagonals; elephant-with-holes'
// last flipped quad went that way). A bad quad no collapse helps is not tried again.
// Edits, consistently: quads (positions on the model), grid (its mesh on P, on_polycube, the
// per-quad arrays, corners; the merged vertex keeps the place on P of the corner kept, or of the
// corner whose place on the model it took) and pinned (per vertex; may be empty). Vertices keep
// their order, the removed ones dropped. When the quads would not be fewer bad, or not the same
// 2-manifold (boundary, Euler characteristic, components), nothing changes. Throws
// std::invalid_argument when grid or pinned do not match the quads.
QuadCollapseResult collapse_bad_quads(QuadMesh& quads, PolycubeGrid& grid, std::vector<char>& pinned,
                                      const SurfaceProjector& model, const QuadQualityOptions& quality = {},
                                      const QuadUntangleOptions& untangle = {});

}  // namespace polycube
