#include "applications/quad/quad_smooth.h"

#include "applications/quad/quad_guard.h"
#include "applications/quad/quad_quality.h"

#include "polycube/closest_point.h"
#include "polycube/parallel.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace polycube {

namespace {

using Complex = std::complex<double>;

constexpr double kPi = 3.14159265358979323846;
// No move shortens an edge below this times the mean quad size.
constexpr double kShortestEdge = 0.02;

// Greedy colouring of the movable vertices such that two vertices of one colour share no quad.
std::vector<std::vector<int>> quad_star_colours(const Eigen::MatrixX4i& Q, const std::vector<std::vector<int>>& around,
                                                const std::vector<char>& pinned) {
  const int nv = static_cast<int>(around.size());
  std::vector<int> colour(nv, -1), seen;
  std::vector<std::vector<int>> colours;
  for (int v = 0; v < nv; ++v) {
    if (around[v].empty() || (!pinned.empty() && pinned[v])) continue;
    for (int q : around[v])
      for (int k = 0; k < 4; ++k) {
        const int c = colour[Q(q, k)];
        if (c >= 0) seen[c] = v + 1;
      }
    int c = 0;
    while (c < static_cast<int>(colours.size()) && seen[c] == v + 1) ++c;
    if (c == static_cast<int>(colours.size())) {
      colours.emplace_back();
      seen.push_back(0);
    }
    colour[v] = c;
    colours[c].push_back(v);
  }
  return colours;
}

}  // namespace

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

QuadSmoothResult smooth_quads(const QuadMesh& quads, const SurfaceProjector& surface, const QuadSmoothOptions& options,
                              const std::vector<char>& pinned) {
  const auto start = std::chrono::steady_clock::now();
  if (options.sweeps < 0) throw std::invalid_argument("smoothing sweeps must be >= 0, got " + std::to_string(options.sweeps));
  if (!(options.step > 0 && options.step <= 2))
    throw std::invalid_argument("smoothing step must be in (0, 2], got " + std::to_string(options.step));
  const double wl = options.average_weight, wa = options.angle_weight, wc = options.cross_weight;
  if (!(wl >= 0 && wa >= 0 && wc >= 0 && wl + wa + wc > 0))
    throw std::invalid_argument("smoothing weights must be >= 0 and not all 0, got " + std::to_string(wl) + ", " +
                                std::to_string(wa) + ", " + std::to_string(wc));
  if (!(options.tolerance >= 0))
    throw std::invalid_argument("smoothing tolerance must be >= 0, got " + std::to_string(options.tolerance));
  if (!pinned.empty() && static_cast<int>(pinned.size()) != quads.num_vertices())
    throw std::invalid_argument("smoothing: " + std::to_string(pinned.size()) + " pinned flags for " + std::to_string(quads.num_vertices()) +
                                " vertices");
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
  const int threads = threads_for(options.threads);
  std::vector<SurfaceHit> vertex_hit(nv);
  parallel_range(nv, threads, [&](int v) { vertex_hit[v] = surface.closest(mesh.V.row(v).transpose()); });
  std::vector<SurfaceHit> quad_hit(mesh.num_quads());
  double size = mean_quad_size(mesh);

  const QuadGuard guard(mesh, surface);
  // During a sweep the guards of quads far from trouble take the quad centres' closest points on
  // their sheets (fast); the sweep's end checks every quad against the whole surface (see below).
  // Quads with a bit unset at the sweep's start, and those within two rings of them, are judged
  // against the whole surface throughout, so that the moves round a tangle are judged as the
  // measure judges them and the ones that repair it count as repairs.
  constexpr int kAllBits = 31;
  std::vector<int> quad_state(mesh.num_quads());
  std::vector<char> whole_surface(mesh.num_quads(), 0);
  const auto state = [&](int q, SurfaceHit& centre) { return guard.state(q, centre, size, !whole_surface[q]); };
  // Marks the quads with a bit unset and those within two rings of them (sharing a vertex).
  const auto mark_trouble = [&]() {
    std::fill(whole_surface.begin(), whole_surface.end(), 0);
    std::vector<int> front;
    for (int q = 0; q < mesh.num_quads(); ++q)
      if (quad_state[q] != kAllBits) {
        whole_surface[q] = 1;
        front.push_back(q);
      }
    for (int ring = 0; ring < 2; ++ring) {
      std::vector<int> next;
      for (int q : front)
        for (int k = 0; k < 4; ++k)
          for (int r : around[mesh.Q(q, k)])
            if (!whole_surface[r]) {
              whole_surface[r] = 1;
              next.push_back(r);
            }
      front = std::move(next);
    }
  };

  // The cross at v: its spokes (edges to its neighbours, counter-clockwise in the tangent plane
  // t1, t2 = n × t1) turned to equal angles (90° at a regular vertex) by the best common
  // rotation, each keeping its length; v goes where those spokes would start from.
  // Work space of one thread's moves.
  struct Scratch {
    std::vector<int> ring;
    std::vector<Complex> spoke;
    std::vector<std::pair<int, int>> rails;
    std::vector<int> after;
    std::vector<SurfaceHit> after_hit;
  };
  const auto cross_target = [&](int v, const Eigen::Vector3d& p, const Eigen::Vector3d& n, Scratch& scratch) -> Eigen::Vector3d {
    std::vector<int>& ring = scratch.ring;
    std::vector<Complex>& spoke = scratch.spoke;
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

  parallel_range(mesh.num_quads(), threads, [&](int q) { quad_state[q] = guard.state(q, quad_hit[q], size); });

  // One Gauss–Seidel move of v; returns how far it moved (-1: refused, 0: nothing to do). Reads
  // the vertices of v's quads, writes v and v's quads' states.
  const auto move = [&](int v, Scratch& scratch) -> double {
    std::vector<std::pair<int, int>>& rails = scratch.rails;
    std::vector<int>& after = scratch.after;
    std::vector<SurfaceHit>& after_hit = scratch.after_hit;
    const Eigen::Vector3d p = mesh.V.row(v), n = vertex_hit[v].normal;
    const SurfaceHit old_hit = vertex_hit[v];
    Eigen::Vector3d average = Eigen::Vector3d::Zero();
    for (int u : neighbours[v]) average += mesh.V.row(u).transpose();
    average /= static_cast<double>(neighbours[v].size());
    Eigen::Vector3d target = wl * average;
    double weight = wl;
    if (wc > 0) {
      const Eigen::Vector3d c = cross_target(v, p, n, scratch);
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
    if (!(weight > 0)) return 0;
    target /= weight;
    Eigen::Vector3d d = target - p;
    d -= d.dot(n) * n;
    if (!d.allFinite() || d.squaredNorm() == 0) return 0;
    // Round a tangle the vertex is placed as the measure would place it (on the whole surface).
    bool near_trouble = false;
    for (int q : around[v]) near_trouble |= whole_surface[q] != 0;
    for (double step = options.step; step >= options.step / 4; step /= 2) {
      const SurfaceHit hit = near_trouble ? surface.closest(p + step * d, old_hit) : surface.closest_on_sheet(p + step * d, old_hit);
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
      bool accepted = true;
      after.clear();
      after_hit.clear();
      for (size_t k = 0; k < around[v].size() && accepted; ++k) {
        after_hit.push_back(quad_hit[around[v][k]]);
        after.push_back(state(around[v][k], after_hit.back()));
        accepted = (quad_state[around[v][k]] & ~after.back()) == 0;
      }
      if (!accepted) continue;
      vertex_hit[v] = hit;
      for (size_t k = 0; k < around[v].size(); ++k) {
        quad_state[around[v][k]] = after[k];
        quad_hit[around[v][k]] = after_hit[k];
      }
      return (hit.point - p).norm();
    }
    mesh.V.row(v) = p;
    return -1;
  };

  // Vertices sharing no quad move independently (a move reads and writes only its vertex's
  // quads): colour by colour, each colour split over the threads. The result does not depend on
  // the number of threads.
  const std::vector<std::vector<int>> colours = quad_star_colours(mesh.Q, around, pinned);
  std::vector<Scratch> scratch(threads);
  struct Tally {
    long long moves = 0, rejected = 0;
    double largest = 0;
  };
  std::vector<int> parts(threads);
  std::iota(parts.begin(), parts.end(), 0);
  // The sweep's start, for its end's check.
  Eigen::MatrixX3d start_V;
  std::vector<SurfaceHit> start_vertex_hit, start_quad_hit, checked_hit(mesh.num_quads());
  std::vector<int> start_quad_state, checked_state(mesh.num_quads()), all_quads(mesh.num_quads());
  std::iota(all_quads.begin(), all_quads.end(), 0);
  const int check_every = std::max(1, options.check_every);
  int since_check = 0;
  for (int sweep = 0; sweep < options.sweeps; ++sweep) {
    ++result.sweeps;
    size = mean_quad_size(mesh);
    if (since_check == 0) {
      start_V = mesh.V;
      start_vertex_hit = vertex_hit;
      start_quad_hit = quad_hit;
      start_quad_state = quad_state;
    }
    mark_trouble();
    std::vector<Tally> tally(threads);
    for (const std::vector<int>& colour : colours) {
      const auto run = [&](int part) {
        const size_t begin = colour.size() * part / threads, end = colour.size() * (part + 1) / threads;
        for (size_t k = begin; k < end; ++k) {
          const double moved = move(colour[k], scratch[part]);
          if (moved > 0) {
            ++tally[part].moves;
            tally[part].largest = std::max(tally[part].largest, moved);
          } else if (moved < 0) {
            ++tally[part].rejected;
          }
        }
      };
      if (threads == 1 || colour.size() < 64) {
        for (int part = 0; part < threads; ++part) run(part);
      } else {
        parallel_for_each(parts, threads, "part", run);
      }
    }
    double largest = 0;
    for (const Tally& t : tally) {
      result.moves += t.moves;
      result.rejected += t.rejected;
      largest = std::max(largest, t.largest);
    }
    result.largest_move = size > 0 ? largest / size : 0;
    const bool converged = result.largest_move <= options.tolerance;
    if (++since_check == check_every || converged || sweep + 1 == options.sweeps) {
      since_check = 0;
      // The check, every check_every sweeps and after the last: every quad judged against the
      // whole surface, as measure_quads judges it (a quad across a thin part can be nearer the far
      // sheet than its own). Where a quad lost a bit it had at the last check, its moved corners
      // go back to where they were then; the quads round them are judged again, until none lost
      // one. Quads whose corners are all back have their state of then again, so this ends, at
      // worst where the last check left the quads.
      const auto judge = [&](int q) {
        checked_hit[q] = start_quad_hit[q];
        checked_state[q] = guard.state(q, checked_hit[q], size);
      };
      parallel_for_each(all_quads, threads, "quad", judge);
      std::vector<int> lost;
      for (int q = 0; q < mesh.num_quads(); ++q)
        if (start_quad_state[q] & ~checked_state[q]) lost.push_back(q);
      while (!lost.empty()) {
        std::vector<int> again;
        for (int q : lost)
          for (int k = 0; k < 4; ++k) {
            const int v = mesh.Q(q, k);
            if (mesh.V.row(v) == start_V.row(v)) continue;
            mesh.V.row(v) = start_V.row(v);
            vertex_hit[v] = start_vertex_hit[v];
            ++result.reverted;
            for (int r : around[v]) again.push_back(r);
          }
        std::sort(again.begin(), again.end());
        again.erase(std::unique(again.begin(), again.end()), again.end());
        lost.clear();
        for (int q : again) {
          judge(q);
          if (start_quad_state[q] & ~checked_state[q]) lost.push_back(q);
        }
      }
      for (int q = 0; q < mesh.num_quads(); ++q) {
        quad_state[q] = checked_state[q];
        quad_hit[q] = checked_hit[q];
      }
    }
    if (converged) {
      result.converged = true;
      break;
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

QuadFitResult fit_quads(const QuadMesh& quads, const SurfaceProjector& surface, const QuadFitOptions& options,
                        const std::vector<char>& pinned) {
  const auto start = std::chrono::steady_clock::now();
  if (options.passes < 0) throw std::invalid_argument("fitting passes must be >= 0, got " + std::to_string(options.passes));
  if (options.stretch_rings < 0)
    throw std::invalid_argument("fitting stretch_rings must be >= 0, got " + std::to_string(options.stretch_rings));
  if (!(options.tolerance >= 0) || !(options.reach > 0) || !(options.max_corner_deviation >= 0))
    throw std::invalid_argument("fitting tolerance and max_corner_deviation must be >= 0 and reach > 0, got " +
                                std::to_string(options.tolerance) + ", " + std::to_string(options.max_corner_deviation) + ", " +
                                std::to_string(options.reach));
  QuadFitResult result;
  result.mesh = quads;
  QuadMesh& mesh = result.mesh;
  const int nv = mesh.num_vertices();
  if (!pinned.empty() && static_cast<int>(pinned.size()) != nv)
    throw std::invalid_argument("fitting: " + std::to_string(pinned.size()) + " pinned flags for " + std::to_string(nv) + " vertices");
  result.pinned = pinned.empty() ? std::vector<char>(nv, 0) : pinned;
  if (mesh.num_quads() == 0 || options.passes == 0) return result;
  const TriMesh& model = surface.sampled();
  const double tolerance = options.tolerance * bounding_box(model.V).diagonal();
  const std::vector<std::vector<int>> neighbours = vertex_neighbours(mesh.Q, nv);
  const std::vector<std::vector<int>> around = vertex_quads(mesh.Q, nv);
  const QuadGuard guard(mesh, surface);
  double size = mean_quad_size(mesh);
  std::vector<SurfaceHit> quad_hit(mesh.num_quads());
  std::vector<int> quad_state(mesh.num_quads());
  parallel_range(mesh.num_quads(), options.threads, [&](int q) { quad_state[q] = guard.state(q, quad_hit[q], size); });

  // The model's points to fit (vertices, centroids of long triangles, points along long edges a
  // quarter of the mean quad size apart: creases of a coarse CAD mesh; the vertices alone when
  // every quad collapsed), the distance of every one from the quads (two triangles each, split as
  // the measure splits them) and the quad it is closest to; per quad, the points closest to it.
  const SurfaceSamples samples = sample_surface(model, size > 0 ? size / 4 : INFINITY);
  const std::vector<Eigen::Vector3d>& points = samples.points;
  const int np = static_cast<int>(points.size());
  std::vector<double> distance(np, 0);
  std::vector<int> owner(np, -1);
  std::vector<std::vector<int>> owned(mesh.num_quads());
  auto measure_all = [&]() {
    const SurfaceProjector triangles(triangulate_quads(mesh));
    for (auto& list : owned) list.clear();
    // Exact for the points beyond the tolerance (which points are far is exact), walks elsewhere.
    const std::vector<SurfaceHit> hits = closest_to_samples(triangles, model, samples, tolerance, options.threads);
    for (int w = 0; w < np; ++w) {
      const SurfaceHit& hit = hits[w];
      distance[w] = hit.distance;
      owner[w] = hit.face / 2;
      owned[owner[w]].push_back(w);
    }
  };
  // Distance of x from quad q as two triangles along its shorter diagonal (triangulate_quads).
  auto quad_distance = [&](int q, const Eigen::Vector3d& x) {
    Eigen::Vector3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = mesh.V.row(mesh.Q(q, k));
    double best = INFINITY;
    for (const auto& c : quad_triangle_corners(mesh, q))
      best = std::min(best, (closest_on_triangle(x, p[c[0]], p[c[1]], p[c[2]]).point - x).norm());
    return best;
  };
  auto farthest = [&]() { return distance.empty() ? 0.0 : *std::max_element(distance.begin(), distance.end()); };
  // How far quad q strays from the model: the largest distance of its edge midpoints and of the
  // centres of its two triangles (split as the measure splits them); off_model: of several quads.
  auto quad_off = [&](int q) {
    Eigen::Vector3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = mesh.V.row(mesh.Q(q, k));
    const auto t = quad_triangle_corners(mesh, q);
    const Eigen::Vector3d samples[6] = {(p[0] + p[1]) / 2, (p[1] + p[2]) / 2, (p[2] + p[3]) / 2, (p[3] + p[0]) / 2,
                                        (p[t[0][0]] + p[t[0][1]] + p[t[0][2]]) / 3, (p[t[1][0]] + p[t[1][1]] + p[t[1][2]]) / 3};
    double off = 0;
    for (const Eigen::Vector3d& y : samples) off = std::max(off, surface.closest(y, quad_hit[q]).distance);
    return off;
  };
  // quad_off of quads as they are before a move, kept until one of their corners moves (a pull
  // tried and undone leaves them as they were: most pulls are refused).
  std::vector<double> off_known(mesh.num_quads(), -1);
  auto off_before = [&](int q) {
    if (off_known[q] < 0) off_known[q] = quad_off(q);
    return off_known[q];
  };
  auto forget_off = [&](const std::vector<int>& quads) {
    for (int q : quads) off_known[q] = -1;
  };
  auto off_model = [&](const std::vector<int>& quads) {
    double off = 0;
    for (int q : quads) off = std::max(off, quad_off(q));
    return off;
  };
  // Whether the model points owned by `quads` (all moved) stay within max(limit, their distance)
  // of the quads round those quads' corners (an upper bound of their distance to the whole mesh);
  // moved_to gets each one's nearest quad and distance, in the order of recheck.
  std::vector<int> nearby, recheck;
  std::vector<std::pair<int, double>> moved_to;
  auto still_covered = [&](const std::vector<int>& quads, double limit) {
    nearby.clear();
    for (int q : quads)
      for (int k = 0; k < 4; ++k)
        for (int r : around[mesh.Q(q, k)]) nearby.push_back(r);
    std::sort(nearby.begin(), nearby.end());
    nearby.erase(std::unique(nearby.begin(), nearby.end()), nearby.end());
    recheck.clear();
    for (int q : quads) recheck.insert(recheck.end(), owned[q].begin(), owned[q].end());
    moved_to.clear();
    for (const int y : recheck) {
      int nearest = -1;
      double d = INFINITY;
      for (int r : nearby) {
        const double dr = quad_distance(r, points[y]);
        if (dr < d) {
          d = dr;
          nearest = r;
        }
      }
      if (!(d <= std::max(limit, distance[y]))) return false;
      moved_to.emplace_back(nearest, d);
    }
    return true;
  };
  // The rechecked points' new distances and quads (after still_covered accepted).
  auto take_rechecked = [&]() {
    for (size_t i = 0; i < recheck.size(); ++i) {
      const int y = recheck[i];
      std::vector<int>& from = owned[owner[y]];
      from.erase(std::find(from.begin(), from.end(), y));
      owner[y] = moved_to[i].first;
      distance[y] = moved_to[i].second;
      owned[owner[y]].push_back(y);
    }
  };
  // The corner of point w's closest quad nearest to it, not pinned, nearer than `within`, and its
  // distance (-1: none).
  auto nearest_free_corner = [&](int w, double within) {
    std::pair<int, double> nearest{-1, within};
    for (int k = 0; k < 4; ++k) {
      const int c = mesh.Q(owner[w], k);
      const double d = (mesh.V.row(c).transpose() - points[w]).norm();
      if (!result.pinned[c] && d < nearest.second) nearest = {c, d};
    }
    return nearest;
  };
  // A point beyond the reach of every corner (a tip the map squeezed: the quads there are small
  // and stop short of it): the nearest free corner of its quad is pulled onto it and the vertices
  // within R rings of it follow, ring r by (1 - r / (R + 1)) of the pull, each placed on its own
  // sheet (closest_on_sheet), R the pull over the corner's mean edge length (at most
  // stretch_rings), so the quads between stretch by about one edge each instead of one quad by
  // the whole pull. Taken when no quad round a moved vertex loses a bit of its guard state, none
  // ends farther off the model than the tolerance, half the point's distance and its own distance
  // before, and the model points stay covered (as for a single pull); the corner is pinned.
  std::vector<int> ring_of(nv, -1), slot(nv, -1), region, touched;
  std::vector<Eigen::Vector3d> region_old;
  std::vector<int> touched_state;
  std::vector<SurfaceHit> touched_hit;
  std::vector<double> touched_off;
  auto stretch = [&](int w, double limit) {
    const Eigen::Vector3d& x = points[w];
    const auto [v, best] = nearest_free_corner(w, INFINITY);
    if (v < 0 || neighbours[v].empty()) return false;
    double edge = 0;
    for (int u : neighbours[v]) edge += (mesh.V.row(u) - mesh.V.row(v)).norm() / neighbours[v].size();
    if (!(edge > 0)) return false;
    const int rings = std::clamp(static_cast<int>(std::ceil(best / edge)), 1, options.stretch_rings);
    const Eigen::Vector3d pull = x - mesh.V.row(v).transpose();
    // The region, ring by ring (pinned vertices stay and are not passed through).
    region.assign(1, v);
    ring_of[v] = 0;
    for (size_t i = 0; i < region.size(); ++i) {
      const int u = region[i];
      if (ring_of[u] == rings) continue;
      for (int t : neighbours[u])
        if (ring_of[t] < 0 && !result.pinned[t]) {
          ring_of[t] = ring_of[u] + 1;
          region.push_back(t);
        }
    }
    touched.clear();
    for (int u : region) touched.insert(touched.end(), around[u].begin(), around[u].end());
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    touched_off.clear();
    for (int q : touched) touched_off.push_back(off_before(q));
    region_old.clear();
    for (size_t i = 0; i < region.size(); ++i) {
      region_old.push_back(mesh.V.row(region[i]));
      slot[region[i]] = static_cast<int>(i);
    }
    const auto undo = [&]() {
      for (size_t i = 0; i < region.size(); ++i) {
        mesh.V.row(region[i]) = region_old[i];
        ring_of[region[i]] = -1;
      }
      return false;
    };
    for (size_t i = 1; i < region.size(); ++i) {
      const int u = region[i];
      const double share = 1 - static_cast<double>(ring_of[u]) / (rings + 1);
      const SurfaceHit from = surface.closest(region_old[i]);
      mesh.V.row(u) = surface.closest_on_sheet(region_old[i] + share * pull, from).point;
    }
    mesh.V.row(v) = x;
    // No edge shortened below kShortestEdge of the mean quad size.
    const auto old_position = [&](int t) -> Eigen::Vector3d {
      return ring_of[t] < 0 ? Eigen::Vector3d(mesh.V.row(t)) : region_old[slot[t]];
    };
    for (int u : region)
      for (int t : neighbours[u]) {
        const double now = (mesh.V.row(t) - mesh.V.row(u)).norm();
        if (now < kShortestEdge * size && now < (old_position(t) - old_position(u)).norm()) return undo();
      }
    touched_state.clear();
    touched_hit.clear();
    for (int q : touched) {
      touched_hit.push_back(quad_hit[q]);
      touched_state.push_back(guard.state(q, touched_hit.back(), size));
      if (quad_state[q] & ~touched_state.back()) return undo();
    }
    // Each quad moved stays within the tolerance of the model, no farther off than it was, or
    // within half the miss being mended (the local distance falls at least by half).
    const double allowed = std::max(tolerance, distance[w] / 2);
    for (size_t i = 0; i < touched.size(); ++i)
      if (quad_off(touched[i]) > std::max(allowed, touched_off[i])) return undo();
    if (!still_covered(touched, limit)) return undo();
    for (size_t i = 0; i < touched.size(); ++i) {
      quad_state[touched[i]] = touched_state[i];
      quad_hit[touched[i]] = touched_hit[i];
    }
    forget_off(touched);
    take_rechecked();
    for (int u : region) ring_of[u] = -1;
    distance[w] = 0;
    result.pinned[v] = 1;
    ++result.stretched;
    return true;
  };
  measure_all();
  result.farthest_before = farthest();
  std::vector<int> after;
  std::vector<SurfaceHit> after_hit;
  for (int pass = 0; pass < options.passes; ++pass) {
    // The model's points beyond the tolerance, farthest first.
    std::vector<int> far;
    for (int w = 0; w < np; ++w)
      if (distance[w] > tolerance) far.push_back(w);
    if (far.empty()) break;
    ++result.passes;
    std::sort(far.begin(), far.end(), [&](int a, int b) { return distance[a] > distance[b]; });
    const double limit = distance[far.front()];  // no model vertex may end farther than this
    int snapped = 0;
    for (const int w : far) {
      if (!(distance[w] > tolerance)) continue;  // an earlier pull covered it
      const Eigen::Vector3d& x = points[w];
      // The nearest corner of the quad the point is closest to, within reach.
      const int v = nearest_free_corner(w, options.reach * size).first;
      if (v < 0) {
        if (options.stretch_rings > 0 && stretch(w, limit)) ++snapped;
        continue;
      }
      bool collapses = false;
      for (int u : neighbours[v]) collapses |= (mesh.V.row(u).transpose() - x).norm() < kShortestEdge * size;
      if (collapses) continue;
      const Eigen::Vector3d old = mesh.V.row(v);
      double off_around = 0;
      for (int q : around[v]) off_around = std::max(off_around, off_before(q));
      mesh.V.row(v) = x;
      bool accepted = true;
      after.clear();
      after_hit.clear();
      for (size_t k = 0; k < around[v].size() && accepted; ++k) {
        after_hit.push_back(quad_hit[around[v][k]]);
        after.push_back(guard.state(around[v][k], after_hit.back(), size));
        accepted = (quad_state[around[v][k]] & ~after.back()) == 0;
      }
      // Nor may v's quads move off the model: sampled, no farther than the tolerance or than before.
      if (accepted) accepted = off_model(around[v]) <= std::max(tolerance, off_around);
      // Nor may a corner of its quads bend farther from 90° than the limit (and than before).
      for (size_t k = 0; k < around[v].size() && accepted; ++k) {
        const int q = around[v][k];
        for (int c = 0; c < 4 && accepted; ++c) {
          const auto deviation = [&](const Eigen::Vector3d& at) {
            Eigen::Vector3d p[4];
            for (int i = 0; i < 4; ++i) p[i] = mesh.Q(q, i) == v ? at : Eigen::Vector3d(mesh.V.row(mesh.Q(q, i)));
            const Eigen::Vector3d next = p[(c + 1) % 4] - p[c], previous = p[(c + 3) % 4] - p[c];
            return std::abs(std::atan2(next.cross(previous).norm(), next.dot(previous)) * 180 / kPi - 90);
          };
          const double now = deviation(x);
          accepted = now <= options.max_corner_deviation || now <= deviation(old);
        }
      }
      // Nor may the place v leaves be uncovered: the model points closest to v's quads must stay
      // within the farthest distance of the pass.
      if (accepted) accepted = still_covered(around[v], limit);
      if (!accepted) {
        mesh.V.row(v) = old;
        continue;
      }
      for (size_t k = 0; k < around[v].size(); ++k) {
        quad_state[around[v][k]] = after[k];
        quad_hit[around[v][k]] = after_hit[k];
      }
      forget_off(around[v]);
      take_rechecked();
      distance[w] = 0;
      result.pinned[v] = 1;
      ++snapped;
    }
    if (snapped == 0) break;
    result.snapped += snapped;
    size = mean_quad_size(mesh);
    measure_all();
  }
  result.farthest_after = farthest();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace polycube
