// The last step of the map: where the piecewise-linear sampling of a map still folds an image
// triangle, move single vertex images by the least tried amount, on the target surface, until
// the audit's test passes.
//
// Why. φ is one-to-one in the continuum, but its files are samples: the images of a mesh's
// vertices, joined by straight chords. Where a source triangle is a sliver, or long against the
// map's bends (coarse CAD models on a fine P: a model triangle whose three images lie on one
// face of P, with one corner a hair's breadth across the line through the other two), the
// chord triangle can face the wrong way although every image is exact. The smoothing's
// untangling moves images too, but keeps both directions consistent (moving a model vertex's
// image relocates the P vertices round it), and there a move that unfolds one direction is
// refused when it folds the other. Here each direction's file is corrected on its own: the
// images stay points of the target surface, each moved at most `max_shift` of the target's
// diagonal, or a quarter of its shortest edge if that is more, from where the map put it
// (reported), so the two files remain inverse to each other to within that distance.
//
// Method. Sweeps, while bad triangles (flipped, as audit_map judges them with the same closest
// faces, or degenerate) remain:
//   1. for each bad triangle, each of its corners tries points round its image in the tangent
//      plane of its closest target face — on rings of radius 5 % to 200 % of its shortest image
//      edge, 16 directions each — projected onto the target (closest point). A point is
//      acceptable if it leaves fewer bad triangles round the vertex and turns none of them from
//      good to bad; of all acceptable points of the three corners the closest to the current
//      image is taken;
//   2. a sweep of 1 that moves nothing is followed by one over the vertices within two edges of a
//      bad triangle whose fans are squeezed (smallest signed area in the tangent plane below a
//      quarter of the fan's mean): each moves towards the point of a square round it (half-width:
//      its shortest image edge) where that smallest area is largest — the areas are linear in the
//      position, so the optimum is a corner, a side point where two are equal or a point where
//      three are — the whole, half or a quarter of the way, if that raises the smallest area,
//      leaves no more bad triangles round it and turns none bad. This makes room where a fold
//      spans several vertices and no single move of step 1 unfolds it.
// Neither kind of move adds a bad triangle, so their number never grows; step 1 lowers it.
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

#include <functional>
#include <vector>

namespace polycube {

struct ImageUntangleOptions {
  // Sweeps over the bad triangles (each sweep tries every one still bad).
  int sweeps = 20;
  // How far an image may move from its input position: the larger of max_shift × the target's
  // bounding-box diagonal and max_edge_share × the image's shortest edge in the input (the
  // sampled map is off the exact one by about its edges anyway: on a coarse model whose triangles
  // span much of P, a move of a few per cent of the diagonal is small against them).
  double max_shift = 0.01;
  double max_edge_share = 0.25;
  // When bad triangles remain after the run at max_shift: runs again from the input images with
  // each of these shifts in turn (fractions of the diagonal, as max_shift, ascending) while each
  // run leaves fewer than the best before it and some are left; the result is the best run. (The
  // moves are greedy and depend on the room, so a wider shift is not always better; on a broadly
  // folded map more room hardly helps — cheese, 6 to 81 left per direction: one fewer in 2 of
  // its 11 finished maps — and a run that brings nothing ends the search.) The set-up (closest
  // faces, the audit's verdicts on the input) is made once for all runs.
  std::vector<double> wider_shifts;
  // Called after each run with its shift (max_shift, then the wider ones tried) and the bad
  // triangles it left: progress for the caller (a run on a large map of a CAD model that passes
  // through itself can take minutes). Not called when nothing is bad to begin with.
  std::function<void(double shift, int bad_left)> after_run;
};

// The corrected images and what it took.
//   image        #V(source) by 3: the input images, moved where a triangle was untangled
//   bad_before   flipped + degenerate image triangles of the input (as audit_map counts them)
//   bad_after    the same after the step (<= bad_before)
//   moved        vertices whose image moved
//   max_shift    largest distance of a moved image from its input position / target diagonal
//   shift_allowed  the max_shift of the run kept (options.max_shift or one of wider_shifts)
struct ImageUntangleResult {
  Eigen::MatrixX3d image;
  int bad_before = 0;
  int bad_after = 0;
  int moved = 0;
  double max_shift = 0;
  double shift_allowed = 0;
};

// Untangles one direction of a map: source's triangles at the positions `image` (points of
// target) against the closed, outward-oriented surface target.
// Throws std::invalid_argument when image does not have one finite row per source vertex, for a
// target without area, or for negative options (wider_shifts included).
ImageUntangleResult untangle_image(const TriMesh& source, const Eigen::MatrixX3d& image, const TriMesh& target,
                                   const ImageUntangleOptions& options = {});

}  // namespace polycube
