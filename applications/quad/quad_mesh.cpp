#include "applications/quad/quad_mesh.h"

#include "polycube/disjoint_sets.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace polycube {

namespace {

void check_indices(const QuadMesh& mesh) {
  const int nv = mesh.num_vertices();
  for (int q = 0; q < mesh.num_quads(); ++q) {
    for (int i = 0; i < 4; ++i) {
      const int v = mesh.Q(q, i);
      if (v < 0 || v >= nv)
        throw std::invalid_argument("quad " + std::to_string(q) + " has vertex index " + std::to_string(v) +
                                    " outside 0.." + std::to_string(nv - 1));
      for (int j = 0; j < i; ++j)
        if (mesh.Q(q, j) == v)
          throw std::invalid_argument("quad " + std::to_string(q) + " repeats vertex " + std::to_string(v));
    }
  }
}

}  // namespace

Eigen::MatrixX2i quad_edges(const Eigen::MatrixX4i& Q) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(4 * Q.rows());
  for (Eigen::Index q = 0; q < Q.rows(); ++q)
    for (int i = 0; i < 4; ++i) {
      const int a = Q(q, i), b = Q(q, (i + 1) % 4);
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  Eigen::MatrixX2i E(edges.size(), 2);
  for (size_t e = 0; e < edges.size(); ++e) E.row(e) << edges[e].first, edges[e].second;
  return E;
}

std::vector<std::vector<int>> vertex_neighbours(const Eigen::MatrixX4i& Q, int num_vertices) {
  std::vector<std::vector<int>> neighbours(num_vertices);
  for (Eigen::Index q = 0; q < Q.rows(); ++q)
    for (int i = 0; i < 4; ++i) {
      neighbours[Q(q, i)].push_back(Q(q, (i + 1) % 4));
      neighbours[Q(q, i)].push_back(Q(q, (i + 3) % 4));
    }
  for (std::vector<int>& n : neighbours) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  return neighbours;
}

std::vector<std::vector<int>> vertex_quads(const Eigen::MatrixX4i& Q, int num_vertices) {
  std::vector<std::vector<int>> quads(num_vertices);
  for (Eigen::Index q = 0; q < Q.rows(); ++q)
    for (int i = 0; i < 4; ++i) quads[Q(q, i)].push_back(static_cast<int>(q));
  return quads;
}

QuadTopology quad_topology(const QuadMesh& mesh) {
  check_indices(mesh);
  const int nv = mesh.num_vertices(), nq = mesh.num_quads();
  QuadTopology t;

  // Directed half-edges sorted by undirected edge: counts and directions per edge.
  std::vector<std::tuple<int, int, int>> half;  // (min, max, +1 if min->max)
  half.reserve(4 * nq);
  for (int q = 0; q < nq; ++q)
    for (int i = 0; i < 4; ++i) {
      const int a = mesh.Q(q, i), b = mesh.Q(q, (i + 1) % 4);
      half.emplace_back(std::min(a, b), std::max(a, b), a < b ? 1 : -1);
    }
  std::sort(half.begin(), half.end());
  for (size_t i = 0; i < half.size();) {
    size_t j = i;
    int forward = 0;
    while (j < half.size() && std::get<0>(half[j]) == std::get<0>(half[i]) && std::get<1>(half[j]) == std::get<1>(half[i])) {
      forward += std::get<2>(half[j]) > 0;
      ++j;
    }
    const size_t count = j - i;
    ++t.edges;
    if (count == 1) ++t.boundary_edges;
    if (count > 2) ++t.nonmanifold_edges;
    if (count == 2 && forward != 1) ++t.misoriented_edges;
    i = j;
  }

  // Valences and fans: around a manifold vertex the wedges (previous, next corner) of its quads
  // chain into one cycle (one path on the boundary); two fans meeting at the vertex give two.
  t.valence = Eigen::VectorXi::Zero(nv);
  std::vector<std::vector<std::pair<int, int>>> wedges(nv);
  for (int q = 0; q < nq; ++q)
    for (int i = 0; i < 4; ++i) {
      ++t.valence[mesh.Q(q, i)];
      wedges[mesh.Q(q, i)].emplace_back(mesh.Q(q, (i + 3) % 4), mesh.Q(q, (i + 1) % 4));
    }
  std::vector<int> local;
  for (int v = 0; v < nv; ++v) {
    if (wedges[v].empty()) {
      ++t.unreferenced_vertices;
      continue;
    }
    local.clear();
    for (const auto& [a, b] : wedges[v]) {
      local.push_back(a);
      local.push_back(b);
    }
    std::sort(local.begin(), local.end());
    local.erase(std::unique(local.begin(), local.end()), local.end());
    const auto id = [&](int x) { return static_cast<int>(std::lower_bound(local.begin(), local.end(), x) - local.begin()); };
    DisjointSets sets(static_cast<int>(local.size()));
    int components = static_cast<int>(local.size());
    for (const auto& [a, b] : wedges[v]) components -= sets.unite(id(a), id(b));
    if (components != 1) ++t.nonmanifold_vertices;
  }

  DisjointSets vertices(nv);
  for (int q = 0; q < nq; ++q)
    for (int i = 1; i < 4; ++i) vertices.unite(mesh.Q(q, 0), mesh.Q(q, i));
  int referenced = 0;
  for (int v = 0; v < nv; ++v)
    if (!wedges[v].empty()) {
      ++referenced;
      t.components += vertices.find(v) == v;
    }
  t.euler = referenced - t.edges + nq;
  return t;
}

TriMesh triangulate_quads(const QuadMesh& mesh) {
  TriMesh tri;
  tri.V = mesh.V;
  tri.F.resize(2 * mesh.num_quads(), 3);
  for (int q = 0; q < mesh.num_quads(); ++q) {
    const auto corners = quad_triangle_corners(mesh, q);
    for (int h = 0; h < 2; ++h)
      for (int i = 0; i < 3; ++i) tri.F(2 * q + h, i) = mesh.Q(q, corners[h][i]);
  }
  return tri;
}

std::array<std::array<int, 3>, 2> quad_triangle_corners(const QuadMesh& mesh, int q) {
  const double d02 = (mesh.V.row(mesh.Q(q, 0)) - mesh.V.row(mesh.Q(q, 2))).squaredNorm();
  const double d13 = (mesh.V.row(mesh.Q(q, 1)) - mesh.V.row(mesh.Q(q, 3))).squaredNorm();
  if (d02 <= d13) return {{{0, 1, 2}, {0, 2, 3}}};
  return {{{1, 2, 3}, {1, 3, 0}}};
}

std::vector<std::vector<int>> quad_polygons(const QuadMesh& mesh) {
  std::vector<std::vector<int>> polygons(mesh.num_quads());
  for (int q = 0; q < mesh.num_quads(); ++q) polygons[q] = {mesh.Q(q, 0), mesh.Q(q, 1), mesh.Q(q, 2), mesh.Q(q, 3)};
  return polygons;
}

}  // namespace polycube
