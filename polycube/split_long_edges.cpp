#include "polycube/split_long_edges.h"

#include "polycube/mesh_topology.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace polycube {

SplitLongEdges split_long_edges(const TriMesh& mesh, double max_length, long long max_faces) {
  if (!(max_length > 0)) throw std::invalid_argument("split_long_edges: max_length must be > 0, got " + std::to_string(max_length));
  if (max_faces < 1) throw std::invalid_argument("split_long_edges: max_faces must be >= 1, got " + std::to_string(max_faces));
  SplitLongEdges out;
  out.mesh = mesh;
  const double limit = max_length * max_length;
  while (true) {
    const TriMesh& m = out.mesh;
    const int nf = m.num_faces();
    const EdgeMap edges = build_edge_map(m.F);
    const int ne = edges.num_edges();
    std::vector<char> split(ne, 0);
    bool any = false;
    for (int e = 0; e < ne; ++e) {
      split[e] = (m.V.row(edges.E(e, 0)) - m.V.row(edges.E(e, 1))).squaredNorm() > limit;
      any = any || split[e];
    }
    if (!any) break;
    // Red closure: a triangle with two edges to split gets its third split too (until none has
    // exactly two).
    for (bool changed = true; changed;) {
      changed = false;
      for (int f = 0; f < nf; ++f) {
        const int count = split[edges.FE(f, 0)] + split[edges.FE(f, 1)] + split[edges.FE(f, 2)];
        if (count != 2) continue;
        for (int i = 0; i < 3; ++i) split[edges.FE(f, i)] = 1;
        changed = true;
      }
    }
    long long faces = 0;
    for (int f = 0; f < nf; ++f) {
      const int count = split[edges.FE(f, 0)] + split[edges.FE(f, 1)] + split[edges.FE(f, 2)];
      faces += count == 3 ? 4 : count == 1 ? 2 : 1;
    }
    if (faces > max_faces) {
      out.capped = true;
      break;
    }
    std::vector<int> midpoint(ne, -1);
    int nv = m.num_vertices();
    for (int e = 0; e < ne; ++e)
      if (split[e]) midpoint[e] = nv++;
    TriMesh next;
    next.V.resize(nv, 3);
    next.V.topRows(m.num_vertices()) = m.V;
    for (int e = 0; e < ne; ++e)
      if (split[e]) next.V.row(midpoint[e]) = (m.V.row(edges.E(e, 0)) + m.V.row(edges.E(e, 1))) / 2;
    next.F.resize(faces, 3);
    int row = 0;
    for (int f = 0; f < nf; ++f) {
      // Edge i of face f runs from corner i to corner i + 1.
      int mid[3];
      int count = 0, only = -1;
      for (int i = 0; i < 3; ++i) {
        mid[i] = midpoint[edges.FE(f, i)];
        if (mid[i] >= 0) {
          ++count;
          only = i;
        }
      }
      const int a = m.F(f, 0), b = m.F(f, 1), c = m.F(f, 2);
      if (count == 0) {
        next.F.row(row++) << a, b, c;
      } else if (count == 3) {
        next.F.row(row++) << a, mid[0], mid[2];
        next.F.row(row++) << mid[0], b, mid[1];
        next.F.row(row++) << mid[2], mid[1], c;
        next.F.row(row++) << mid[0], mid[1], mid[2];
      } else {
        const int u = m.F(f, only), v = m.F(f, (only + 1) % 3), w = m.F(f, (only + 2) % 3);
        next.F.row(row++) << u, mid[only], w;
        next.F.row(row++) << mid[only], v, w;
      }
    }
    out.mesh = std::move(next);
    ++out.rounds;
  }
  return out;
}

double sliver_area_share(const TriMesh& mesh, double aspect) {
  if (!(aspect > 0)) throw std::invalid_argument("sliver_area_share: aspect must be > 0, got " + std::to_string(aspect));
  double total = 0, slivers = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const double area = 0.5 * (b - a).cross(c - a).norm();
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    total += area;
    // height onto the longest edge = 2 area / longest; longest > aspect * height
    if (longest * longest > aspect * 2 * area) slivers += area;
  }
  return total > 0 ? slivers / total : 0;
}

}  // namespace polycube
