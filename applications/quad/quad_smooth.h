// Tangential relaxation of a quad mesh lying on a surface: evens out quad sizes and angles where
// the map stretched the grid, keeps every vertex on the surface and never flips a quad.
#pragma once

#include "applications/quad/quad_mesh.h"
#include "applications/quad/surface_projector.h"

namespace polycube {

// Where a relaxation step pulls a vertex.
//   kNeighbourAverage  the average of its edge neighbours (uniform Laplacian): evens out sizes
//   kRightAngles       angle-based (Zhou & Shimada 2000, for quads): for each edge neighbour a,
//                      the point at the same distance from a along the bisector of the two grid
//                      lines leaving a through v's quads, so that both corners at a become right
//                      angles; averaged over the neighbours
//   kBoth              the mean of the two
enum class QuadSmoothTarget { kNeighbourAverage, kRightAngles, kBoth };

struct QuadSmoothOptions {
  // Gauss–Seidel sweeps over all vertices (0: nothing moves).
  int sweeps = 0;
  // Fraction of the tangential way to the average of the edge neighbours moved per sweep, in
  // (0, 1]. A rejected move is retried at half and a quarter of it.
  double step = 0.5;
  QuadSmoothTarget target = QuadSmoothTarget::kBoth;
};

// What happened.
//   mesh      the relaxed quads (same connectivity), every vertex that moved on the surface
//   moves     accepted vertex moves; rejected: moves refused at every tried length
//   seconds   wall time
struct QuadSmoothResult {
  QuadMesh mesh;
  int sweeps = 0;
  long long moves = 0;
  long long rejected = 0;
  double seconds = 0;
};

// Per sweep and vertex: the target (options.target), minus its component along the surface
// normal at the vertex, a step towards it, then the closest point of the surface. The
// move is refused when it turns any corner or any quad (by its diagonals) of the vertex's quads
// from agreeing with the surface normal at the quad (quad_surface_normal) to disagreeing, so the
// flipped quads and inverted corners measure_quads counts never grow.
// Throws std::invalid_argument for step outside (0, 1] or negative sweeps.
QuadSmoothResult smooth_quads(const QuadMesh& quads, const SurfaceProjector& surface, const QuadSmoothOptions& options = {});

}  // namespace polycube
