// The untangling of quads a map folded (declared in quad_smooth.h): vertex moves, then, for quads
// still flipped, whole patches round them laid out again.
#include "applications/quad/quad_guard.h"
#include "applications/quad/quad_smooth.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <chrono>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace polycube {

namespace {

// The directed edges of the patch's quads, each with how many of them have it (an edge whose
// reverse is missing is on the patch's boundary).
std::map<std::pair<int, int>, int> directed_edges(const Eigen::MatrixX4i& Q, const std::vector<int>& patch) {
  std::map<std::pair<int, int>, int> edges;
  for (int q : patch)
    for (int k = 0; k < 4; ++k) ++edges[{Q(q, k), Q(q, (k + 1) % 4)}];
  return edges;
}

// The quads round quad `seed`: those within `rings` rings of it (sharing a vertex, ring by ring)
// when radius is 0, else those reached from it through shared vertices whose centres lie within
// `radius` of its centre. Then, a few times, the quads round each vertex where the patch touches
// itself (two of its boundary edges leave the vertex) join it, then the quads round the vertices
// of its holes (every boundary loop but the longest). Empty when it would have more than
// max_quads quads (0: no limit).
std::vector<int> patch_round(const QuadMesh& mesh, const std::vector<std::vector<int>>& around, int seed, int rings,
                             double radius, int max_quads) {
  const Eigen::MatrixX4i& Q = mesh.Q;
  const auto centre = [&](int q) {
    return Eigen::Vector3d((mesh.V.row(Q(q, 0)) + mesh.V.row(Q(q, 1)) + mesh.V.row(Q(q, 2)) + mesh.V.row(Q(q, 3))) / 4);
  };
  const Eigen::Vector3d middle = centre(seed);
  std::vector<int> patch{seed};
  std::vector<char> in_patch(Q.rows(), 0);
  in_patch[seed] = 1;
  size_t ring_start = 0;
  for (int ring = 0; radius > 0 || ring < rings; ++ring) {
    const size_t ring_end = patch.size();
    if (ring_start == ring_end) break;
    for (size_t i = ring_start; i < ring_end; ++i)
      for (int k = 0; k < 4; ++k)
        for (int q : around[Q(patch[i], k)])
          if (!in_patch[q] && (radius <= 0 || (centre(q) - middle).norm() <= radius)) {
            in_patch[q] = 1;
            patch.push_back(q);
          }
    if (max_quads > 0 && static_cast<int>(patch.size()) > max_quads) return {};
    ring_start = ring_end;
  }
  for (int round = 0; round < 6; ++round) {
    const std::map<std::pair<int, int>, int> edges = directed_edges(Q, patch);
    std::map<int, int> leaving;
    for (const auto& [edge, count] : edges)
      if (!edges.count({edge.second, edge.first})) ++leaving[edge.first];
    bool grew = false;
    for (const auto& [v, count] : leaving)
      if (count > 1)
        for (int q : around[v])
          if (!in_patch[q]) {
            in_patch[q] = 1;
            patch.push_back(q);
            grew = true;
          }
    if (!grew) {
      // Holes: every boundary loop but the longest gets the quads round its vertices.
      std::map<int, int> next;
      for (const auto& [edge, count] : edges)
        if (!edges.count({edge.second, edge.first})) next[edge.first] = edge.second;
      std::vector<std::vector<int>> loops;
      std::set<int> traced;
      for (const auto& [start, unused] : next) {
        if (traced.count(start)) continue;
        loops.emplace_back();
        for (int v = start; !traced.count(v) && next.count(v); v = next[v]) {
          traced.insert(v);
          loops.back().push_back(v);
        }
      }
      std::sort(loops.begin(), loops.end(), [](const auto& a, const auto& b) { return a.size() > b.size(); });
      for (size_t l = 1; l < loops.size(); ++l)
        for (int v : loops[l])
          for (int q : around[v])
            if (!in_patch[q]) {
              in_patch[q] = 1;
              patch.push_back(q);
              grew = true;
            }
    }
    if (!grew) break;
  }
  if (max_quads > 0 && static_cast<int>(patch.size()) > max_quads) return {};
  return patch;
}

// Lays a patch of quads out again (Tutte's embedding): the patch, a disk, is projected on the
// plane across the mean surface normal under it; its boundary loop stays, its inner vertices go
// to the mean of their edge neighbours (uniform weights: with a convex boundary every quad comes
// out convex), each then placed on the surface where it projects onto its place in the plane.
// Refused (false, nothing moved) when the patch is not a disk, the surface under it turns more
// than about 70° from the plane's normal, its boundary does not project to a simple loop turning
// the patch's way, or a laid-out quad turns over in the plane.
class PatchEmbedder {
 public:
  PatchEmbedder(QuadMesh& mesh, const SurfaceProjector& surface, const std::vector<std::vector<int>>& neighbours,
                const std::vector<char>& pinned)
      : mesh_(mesh), surface_(surface), neighbours_(neighbours), pinned_(pinned) {}

  // moved: out, the vertices moved and their old positions (to put them back).
  bool reembed(const std::vector<int>& patch, double size, std::vector<std::pair<int, Eigen::Vector3d>>& moved) const {
    moved.clear();
    const Eigen::MatrixX4i& Q = mesh_.Q;
    // Boundary: the directed quad edges whose reverse is not in the patch.
    const std::map<std::pair<int, int>, int> edges = directed_edges(Q, patch);
    std::map<int, int> next;  // boundary vertex -> the next one along the loop
    std::vector<int> vertices;
    for (const auto& [edge, count] : edges) {
      vertices.push_back(edge.first);
      if (edges.count({edge.second, edge.first})) continue;
      if (count > 1 || next.count(edge.first)) return false;  // not a manifold disk
      next[edge.first] = edge.second;
    }
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    const long long num_edges = static_cast<long long>(edges.size() + next.size()) / 2;
    if (next.empty() || static_cast<long long>(vertices.size()) - num_edges + static_cast<long long>(patch.size()) != 1) return false;
    std::vector<int> loop{next.begin()->first};
    while (loop.size() <= next.size()) {
      const auto it = next.find(loop.back());
      if (it == next.end()) return false;
      if (it->second == loop.front()) break;
      loop.push_back(it->second);
    }
    if (loop.size() != next.size()) return false;  // more than one loop
    // The plane: across the mean of the surface normals at the patch's vertices.
    std::map<int, int> index;  // patch vertex -> its row in the layout
    Eigen::Vector3d normal = Eigen::Vector3d::Zero(), origin = Eigen::Vector3d::Zero();
    std::vector<Eigen::Vector3d> normals;
    for (int v : vertices) {
      index[v] = static_cast<int>(normals.size());
      const SurfaceHit hit = surface_.closest(mesh_.V.row(v).transpose());
      normals.push_back(surface_.face_normal(hit.face));
      normal += normals.back();
      origin += mesh_.V.row(v).transpose() / static_cast<double>(vertices.size());
    }
    if (normal.norm() == 0) return false;
    normal.normalize();
    for (const Eigen::Vector3d& n : normals)
      if (n.dot(normal) < kSameSheet) return false;
    const Eigen::Vector3d e1 = normal.unitOrthogonal(), e2 = normal.cross(e1);
    const auto plane = [&](const Eigen::Vector3d& p) { return Eigen::Vector2d((p - origin).dot(e1), (p - origin).dot(e2)); };
    // The boundary loop in the plane: simple, and turning counter-clockwise (as the quads do
    // about the surface's normal).
    std::vector<Eigen::Vector2d> ring;
    for (int v : loop) ring.push_back(plane(mesh_.V.row(v).transpose()));
    const int n = static_cast<int>(ring.size());
    double area = 0;
    for (int i = 0; i < n; ++i) area += cross(ring[i], ring[(i + 1) % n]) / 2;
    if (!(area > 0)) return false;
    for (int i = 0; i < n; ++i)
      for (int j = i + 2; j < n; ++j)
        if ((j + 1) % n != i && segments_cross(ring[i], ring[(i + 1) % n], ring[j], ring[(j + 1) % n])) return false;
    // Unknowns: the inner vertices that may move; the boundary and pinned ones stay.
    std::vector<char> fixed(vertices.size(), 0);
    for (int v : loop) fixed[index[v]] = 1;
    for (int v : vertices)
      if (!pinned_.empty() && pinned_[v]) fixed[index[v]] = 1;
    std::vector<int> unknown(vertices.size(), -1), free_vertices;
    for (size_t i = 0; i < vertices.size(); ++i)
      if (!fixed[i]) {
        unknown[i] = static_cast<int>(free_vertices.size());
        free_vertices.push_back(vertices[i]);
      }
    if (free_vertices.empty()) return false;
    // Uniform weights: degree x_i - sum of neighbours = 0; the heights over the plane the same
    // way, for a first guess where to look for the surface.
    const int m = static_cast<int>(free_vertices.size());
    std::vector<Eigen::Triplet<double>> triplets;
    Eigen::MatrixX3d rhs = Eigen::MatrixX3d::Zero(m, 3);
    for (int i = 0; i < m; ++i) {
      const int v = free_vertices[i];
      triplets.emplace_back(i, i, static_cast<double>(neighbours_[v].size()));
      for (int w : neighbours_[v]) {
        const auto at = index.find(w);
        if (at == index.end()) return false;  // not a disk round v
        const int j = unknown[at->second];
        if (j >= 0) {
          triplets.emplace_back(i, j, -1.0);
        } else {
          const Eigen::Vector3d p = mesh_.V.row(w).transpose();
          rhs.row(i) += Eigen::RowVector3d(plane(p).x(), plane(p).y(), (p - origin).dot(normal));
        }
      }
    }
    Eigen::SparseMatrix<double> A(m, m);
    A.setFromTriplets(triplets.begin(), triplets.end());
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
    if (solver.info() != Eigen::Success) return false;
    const Eigen::MatrixX3d layout = solver.solve(rhs);
    if (solver.info() != Eigen::Success || !layout.allFinite()) return false;
    std::vector<Eigen::Vector2d> flat(vertices.size());
    for (size_t i = 0; i < vertices.size(); ++i)
      flat[i] = unknown[i] >= 0 ? Eigen::Vector2d(layout(unknown[i], 0), layout(unknown[i], 1))
                                : plane(mesh_.V.row(vertices[i]).transpose());
    for (int q : patch) {
      Eigen::Vector2d c[4];
      for (int k = 0; k < 4; ++k) c[k] = flat[index[Q(q, k)]];
      if (!(cross(c[2] - c[0], c[3] - c[1]) > 0)) return false;
    }
    // Onto the surface: the point whose projection is the vertex's place, by closest points
    // corrected in the plane a few times.
    for (int i = 0; i < m; ++i) {
      const int v = free_vertices[i];
      const Eigen::Vector2d target(layout(i, 0), layout(i, 1));
      Eigen::Vector3d p = origin + target.x() * e1 + target.y() * e2 + layout(i, 2) * normal;
      SurfaceHit hit = surface_.closest(p);
      for (int round = 0; round < 4; ++round) {
        const Eigen::Vector2d off = target - plane(hit.point);
        if (off.norm() < 1e-3 * size) break;
        p = hit.point + off.x() * e1 + off.y() * e2;
        hit = surface_.closest(p, hit);
      }
      if (surface_.face_normal(hit.face).dot(normal) < kSameSheet) {
        for (const auto& [u, position] : moved) mesh_.V.row(u) = position.transpose();
        moved.clear();
        return false;
      }
      moved.emplace_back(v, mesh_.V.row(v).transpose());
      mesh_.V.row(v) = hit.point.transpose();
    }
    return true;
  }

 private:
  static double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
  // Whether segments ab and cd cross or touch.
  static bool segments_cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
    const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a), d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
    if (d1 == 0 && d2 == 0) {  // on one line: do they overlap along it?
      const Eigen::Vector2d u = b - a;
      const double t0 = (c - a).dot(u), t1 = (d - a).dot(u);
      return std::max(t0, t1) >= 0 && std::min(t0, t1) <= u.squaredNorm();
    }
    return ((d1 > 0) != (d2 > 0) || d1 == 0 || d2 == 0) && ((d3 > 0) != (d4 > 0) || d3 == 0 || d4 == 0);
  }

  QuadMesh& mesh_;
  const SurfaceProjector& surface_;
  const std::vector<std::vector<int>>& neighbours_;
  const std::vector<char>& pinned_;
};

}  // namespace

QuadUntangleResult untangle_quads(const QuadMesh& quads, const SurfaceProjector& surface, const QuadUntangleOptions& options,
                                  const std::vector<char>& pinned) {
  const auto start = std::chrono::steady_clock::now();
  if (options.passes < 0 || options.rings < 0 || options.patch_rings < 0 || options.max_patch_quads < 0)
    throw std::invalid_argument("untangling passes, rings, patch rings and patch quads must be >= 0, got " +
                                std::to_string(options.passes) + ", " + std::to_string(options.rings) + ", " +
                                std::to_string(options.patch_rings) + " and " + std::to_string(options.max_patch_quads));
  if (!pinned.empty() && static_cast<int>(pinned.size()) != quads.num_vertices())
    throw std::invalid_argument("untangling: " + std::to_string(pinned.size()) + " pinned flags for " +
                                std::to_string(quads.num_vertices()) + " vertices");
  QuadUntangleResult result;
  result.mesh = quads;
  QuadMesh& mesh = result.mesh;
  const int nv = mesh.num_vertices(), nq = mesh.num_quads();
  const std::vector<std::vector<int>> neighbours = vertex_neighbours(mesh.Q, nv);
  const std::vector<std::vector<int>> around = vertex_quads(mesh.Q, nv);
  const double size = mean_quad_size(mesh);
  const QuadGuard guard(mesh, surface);
  // Per quad: flipped (its diagonals against the surface), collapsed (an edge below kCollapsedEdge
  // of the mean quad size, or an area below its square; or degenerate as measure_quads judges it)
  // and inverted corners, as measure_quads counts
  // them (kCollapsedEdge aside: a corner with a collapsed edge counts as inverted here). Moves and
  // patches are judged by (flipped + collapsed quads, inverted corners), in that order.
  // At most this is degenerate to measure_quads (its default tolerance).
  const double diagonal = bounding_box(surface.surface().V).diagonal();
  const double degenerate_length = QuadQualityOptions{}.degenerate_tolerance * diagonal;
  const double degenerate_area = degenerate_length * diagonal;
  struct Badness {
    int flipped = 0, collapsed = 0, inverted = 0, sharp = 0;
    bool bad() const { return flipped + collapsed > 0; }
  };
  // What the moves and patches work on.
  const auto worked_on = [&](const Badness& b) {
    return b.bad() || (options.inverted && b.inverted > 0) || b.sharp > 0;
  };
  const auto badness = [&](int q) {
    SurfaceHit centre;
    const int bits = guard.state(q, centre, size);
    Badness b;
    b.flipped = bits & 16 ? 0 : 1;
    const double shortest = std::max(kCollapsedEdge * size, degenerate_length);
    for (int k = 0; k < 4; ++k) {
      b.inverted += !(bits & (1 << k));
      b.collapsed = b.collapsed || (mesh.V.row(mesh.Q(q, (k + 1) % 4)) - mesh.V.row(mesh.Q(q, k))).norm() <= shortest;
    }
    const Eigen::Vector3d d1 = mesh.V.row(mesh.Q(q, 2)) - mesh.V.row(mesh.Q(q, 0));
    const Eigen::Vector3d d2 = mesh.V.row(mesh.Q(q, 3)) - mesh.V.row(mesh.Q(q, 1));
    b.collapsed = b.collapsed || d1.cross(d2).norm() / 2 <= std::max(shortest * shortest, degenerate_area);
    if (!options.collapsed) b.collapsed = 0;
    if (options.sharp_degrees > 0)
      for (int k = 0; k < 4; ++k)
        b.sharp += sharp_corner(mesh.V.row(mesh.Q(q, (k + 1) % 4)) - mesh.V.row(mesh.Q(q, k)),
                                mesh.V.row(mesh.Q(q, (k + 3) % 4)) - mesh.V.row(mesh.Q(q, k)), options.sharp_degrees);
    return b;
  };
  std::vector<Badness> state(nq);
  for (int q = 0; q < nq; ++q) state[q] = badness(q);
  const auto count_flipped = [&]() {
    int n = 0;
    for (const Badness& b : state) n += b.flipped;
    return n;
  };
  result.flipped_before = result.flipped_after = count_flipped();
  const auto sum = [](const std::vector<Badness>& of) {
    std::tuple<int, int, int> total{0, 0, 0};
    for (const Badness& b : of) {
      std::get<0>(total) += b.flipped + b.collapsed;
      std::get<1>(total) += b.inverted;
      std::get<2>(total) += b.sharp;
    }
    return total;
  };
  std::vector<Badness> before, after;
  std::vector<Eigen::Vector3d> targets;
  // Tries to move v; true when it moved.
  const auto try_vertex = [&](int v) {
    if ((!pinned.empty() && pinned[v]) || neighbours[v].empty()) return false;
    before.clear();
    for (int q : around[v]) before.push_back(state[q]);
    const std::tuple<int, int, int> was = sum(before);
    if (was == std::tuple<int, int, int>{0, 0, 0}) return false;
    const Eigen::Vector3d p = mesh.V.row(v);
    const SurfaceHit here = surface.closest(p);
    // The mean of the edge neighbours, of the quads' centres, of the parallelogram corners
    // a + c - b (a, b, c: the quad's other corners in order, b opposite v), each bad quad's, and
    // for a collapsed quad two points off its line.
    targets.assign(3, Eigen::Vector3d::Zero());
    for (int w : neighbours[v]) targets[0] += mesh.V.row(w).transpose() / static_cast<double>(neighbours[v].size());
    for (int q : around[v]) {
      int c = 0;
      while (mesh.Q(q, c) != v) ++c;
      const Eigen::Vector3d parallelogram = mesh.V.row(mesh.Q(q, (c + 1) % 4)) + mesh.V.row(mesh.Q(q, (c + 3) % 4)) -
                                            mesh.V.row(mesh.Q(q, (c + 2) % 4));
      targets[1] += (p + mesh.V.row(mesh.Q(q, (c + 1) % 4)).transpose() + mesh.V.row(mesh.Q(q, (c + 2) % 4)).transpose() +
                     mesh.V.row(mesh.Q(q, (c + 3) % 4)).transpose()) /
                    (4.0 * around[v].size());
      targets[2] += parallelogram / static_cast<double>(around[v].size());
      if (worked_on(state[q])) targets.push_back(parallelogram);
      if (state[q].collapsed) {
        // A quad squashed onto a line (its neighbours often with it): off the line both ways, in
        // the surface's tangent plane, by half its longest edge.
        Eigen::Vector3d longest = Eigen::Vector3d::Zero();
        for (int k = 0; k < 4; ++k) {
          const Eigen::Vector3d e = mesh.V.row(mesh.Q(q, (k + 1) % 4)) - mesh.V.row(mesh.Q(q, k));
          if (e.norm() > longest.norm()) longest = e;
        }
        const Eigen::Vector3d across = here.normal.cross(longest) / 2;
        targets.push_back(p + across);
        targets.push_back(p - across);
      }
    }
    for (const Eigen::Vector3d& target : targets)
      for (double t : {1.0, 0.5, 0.25}) {
        const SurfaceHit hit = surface.closest(p + t * (target - p), here);
        if (hit.normal.dot(here.normal) < kSameSheet) continue;
        mesh.V.row(v) = hit.point.transpose();
        after.clear();
        for (int q : around[v]) after.push_back(badness(q));
        if (sum(after) < was) {
          for (size_t i = 0; i < around[v].size(); ++i) state[around[v][i]] = after[i];
          ++result.moves;
          return true;
        }
        mesh.V.row(v) = p.transpose();
      }
    return false;
  };
  for (int pass = 0; pass < options.passes; ++pass) {
    // The vertices of the bad quads and, ring by ring, round them, while a ring gains nothing.
    std::vector<char> in(nv, 0);
    std::vector<int> front;
    for (int q = 0; q < nq; ++q)
      if (worked_on(state[q]))
        for (int k = 0; k < 4; ++k)
          if (!in[mesh.Q(q, k)]) {
            in[mesh.Q(q, k)] = 1;
            front.push_back(mesh.Q(q, k));
          }
    if (front.empty()) break;
    bool moved = false;
    for (int ring = 0; ring <= options.rings && !moved; ++ring) {
      if (ring > 0) {
        std::vector<int> next;
        for (int v : front)
          for (int w : neighbours[v])
            if (!in[w]) {
              in[w] = 1;
              next.push_back(w);
            }
        front.insert(front.end(), next.begin(), next.end());
      }
      for (int v : front) moved = try_vertex(v) || moved;
    }
    if (!moved) break;
  }
  if (options.patch_rings > 0 && std::any_of(state.begin(), state.end(), worked_on)) {
    const PatchEmbedder embedder(mesh, surface, neighbours, pinned);
    for (int q = 0; q < nq; ++q) {
      if (!worked_on(state[q])) continue;
      // Patches ring by ring, and round ones (by distance: the quads a map folds are often
      // long and thin, and rings of them make a ragged patch).
      for (int attempt = 0; attempt < 2 * options.patch_rings; ++attempt) {
        const int rings = attempt / 2 + 1;
        const std::vector<int> patch = patch_round(mesh, around, q, rings, attempt % 2 ? rings * size : 0.0, options.max_patch_quads);
        if (patch.empty()) continue;  // larger than max_patch_quads
        std::vector<Badness> was;
        for (int p : patch) was.push_back(state[p]);
        std::vector<std::pair<int, Eigen::Vector3d>> old_positions;
        if (!embedder.reembed(patch, size, old_positions)) continue;
        std::vector<Badness> now;
        for (int p : patch) now.push_back(badness(p));
        if (sum(now) < sum(was)) {
          for (size_t i = 0; i < patch.size(); ++i) state[patch[i]] = now[i];
          ++result.patches;
          break;
        }
        for (const auto& [v, position] : old_positions) mesh.V.row(v) = position.transpose();
      }
    }
  }
  result.flipped_after = count_flipped();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace polycube
