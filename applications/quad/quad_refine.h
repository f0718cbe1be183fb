// Local refinement of the quad grid where the quads miss the model (issue 7's Hausdorff bound).
// A uniform grid on P carried by φ is coarse on M wherever φ squeezes a part of M into a small
// part of P (a horn, an ear, a fin): the model sticks out between the quads. The places are
// found on the finished quads (find_quad_misses) and taken back to P (PreimageLocator), where the grid's chords through them get
// their parts halved (PolycubeGridOptions::refine_rounds): a new grid line along each chord, so
// the grid stays conforming, all-quad and irregular only at P's corners.
#pragma once

#include "applications/quad/polycube_grid.h"
#include "applications/quad/quad_mesh.h"
#include "applications/quad/surface_projector.h"
#include "polycube/mesh.h"
#include "polycube/polycube_map.h"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace polycube {

struct QuadRefineOptions {
  // Rounds of refinement (each: find the misses of the finished quads, halve the chord parts
  // there, carry, relax and fit again: a whole pass); 0: none.
  int rounds = 3;
  // Each round refines at the misses within this fraction of the farthest one (the worst
  // places first; the others may be fixed on the way, or in a later round).
  double worst_fraction = 0.6;
  // Aim, in % of the model's bounding-box diagonal: every vertex of M within it from the
  // carried quads, every quad's centre within it from M.
  double target_percent = 0.25;
  // At most this times the unrefined grid's quads; a round that would exceed it is retried with
  // the worse half of its places (down to one), then refinement stops.
  double max_growth = 1.3;
  // The bound the result must meet, in % of the diagonal (issue 7: 0.5): while the quads miss the
  // model by more than this when the rounds or the budget above are spent, the refinement goes on
  // for up to bound_rounds more rounds with a budget of bound_growth times the unrefined grid's
  // quads. 0: no bound.
  double bound_percent = 0.5;
  double bound_growth = 3;
  int bound_rounds = 8;
  // A round's grid keeps the places the quads it refines have for the vertices it shares with
  // them (carry_refined_grid: only the added lines are carried by the map) and is relaxed with at
  // most this many sweeps; 0: all carried by the map and relaxed with all the sweeps, as the
  // first pass.
  int warm_sweeps = 15;
  // A warm round relaxes only the vertices of quads with a new corner and of this many rings of
  // quads round them; the others keep their places. -1: every vertex relaxes.
  int local_rings = 2;
  // After refinement rounds were kept, this many relaxation sweeps of every vertex (fitted ones
  // held), kept only if the quads then flip nothing more and miss the model no farther or within
  // 0.9 × bound_percent; 0: none.
  int polish_sweeps = 15;
  // When the quads still miss the model by more than bound_percent after all that: up to this
  // many rounds of template refinement (quad_templates.h: only the quads at the misses are split,
  // with transitions round them; irregular vertices off P's corners), all of them together up to
  // template_growth times the quads they start from; a round is kept when it misses less and
  // flips nothing more. 0: none.
  int template_rounds = 4;
  double template_growth = 1.5;
  // Threads for the distance queries and the map's values at P's vertices (the map must then be
  // thread-safe); 0: one per hardware thread, 1: the calling thread.
  int threads = 1;
};

// Preimages under a map P → M of points near M, through the map's chords: the images of P's
// vertices span a triangle mesh with P's triangles; a point's closest point on it, with its
// barycentric coordinates, is the same triangle and coordinates of P.
class PreimageLocator {
 public:
  // to_model is evaluated at every vertex of P (threads as in QuadRefineOptions).
  PreimageLocator(const TriMesh& polycube, const SurfaceMap& to_model, int threads);
  // The point of P whose chord image is closest to x.
  SurfacePoint preimage(const Eigen::Vector3d& x) const;
  // The closest point of P to p (p on P up to rounding).
  SurfacePoint on_polycube(const Eigen::Vector3d& p) const;

 private:
  std::unique_ptr<SurfaceProjector> on_polycube_;  // P (its copy of P is the one used)
  std::unique_ptr<SurfaceProjector> on_images_;  // P's triangles at their vertices' images
};

// Where quads on M (the grid carried, perhaps relaxed: same connectivity) miss M by more than
// `distance`:
//   points    points of P to refine at, the worst first: the preimages (and the points of P
//             under the quads' closest points) of the points of M
//             farther than `distance` from the quads (two triangles each) — M's vertices, the
//             centroids of its triangles longer than cell_size / 4 and points along its edges
//             longer than that, at most cell_size / 4 apart (a coarse CAD mesh is missed between
//             its vertices, along its creases) — and the points on P of quad centres, of the
//             centroids of each quad's two triangles (split as the measure splits it) and of quad
//             edge midpoints farther than `distance` from M (quads bridging a concave crease)
//   distances their distances
//   farthest  the largest of both distances: exact when above `distance`; when every point is
//             within it, perhaps a little over the true largest (a point of M may be measured by
//             a walk on the quads' sheet, which never comes out nearer than the closest point)
struct QuadMiss {
  std::vector<SurfacePoint> points;
  std::vector<double> distances;  // per point, descending
  double farthest = 0;
};
QuadMiss find_quad_misses(const PolycubeGrid& grid, const QuadMesh& quads, const SurfaceProjector& model,
                          const PreimageLocator& locator, double distance, double cell_size, int threads);

}  // namespace polycube
