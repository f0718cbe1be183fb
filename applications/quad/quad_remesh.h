// The quad application in one call (issue 7): a conforming grid on the polycube P, carried to the
// model M by a map P → M, optionally relaxed on M, and measured.
//
//   grid    = build_polycube_grid(P, φ)         quads on P, irregular only at P's corners,
//                                               chords sized by their length on M
//   quads   = carry_grid(grid, map)             the same quads on M
//   quads   = smooth_quads(quads, M)            optional: towards right angles, never flips a quad
//   quads   = fit_quads(quads, M)               optional: corners pulled onto the model's tips,
//                                               then relaxed again around them (pinned)
//   quads   = untangle_quads(quads, M)          optional: flipped quads' vertices moved apart
//   repeat: find_quad_misses(grid, quads, M)    optional: where the finished quads miss M, taken
//           grid = build_polycube_grid(+ those) back to P; the chord parts there halved; the
//           carry (kept vertices where the      grid carried (carry_refined_grid: the vertices
//           last quads have them), smooth, fit  it keeps where the last round's quads have them,
//                                               fitted corners pinned where no line was added),
//                                               relaxed with fewer
//                                               sweeps, fitted; the round that misses least
//                                               without flipping more is kept; past the rounds
//                                               and budget asked for, more of both while beyond
//                                               the bound (QuadRefineOptions)
//   still beyond the bound: template rounds      the quads at the misses split 3 x 3 with
//           (quad_templates.h)                   transitions round them (irregular vertices off
//                                                P's corners), the new vertices placed on the
//                                                quads they split, relaxed round them, fitted
//   quads   = untangle_quads(quads, M)          optional, when quads are bad: every vertex free,
//                                                collapsed quads bad too, patches laid out again
//   quads   = collapse_bad_quads(quads, M)      optional, when quads are still bad: each removed
//                                                by a diagonal collapse (quad_collapse.h;
//                                                irregular vertices off P's corners)
//   quads   = untangle_quads(quads, M)          optional (mend_corners): inverted and sharp
//                                                corners too; kept when the quads miss M no farther
//   quality = measure_quads(quads, M, corners)
#pragma once

#include "applications/quad/carry_grid.h"
#include "applications/quad/polycube_grid.h"
#include "applications/quad/quad_quality.h"
#include "applications/quad/quad_refine.h"
#include "applications/quad/quad_smooth.h"
#include "applications/quad/surface_projector.h"

#include <functional>
#include <string>

namespace polycube {

// Called when a step starts and when it ends: (stage, message). Stages: "grid", "carry",
// "refine", "smooth", "fit", "untangle", "quality".
using QuadProgress = std::function<void(const std::string& stage, const std::string& message)>;

struct QuadRemeshOptions {
  PolycubeGridOptions grid;
  // Size the grid's chords by their lengths on M (through to_model) rather than on P, so quads
  // are near h wide on the model where φ stretches or shrinks P.
  bool size_on_model = true;
  CarryOptions carry;
  QuadRefineOptions refine;
  QuadSmoothOptions smooth;
  // The fit to the model's extremities after the relaxation (passes 0: none), then this many
  // relaxation sweeps with the pulled vertices pinned (at most smooth.sweeps).
  QuadFitOptions fit;
  int refit_sweeps = 10;
  // After the fit, the vertices of flipped quads moved apart where that unflips them (passes 0:
  // not).
  QuadUntangleOptions untangle;
  // At the end, quads with inverted corners (non-convex) or sharp ones (quality.sharp_degrees
  // from 90°) mended by the untangling's moves and patches (with untangle's passes;
  // QuadUntangleOptions::inverted, sharp_degrees), held where the quads would miss the model
  // farther.
  bool mend_corners = true;
  // Quads still flipped or degenerate after the last untangling removed by diagonal collapses
  // (quad_collapse.h), when that leaves fewer of them.
  bool collapse_bad = true;
  QuadQualityOptions quality;
  bool measure = true;  // false: skip measure_quads
};

// Everything produced.
//   grid       the grid on P (positions on P, vertices as points of P, corners)
//   mesh       the quads on M (grid's connectivity)
//   refine_rounds  refinement rounds kept; refine_miss_before / _after: the farthest miss
//              (find_quad_misses) of the uniform and of the refined carried grid, input units
//   smoothing  what the relaxation did (nothing when options.smooth.sweeps is 0)
//   fitting    what the fit did (its mesh left empty; nothing when options.fit.passes is 0)
//   refitting  the relaxation after the fit, pulled vertices pinned (its mesh left empty)
//   untangling what the untangling did after the fit (its mesh left empty)
//   quality    of mesh against M (quality.seconds: its time)
//   seconds_*  wall time per stage
struct QuadRemeshResult {
  PolycubeGrid grid;
  QuadMesh mesh;
  int refine_rounds = 0;
  int template_rounds = 0;  // template refinement rounds kept (QuadRefineOptions::template_rounds)
  double refine_miss_before = 0;
  double refine_miss_after = 0;
  QuadSmoothResult smoothing;
  QuadFitResult fitting;
  QuadSmoothResult refitting;
  QuadUntangleResult untangling;
  // What the corners' mending found and left (mend_quad_corners; -1: it did not run), how many
  // tries it made and whether one was kept.
  int inverted_before_mending = -1, sharp_before_mending = -1;
  int mending_tries = 0;
  bool mending_kept = false;
  int collapsed_quads = 0;  // bad quads removed by diagonal collapses (collapse_bad)
  QuadQuality quality;
  double seconds_grid = 0;
  double seconds_carry = 0;
  double seconds_refine = 0;
  double seconds_smooth = 0;
  double seconds_fit = 0;
  double seconds_untangle = 0;
  double seconds_quality = 0;
};

// Runs the four steps.
//   polycube  P's triangle mesh (SurfacePoint faces passed to `to_model` refer to it)
//   to_model  φ: P → M, point by point
//   model     M, as a projector (smoothing keeps vertices on it, quality measures against it)
//   progress  optional
// Throws what the steps throw.
QuadRemeshResult remesh_quads(const TriMesh& polycube, const SurfaceMap& to_model, const SurfaceProjector& model,
                              const QuadRemeshOptions& options = {}, const QuadProgress& progress = {});

// The corners' mending of remesh_quads (QuadRemeshOptions::mend_corners) on its result, on its
// own (`polycube quad` mends only the try it keeps): quads with inverted or sharp corners
// untangled, kept when that raises neither the bad quads nor the inverted corners nor the
// Hausdorff distance (beyond 1 %, and not out of options.refine.bound_percent); then, when
// options.measure, result.quality measured again (else, if the mesh changed, left unmeasured:
// result.quality is reused as the starting figures only when it is of result.mesh). The mesh
// keeps its connectivity.
void mend_quad_corners(QuadRemeshResult& result, const SurfaceProjector& model, const QuadRemeshOptions& options = {},
                       const QuadProgress& progress = {});

}  // namespace polycube
