#include "applications/quad/quad_collapse.h"

#include <algorithm>
#include <array>
#include <limits>
#include <set>
#include <stdexcept>
#include <utility>

namespace polycube {

namespace {

// Collapses whose merged vertex leaves quads bad get the untangling round it (this many rings of
// quads), at most this many times per call.
constexpr int kCollapseRings = 2;
constexpr int kCollapseUntangles = 24;
// At most this many collapses per call (a try with more bad quads than that is folded beyond
// what collapses mend, and loses to the others anyway).
constexpr int kCollapseMost = 64;

// One collapse: quad q removed, vertex `gone` merged into `keep`, which goes to `place` (the
// place of corner `from`, or, -1, another point).
struct Collapse {
  int q = -1, keep = -1, gone = -1, from = -1;
  Eigen::Vector3d place = Eigen::Vector3d::Zero();
};

// The quads after the collapse, vertices in their order without `gone`; index: old -> new
// vertex (-1 for gone).
QuadMesh collapsed(const QuadMesh& mesh, const Collapse& c, std::vector<int>& index) {
  const int nv = mesh.num_vertices(), nq = mesh.num_quads();
  index.assign(nv, -1);
  int count = 0;
  for (int v = 0; v < nv; ++v)
    if (v != c.gone) index[v] = count++;
  QuadMesh out;
  out.V.resize(count, 3);
  for (int v = 0; v < nv; ++v)
    if (index[v] >= 0) out.V.row(index[v]) = mesh.V.row(v);
  out.V.row(index[c.keep]) = c.place.transpose();
  out.Q.resize(nq - 1, 4);
  for (int q = 0, row = 0; q < nq; ++q) {
    if (q == c.q) continue;
    for (int k = 0; k < 4; ++k) {
      const int v = mesh.Q(q, k);
      out.Q(row, k) = index[v == c.gone ? c.keep : v];
    }
    ++row;
  }
  return out;
}

// The rows of `rows` but row q, in order.
template <typename Matrix>
Matrix without_row(const Matrix& rows, int q) {
  Matrix out(rows.rows() - 1, rows.cols());
  out.topRows(q) = rows.topRows(q);
  out.bottomRows(rows.rows() - 1 - q) = rows.bottomRows(rows.rows() - 1 - q);
  return out;
}

// The quads within `rings` rings of quad `seed` (sharing a vertex, ring by ring), seed first.
std::vector<int> quads_round(const QuadMesh& mesh, const std::vector<std::vector<int>>& around, int seed, int rings) {
  std::vector<int> out{seed};
  std::set<int> in{seed};
  size_t start = 0;
  for (int ring = 0; ring < rings; ++ring) {
    const size_t end = out.size();
    for (size_t i = start; i < end; ++i)
      for (int k = 0; k < 4; ++k)
        for (int r : around[mesh.Q(out[i], k)])
          if (in.insert(r).second) out.push_back(r);
    start = end;
  }
  return out;
}

// How many of the quads `which` of mesh are bad (bad_quads), judged on a mesh of those quads and
// their vertices alone.
int bad_among(const QuadMesh& mesh, const std::vector<int>& which, const SurfaceProjector& model,
              const QuadQualityOptions& options) {
  QuadMesh sub;
  std::vector<int> index(mesh.num_vertices(), -1);
  std::vector<int> used;
  sub.Q.resize(static_cast<Eigen::Index>(which.size()), 4);
  for (size_t i = 0; i < which.size(); ++i)
    for (int k = 0; k < 4; ++k) {
      int& slot = index[mesh.Q(which[i], k)];
      if (slot < 0) {
        slot = static_cast<int>(used.size());
        used.push_back(mesh.Q(which[i], k));
      }
      sub.Q(static_cast<Eigen::Index>(i), k) = slot;
    }
  sub.V.resize(static_cast<Eigen::Index>(used.size()), 3);
  for (size_t i = 0; i < used.size(); ++i) sub.V.row(static_cast<Eigen::Index>(i)) = mesh.V.row(used[i]);
  return static_cast<int>(bad_quads(sub, model, options).size());
}

}  // namespace

QuadCollapseResult collapse_bad_quads(QuadMesh& quads, PolycubeGrid& grid, std::vector<char>& pinned,
                                      const SurfaceProjector& model, const QuadQualityOptions& quality,
                                      const QuadUntangleOptions& untangle) {
  const int nv = quads.num_vertices(), nq = quads.num_quads();
  if (grid.mesh.num_vertices() != nv || grid.mesh.num_quads() != nq || static_cast<int>(grid.on_polycube.size()) != nv)
    throw std::invalid_argument("collapse_bad_quads: the grid does not match the quads");
  if (!pinned.empty() && static_cast<int>(pinned.size()) != nv)
    throw std::invalid_argument("collapse_bad_quads: pinned flags of the wrong size");
  QuadQualityOptions topology_only = quality;
  topology_only.hausdorff = false;
  QuadCollapseResult out;
  std::vector<int> bad = bad_quads(quads, model, topology_only);
  out.bad_before = out.bad_after = static_cast<int>(bad.size());
  if (bad.empty()) return out;

  QuadMesh mesh = quads;
  PolycubeGrid on_p = grid;
  std::vector<char> held = pinned;
  held.resize(nv, 0);
  int untangles_left = kCollapseUntangles;
  // Vertex moves only: with patches, the collapses on a femur try's quads (dumped, 34 bad) took
  // 18.7 s instead of 2.6.
  QuadUntangleOptions moves = untangle;
  moves.patch_rings = 0;
  // Quads no collapse helped, by their corners' places (indices change with every collapse).
  std::set<std::array<double, 12>> failed;
  const auto key = [&](int q) {
    std::array<double, 12> k{};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 3; ++j) k[3 * i + j] = mesh.V(mesh.Q(q, i), j);
    return k;
  };
  // One collapse taken per step (indices change); the steps stop when no bad quad can go.
  for (bool progress = true; progress && !bad.empty() && out.collapsed < kCollapseMost;) {
    progress = false;
    const std::vector<std::vector<int>> around = vertex_quads(mesh.Q, mesh.num_vertices());
    std::vector<char> corner(mesh.num_vertices(), 0);
    for (int c : on_p.corners) corner[c] = 1;
    const auto star = [&](int v) {
      std::vector<int> vertices;
      for (int r : around[v])
        for (int k = 0; k < 4; ++k) vertices.push_back(mesh.Q(r, k));
      std::sort(vertices.begin(), vertices.end());
      vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
      return vertices;
    };
    for (int b : bad) {
      if (failed.count(key(b))) continue;
      // The bad quad first, then the quads sharing an edge with it: collapsing one of those can
      // free a bad quad whose own diagonals cannot go (a valence-3 corner beside it).
      std::vector<int> targets{b};
      for (int k = 0; k < 4; ++k) {
        const std::vector<int>& next = around[mesh.Q(b, (k + 1) % 4)];
        for (int r : around[mesh.Q(b, k)])
          if (r != b && std::find(next.begin(), next.end(), r) != next.end()) targets.push_back(r);
      }
      bool taken = false;
      for (int q : targets) {
        // What a collapse of q can change: the quads within kCollapseRings + 2 rings of q (the
        // untangling moves vertices within kCollapseRings rings of the merged vertex).
        const std::vector<int> region = quads_round(mesh, around, q, kCollapseRings + 2);
        std::vector<int> region_after;  // the same quads after the collapse (q dropped, rows shift)
        for (int r : region)
          if (r != q) region_after.push_back(r < q ? r : r - 1);
        const int bad_here = bad_among(mesh, region, model, topology_only);
        Collapse best;
        QuadMesh best_mesh;
        int best_bad = bad_here;
        std::vector<Collapse> tried;  // every collapse that keeps a 2-manifold, every place
        for (int diagonal = 0; diagonal < 2 && best_bad > 0; ++diagonal) {
          const int u = mesh.Q(q, diagonal), w = mesh.Q(q, diagonal + 2);
          const int s = mesh.Q(q, diagonal + 1), t = mesh.Q(q, (diagonal + 3) % 4);
          if (corner[u] && corner[w]) continue;
          if (around[s].size() < 4 || around[t].size() < 4) continue;
          const std::vector<int> su = star(u), sw = star(w);
          std::vector<int> shared;
          std::set_intersection(su.begin(), su.end(), sw.begin(), sw.end(), std::back_inserter(shared));
          const auto outside = [&](int x) { return x != u && x != w && x != s && x != t; };
          if (std::any_of(shared.begin(), shared.end(), outside)) continue;
          Collapse c;
          c.q = q;
          c.keep = corner[w] ? w : u;
          c.gone = c.keep == u ? w : u;
          std::vector<std::pair<Eigen::Vector3d, int>> places;
          if (corner[c.keep]) {
            places.emplace_back(mesh.V.row(c.keep).transpose(), c.keep);
          } else {
            places.emplace_back(model.closest(0.5 * (mesh.V.row(u) + mesh.V.row(w)).transpose()).point, -1);
            places.emplace_back(mesh.V.row(u).transpose(), u);
            places.emplace_back(mesh.V.row(w).transpose(), w);
          }
          for (const auto& [place, from] : places) {
            c.place = place;
            c.from = from;
            tried.push_back(c);
            std::vector<int> index;
            QuadMesh candidate = collapsed(mesh, c, index);
            const int n = bad_among(candidate, region_after, model, topology_only);
            if (n < best_bad) {
              best_bad = n;
              best = c;
              best_mesh = std::move(candidate);
              if (n == 0) break;
            }
          }
        }
        // No place lowers the bad quads: the quads round the merged vertex untangled (its rings;
        // the rest held), a few times in all.
        for (const Collapse& c : tried) {
          if (best_bad < bad_here || untangles_left <= 0) break;
          --untangles_left;
          std::vector<int> index;
          const QuadMesh candidate = collapsed(mesh, c, index);
          const std::vector<std::vector<int>> near = vertex_quads(candidate.Q, candidate.num_vertices());
          std::vector<char> fixed(candidate.num_vertices(), 1);
          for (int r : quads_round(candidate, near, near[index[c.keep]].front(), kCollapseRings))
            for (int k = 0; k < 4; ++k) fixed[candidate.Q(r, k)] = 0;
          QuadUntangleResult untangled = untangle_quads(candidate, model, moves, fixed);
          const int n = bad_among(untangled.mesh, region_after, model, topology_only);
          if (n < best_bad) {
            best_bad = n;
            best = c;
            best.from = -1;  // moved by the untangling
            best_mesh = std::move(untangled.mesh);
          }
        }
        if (best_bad >= bad_here) continue;
        // Taken: the grid, the corners and the pinned flags follow the vertices.
        const int keep = best.keep, gone = best.gone;
        if (best.from == gone) {
          on_p.mesh.V.row(keep) = on_p.mesh.V.row(gone);
          on_p.on_polycube[keep] = on_p.on_polycube[gone];
        }
        const bool pinned_place = best.from >= 0 && held[best.from];
        Collapse bookkeeping = best;
        bookkeeping.place = on_p.mesh.V.row(keep).transpose();
        std::vector<int> index;
        on_p.mesh = collapsed(on_p.mesh, bookkeeping, index);
        std::vector<SurfacePoint> points(best_mesh.num_vertices());
        std::vector<char> flags(best_mesh.num_vertices(), 0);
        for (int v = 0; v < static_cast<int>(index.size()); ++v)
          if (index[v] >= 0) {
            points[index[v]] = on_p.on_polycube[v];
            flags[index[v]] = held[v];
          }
        flags[index[keep]] = pinned_place;
        on_p.on_polycube = std::move(points);
        held = std::move(flags);
        if (on_p.quad_axis.size() == mesh.num_quads()) on_p.quad_axis = without_row(on_p.quad_axis, best.q);
        if (on_p.quad_cell.size() == mesh.num_quads()) on_p.quad_cell = without_row(on_p.quad_cell, best.q);
        if (on_p.quad_refined_by.size() == mesh.num_quads())
          on_p.quad_refined_by = without_row(on_p.quad_refined_by, best.q);
        for (int& c : on_p.corners) c = index[c];
        mesh = std::move(best_mesh);
        bad = bad_quads(mesh, model, topology_only);
        ++out.collapsed;
        progress = taken = true;
        break;
      }
      if (taken) break;
      failed.insert(key(b));
    }
  }
  if (out.collapsed == 0) return out;
  // Kept only when fewer quads are bad and the surface is the same 2-manifold.
  const QuadTopology topology = quad_topology(mesh);
  const QuadTopology was = quad_topology(quads);
  const bool manifold = topology.nonmanifold_edges == 0 && topology.misoriented_edges == 0 &&
                        topology.nonmanifold_vertices == 0 && topology.unreferenced_vertices == 0;
  if (static_cast<int>(bad.size()) >= out.bad_before || !manifold || topology.boundary_edges != was.boundary_edges ||
      topology.euler != was.euler || topology.components != was.components) {
    out.collapsed = 0;
    return out;
  }
  out.bad_after = static_cast<int>(bad.size());
  const auto irregular = [](const QuadTopology& t) {
    return static_cast<int>(((t.valence.array() != 4) && (t.valence.array() != 0)).count());
  };
  out.irregular_added = irregular(topology) - irregular(was);
  quads = std::move(mesh);
  grid = std::move(on_p);
  if (!pinned.empty()) pinned = std::move(held);
  return out;
}

}  // namespace polycube
