#include "applications/quad/quad_smooth.h"

#include "applications/quad/quad_quality.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace polycube {

namespace {

using Complex = std::complex<double>;

// A move's closest point is taken when the surface normal there is within about 70° of the
// normal at the vertex.
constexpr double kSameSheet = 0.3;
constexpr double kPi = 3.14159265358979323846;
// No move shortens an edge below this times the mean quad size.
constexpr double kShortestEdge = 0.02;
// Edges up to this times the mean quad size count as collapsed (a map sent both ends to one
// point): their corners are free to move.
constexpr double kCollapsedEdge = 1e-3;

// Square root of the mean quad area (areas by the diagonals' cross product).
double mean_quad_size(const QuadMesh& mesh) {
  if (mesh.num_quads() == 0) return 0;
  double area = 0;
  for (int q = 0; q < mesh.num_quads(); ++q) {
    const Eigen::Vector3d d1 = mesh.V.row(mesh.Q(q, 2)) - mesh.V.row(mesh.Q(q, 0));
    const Eigen::Vector3d d2 = mesh.V.row(mesh.Q(q, 3)) - mesh.V.row(mesh.Q(q, 1));
    area += d1.cross(d2).norm() / 2;
  }
  return std::sqrt(area / mesh.num_quads());
}

}  // namespace

QuadSmoothResult smooth_quads(const QuadMesh& quads, const SurfaceProjector& surface, const QuadSmoothOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (options.sweeps < 0) throw std::invalid_argument("smoothing sweeps must be >= 0, got " + std::to_string(options.sweeps));
  if (!(options.step > 0 && options.step <= 1))
    throw std::invalid_argument("smoothing step must be in (0, 1], got " + std::to_string(options.step));
  const double wl = options.average_weight, wa = options.angle_weight, wc = options.cross_weight;
  if (!(wl >= 0 && wa >= 0 && wc >= 0 && wl + wa + wc > 0))
    throw std::invalid_argument("smoothing weights must be >= 0 and not all 0, got " + std::to_string(wl) + ", " +
                                std::to_string(wa) + ", " + std::to_string(wc));
  if (!(options.tolerance >= 0))
    throw std::invalid_argument("smoothing tolerance must be >= 0, got " + std::to_string(options.tolerance));
  QuadSmoothResult result;
  result.mesh = quads;
  if (options.sweeps == 0) return result;

  QuadMesh& mesh = result.mesh;
  const int nv = mesh.num_vertices();
  const std::vector<std::vector<int>> neighbours = vertex_neighbours(mesh.Q, nv);
  const std::vector<std::vector<int>> around = vertex_quads(mesh.Q, nv);
  // Closest surface point of each vertex (its normal: the tangent plane moves stay in) and of
  // each quad's centre (the quad's surface normal, as quad_surface_normal finds it), kept as
  // search hints for the next queries nearby.
  std::vector<SurfaceHit> vertex_hit(nv);
  for (int v = 0; v < nv; ++v) vertex_hit[v] = surface.closest(mesh.V.row(v).transpose());
  std::vector<SurfaceHit> quad_hit(mesh.num_quads());
  double size = mean_quad_size(mesh);

  // Bit k: corner k turns with the quad's surface normal (as measure_quads counts inverted
  // corners); bit 4: the quad (diagonals) does (flipped quads). centre: in, the hint (face -1:
  // none); out, the centre's closest point.
  const auto state = [&](int q, SurfaceHit& centre) {
    int bits = 0;
    Eigen::Vector3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = mesh.V.row(mesh.Q(q, k));
    const Eigen::Vector3d middle = (p[0] + p[1] + p[2] + p[3]) / 4;
    centre = centre.face >= 0 ? surface.closest(middle, centre) : surface.closest(middle);
    const Eigen::Vector3d n = quad_surface_normal(surface, centre);
    // A corner with an edge of (almost) no length has no meaningful turn: it is not held, so
    // vertices a map collapsed onto one point can move apart.
    const double shortest = kCollapsedEdge * size;
    for (int k = 0; k < 4; ++k)
      if ((p[(k + 1) % 4] - p[k]).norm() > shortest && (p[(k + 3) % 4] - p[k]).norm() > shortest &&
          (p[(k + 1) % 4] - p[k]).cross(p[(k + 3) % 4] - p[k]).dot(n) > 0)
        bits |= 1 << k;
    if ((p[2] - p[0]).cross(p[3] - p[1]).dot(n) > 0) bits |= 16;
    return bits;
  };

  // The cross at v: its spokes (edges to its neighbours, counter-clockwise in the tangent plane
  // t1, t2 = n × t1) turned to equal angles (90° at a regular vertex) by the best common
  // rotation, each keeping its length; v goes where those spokes would start from.
  std::vector<int> ring;
  std::vector<Complex> spoke;
  const auto cross_target = [&](int v, const Eigen::Vector3d& p, const Eigen::Vector3d& n) -> Eigen::Vector3d {
    const Eigen::Vector3d nan = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    const int k = static_cast<int>(around[v].size());
    if (k < 3) return nan;
    // Quad (v, next, opposite, previous) turns counter-clockwise from spoke next to spoke previous.
    const auto corner = [&](int q) {
      int c = 0;
      while (mesh.Q(q, c) != v) ++c;
      return c;
    };
    ring.clear();
    const int first = mesh.Q(around[v][0], (corner(around[v][0]) + 1) % 4);
    int current = first;
    for (int step = 0; step < k; ++step) {
      int previous = -1;
      for (int q : around[v]) {
        const int c = corner(q);
        if (mesh.Q(q, (c + 1) % 4) == current) previous = mesh.Q(q, (c + 3) % 4);
      }
      if (previous < 0) return nan;
      ring.push_back(current);
      current = previous;
    }
    if (current != first) return nan;
    const Eigen::Vector3d t1 = n.unitOrthogonal();
    const Eigen::Vector3d t2 = n.cross(t1);
    Complex turn = 0;
    spoke.resize(k);
    for (int j = 0; j < k; ++j) {
      const Eigen::Vector3d d = mesh.V.row(ring[j]).transpose() - p;
      spoke[j] = {d.dot(t1), d.dot(t2)};
      if (std::abs(spoke[j]) == 0) return nan;
      turn += std::conj(std::polar(1.0, 2 * kPi * j / k)) * spoke[j] / std::abs(spoke[j]);
    }
    if (std::abs(turn) == 0) return nan;
    turn /= std::abs(turn);
    Complex offset = 0;
    for (int j = 0; j < k; ++j) offset += spoke[j] - std::abs(spoke[j]) * turn * std::polar(1.0, 2 * kPi * j / k);
    offset /= static_cast<double>(k);
    return p + offset.real() * t1 + offset.imag() * t2;
  };

  std::vector<int> quad_state(mesh.num_quads()), after;
  std::vector<SurfaceHit> after_hit;
  for (int q = 0; q < mesh.num_quads(); ++q) quad_state[q] = state(q, quad_hit[q]);
  std::vector<std::pair<int, int>> rails;
  for (int sweep = 0; sweep < options.sweeps; ++sweep) {
    ++result.sweeps;
    size = mean_quad_size(mesh);
    double largest = 0;
    for (int v = 0; v < nv; ++v) {
      if (neighbours[v].empty()) continue;
      const Eigen::Vector3d p = mesh.V.row(v), n = vertex_hit[v].normal;
      const SurfaceHit old_hit = vertex_hit[v];
      Eigen::Vector3d average = Eigen::Vector3d::Zero();
      for (int u : neighbours[v]) average += mesh.V.row(u).transpose();
      average /= static_cast<double>(neighbours[v].size());
      Eigen::Vector3d target = wl * average;
      double weight = wl;
      if (wc > 0) {
        const Eigen::Vector3d c = cross_target(v, p, n);
        if (c.allFinite()) {
          target += wc * c;
          weight += wc;
        }
      }
      if (wa > 0) {
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
          Eigen::Vector3d bisector = vertex_hit[rails[r].first].normal.cross(u2 - u1);
          const double length = (p - a).norm();
          if (!(bisector.norm() > 1e-12) || !(length > 0)) continue;
          bisector.normalize();
          if (bisector.dot(p - a) < 0) bisector = -bisector;
          angles += a + length * bisector;
          ++spokes;
        }
        if (spokes > 0) {
          target += wa * angles / spokes;
          weight += wa;
        }
      }
      if (!(weight > 0)) continue;
      target /= weight;
      Eigen::Vector3d d = target - p;
      d -= d.dot(n) * n;
      if (!d.allFinite() || d.squaredNorm() == 0) continue;
      bool accepted = false;
      for (double step = options.step; !accepted && step >= options.step / 4; step /= 2) {
        const SurfaceHit hit = surface.closest(p + step * d, old_hit);
        // The closest point must be the surface under the vertex, not another sheet of a thin
        // part (the far side of an ear) that happens to be nearer to the moved point.
        if (!(hit.normal.dot(n) > kSameSheet) || (hit.point - p).norm() > 2 * step * d.norm()) continue;
        // Nor may an edge shrink to almost nothing: near a convex corner of the surface, a whole
        // cone of space has the corner as closest point, and vertices moved into it would merge
        // into degenerate quads.
        bool collapses = false;
        for (int u : neighbours[v]) {
          const double before = (mesh.V.row(u).transpose() - p).norm();
          const double now = (mesh.V.row(u).transpose() - hit.point).norm();
          collapses |= now < before && now < kShortestEdge * size;
        }
        if (collapses) continue;
        mesh.V.row(v) = hit.point;
        vertex_hit[v] = hit;
        accepted = true;
        after.clear();
        after_hit.clear();
        for (size_t k = 0; k < around[v].size() && accepted; ++k) {
          after_hit.push_back(quad_hit[around[v][k]]);
          after.push_back(state(around[v][k], after_hit.back()));
          accepted = (quad_state[around[v][k]] & ~after.back()) == 0;
        }
      }
      if (accepted) {
        ++result.moves;
        largest = std::max(largest, (mesh.V.row(v).transpose() - p).norm());
        for (size_t k = 0; k < around[v].size(); ++k) {
          quad_state[around[v][k]] = after[k];
          quad_hit[around[v][k]] = after_hit[k];
        }
      } else {
        ++result.rejected;
        mesh.V.row(v) = p;
        vertex_hit[v] = old_hit;
      }
    }
    result.largest_move = size > 0 ? largest / size : 0;
    if (result.largest_move <= options.tolerance) {
      result.converged = true;
      break;
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace polycube
