#include "polycube/mesh_topology.h"

#include "polycube/disjoint_sets.h"

#include <algorithm>
#include <unordered_map>

namespace polycube {

EdgeMap build_edge_map(const Eigen::MatrixX3i& F) {
  const int nf = static_cast<int>(F.rows());
  // Sort half-edges by their undirected key; equal keys form one edge.
  struct HalfEdge {
    int a, b, face, corner;
  };
  std::vector<HalfEdge> halfedges;
  halfedges.reserve(3 * nf);
  for (int f = 0; f < nf; ++f)
    for (int i = 0; i < 3; ++i) {
      const int u = F(f, i), v = F(f, (i + 1) % 3);
      halfedges.push_back({std::min(u, v), std::max(u, v), f, i});
    }
  const auto by_b_then_face = [](const HalfEdge& x, const HalfEdge& y) { return x.b != y.b ? x.b < y.b : x.face < y.face; };
  if (nf > 0 && F.minCoeff() >= 0) {
    // Bucketed by the smaller vertex (counting sort), each bucket (a vertex's few edges) sorted
    // by the larger vertex and the face: the order of one sort by (a, b, face), much faster.
    const int nv = F.maxCoeff() + 1;
    std::vector<int> start(nv + 1, 0);
    for (const HalfEdge& h : halfedges) ++start[h.a + 1];
    for (int v = 0; v < nv; ++v) start[v + 1] += start[v];
    std::vector<HalfEdge> bucketed(halfedges.size());
    std::vector<int> next(start.begin(), start.end() - 1);
    for (const HalfEdge& h : halfedges) bucketed[next[h.a]++] = h;
    for (int v = 0; v < nv; ++v) std::sort(bucketed.begin() + start[v], bucketed.begin() + start[v + 1], by_b_then_face);
    halfedges = std::move(bucketed);
  } else {
    std::sort(halfedges.begin(), halfedges.end(),
              [&](const HalfEdge& x, const HalfEdge& y) { return x.a != y.a ? x.a < y.a : by_b_then_face(x, y); });
  }

  EdgeMap map;
  map.FE.resize(nf, 3);
  std::vector<Eigen::Vector2i> edges, edge_faces;
  std::vector<int> counts;
  for (size_t i = 0; i < halfedges.size();) {
    size_t j = i;
    const int e = static_cast<int>(edges.size());
    Eigen::Vector2i ef(-1, -1);
    while (j < halfedges.size() && halfedges[j].a == halfedges[i].a && halfedges[j].b == halfedges[i].b) {
      map.FE(halfedges[j].face, halfedges[j].corner) = e;
      if (j - i < 2) ef[static_cast<int>(j - i)] = halfedges[j].face;
      ++j;
    }
    edges.emplace_back(halfedges[i].a, halfedges[i].b);
    edge_faces.push_back(ef);
    counts.push_back(static_cast<int>(j - i));
    i = j;
  }
  const int ne = static_cast<int>(edges.size());
  map.E.resize(ne, 2);
  map.EF.resize(ne, 2);
  map.face_count.resize(ne);
  for (int e = 0; e < ne; ++e) {
    map.E.row(e) = edges[e].transpose();
    map.EF.row(e) = edge_faces[e].transpose();
    map.face_count[e] = counts[e];
  }
  return map;
}

EdgeDefects edge_defects(const Eigen::MatrixX3i& F, const EdgeMap& edges) {
  EdgeDefects defects;
  for (int e = 0; e < edges.num_edges(); ++e) {
    if (edges.face_count[e] == 1) ++defects.boundary;
    if (edges.face_count[e] > 2) ++defects.nonmanifold;
    if (edges.face_count[e] != 2) continue;
    // The two faces must run through the edge in opposite directions.
    int forward = 0;
    for (int k = 0; k < 2; ++k) {
      const int f = edges.EF(e, k);
      for (int i = 0; i < 3; ++i)
        if (edges.FE(f, i) == e) forward += F(f, i) == edges.E(e, 0);
    }
    if (forward != 1) ++defects.misoriented;
  }
  return defects;
}

std::vector<std::vector<int>> boundary_loops(const Eigen::MatrixX3i& F) {
  const EdgeMap map = build_edge_map(F);
  // Directed boundary half-edges u -> v, keyed by their start vertex.
  std::unordered_multimap<int, int> next;
  for (int f = 0; f < F.rows(); ++f)
    for (int i = 0; i < 3; ++i)
      if (map.face_count[map.FE(f, i)] == 1) next.emplace(F(f, i), F(f, (i + 1) % 3));

  std::vector<std::vector<int>> loops;
  while (!next.empty()) {
    const int start = next.begin()->first;
    std::vector<int> loop;
    int current = start;
    while (true) {
      auto it = next.find(current);
      if (it == next.end()) break;  // open chain (inconsistent orientation): stop here
      loop.push_back(current);
      current = it->second;
      next.erase(it);
      if (current == start) break;
    }
    if (!loop.empty()) loops.push_back(std::move(loop));
  }
  return loops;
}

int connected_components(const Eigen::MatrixX3i& F, int num_vertices, Eigen::VectorXi* face_component) {
  DisjointSets sets(num_vertices);
  for (int f = 0; f < F.rows(); ++f) {
    sets.unite(F(f, 0), F(f, 1));
    sets.unite(F(f, 0), F(f, 2));
  }
  std::unordered_map<int, int> ids;
  Eigen::VectorXi component(F.rows());
  for (int f = 0; f < F.rows(); ++f) {
    const int root = sets.find(F(f, 0));
    auto [it, inserted] = ids.emplace(root, static_cast<int>(ids.size()));
    component[f] = it->second;
  }
  if (face_component) *face_component = component;
  return static_cast<int>(ids.size());
}

CompressedLists::CompressedLists(int keys, const std::vector<std::pair<int, int>>& pairs)
    : begin(keys + 1, 0), items(pairs.size()) {
  for (const auto& pair : pairs) ++begin[pair.first + 1];
  for (int k = 0; k < keys; ++k) begin[k + 1] += begin[k];
  std::vector<int> at(begin.begin(), begin.end() - 1);
  for (const auto& [k, i] : pairs) items[at[k]++] = i;
}

CompressedLists vertex_faces(const Eigen::MatrixX3i& F, int num_vertices) {
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(3 * F.rows());
  for (int f = 0; f < F.rows(); ++f)
    for (int i = 0; i < 3; ++i) pairs.emplace_back(F(f, i), f);
  return CompressedLists(num_vertices, pairs);
}

int count_nonmanifold_vertices(const Eigen::MatrixX3i& F, int num_vertices) {
  // Around each vertex, faces sharing an edge through the vertex are linked; a manifold vertex
  // has exactly one linked group of faces.
  const CompressedLists faces_at = vertex_faces(F, num_vertices);
  int bad = 0;
  std::vector<std::pair<int, int>> by_neighbour;  // (other end of an edge through v, local face)
  for (int v = 0; v < num_vertices; ++v) {
    const int count = faces_at.count(v);
    if (count <= 1) continue;
    by_neighbour.clear();
    for (int k = 0; k < count; ++k) {
      const int f = faces_at.first(v)[k];
      for (int i = 0; i < 3; ++i)
        if (F(f, i) != v) by_neighbour.emplace_back(F(f, i), k);
    }
    std::sort(by_neighbour.begin(), by_neighbour.end());
    DisjointSets local(count);
    for (size_t j = 1; j < by_neighbour.size(); ++j)
      if (by_neighbour[j].first == by_neighbour[j - 1].first) local.unite(by_neighbour[j - 1].second, by_neighbour[j].second);
    int groups = 0;
    for (int k = 0; k < count; ++k) groups += local.find(k) == k;
    if (groups > 1) ++bad;
  }
  return bad;
}

int count_unreferenced_vertices(const Eigen::MatrixX3i& F, int num_vertices) {
  std::vector<char> used(num_vertices, 0);
  for (int f = 0; f < F.rows(); ++f)
    for (int i = 0; i < 3; ++i) used[F(f, i)] = 1;
  return num_vertices - static_cast<int>(std::count(used.begin(), used.end(), 1));
}

int euler_characteristic(const Eigen::MatrixX3i& F, int num_vertices) {
  const int used_vertices = num_vertices - count_unreferenced_vertices(F, num_vertices);
  return used_vertices - build_edge_map(F).num_edges() + static_cast<int>(F.rows());
}

int genus(const Eigen::MatrixX3i& F, int num_vertices) {
  Eigen::VectorXi component;
  const int count = connected_components(F, num_vertices, &component);
  std::vector<std::vector<int>> faces_of(count);
  for (int f = 0; f < F.rows(); ++f) faces_of[component[f]].push_back(f);
  int total = 0;
  for (const auto& faces : faces_of) {
    Eigen::MatrixX3i Fc(faces.size(), 3);
    for (size_t k = 0; k < faces.size(); ++k) Fc.row(k) = F.row(faces[k]);
    const int chi = euler_characteristic(Fc, num_vertices);
    const int loops = static_cast<int>(boundary_loops(Fc).size());
    total += (2 - chi - loops) / 2;
  }
  return total;
}

}  // namespace polycube
