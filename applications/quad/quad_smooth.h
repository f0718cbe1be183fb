// Tangential relaxation of a quad mesh lying on a surface: drives the quads towards squares of
// even size where the map stretched the grid, keeps every vertex on the surface and never flips a
// quad.
#pragma once

#include "applications/quad/quad_mesh.h"
#include "applications/quad/surface_projector.h"

#include <vector>

namespace polycube {

struct QuadSmoothOptions {
  // Gauss–Seidel sweeps over all vertices at most (0: nothing moves).
  int sweeps = 0;
  // Fraction of the tangential way to the target moved per step, in (0, 2]; above 1 the sweeps
  // over-relax (1.4: the angles of 60 sweeps at step 1 in 30, on bunny and kitten). A refused
  // move is retried at half and a quarter of it.
  double step = 1.4;
  // Where a step pulls a vertex v: the weighted mean of three targets (weights >= 0, not all 0;
  // a target that does not apply at v, such as the cross at a vertex with a non-disk fan, drops
  // out of the mean).
  //   average_weight  the average of v's edge neighbours (uniform Laplacian): evens out sizes
  //   angle_weight    angle-based (Zhou & Shimada 2000, for quads): for each edge neighbour a,
  //                   the point at the same distance from a along the bisector of the two grid
  //                   lines leaving a through v's quads, so that both corners at a become right
  //                   angles; averaged over the neighbours
  //   cross_weight    the corners at v itself: v's spokes (edges to its neighbours, in fan order
  //                   in its tangent plane) turned by the best common rotation to equal angles
  //                   (90° at a valence-4 vertex), each keeping its length; v goes where the
  //                   turned spokes would start from
  // The Laplacian alone drifts vertices off thin parts; the two angle targets alone overshoot at
  // full steps; the mix converges and keeps the sampling.
  double average_weight = 0.5;
  double angle_weight = 1;
  double cross_weight = 1;
  // Stop before `sweeps` once a whole sweep moves no vertex farther than this times the mean
  // quad size (square root of the mean quad area); 0: always run every sweep.
  double tolerance = 1e-3;
  // Worker threads (vertices sharing no quad move in parallel); 0: one per hardware thread. The
  // result does not depend on it.
  int threads = 0;
  // The moves are judged against the whole surface (see smooth_quads) after every this many
  // sweeps and after the last; 1: after every sweep. Between checks the moves are judged on the
  // quads' own sheets; a quad that lost a bit sends its corners back to the last check.
  int check_every = 4;
};

// What happened.
//   mesh      the relaxed quads (same connectivity), every vertex that moved on the surface
//   sweeps    sweeps run; converged: the last one moved less than the tolerance
//   moves     accepted vertex moves; rejected: moves refused at every tried length; reverted:
//             accepted moves undone at the end of their sweep (see smooth_quads)
//   largest_move  of the last sweep, over the mean quad size
//   seconds   wall time
struct QuadSmoothResult {
  QuadMesh mesh;
  int sweeps = 0;
  bool converged = false;
  long long moves = 0;
  long long rejected = 0;
  long long reverted = 0;  // vertex moves undone by the sweeps' end checks
  double largest_move = 0;
  double seconds = 0;
};

// Per sweep and vertex: the target (options' weights), minus its component along the surface normal
// at the vertex, a step towards it, then the closest point of the surface. The move is refused when
// it turns any corner or any quad (by its diagonals) of the vertex's quads from agreeing with the
// quad's surface normal (quad_surface_normal) to disagreeing, so the flipped quads measure_quads
// counts never grow, nor do its inverted corners (one exception below); moves that make a flipped
// quad or an inverted corner agree are taken (a tangled map's folds get undone where they can).
// Also refused: a move whose closest point has a surface normal more than about 70° from the
// vertex's (the far side of a thin part, not the surface under the vertex), and one that shortens
// an edge below 2 % of the mean quad size (near a convex corner of the surface a whole cone of
// space projects onto the corner, and vertices moved into it would merge). The exception: a corner
// with an edge below 0.1 % of the mean quad size (both ends sent to about one point by the map: a
// degenerate or nearly degenerate quad) is not held, so collapsed vertices can move apart (the
// quad's diagonal test still is).
// Within a sweep the moves are judged against the quads' surface normals found on their own sheet
// (fast walks); every options.check_every sweeps and after the last, every quad is judged against
// the whole surface, as measure_quads judges it, and the moves since the last such check that
// lost a quad a bit there are undone (reverted).
// pinned (empty, or one flag per vertex): vertices that do not move (fit_quads' snapped ones).
// Throws std::invalid_argument for step outside (0, 2], negative sweeps, weights or tolerance,
// all weights 0, or pinned flags of the wrong size.
QuadSmoothResult smooth_quads(const QuadMesh& quads, const SurfaceProjector& surface, const QuadSmoothOptions& options = {},
                              const std::vector<char>& pinned = {});

// Fitting the quads to the model's extremities. A uniform grid relaxed towards even squares puts
// its vertices anywhere along the model, so tips, fins, sharp corners and creases of the model fall
// inside quads that cut across them: that is where the Hausdorff distance of the quads comes from.
// Here the model's points (sample_surface: its vertices, the centroids of its triangles and points
// along its edges longer than a quarter of the mean quad size, that far apart, so a coarse CAD
// mesh's creases too) farther than `tolerance` × the model's bounding-box diagonal from the quads
// (two triangles each, as the measure splits them) pull, farthest first, the nearest corner of the
// quad they are closest to onto themselves: only a corner within `reach` × the mean quad size, not
// already pulled, whose edges stay above 2 % of the mean quad size, under the relaxation's guard
// (no corner or quad of the vertex's quads turns against the surface that did not before), bending
// no corner of its quads beyond max_corner_deviation from 90°, moving its quads off the model
// (sampled at edge midpoints and triangle centres) no farther than the tolerance or than before,
// and uncovering nothing: the model's points closest to the vertex's quads must stay within the
// farthest distance of the pass. So the farthest model point never gets farther. Pulled vertices
// are pinned. Passes repeat while vertices are pulled.
struct QuadFitOptions {
  int passes = 4;
  double tolerance = 0.002;
  double reach = 0.75;
  // A pull is refused when it bends a corner of the vertex's quads more than this many degrees
  // away from 90° (unless that corner was bent farther before).
  double max_corner_deviation = 60;
  // A point farther than `reach` from every corner of its quad (a tip the map squeezed, the quads
  // round it small and short of it): the nearest corner is pulled onto it with the vertices
  // within up to this many rings following by less and less, so the pull spreads over a few
  // quads (no corner-angle limit: a tip's corner is sharp; the guard and the covering still hold
  // over all the quads moved, and each of them ends within the tolerance of the model, within
  // half the point's distance, or no farther off than before). 0: such points are left.
  int stretch_rings = 8;
  // Threads for the closest points of the model's points and of the quads (0: one per hardware
  // thread); the pulls themselves run in order, so the result does not depend on it.
  int threads = 0;
};

//   mesh       the fitted quads (same connectivity)
//   pinned     per vertex: pulled onto a point of the model
//   snapped    vertices pulled; passes run (including an undone one)
//   farthest_before, farthest_after  largest distance of a model point from the quads, input
//              units (after <= before)
//   seconds    wall time
struct QuadFitResult {
  QuadMesh mesh;
  std::vector<char> pinned;
  int snapped = 0;
  int stretched = 0;  // of the snapped, pulled with rings following (QuadFitOptions::stretch_rings)
  int passes = 0;
  double farthest_before = 0, farthest_after = 0;
  double seconds = 0;
};

// pinned (empty, or one flag per vertex): vertices already fitted (a refinement round's, from the
// quads it refines), not moved and pinned in the result.
// Throws std::invalid_argument for negative passes, tolerance or max_corner_deviation, reach <= 0,
// or pinned flags of the wrong size.
QuadFitResult fit_quads(const QuadMesh& quads, const SurfaceProjector& surface, const QuadFitOptions& options = {},
                        const std::vector<char>& pinned = {});

// Untangling the quads a map folded: vertices of bad quads (flipped, or with an edge or the
// area collapsed below 1e-3 of the mean quad size, or its square) and, when that is not enough, those within `rings` rings of
// quads of them move, one at a time, towards the mean of their edge neighbours, then the mean of
// their quads' centres (full, half or a quarter of the way, on the surface near the vertex: a
// closest point whose normal is within about 70° of the vertex's). A move is taken only if, over
// the vertex's quads, it lowers (bad quads, inverted corners) in that order, judged as
// measure_quads judges them (a corner with a collapsed edge counts as inverted); so the bad
// quads in all never grow. Passes repeat while they gain.
// Quads still bad after that: a patch round each, the quads within r rings of it or those
// reached from it with centres within r mean quad sizes (r = 1, 2, ..., patch_rings, until one
// gains; closed over where it touches itself and over its holes), laid out again by Tutte's
// embedding in the plane across the surface's mean normal under it, its boundary and pinned
// vertices kept, its inner vertices placed on the surface where they project onto their places
// (refused when the patch is no disk, the surface under it turns more than about 70° from the
// plane, or its boundary or a quad turns over in the plane); taken by the same rule as a vertex
// move, over the patch's quads.
struct QuadUntangleOptions {
  int passes = 10;
  int rings = 2;
  int patch_rings = 6;  // 0: no patches
  // A patch with more quads than this is not tried (0: no limit). A regular grid's patch of 6
  // rings has 169 quads, a round one of radius 6 about 113; the largest tried by default on
  // anchor, elk, femur and cow had 277, 544, 2 413 and 3 248. Where a layout is all slivers (femur through a map whose P has 2 952
  // corners: 224 528 quads, each a layout cell of its own), round patches reached 41 665 quads
  // and the patches of 231 flipped quads had not ended after 14 minutes.
  int max_patch_quads = 5000;
  // Collapsed quads count as bad (false: flipped ones only).
  bool collapsed = true;
  // Quads with an inverted corner (non-convex or folded at a corner) are worked on too: their
  // vertices seed the moves and they seed patches. The rule that takes a move stays the same
  // (fewer bad quads, else as many and fewer inverted corners), so no quad turns bad for it.
  bool inverted = false;
  // Corners further than this many degrees from 90° (nearly shut or folded flat; measure_quads'
  // sharp corners) count third: a move or patch is also taken when it keeps the bad quads and
  // the inverted corners and has fewer of these, and their quads are worked on. 0: not counted.
  double sharp_degrees = 0;
};

//   mesh           the quads (same connectivity)
//   moves          vertex moves taken
//   patches        patches laid out again
//   flipped_before, flipped_after  flipped quads as measure_quads counts them
struct QuadUntangleResult {
  QuadMesh mesh;
  int moves = 0;
  int patches = 0;  // patches laid out again
  int flipped_before = 0, flipped_after = 0;
  double seconds = 0;
};

// pinned (empty, or one flag per vertex): vertices that do not move.
// Throws std::invalid_argument for negative passes, rings, patch_rings or max_patch_quads, or pinned flags of
// the wrong size.
QuadUntangleResult untangle_quads(const QuadMesh& quads, const SurfaceProjector& surface, const QuadUntangleOptions& options = {},
                                  const std::vector<char>& pinned = {});

}  // namespace polycube
