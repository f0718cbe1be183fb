// Internal to flat_metric / circle_domain / intrinsic_delaunay: a triangulated surface with boundary as a Δ-complex
// (halfedges with explicit next pointers, so intrinsic flips can join two vertices by several
// edges), carrying a discrete conformal metric in the form of Gillespie–Springborn–Crane,
// "Discrete conformal equivalence of polyhedral surfaces" (2021): every edge e = ij stores a base
// log-length lambda_e (a Penner coordinate), and the metric at the vertex scale factors u is
//   l_ij = exp(lambda_ij + (u_i + u_j) / 2).
// Flips use Ptolemy's relation on these lengths, which keeps the discrete conformal class, so the
// energy of flat_metric is C^1 and convex in u when the triangulation is kept Delaunay.
// Not a public header: only polycube/*.cpp include it.
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

#include <vector>

namespace polycube::ricci {

// Lobachevsky's function L(x) = -integral_0^x log|2 sin t| dt (pi-periodic, odd, L(0) = L(pi/2) =
// L(pi) = 0), accurate to about 1e-16 absolute.
double lobachevsky(double x);

// Angles and cotangents of a triangle given by the logarithms of its edge lengths.
//   x[i]        log-length of edge i
//   opposite[i] angle opposite edge i
//   cot[i]      cotangent of that angle; 0 for a degenerate triangle
// A triangle violating the triangle inequality is extended as in Bobenko–Pinkall–Springborn: the
// angle opposite the too-long edge is pi, the other two 0. Returns false in that case.
bool triangle_angles(const double x[3], double opposite[3], double cot[3]);

// A boundary loop's polygon inscribed in a circle (the discrete "constant geodesic curvature"):
// given the log-lengths x_e of its edges, rho = log R of the circumcircle with the same edge
// lengths and the half central angles phi_e (sum phi_e = pi, l_e = 2 R sin phi_e). The centre may
// lie outside the polygon when one edge is longer than a diameter would allow otherwise; then
// that edge has phi_e > pi/2. Returns false when no such polygon exists (the longest edge is at
// least as long as all others together).
bool cyclic_polygon(const std::vector<double>& x, double& rho, std::vector<double>& phi);

// The Δ-complex. Halfedge h runs from vert[h] to vert[next[h]] inside face[h]; twin[h] is the
// opposite halfedge, or -1 on the boundary. lambda[h] is the base log-length of its edge (equal
// on both halves).
struct RicciMesh {
  std::vector<int> next, twin, vert, face;
  std::vector<double> lambda;
  std::vector<int> face_halfedge;
  int num_vertices = 0;
  std::vector<char> boundary_vertex;
  long long flips = 0;
  long long connectivity_version = 0;  // incremented on every flip

  int num_faces() const { return static_cast<int>(face_halfedge.size()); }
  int num_halfedges() const { return static_cast<int>(next.size()); }
  int head(int h) const { return vert[next[h]]; }
  // log-length of the edge of h at scale factors u
  double log_length(int h, const Eigen::VectorXd& u) const {
    return lambda[h] + 0.5 * (u[vert[h]] + u[vert[next[h]]]);
  }
};

// Halfedges of an oriented, edge-manifold triangle mesh with boundary; lambda = log of the
// Euclidean edge lengths minus log_scale (so the lengths are in units of exp(log_scale)).
// Throws MeshError (its message starting with `caller`) for an edge with more than two faces, two
// faces traversing an edge in the same direction, a face repeating a vertex, or an edge of zero or
// non-finite length.
RicciMesh build_ricci_mesh(const TriMesh& mesh, double log_scale, const char* caller = "flat_metric");

// How make_delaunay flips.
//   euclidean          the new edge gets the length of the other diagonal of the two triangles
//                      laid out in the plane (the metric is kept: intrinsic Delaunay
//                      triangulation); otherwise Ptolemy's relation l_kl = (l_ik l_jl + l_il l_jk)
//                      / l_ij (the conformal class is kept)
//   tolerance          an edge is Delaunay when cos(alpha) + cos(beta) >= -tolerance
//   max_flips          stop after this many flips (then some edges may stay non-Delaunay)
//   keep_links_simple  never flip to an edge from a vertex to itself, nor leave a vertex with
//                      fewer than three edges (PL Morse theory needs every vertex link to be a
//                      cycle of at least three other vertices); for closed meshes
struct FlipRules {
  bool euclidean = true;
  double tolerance = 0;
  long long max_flips = 0;
  bool keep_links_simple = false;
};

// Flips interior edges until every one is Delaunay at the scale factors u:
// cos(alpha) + cos(beta) >= -tolerance for the angles alpha, beta opposite it (meaningful for
// lengths violating the triangle inequality, too). Edges whose two sides are the same face are
// never flipped. Returns the number of flips.
long long make_delaunay(RicciMesh& mesh, const Eigen::VectorXd& u, const FlipRules& rules);

// Splits the edge of h at its midpoint in the metric at u: a new vertex m (id num_vertices - 1
// afterwards, u extended by u_m = (u_a + u_b) / 2) joined to the vertex opposite the edge in each
// of its faces, the new edges' lengths from Apollonius' theorem in those (valid) triangles. On a
// boundary edge h: a->b becomes h: a->m and the returned halfedge m->b (both boundary); on an
// interior edge likewise on both sides. Returns -1 (and changes nothing) if a face of the edge
// violates the triangle inequality or both sides are the same face.
int split_edge(RicciMesh& mesh, int h, Eigen::VectorXd& u);

// Number of interior edges with cos(alpha) + cos(beta) < -tolerance at u.
int count_non_delaunay(const RicciMesh& mesh, const Eigen::VectorXd& u, double tolerance);

// cot(alpha) + cot(beta) of the interior edge of h at u (alpha, beta opposite it; a degenerate
// triangle contributes 0): the edge's cotangent Laplacian weight, times 2.
double cotan_sum(const RicciMesh& mesh, int h, const Eigen::VectorXd& u);

}  // namespace polycube::ricci
