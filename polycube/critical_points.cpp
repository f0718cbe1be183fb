#include "polycube/critical_points.h"

#include "polycube/disjoint_sets.h"

#include "polycube/errors.h"

#include <algorithm>
#include <numeric>
#include <string>

namespace polycube {

namespace {

// Vertex links as cyclic sequences, stored contiguously (CSR).
struct Links {
  std::vector<int> offset;  // #V + 1
  std::vector<int> vertex;  // link vertices, counter-clockwise around each vertex
};

Links vertex_links(const Eigen::MatrixX3i& F, const Eigen::MatrixX3i& adjacent, const Eigen::MatrixX3i& adjacent_edge,
                   int nv) {
  const int nf = static_cast<int>(F.rows());
  std::vector<int> start_face(nv, -1), start_corner(nv, -1), degree(nv, 0);
  for (int f = 0; f < nf; ++f)
    for (int c = 0; c < 3; ++c) {
      const int v = F(f, c);
      ++degree[v];
      if (start_face[v] < 0) {
        start_face[v] = f;
        start_corner[v] = c;
      }
    }
  Links links;
  links.offset.assign(nv + 1, 0);
  for (int v = 0; v < nv; ++v) links.offset[v + 1] = links.offset[v] + degree[v];
  links.vertex.resize(links.offset[nv]);
  for (int v = 0; v < nv; ++v) {
    if (start_face[v] < 0) continue;
    // Walk the faces around v: the face across the edge entering v (F(f,c+2) -> v) holds the
    // next link vertex; in that face, v sits at the corner where the shared edge starts.
    int f = start_face[v], c = start_corner[v], k = 0;
    do {
      if (k == degree[v])
        throw MeshError("critical_points: faces around vertex " + std::to_string(v) + " do not close into a fan");
      links.vertex[links.offset[v] + k++] = F(f, (c + 1) % 3);
      const int e = (c + 2) % 3;
      const int g = adjacent(f, e);
      c = adjacent_edge(f, e);
      f = g;
    } while (f != start_face[v] || c != start_corner[v]);
    if (k != degree[v])
      throw MeshError("critical_points: vertex " + std::to_string(v) + " is not manifold (" + std::to_string(degree[v]) +
                      " faces, " + std::to_string(k) + " in its first fan)");
  }
  return links;
}

// One sweep of 0-dimensional persistence over `order` (ascending in the sweep direction):
// components of the swept part are born at extrema and die, elder rule, at the vertex where they
// join an older one; the component of `keep` never dies. Each death cancels that extremum with
// the joining vertex, whose remaining multiplicity drops by one.
void cancel_sweep(const std::vector<int>& order, const std::vector<int>& rank, const Links& links, int keep,
                  std::vector<char>& extremum_cancelled, std::vector<int>& multiplicity, CriticalPoints& result) {
  const int nv = static_cast<int>(order.size());
  DisjointSets sets(nv);
  std::vector<int> birth(nv, -1);  // per root: its extremum
  std::vector<int> roots;
  for (int v : order) {
    roots.clear();
    for (int k = links.offset[v]; k < links.offset[v + 1]; ++k) {
      const int u = links.vertex[k];
      if (rank[u] < rank[v]) {
        const int r = sets.find(u);
        if (std::find(roots.begin(), roots.end(), r) == roots.end()) roots.push_back(r);
      }
    }
    if (roots.empty()) {
      birth[v] = v;
      continue;
    }
    int survivor = roots[0];
    for (int r : roots) {
      const bool r_kept = birth[r] == keep, s_kept = birth[survivor] == keep;
      if (r_kept || (!s_kept && rank[birth[r]] < rank[birth[survivor]])) survivor = r;
    }
    for (int r : roots) {
      if (r == survivor) continue;
      extremum_cancelled[birth[r]] = 1;
      ++result.cancelled_pairs;
      if (multiplicity[v] > 0)
        --multiplicity[v];
      else
        ++result.unmatched_cancellations;
      sets.unite(r, survivor);
    }
    sets.unite(v, survivor);
  }
}

}  // namespace

int CriticalPoints::saddle_count() const {
  return std::accumulate(saddle_multiplicity.begin(), saddle_multiplicity.end(), 0);
}

CriticalPoints critical_points(const IntrinsicTriangulation& triangulation, const Eigen::VectorXd& f,
                               const CriticalPointOptions& options) {
  const Eigen::MatrixX3i& F = triangulation.F;
  const int nv = static_cast<int>(f.size());
  if (!f.allFinite()) throw AlgorithmError("critical_points: function has non-finite values");
  if (F.rows() > 0 && F.maxCoeff() >= nv)
    throw MeshError("critical_points: face refers to vertex " + std::to_string(F.maxCoeff()) + " but f has " +
                    std::to_string(nv) + " values");
  const Links links = vertex_links(F, triangulation.adjacent, triangulation.adjacent_edge, nv);

  // Simulation of simplicity: the total order (f, tie_break, id).
  const Eigen::VectorXd* second = options.tie_break;
  if (second && second->size() != nv)
    throw AlgorithmError("critical_points: tie_break has " + std::to_string(second->size()) + " values, f has " +
                         std::to_string(nv));
  std::vector<int> order(nv);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (f[a] != f[b]) return f[a] < f[b];
    if (second && (*second)[a] != (*second)[b]) return (*second)[a] < (*second)[b];
    return a < b;
  });
  std::vector<int> rank(nv);
  for (int i = 0; i < nv; ++i) rank[order[i]] = i;

  CriticalPoints result;
  std::vector<int> multiplicity(nv, 0);
  std::vector<char> is_min(nv, 0), is_max(nv, 0);
  for (int v = 0; v < nv; ++v) {
    const int begin = links.offset[v], end = links.offset[v + 1];
    if (begin == end) continue;
    int changes = 0, lower = 0;
    for (int k = begin; k < end; ++k) {
      const int u = links.vertex[k], w = links.vertex[k + 1 < end ? k + 1 : begin];
      const bool u_lower = rank[u] < rank[v], w_lower = rank[w] < rank[v];
      lower += u_lower;
      changes += u_lower != w_lower;
    }
    if (changes == 0) {
      (lower == 0 ? is_min : is_max)[v] = 1;
    } else {
      multiplicity[v] = changes / 2 - 1;
    }
  }
  result.raw_minima = static_cast<int>(std::count(is_min.begin(), is_min.end(), 1));
  result.raw_maxima = static_cast<int>(std::count(is_max.begin(), is_max.end(), 1));
  result.raw_saddle_count = std::accumulate(multiplicity.begin(), multiplicity.end(), 0);

  if (options.cancel_extra_extrema && nv > 0) {
    std::vector<char> cancelled(nv, 0);
    const int keep_min = options.keep_minimum >= 0 ? options.keep_minimum : order.front();
    const int keep_max = options.keep_maximum >= 0 ? options.keep_maximum : order.back();
    cancel_sweep(order, rank, links, keep_min, cancelled, multiplicity, result);
    std::vector<int> reversed(order.rbegin(), order.rend()), reversed_rank(nv);
    for (int i = 0; i < nv; ++i) reversed_rank[reversed[i]] = i;
    cancel_sweep(reversed, reversed_rank, links, keep_max, cancelled, multiplicity, result);
    for (int v = 0; v < nv; ++v)
      if (cancelled[v]) is_min[v] = is_max[v] = 0;
  }

  for (int v = 0; v < nv; ++v) {
    if (is_min[v]) result.minima.push_back(v);
    if (is_max[v]) result.maxima.push_back(v);
    if (multiplicity[v] > 0) {
      result.saddles.push_back(v);
      result.saddle_multiplicity.push_back(multiplicity[v]);
    }
  }
  return result;
}

}  // namespace polycube
