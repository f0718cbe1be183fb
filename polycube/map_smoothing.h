// Stage 5 of the method (§3.5): smoothing the glued polycube map φ: P → M, which stage 4 builds
// piece by piece and which is therefore only C0 across the cutting contours, while keeping it
// bijective in the audit's sense: no image triangle of either direction may flip where it did not
// before, and neither direction may end with more flipped triangles than the input.
//
// Method. The paper solves harmonic maps of M's part over face, edge and corner charts of P
// (cotangent weights of M, chart boundary fixed) and iterates. We minimise the same kind of energy
// from P's side, which measured better on the shipped meshes:
//   - ε_angle (eq. 9) of the map sampled at P's vertices is exactly the Dirichlet energy of
//     φ: P → M in P's metric divided by the image area, so moving P's vertex images on M towards
//     that energy's minimiser lowers the measured quantity itself;
//   - P's triangulation is well shaped (a lattice inside every face) and P's corners need no chart
//     of their own: a corner is a vertex with its own cotangent weights. Charts of P are cut
//     wherever they go round another corner, which on staircase-like polycubes is everywhere, and
//     M's triangles are often long (CAD models);
//   - it untangles: a first version with the paper's chart solves on P (harmonic with M's weights,
//     moves refused where a triangle would turn bad) hardly moved the tangled meshes (cow, helmet,
//     elk: free vertices are blocked by the very tangles they should remove), where sweeping P's
//     vertices removes most P → M flips (those straddling cutting planes first).
// Concretely:
//   1. Gauss–Seidel sweeps over P's vertices, in parallel by a distance-2 colouring (the result
//      does not depend on the thread count): each image moves towards the cotangent-weighted
//      average of its neighbours' images, over-relaxed, projected onto M near the old image (a
//      local closest point that never jumps to another sheet). The move — or 1, ½, ¼ of the way —
//      is taken only if no image triangle around it turns from good to bad (good: not degenerate,
//      facing along M's normal at each corner and along the area vectors of its corners' faces)
//      and every image fan still winds once round its vertex in M's tangent plane. Bad triangles
//      of the input may change freely, so they untangle where their neighbours allow.
//   2. φ⁻¹ at M's vertices, consistently with the new φ: each model vertex w whose old P triangle
//      moved is located among P's triangles drawn on M (their corners are points of M) by a walk
//      over P's triangles from the old one, in the chords' normal-prism coordinates
//      (w = Σ bᵢ yᵢ + s Σ bᵢ nᵢ, nᵢ M's normals at the images yᵢ: consistent along shared edges,
//      so the prisms tile the space round the image without gaps), and failing that in an
//      intrinsic chart of M centred at w (unfolding, conformally flattened at w). The barycentrics
//      b in that P triangle give φ⁻¹(w) on P.
//   3. The guard, in rounds. Both directions are judged per triangle exactly as audit_map judges
//      them (same test, same closest faces). After a round, the P vertices of the image
//      triangles it left tangled (first round) and of every place where it is worse than the
//      input — a triangle of either direction flipped that was not, a model vertex that could not
//      be located — are frozen, and the next round restarts from the input. Frozen P vertices keep
//      their input images and the model vertices over them theirs, so frozen places carry the
//      input map in both directions, whose directions agree. The round with the fewest flips in
//      all, and no more than the input's in either direction, is returned; if none, the input.
//   4. Untangling, while flips remain (at most 4 passes): the rounds of 1–3 restricted to the
//      vertices within a few edges of the flipped triangles of one direction, the rest frozen,
//      first with the roles of the meshes swapped — M's vertices move on P (M's fans and
//      cotangent weights; the guard judges M's image triangles on P) and P's vertices whose image
//      lies in a model triangle with a moved corner are relocated among M's triangles drawn on P,
//      as in step 2 — then P's vertices on M again, near the P → M flips. In these phases a vertex
//      of a bad triangle first tries the point of its tangent plane where the smallest triangle of
//      its fan (the neighbours' images projected) is largest, taken only if it leaves fewer bad
//      triangles round the vertex and turns no good one bad. The M-side phase is first run
//      letting P → M get worse (the P-side phase then repairs it), and if that pair does not pay,
//      with neither direction allowed to get worse. The vertices within r rings of the flipped
//      triangles move (r = untangle_rings); a pass is kept
//      only if it leaves neither direction worse and lowers the flips in all, so the untangling
//      never adds a flip.
//      Diagnosis behind it (dev meshes; scratch tools, default parameters): the M → P flips that
//      steps 1–3 leave are small M triangles (under one P triangle's area) almost all next to the
//      cutting contours and P's corners; their three images are squeezed across the contour (the
//      disk maps of the two pieces compress the contour-normal direction 10–30× and shear it
//      there). Many are truly reversed (on one flat face of P, or on two faces unfolded across
//      their edge); on thin parts (anchor) many span two opposite parallel faces of P, where the
//      audit's "normal nearby" is a sum of opposite normals. Even the continuous φ⁻¹ sampled inside one model
//      face and one P triangle has reversed sub-triangles (cow: 38 of 199648), where the two
//      disk maps are strongly anisotropic in different directions: the harmonic disk maps with
//      an arc-length boundary are far from conformal on long pieces. Moving M's vertices on P
//      removes most of those flips; the rest needs better disk maps (see the report of issue 5).
// Every image is a point of a face (face + barycentrics), so images lie on the surfaces to
// rounding.
// What it cannot do: untangle regions where the input map folds over many triangles
// (they stay frozen as the input had them), or lower the distortion that P's corners force.
#pragma once

#include "polycube/map_quality.h"
#include "polycube/polycube_map.h"
#include "polycube/polycube_surface.h"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace polycube {

struct MapSmoothingOptions {
  // Gauss–Seidel sweeps over P's vertices per round (a round stops early when no vertex moves).
  int sweeps = 10;
  // Worker threads; 0: one per hardware thread. The result does not depend on it.
  int threads = 0;
  // Most rounds (>= 1): the first with every vertex free, each further one with more frozen.
  int rounds = 6;
  // Over-relaxation of each move, in [1, 2): a move first goes this many times the way to its
  // neighbours' average (then 1, ½, ¼ if that spoils a triangle). 1.5 roughly halves the sweeps
  // needed for the same angle distortion on the paper's models.
  double relaxation = 1.5;
  // The untangling (step 4 at the top): the number r of edges round a flipped triangle within
  // which vertices may move; 0: no untangling.
  int untangle_rings = 3;
};

// The smoothed map at the vertices of both meshes, and what it took.
//   polycube_on_model      per vertex of P (Polycube::mesh): φ(v) as a point of the model
//   polycube_on_model_xyz  the same as positions
//   model_on_polycube      per vertex of the model: φ⁻¹(w) as a point of P
//   model_on_polycube_xyz  the same as positions
//   sweeps, moves, rejected  Gauss–Seidel sweeps run, vertex moves taken, and moves refused even
//                          at a quarter step (summed over all rounds of the smoothing proper)
//   untangle_phases        untangling phases kept (in passes that lowered the flips in all)
//   untangle_sweeps, untangle_moves  sweeps run and moves taken in all untangling phases tried
//   rounds                 rounds run; the returned map is the best of them
//   frozen                 P vertices that keep their input images in the returned map (all of
//                          them when no round was as good as the input)
//   relocated              model vertices whose φ⁻¹ was recomputed in the returned map
//   flipped_before/after   {P → M, M → P} flipped or degenerate image triangles, as audit_map
//                          counts them, of the input and of the returned map (after <= before)
//   kept                   the smoothed map is returned: it has fewer flipped triangles (both
//                          directions together) or a lower ε_angle than the input; otherwise the
//                          input is (a map already near-conformal, whose P matches the model face
//                          for face, only loses by relaxation: images leave the model's corners)
//   distortion_before/after  map_distortion of the input's and the smoothed map's P → M samples
//                          (after: the smoothed map's even when it is not kept)
//   seconds                wall time
struct MapSmoothingResult {
  std::vector<SurfacePoint> polycube_on_model;
  Eigen::MatrixX3d polycube_on_model_xyz;
  std::vector<SurfacePoint> model_on_polycube;
  Eigen::MatrixX3d model_on_polycube_xyz;
  int sweeps = 0;
  int moves = 0;
  int rejected = 0;
  int rounds = 0;
  int frozen = 0;
  int relocated = 0;
  int untangle_phases = 0;
  int untangle_sweeps = 0;
  int untangle_moves = 0;
  std::array<int, 2> flipped_before{0, 0}, flipped_after{0, 0};
  bool kept = true;
  DistortionStats distortion_before, distortion_after;
  double seconds = 0;
};

// Smooths the map.
//   model     the mesh build_polycube_map was given (closed, manifold, outward)
//   polycube  its polycube (only Polycube::mesh is used)
//   map       build_polycube_map's result (only its vertex images are used: polycube_on_model,
//             model_on_polycube and their _xyz)
// Throws std::invalid_argument when the images do not match the meshes (counts, face indices), a
// mesh is not closed and manifold, or sweeps < 0 or rounds < 1.
MapSmoothingResult smooth_map(const TriMesh& model, const Polycube& polycube, const PolycubeMap& map,
                              const MapSmoothingOptions& options = {});

}  // namespace polycube
