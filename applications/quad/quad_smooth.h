// Tangential relaxation of a quad mesh lying on a surface: drives the quads towards squares of
// even size where the map stretched the grid, keeps every vertex on the surface and never flips a
// quad.
#pragma once

#include "applications/quad/quad_mesh.h"
#include "applications/quad/surface_projector.h"

namespace polycube {

struct QuadSmoothOptions {
  // Gauss–Seidel sweeps over all vertices at most (0: nothing moves).
  int sweeps = 0;
  // Fraction of the tangential way to the target moved per step, in (0, 1]. A refused move is
  // retried at half and a quarter of it.
  double step = 1.0;
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
};

// What happened.
//   mesh      the relaxed quads (same connectivity), every vertex that moved on the surface
//   sweeps    sweeps run; converged: the last one moved less than the tolerance
//   moves     accepted vertex moves; rejected: moves refused at every tried length
//   largest_move  of the last sweep, over the mean quad size
//   seconds   wall time
struct QuadSmoothResult {
  QuadMesh mesh;
  int sweeps = 0;
  bool converged = false;
  long long moves = 0;
  long long rejected = 0;
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
// Throws std::invalid_argument for step outside (0, 1], negative sweeps, weights or tolerance,
// or all weights 0.
QuadSmoothResult smooth_quads(const QuadMesh& quads, const SurfaceProjector& surface, const QuadSmoothOptions& options = {});

}  // namespace polycube
