#include "polycube/intrinsic_delaunay.h"

#include "polycube/triangle_geometry.h"

#include "polycube/errors.h"
#include "polycube/mesh_topology.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace polycube {

namespace {

// Halfedge structure with explicit next pointers, so that flips can move halfedges between faces.
// Halfedge h runs from vert[h] to vert[next[h]].
struct Halfedges {
  std::vector<int> next, twin, vert, face;
  std::vector<double> length;  // per halfedge, equal on both halves of an edge
  std::vector<int> face_halfedge;

  int head(int h) const { return vert[next[h]]; }

  // cot(alpha) + cot(beta) of the edge of h: alpha, beta are the angles opposite it.
  double cotan_sum(int h) const {
    const int t = twin[h];
    const double a = length[h];
    return cotan_opposite(a, length[next[h]], length[next[next[h]]]) +
           cotan_opposite(a, length[next[t]], length[next[next[t]]]);
  }
};

Halfedges build_halfedges(const TriMesh& mesh) {
  const Eigen::MatrixX3i& F = mesh.F;
  const int nf = static_cast<int>(F.rows());
  const EdgeMap edges = build_edge_map(F);
  Halfedges he;
  he.next.resize(3 * nf);
  he.twin.assign(3 * nf, -1);
  he.vert.resize(3 * nf);
  he.face.resize(3 * nf);
  he.length.resize(3 * nf);
  he.face_halfedge.resize(nf);
  std::vector<int> first_half(edges.num_edges(), -1);
  for (int f = 0; f < nf; ++f) {
    he.face_halfedge[f] = 3 * f;
    for (int i = 0; i < 3; ++i) {
      const int h = 3 * f + i;
      he.next[h] = 3 * f + (i + 1) % 3;
      he.vert[h] = F(f, i);
      he.face[h] = f;
      const int e = edges.FE(f, i);
      if (edges.face_count[e] != 2)
        throw MeshError("intrinsic_delaunay: edge (" + std::to_string(edges.E(e, 0)) + ", " +
                        std::to_string(edges.E(e, 1)) + ") has " + std::to_string(edges.face_count[e]) +
                        " faces, expected 2 (closed 2-manifold mesh required)");
      const double len = (mesh.V.row(F(f, i)) - mesh.V.row(F(f, (i + 1) % 3))).norm();
      if (!(len > 0) || !std::isfinite(len))
        throw MeshError("intrinsic_delaunay: edge (" + std::to_string(F(f, i)) + ", " +
                        std::to_string(F(f, (i + 1) % 3)) + ") has length " + std::to_string(len));
      he.length[h] = len;
      if (first_half[e] < 0) {
        first_half[e] = h;
      } else {
        const int g = first_half[e];
        if (he.vert[g] == F(f, i))
          throw MeshError("intrinsic_delaunay: faces " + std::to_string(g / 3) + " and " + std::to_string(f) +
                          " traverse edge (" + std::to_string(edges.E(e, 0)) + ", " +
                          std::to_string(edges.E(e, 1)) + ") in the same direction (inconsistent orientation)");
        he.twin[g] = h;
        he.twin[h] = g;
      }
    }
  }
  return he;
}

// Flips the edge of h inside the quad of its two faces. Before: h = i->j, next j->k, k->i in
// face A; twin t = j->i, next i->l, l->j in face B. After: A = (k, i, l), B = (l, j, k) with the
// new edge h = l->k, t = k->l.
void flip(Halfedges& he, int h, double new_length) {
  const int t = he.twin[h];
  const int h1 = he.next[h], h2 = he.next[h1];
  const int t1 = he.next[t], t2 = he.next[t1];
  const int A = he.face[h], B = he.face[t];
  const int k = he.vert[h2], l = he.vert[t2];
  he.vert[h] = l;
  he.vert[t] = k;
  he.next[h] = h2;
  he.next[h2] = t1;
  he.next[t1] = h;
  he.next[t] = t2;
  he.next[t2] = h1;
  he.next[h1] = t;
  he.face[t1] = A;
  he.face[h1] = B;
  he.face_halfedge[A] = h;
  he.face_halfedge[B] = t;
  he.length[h] = he.length[t] = new_length;
}

// Length of the other diagonal k-l of the quad around the edge of h, from a planar layout of the
// two triangles on either side of it.
double flipped_length(const Halfedges& he, int h) {
  const int t = he.twin[h];
  const double a = he.length[h];
  const double jk = he.length[he.next[h]], ki = he.length[he.next[he.next[h]]];
  const double il = he.length[he.next[t]], lj = he.length[he.next[he.next[t]]];
  // i at the origin, j at (a, 0), k above the axis, l below it.
  const double xk = (a * a + ki * ki - jk * jk) / (2 * a);
  const double yk = 2 * triangle_area(a, jk, ki) / a;
  const double xl = (a * a + il * il - lj * lj) / (2 * a);
  const double yl = 2 * triangle_area(a, il, lj) / a;
  return std::hypot(xk - xl, yk + yl);
}

}  // namespace

IntrinsicTriangulation intrinsic_delaunay(const TriMesh& mesh, const IntrinsicDelaunayOptions& options) {
  Halfedges he = build_halfedges(mesh);
  const int nh = static_cast<int>(he.next.size());
  const int nf = nh / 3;
  IntrinsicTriangulation result;

  const long long max_flips = static_cast<long long>(options.max_flips_per_edge * (nh / 2));
  if (max_flips > 0) {
    // Stack of edges (by their smaller halfedge) that may be non-Delaunay.
    std::vector<int> stack;
    std::vector<char> queued(nh, 0);
    stack.reserve(nh / 2);
    for (int h = nh - 1; h >= 0; --h)
      if (h < he.twin[h]) {
        stack.push_back(h);
        queued[h] = 1;
      }
    std::vector<int> degree(mesh.num_vertices(), 0);
    for (int h = 0; h < nh; ++h) ++degree[he.vert[h]];
    long long flips = 0;
    while (!stack.empty() && flips < max_flips) {
      const int h = stack.back();
      stack.pop_back();
      queued[h] = 0;
      if (he.cotan_sum(h) >= -options.tolerance) continue;
      const int t = he.twin[h];
      const int k = he.vert[he.next[he.next[h]]], l = he.vert[he.next[he.next[t]]];
      // Counted below if still non-Delaunay: no loop edges, and no vertex of degree 2 (whose
      // value would be the average of two neighbours, often tied with one of them).
      const int i = he.vert[h], j = he.vert[t];
      if (k == l || degree[i] <= 3 || degree[j] <= 3) continue;
      const double new_length = flipped_length(he, h);
      if (!(new_length > 0) || !std::isfinite(new_length)) continue;
      const int outer[4] = {he.next[h], he.next[he.next[h]], he.next[t], he.next[he.next[t]]};
      flip(he, h, new_length);
      --degree[i];
      --degree[j];
      ++degree[k];
      ++degree[l];
      ++flips;
      for (int g : outer) {
        const int rep = std::min(g, he.twin[g]);
        if (!queued[rep]) {
          queued[rep] = 1;
          stack.push_back(rep);
        }
      }
    }
    result.flips = static_cast<int>(flips);
  }

  result.min_cotan_sum = std::numeric_limits<double>::infinity();
  for (int h = 0; h < nh; ++h) {
    if (h > he.twin[h]) continue;
    const double s = he.cotan_sum(h);
    result.min_cotan_sum = std::min(result.min_cotan_sum, s);
    if (max_flips > 0 && s < -options.tolerance) ++result.non_delaunay_edges;
  }

  // Faces in the order of face_halfedge; the face ids of halfedges are kept from the flips.
  result.F.resize(nf, 3);
  result.adjacent.resize(nf, 3);
  result.adjacent_edge.resize(nf, 3);
  result.length.resize(nf, 3);
  std::vector<int> slot(nh);  // position of each halfedge inside its face
  for (int f = 0; f < nf; ++f) {
    int h = he.face_halfedge[f];
    for (int i = 0; i < 3; ++i, h = he.next[h]) slot[h] = i;
  }
  for (int f = 0; f < nf; ++f) {
    int h = he.face_halfedge[f];
    for (int i = 0; i < 3; ++i, h = he.next[h]) {
      result.F(f, i) = he.vert[h];
      result.length(f, i) = he.length[h];
      result.adjacent(f, i) = he.face[he.twin[h]];
      result.adjacent_edge(f, i) = slot[he.twin[h]];
    }
  }
  return result;
}

}  // namespace polycube
