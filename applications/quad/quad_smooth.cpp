#include "applications/quad/quad_smooth.h"

#include "applications/quad/quad_quality.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <utility>
#include <stdexcept>
#include <string>
#include <vector>

namespace polycube {

QuadSmoothResult smooth_quads(const QuadMesh& quads, const SurfaceProjector& surface, const QuadSmoothOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (options.sweeps < 0) throw std::invalid_argument("smoothing sweeps must be >= 0, got " + std::to_string(options.sweeps));
  if (!(options.step > 0 && options.step <= 1))
    throw std::invalid_argument("smoothing step must be in (0, 1], got " + std::to_string(options.step));
  QuadSmoothResult result;
  result.mesh = quads;
  if (options.sweeps == 0) return result;

  QuadMesh& mesh = result.mesh;
  const int nv = mesh.num_vertices();
  const std::vector<std::vector<int>> neighbours = vertex_neighbours(mesh.Q, nv);
  const std::vector<std::vector<int>> around = vertex_quads(mesh.Q, nv);
  // Surface normal at each vertex (interpolated at its closest point): the tangent plane moves
  // stay in.
  Eigen::MatrixX3d normal(nv, 3);
  for (int v = 0; v < nv; ++v) normal.row(v) = surface.closest(mesh.V.row(v).transpose()).normal;

  // Bit k: corner k turns with the surface normal at the quad (quad_surface_normal, as
  // measure_quads counts flips); bit 4: the quad (diagonals) does.
  const auto state = [&](int q) {
    int bits = 0;
    Eigen::Vector3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = mesh.V.row(mesh.Q(q, k));
    const Eigen::Vector3d n = quad_surface_normal(surface, p);
    for (int k = 0; k < 4; ++k)
      if ((p[(k + 1) % 4] - p[k]).cross(p[(k + 3) % 4] - p[k]).dot(n) > 0) bits |= 1 << k;
    if ((p[2] - p[0]).cross(p[3] - p[1]).dot(n) > 0) bits |= 16;
    return bits;
  };

  std::vector<int> quad_state(mesh.num_quads()), after;
  for (int q = 0; q < mesh.num_quads(); ++q) quad_state[q] = state(q);
  std::vector<std::pair<int, int>> rails;
  for (int sweep = 0; sweep < options.sweeps; ++sweep) {
    ++result.sweeps;
    for (int v = 0; v < nv; ++v) {
      if (neighbours[v].empty()) continue;
      const Eigen::Vector3d p = mesh.V.row(v), n = normal.row(v);
      Eigen::Vector3d average = Eigen::Vector3d::Zero();
      for (int u : neighbours[v]) average += mesh.V.row(u).transpose();
      average /= static_cast<double>(neighbours[v].size());
      Eigen::Vector3d target = average;
      if (options.target != QuadSmoothTarget::kNeighbourAverage) {
        // Each spoke (v, a) lies in two of v's quads; the rails at a run to their corners
        // opposite v.
        rails.clear();
        for (int q : around[v]) {
          int k = 0;
          while (mesh.Q(q, k) != v) ++k;
          const int c = mesh.Q(q, (k + 2) % 4);
          rails.emplace_back(mesh.Q(q, (k + 1) % 4), c);
          rails.emplace_back(mesh.Q(q, (k + 3) % 4), c);
        }
        std::sort(rails.begin(), rails.end());
        Eigen::Vector3d angles = Eigen::Vector3d::Zero();
        int spokes = 0;
        for (size_t r = 0; r + 1 < rails.size(); r += 2) {
          if (rails[r].first != rails[r + 1].first) {  // not a closed fan: keep the average
            spokes = 0;
            break;
          }
          const Eigen::Vector3d a = mesh.V.row(rails[r].first);
          const Eigen::Vector3d u1 = (mesh.V.row(rails[r].second).transpose() - a).normalized();
          const Eigen::Vector3d u2 = (mesh.V.row(rails[r + 1].second).transpose() - a).normalized();
          Eigen::Vector3d bisector = normal.row(rails[r].first).transpose().cross(u2 - u1);
          const double length = (p - a).norm();
          if (!(bisector.norm() > 1e-12) || !(length > 0)) continue;
          bisector.normalize();
          if (bisector.dot(p - a) < 0) bisector = -bisector;
          angles += a + length * bisector;
          ++spokes;
        }
        if (spokes > 0) {
          angles /= spokes;
          target = options.target == QuadSmoothTarget::kRightAngles ? angles : ((angles + average) / 2).eval();
        }
      }
      Eigen::Vector3d d = target - p;
      d -= d.dot(n) * n;
      if (d.squaredNorm() == 0) continue;
      bool accepted = false;
      for (double step = options.step; !accepted && step >= options.step / 4; step /= 2) {
        const SurfaceHit hit = surface.closest(p + step * d);
        mesh.V.row(v) = hit.point;
        normal.row(v) = hit.normal;
        accepted = true;
        after.clear();
        for (size_t k = 0; k < around[v].size() && accepted; ++k) {
          after.push_back(state(around[v][k]));
          accepted = (quad_state[around[v][k]] & ~after.back()) == 0;
        }
      }
      if (accepted) {
        ++result.moves;
        for (size_t k = 0; k < around[v].size(); ++k) quad_state[around[v][k]] = after[k];
      } else {
        ++result.rejected;
        mesh.V.row(v) = p;
        normal.row(v) = n;
      }
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace polycube
