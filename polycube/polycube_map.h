// Stage 4 of the method (§3.4): the bijection φ: P → M, built piece by piece and glued along the
// cutting contours, and its inverse φ⁻¹: M → P.
//
// Per contour (once, shared by the two pieces that meet there): the boundary map ψ between the
// model's contour and P's polygon on the same plane (eq. 6: arc length with the offset that
// minimises the squared distance), pinned at the slit ends so that both pieces use it exactly.
// Per matched piece pair (M_j, P_j): slits join the loops into one boundary (the shortest paths
// of the circle domain's flat metric on M_j, the same loops joined in the same order on P_j),
// both cut pieces become disks whose boundaries are mapped to the unit circle by the same
// parameter (ψ on the loops, arc length on the slits), with every boundary point of either side
// present on both, and both are embedded by a harmonic map with positive weights (Tutte /
// Floater: an embedding on a convex boundary). φ on the piece is then
// (disk map of M_j)⁻¹ ∘ (disk map of P_j), evaluated by point location in the disks.
#pragma once

#include "polycube/mesh.h"
#include "polycube/polycube_build.h"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace polycube {

// A point on a triangle mesh: a face and barycentric coordinates (summing to 1) in it.
struct SurfacePoint {
  int face = -1;
  Eigen::Vector3d bary = Eigen::Vector3d::Zero();
};

// Position of a surface point.
Eigen::Vector3d surface_position(const TriMesh& mesh, const SurfacePoint& point);

struct PolycubeMapOptions {
  // Worker threads over pieces; 0: one per hardware thread.
  int threads = 0;
};

// Per matched piece pair.
//   model_piece, polycube_piece  indices into PolycubeResult::model_sliced / polycube_sliced
//   loops, slits                  boundary loops, slits cut to make a disk (loops - 1)
//   disk_boundary                 vertices on the common unit-circle polygon
//   model_disk_vertices, polycube_disk_vertices  vertices of the cut disks
//   flipped_model_disk, flipped_polycube_disk    triangles of the disk embeddings with signed
//                                 area <= 0 (0 by Floater's theorem up to rounding)
//   seconds                       wall time of this piece
struct PieceMapStats {
  int model_piece = -1;
  int polycube_piece = -1;
  int loops = 0;
  int slits = 0;
  int disk_boundary = 0;
  int model_disk_vertices = 0;
  int polycube_disk_vertices = 0;
  int flipped_model_disk = 0;
  int flipped_polycube_disk = 0;
  double min_disk_area = 0;  // smallest triangle area in either disk, unit-disk units
  int ricci_iterations = 0;  // Newton iterations of the model piece's flat metric (0: one loop, not needed)
  double ricci_residual = 0; // its max |curvature error|
  bool flat_slits = false;   // slits chosen in the circle domain (false: by 3D length, the metric failed)
  // Crowding of the model's disk (piece_disk.h, decrowd_disk): the smallest ratio, over its faces,
  // of the share of P_j's area a face's image covers to its share of M_j's area, before and after
  // the re-weighting, and the re-weighting's iterations (0: not needed).
  double min_area_ratio_before = 1;
  double min_area_ratio = 1;
  int decrowd_iterations = 0;
  double seconds = 0;
};

class PolycubeMapData;  // internal: per piece disks and point locators

// The map, evaluated at the vertices of both meshes, and evaluable anywhere.
//   polycube_on_model   per vertex of Polycube::mesh: φ(v) as a point of the model (faces of the
//                       model mesh given to build_polycube_map)
//   model_on_polycube   per vertex of the model: φ⁻¹(v) as a point of Polycube::mesh
//   polycube_on_model_xyz, model_on_polycube_xyz  the same as positions
//   pieces              per matched piece pair
//   contours            how many contour correspondences ψ were built
//   seconds             wall time
struct PolycubeMap {
  std::vector<SurfacePoint> polycube_on_model;
  std::vector<SurfacePoint> model_on_polycube;
  Eigen::MatrixX3d polycube_on_model_xyz;
  Eigen::MatrixX3d model_on_polycube_xyz;
  std::vector<PieceMapStats> pieces;
  int contours = 0;
  double seconds = 0;

  // φ at any point of P (a face of Polycube::mesh), as a point of the model.
  SurfacePoint to_model(const SurfacePoint& on_polycube) const;
  // φ⁻¹ at any point of the model, as a point of Polycube::mesh.
  SurfacePoint to_polycube(const SurfacePoint& on_model) const;

  std::shared_ptr<const PolycubeMapData> data;
};

// Builds φ and φ⁻¹.
//   model     the mesh build_polycube was given (the validated input)
//   polycube  its result
// Throws AlgorithmError when a piece cannot be cut into a disk or its disks are not embedded.
PolycubeMap build_polycube_map(const TriMesh& model, const PolycubeResult& polycube, const PolycubeMapOptions& options = {});

}  // namespace polycube
