#include "polycube/intrinsic_delaunay.h"

#include "polycube/errors.h"
#include "polycube/ricci_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace polycube {

// The flips are ricci::make_delaunay's on the Δ-complex of ricci_mesh.h, at scale factors 0 (the
// input's Euclidean lengths), with the vertex links kept simple for PL Morse theory.
IntrinsicTriangulation intrinsic_delaunay(const TriMesh& mesh, const IntrinsicDelaunayOptions& options) {
  ricci::RicciMesh he = ricci::build_ricci_mesh(mesh, 0, "intrinsic_delaunay");
  const int nh = he.num_halfedges();
  const int nf = he.num_faces();
  for (int h = 0; h < nh; ++h)
    if (he.twin[h] < 0)
      throw MeshError("intrinsic_delaunay: edge (" + std::to_string(he.vert[h]) + ", " + std::to_string(he.head(h)) +
                      ") has 1 face, expected 2 (closed 2-manifold mesh required)");
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(mesh.num_vertices());
  IntrinsicTriangulation result;

  const long long max_flips = static_cast<long long>(options.max_flips_per_edge * (nh / 2));
  if (max_flips > 0) {
    ricci::FlipRules rules;
    rules.euclidean = true;
    rules.tolerance = options.tolerance;
    rules.max_flips = max_flips;
    rules.keep_links_simple = true;
    result.flips = static_cast<int>(ricci::make_delaunay(he, u, rules));
  }

  result.min_cotan_sum = std::numeric_limits<double>::infinity();
  for (int h = 0; h < nh; ++h) {
    if (h > he.twin[h]) continue;
    const double s = ricci::cotan_sum(he, h, u);
    result.min_cotan_sum = std::min(result.min_cotan_sum, s);
    if (max_flips > 0 && s < -options.tolerance) ++result.non_delaunay_edges;
  }

  // Faces in the order of face_halfedge; the face ids of halfedges are kept by the flips.
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
      result.length(f, i) = std::exp(he.lambda[h]);
      result.adjacent(f, i) = he.face[he.twin[h]];
      result.adjacent_edge(f, i) = slot[he.twin[h]];
    }
  }
  return result;
}

}  // namespace polycube
