// Internal to applications/quad: what the relaxation, the fit and the untangling share to judge a
// quad against the surface it lies on (not part of the application's interface).
#pragma once

#include "applications/quad/quad_mesh.h"
#include "applications/quad/quad_quality.h"
#include "applications/quad/surface_projector.h"

#include <Eigen/Geometry>

namespace polycube {

// A move's closest point is taken when the surface normal there is within about 70° of the
// normal at the vertex.
inline constexpr double kSameSheet = 0.3;
// Edges up to this times the mean quad size count as collapsed (a map sent both ends to one
// point): their corners are free to move.
inline constexpr double kCollapsedEdge = 1e-3;

// Square root of the mean quad area (areas by the diagonals' cross product).
double mean_quad_size(const QuadMesh& mesh);

// What the moves of a vertex may not spoil, per quad: bit k is set when corner k turns with the
// quad's surface normal (as measure_quads counts inverted corners), bit 4 when the quad (its
// diagonals) does (flipped quads). A move is refused when it clears a bit of one of the vertex's
// quads.
class QuadGuard {
 public:
  QuadGuard(const QuadMesh& mesh, const SurfaceProjector& surface) : mesh_(mesh), surface_(surface) {}

  // centre: in, the search hint for the quad centre's closest point (face -1: none); out, that
  // point. size: the mean quad size (corners with an edge below kCollapsedEdge of it are free).
  // on_sheet: the centre's closest point on the hint's sheet (SurfaceProjector::closest_on_sheet,
  // fast) instead of on the whole surface (as measure_quads takes it).
  int state(int q, SurfaceHit& centre, double size, bool on_sheet = false) const {
    int bits = 0;
    Eigen::Vector3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = mesh_.V.row(mesh_.Q(q, k));
    const Eigen::Vector3d middle = (p[0] + p[1] + p[2] + p[3]) / 4;
    centre = centre.face < 0 ? surface_.closest(middle)
             : on_sheet        ? surface_.closest_on_sheet(middle, centre)
                               : surface_.closest(middle, centre);
    const Eigen::Vector3d n = quad_surface_normal(surface_, centre);
    // A corner with an edge of (almost) no length has no meaningful turn: it is not held, so
    // vertices a map collapsed onto one point can move apart.
    const double shortest = kCollapsedEdge * size;
    for (int k = 0; k < 4; ++k)
      if ((p[(k + 1) % 4] - p[k]).norm() > shortest && (p[(k + 3) % 4] - p[k]).norm() > shortest &&
          (p[(k + 1) % 4] - p[k]).cross(p[(k + 3) % 4] - p[k]).dot(n) > 0)
        bits |= 1 << k;
    if ((p[2] - p[0]).cross(p[3] - p[1]).dot(n) > 0) bits |= 16;
    return bits;
  }

 private:
  const QuadMesh& mesh_;
  const SurfaceProjector& surface_;
};

}  // namespace polycube
