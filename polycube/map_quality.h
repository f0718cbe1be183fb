// Distortion of a piecewise-linear map between two triangulations with the same connectivity: the
// paper's angle (eq. 9) and area (eq. 10) distortion (He et al.; the definitions of the project's
// quality measures). Independent of how the map was built: it sees only the domain mesh and its
// vertices' images.
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

namespace polycube {

// Per map, over the triangles where neither the domain triangle T nor its image T' is degenerate.
//   eps_angle  Σ A(T')·ε_angle(T) / Σ A(T'), with ε_angle(T) = (σ1² + σ2²) / (2 σ1 σ2) (eq. 9)
//   eps_area   Σ A(T')·ε_area(T) / Σ A(T'), with ε_area(T) = ½ (A(T)/A(T') + A(T')/A(T)) (eq. 10)
//              where A(T), A(T') are normalised: both meshes scaled to total area 1
//   angle_*, area_*  median, 95th percentile and maximum of the per-triangle values, unweighted
//              (nearest rank: the value at sorted position ceil(p·n) - 1)
//   degenerate_domain  triangles with A(T) <= 1e-14 × total domain area
//   degenerate_image   triangles with A(T') <= 1e-14 × total image area, or a non-finite image
//                      vertex (a triangle may count in both); skipped from every sum
//   triangles  #F of the domain
// All values are >= 1, and 1 for a similarity. When every triangle is degenerate, the distortion
// fields are +infinity (nothing was measured: no map deserves a perfect score for it).
struct DistortionStats {
  double eps_angle = 1, eps_area = 1;
  double angle_p50 = 1, angle_p95 = 1, angle_max = 1;
  double area_p50 = 1, area_p95 = 1, area_max = 1;
  int degenerate_domain = 0, degenerate_image = 0;
  int triangles = 0;
};

// Distortion of the map T → T' that is linear on each triangle.
//   domain  the triangulation the map starts from (T; e.g. the polycube P), #F >= 1, finite V
//   image   #V(domain) by 3 positions of its vertices' images (T'; e.g. on the model M), same
//           connectivity
// σ1 ≥ σ2 are the singular values of the linear map T → T'; ε_angle is computed in the cotangent
// form (cot α·a'² + cot β·b'² + cot γ·c'²) / (4 A(T')) with α, β, γ the angles of T and a', b', c'
// the image edge lengths opposite them (= ||J||²_F / (2 det J), no SVD). A(T') is unsigned: an
// inverted image triangle is not detected here (see audit_map).
// Throws std::invalid_argument for a domain without faces, bad face indices, non-finite domain
// vertices, zero domain area, or an image with the wrong number of rows.
DistortionStats map_distortion(const TriMesh& domain, const Eigen::MatrixX3d& image);

// ε_angle of one triangle (p0, p1, p2) → (q0, q1, q2), in the cotangent form above; +infinity
// when either triangle has zero area.
double triangle_angle_distortion(const Eigen::Vector3d p[3], const Eigen::Vector3d q[3]);

}  // namespace polycube
