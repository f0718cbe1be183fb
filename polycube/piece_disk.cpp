#include "polycube/piece_disk.h"

#include "polycube/disjoint_sets.h"
#include "polycube/errors.h"
#include "polycube/mesh_topology.h"
#include "polycube/triangle_geometry.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <queue>
#include <string>
#include <utility>

namespace polycube {

namespace {

std::vector<std::vector<int>> vertex_neighbours(const TriMesh& mesh) {
  std::vector<std::vector<int>> adjacent(mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) {
      adjacent[mesh.F(f, i)].push_back(mesh.F(f, (i + 1) % 3));
      adjacent[mesh.F(f, i)].push_back(mesh.F(f, (i + 2) % 3));
    }
  for (auto& list : adjacent) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return adjacent;
}

using QueueEntry = std::pair<double, int>;
using MinQueue = std::priority_queue<QueueEntry, std::vector<QueueEntry>, std::greater<QueueEntry>>;

std::vector<int> trace_back(const std::vector<int>& parent, int end) {
  std::vector<int> path;
  for (int v = end; v >= 0; v = parent[v]) path.push_back(v);
  std::reverse(path.begin(), path.end());
  return path;
}

}  // namespace

std::vector<Slit> find_slits(const TriMesh& piece, const std::vector<std::vector<int>>& loops, int root, const EdgeLength& edge_length) {
  const int n = piece.num_vertices();
  const int loop_count = static_cast<int>(loops.size());
  std::vector<int> on_loop(n, -1);
  for (int l = 0; l < loop_count; ++l)
    for (int v : loops[l]) on_loop[v] = l;
  const std::vector<std::vector<int>> adjacent = vertex_neighbours(piece);
  std::vector<char> joined(loop_count, 0), used_end(n, 0), on_slit(n, 0);
  joined[root] = 1;
  std::vector<Slit> slits;
  for (int round = 1; round < loop_count; ++round) {
    std::vector<double> dist(n, INFINITY);
    std::vector<int> parent(n, -1);
    MinQueue queue;
    for (int v = 0; v < n; ++v)
      if (on_loop[v] >= 0 && joined[on_loop[v]] && !used_end[v]) {
        dist[v] = 0;
        queue.emplace(0.0, v);
      }
    int best = -1;
    while (!queue.empty()) {
      const auto [d, v] = queue.top();
      queue.pop();
      if (d > dist[v]) continue;
      if (best >= 0 && d >= dist[best]) break;
      const bool source = on_loop[v] >= 0;
      if (source && !joined[on_loop[v]]) continue;  // a target: never expanded
      for (int w : adjacent[v]) {
        if (on_slit[w] || used_end[w]) continue;
        if (on_loop[w] >= 0 && joined[on_loop[w]]) continue;
        const double nd = d + edge_length(v, w);
        if (nd < dist[w]) {
          dist[w] = nd;
          parent[w] = v;
          if (on_loop[w] >= 0) {
            if (best < 0 || nd < dist[best]) best = w;
          } else {
            queue.emplace(nd, w);
          }
        }
      }
    }
    if (best < 0)
      throw AlgorithmError("cannot join the " + std::to_string(loop_count) + " boundary loops of a piece by slits (no free path)");
    Slit slit;
    slit.path = trace_back(parent, best);
    slit.from = on_loop[slit.path.front()];
    slit.to = on_loop[best];
    joined[slit.to] = 1;
    used_end[slit.path.front()] = used_end[slit.path.back()] = 1;
    for (size_t k = 1; k + 1 < slit.path.size(); ++k) on_slit[slit.path[k]] = 1;
    slits.push_back(std::move(slit));
  }
  return slits;
}

std::vector<int> shortest_path(const TriMesh& piece, int a, int b, const std::vector<char>& blocked, const EdgeLength& edge_length) {
  const int n = piece.num_vertices();
  const std::vector<std::vector<int>> adjacent = vertex_neighbours(piece);
  std::vector<double> dist(n, INFINITY);
  std::vector<int> parent(n, -1);
  MinQueue queue;
  dist[a] = 0;
  queue.emplace(0.0, a);
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    if (v == b) return trace_back(parent, b);
    for (int w : adjacent[v]) {
      if (blocked[w] && w != b) continue;
      const double nd = d + edge_length(v, w);
      if (nd < dist[w]) {
        dist[w] = nd;
        parent[w] = v;
        queue.emplace(nd, w);
      }
    }
  }
  return {};
}

TriMesh split_inner_edges(const TriMesh& mesh, std::vector<int>& face_parent) {
  const EdgeMap edges = build_edge_map(mesh.F);
  std::vector<int> midpoint(edges.num_edges(), -1);
  std::vector<Eigen::Vector3d> positions;
  for (int v = 0; v < mesh.num_vertices(); ++v) positions.push_back(mesh.V.row(v));
  for (int e = 0; e < edges.num_edges(); ++e) {
    if (edges.face_count[e] != 2) continue;
    midpoint[e] = static_cast<int>(positions.size());
    positions.push_back(0.5 * (positions[edges.E(e, 0)] + positions[edges.E(e, 1)]));
  }
  std::vector<Eigen::Vector3i> faces;
  face_parent.clear();
  auto add = [&](int f, int a, int b, int c) {
    faces.emplace_back(a, b, c);
    face_parent.push_back(f);
  };
  for (int f = 0; f < mesh.num_faces(); ++f) {
    int v[3], m[3], split = 0;
    for (int i = 0; i < 3; ++i) {
      v[i] = mesh.F(f, i);
      m[i] = midpoint[edges.FE(f, i)];  // on the edge from v[i] to v[i+1]
      split += m[i] >= 0;
    }
    if (split == 3) {
      add(f, v[0], m[0], m[2]);
      add(f, m[0], v[1], m[1]);
      add(f, m[2], m[1], v[2]);
      add(f, m[0], m[1], m[2]);
    } else if (split == 2) {
      int r = 0;  // rotate so that the unsplit edge runs from v[r+2] to v[r]
      while (m[(r + 2) % 3] >= 0) ++r;
      const int a = v[r], b = v[(r + 1) % 3], c = v[(r + 2) % 3], mab = m[r], mbc = m[(r + 1) % 3];
      add(f, mab, b, mbc);
      add(f, a, mab, mbc);
      add(f, a, mbc, c);
    } else if (split == 1) {
      int r = 0;
      while (m[r] < 0) ++r;
      add(f, v[r], m[r], v[(r + 2) % 3]);
      add(f, m[r], v[(r + 1) % 3], v[(r + 2) % 3]);
    } else {
      add(f, v[0], v[1], v[2]);
    }
  }
  TriMesh out;
  out.V.resize(positions.size(), 3);
  for (size_t i = 0; i < positions.size(); ++i) out.V.row(i) = positions[i];
  out.F.resize(faces.size(), 3);
  for (size_t i = 0; i < faces.size(); ++i) out.F.row(i) = faces[i];
  return out;
}

CutDisk cut_open(const TriMesh& piece, const std::vector<Slit>& slits) {
  std::vector<std::pair<int, int>> cut_edges;
  for (const Slit& s : slits)
    for (size_t k = 0; k + 1 < s.path.size(); ++k)
      cut_edges.emplace_back(std::min(s.path[k], s.path[k + 1]), std::max(s.path[k], s.path[k + 1]));
  std::sort(cut_edges.begin(), cut_edges.end());

  const EdgeMap edges = build_edge_map(piece.F);
  const int nf = piece.num_faces();
  DisjointSets corners(3 * nf);
  auto corner_of = [&](int f, int v) {
    for (int i = 0; i < 3; ++i)
      if (piece.F(f, i) == v) return 3 * f + i;
    return -1;
  };
  for (int e = 0; e < edges.num_edges(); ++e) {
    if (edges.face_count[e] != 2) continue;
    const int a = edges.E(e, 0), b = edges.E(e, 1);
    if (std::binary_search(cut_edges.begin(), cut_edges.end(), std::make_pair(a, b))) continue;
    const int f = edges.EF(e, 0), g = edges.EF(e, 1);
    corners.unite(corner_of(f, a), corner_of(g, a));
    corners.unite(corner_of(f, b), corner_of(g, b));
  }
  CutDisk cut;
  std::vector<int> vertex_of(3 * nf, -1);
  cut.mesh.F.resize(nf, 3);
  for (int f = 0; f < nf; ++f)
    for (int i = 0; i < 3; ++i) {
      const int root = corners.find(3 * f + i);
      if (vertex_of[root] < 0) {
        vertex_of[root] = static_cast<int>(cut.vertex_origin.size());
        cut.vertex_origin.push_back(piece.F(f, i));
      }
      cut.mesh.F(f, i) = vertex_of[root];
    }
  cut.mesh.V.resize(cut.vertex_origin.size(), 3);
  for (size_t v = 0; v < cut.vertex_origin.size(); ++v) cut.mesh.V.row(v) = piece.V.row(cut.vertex_origin[v]);
  const std::vector<std::vector<int>> loops = boundary_loops(cut.mesh.F);
  const int euler = euler_characteristic(cut.mesh.F, cut.mesh.num_vertices());
  if (loops.size() != 1 || euler != 1)
    throw AlgorithmError("a piece cut along its slits is not a disk (" + std::to_string(loops.size()) + " boundary loops, Euler characteristic " +
                         std::to_string(euler) + ")");
  cut.boundary = loops.front();
  return cut;
}

namespace {

// Counts the flipped faces and the smallest signed area of the embedding.
void measure(DiskEmbedding& disk) {
  disk.flipped = 0;
  disk.min_area = INFINITY;
  for (int f = 0; f < disk.mesh.num_faces(); ++f) {
    const double area = uv_area(disk, f);
    disk.min_area = std::min(disk.min_area, area);
    if (!(area > 0)) ++disk.flipped;
  }
}

// The harmonic map of a disk for given edge weights: Dirichlet on the fixed vertices, the sparse
// pattern analysed once so that several weightings of the same disk factorise cheaply.
class DiskSolver {
 public:
  explicit DiskSolver(const DiskEmbedding& disk) : index_(disk.uv.rows(), -1) {
    for (int v = 0; v < static_cast<int>(index_.size()); ++v)
      if (!disk.fixed[v]) index_[v] = count_++;
  }

  // Solves with `weights` (per disk.edges, all > 0) into disk.uv, then measures disk.flipped and
  // disk.min_area.
  void solve(const std::vector<double>& weights, DiskEmbedding& disk) {
    if (count_ > 0) {
      std::vector<Eigen::Triplet<double>> triplets;
      Eigen::MatrixX2d rhs = Eigen::MatrixX2d::Zero(count_, 2);
      for (size_t e = 0; e < disk.edges.size(); ++e) {
        const double w = weights[e];
        const int a = disk.edges[e].first, b = disk.edges[e].second;
        const int ia = index_[a], ib = index_[b];
        if (ia >= 0) triplets.emplace_back(ia, ia, w);
        if (ib >= 0) triplets.emplace_back(ib, ib, w);
        if (ia >= 0 && ib >= 0) {
          triplets.emplace_back(ia, ib, -w);
          triplets.emplace_back(ib, ia, -w);
        } else if (ia >= 0) {
          rhs.row(ia) += w * disk.uv.row(b);
        } else if (ib >= 0) {
          rhs.row(ib) += w * disk.uv.row(a);
        }
      }
      Eigen::SparseMatrix<double> L(count_, count_);
      L.setFromTriplets(triplets.begin(), triplets.end());
      if (!analysed_) {
        solver_.analyzePattern(L);
        analysed_ = true;
      }
      solver_.factorize(L);
      if (solver_.info() != Eigen::Success) throw AlgorithmError("disk map: the Laplacian of a cut piece could not be factorised");
      Eigen::MatrixX2d x = solver_.solve(rhs);
      // Two refinement steps against rounding in badly scaled weights.
      for (int it = 0; it < 2; ++it) x += solver_.solve(rhs - L * x);
      for (size_t v = 0; v < index_.size(); ++v)
        if (index_[v] >= 0) disk.uv.row(v) = x.row(index_[v]);
    }
    measure(disk);
  }

 private:
  std::vector<int> index_;
  int count_ = 0;
  bool analysed_ = false;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver_;
};

}  // namespace

double uv_area(const DiskEmbedding& disk, int f) {
  const Eigen::Vector2d a = disk.uv.row(disk.mesh.F(f, 0)), b = disk.uv.row(disk.mesh.F(f, 1)), c = disk.uv.row(disk.mesh.F(f, 2));
  return 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
}

DiskEmbedding embed_disk(const CutDisk& cut, const std::vector<double>& angle_of,
                         const std::vector<std::vector<std::pair<double, double>>>& extra) {
  const int nb = static_cast<int>(cut.boundary.size());
  const int nc = cut.mesh.num_vertices();
  DiskEmbedding out;
  out.vertex_origin = cut.vertex_origin;
  std::vector<double> angle(nc, NAN);
  std::vector<Eigen::Vector3d> positions;
  for (int v = 0; v < nc; ++v) positions.push_back(cut.mesh.V.row(v));
  for (int k = 0; k < nb; ++k) angle[cut.boundary[k]] = angle_of[k];
  // Extra vertices per directed boundary edge.
  std::map<std::pair<int, int>, std::vector<int>> inserted;
  for (int k = 0; k < nb; ++k) {
    if (extra[k].empty()) continue;
    const int a = cut.boundary[k], b = cut.boundary[(k + 1) % nb];
    std::vector<int>& ids = inserted[{a, b}];
    for (const auto& [theta, fraction] : extra[k]) {
      ids.push_back(static_cast<int>(positions.size()));
      positions.push_back((1 - fraction) * positions[a] + fraction * positions[b]);
      angle.push_back(theta);
      out.vertex_origin.push_back(-1);
    }
  }
  std::vector<Eigen::Vector3i> faces;
  for (int f = 0; f < cut.mesh.num_faces(); ++f) {
    const Eigen::Vector3i t = cut.mesh.F.row(f);
    int apex = -1, split_edges = 0;
    std::vector<int> ring;
    for (int i = 0; i < 3; ++i) {
      ring.push_back(t[i]);
      auto it = inserted.find({t[i], t[(i + 1) % 3]});
      if (it == inserted.end()) continue;
      ring.insert(ring.end(), it->second.begin(), it->second.end());
      ++split_edges;
      apex = (i + 2) % 3;
    }
    if (split_edges == 0) {
      faces.push_back(t);
      out.face_origin.push_back(f);
    } else if (split_edges == 1) {
      // Fan from the corner opposite the split edge.
      const int start = static_cast<int>(std::find(ring.begin(), ring.end(), t[apex]) - ring.begin());
      std::rotate(ring.begin(), ring.begin() + start, ring.end());
      for (size_t j = 1; j + 1 < ring.size(); ++j) {
        faces.emplace_back(ring[0], ring[j], ring[j + 1]);
        out.face_origin.push_back(f);
      }
    } else {
      // Points on two or three sides: fan from a new vertex at the centroid (inside the face).
      const int centre = static_cast<int>(positions.size());
      positions.push_back((positions[t[0]] + positions[t[1]] + positions[t[2]]) / 3);
      angle.push_back(NAN);
      out.vertex_origin.push_back(-1);
      for (size_t j = 0; j < ring.size(); ++j) {
        faces.emplace_back(centre, ring[j], ring[(j + 1) % ring.size()]);
        out.face_origin.push_back(f);
      }
    }
  }
  const int n = static_cast<int>(positions.size());
  out.mesh.V.resize(n, 3);
  for (int v = 0; v < n; ++v) out.mesh.V.row(v) = positions[v];
  out.mesh.F.resize(faces.size(), 3);
  for (size_t f = 0; f < faces.size(); ++f) out.mesh.F.row(f) = faces[f];

  // Harmonic map with positive weights, Dirichlet on the circle.
  out.uv.resize(n, 2);
  out.fixed.assign(n, 0);
  for (int v = 0; v < n; ++v) {
    if (std::isnan(angle[v])) continue;
    out.fixed[v] = 1;
    out.uv(v, 0) = std::cos(angle[v]);
    out.uv(v, 1) = std::sin(angle[v]);
  }
  std::map<std::pair<int, int>, double> weight;
  for (const Eigen::Vector3i& t : faces) {
    for (int i = 0; i < 3; ++i) {
      const int a = t[(i + 1) % 3], b = t[(i + 2) % 3];
      const double la = (positions[b] - positions[a]).norm();
      const double lb = (positions[t[i]] - positions[b]).norm();
      const double lc = (positions[t[i]] - positions[a]).norm();
      weight[{std::min(a, b), std::max(a, b)}] += cotan_opposite(la, lb, lc);
    }
  }
  for (const auto& [edge, raw] : weight) {
    if (out.fixed[edge.first] && out.fixed[edge.second]) continue;
    out.edges.emplace_back(edge.first, edge.second);
    out.edge_weight.push_back(std::clamp(std::isfinite(raw) ? raw : 1.0, 1e-3, 1e3));
  }
  DiskSolver(out).solve(out.edge_weight, out);
  return out;
}

DecrowdResult decrowd_disk(DiskEmbedding& disk, const AreaRatio& area_ratio, const DecrowdOptions& options) {
  DecrowdResult result;
  std::vector<double> ratio = area_ratio(disk);
  auto smallest = [](const std::vector<double>& r) { return r.empty() ? 1.0 : *std::min_element(r.begin(), r.end()); };
  result.min_ratio_before = result.min_ratio_after = smallest(ratio);
  if (!(result.min_ratio_before < options.trigger) || disk.flipped > 0) return result;
  // Faces of each edge (one or two; the disk is a manifold triangle mesh).
  std::map<std::pair<int, int>, int> edge_id;
  for (size_t e = 0; e < disk.edges.size(); ++e) edge_id[disk.edges[e]] = static_cast<int>(e);
  std::vector<std::vector<int>> edge_faces(disk.edges.size());
  for (int f = 0; f < disk.mesh.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) {
      const int a = disk.mesh.F(f, i), b = disk.mesh.F(f, (i + 1) % 3);
      const auto it = edge_id.find({std::min(a, b), std::max(a, b)});
      if (it != edge_id.end()) edge_faces[it->second].push_back(f);
    }
  DiskSolver solver(disk);
  std::vector<double> log_scale(disk.edges.size(), 0.0), weights(disk.edges.size());
  const double log_target = std::log(options.target);
  Eigen::MatrixX2d best_uv = disk.uv;
  for (int it = 1; it <= options.max_iterations; ++it) {
    for (size_t e = 0; e < disk.edges.size(); ++e) {
      double step = 0;
      for (int f : edge_faces[e]) step += std::min(std::log(std::max(ratio[f], 1e-300)) - log_target, 0.0);
      if (!edge_faces[e].empty()) log_scale[e] += options.step * step / static_cast<double>(edge_faces[e].size());
      weights[e] = disk.edge_weight[e] * std::exp(log_scale[e]);
    }
    solver.solve(weights, disk);
    if (disk.flipped > 0) break;
    ratio = area_ratio(disk);
    result.iterations = it;
    const double now = smallest(ratio);
    if (now > result.min_ratio_after) {
      result.min_ratio_after = now;
      best_uv = disk.uv;
    }
    if (now >= options.stop) break;
  }
  disk.uv = best_uv;
  measure(disk);
  return result;
}

}  // namespace polycube
