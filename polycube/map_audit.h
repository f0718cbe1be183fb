// An outside audit of a claimed bijection φ: P → M between a polycube and a model, judged only
// from the two meshes and the images of their vertices (never from how the map was built): do the
// images lie on the other surface, cover it once (area), keep their orientation (no flipped
// triangles), and how much do they distort (eq. 9, 10).
#pragma once

#include "polycube/map_quality.h"
#include "polycube/mesh.h"

#include <Eigen/Core>

namespace polycube {

// Image triangles with an area at or below this fraction of the target's area are degenerate.
inline constexpr double kAuditDegenerateArea = 1e-14;

struct MapAuditOptions {
  // Largest accepted distance of an image vertex from the target surface, × the target's
  // bounding-box diagonal.
  double surface_tolerance = 1e-3;
  // Largest accepted |image area / target area - 1|. Image triangles are chords of the target, so
  // a correct map has a ratio below 1: slightly on a curved model, and markedly for a coarse model
  // on P, where each chord across a 90° edge loses (2 - √2)·w·L of P's area (w: how far its
  // corners are from the edge, L: its length along it).
  double area_tolerance = 0.02;
  // Threads for the closest faces and the verdicts (0: one per hardware thread); the audit does
  // not depend on it.
  int threads = 0;
};

// One direction of the map: the triangles of a source mesh, placed at their vertices' images,
// against the target surface they should tile.
//   triangles     #F of the source
//   flipped       non-degenerate image triangles whose normal has a non-positive dot product with
//                 the target's outward normal nearby: the area-weighted sum of the normals of the
//                 distinct target faces closest to the image triangle's centroid and to its three
//                 vertices (several faces, so that a chord across a polycube edge, whose normal
//                 lies between the two face normals, is not called flipped) and, on a second look
//                 at a triangle that fails the first, of those closest to 15 points spread over it
//                 (a chord from one face of a thin part to the opposite one; image_orientation.h).
//                 Where faces tie for closest (a point on an edge or a vertex of the target) all
//                 of them count, so the verdict does not depend on the frame the meshes are in
//   degenerate    image triangles with area <= 1e-14 × target area, or with a non-finite vertex
//   max_distance  largest distance of an image vertex from the target surface, / target bounding-box
//                 diagonal (+infinity for a non-finite vertex)
//   area_ratio    total area of the finite image triangles / target surface area (≈ 1 when the
//                 image covers the target exactly once)
//   ok            flipped == 0 && degenerate == 0 && max_distance <= surface_tolerance &&
//                 |area_ratio - 1| <= area_tolerance
struct MapDirectionAudit {
  int triangles = 0;
  int flipped = 0;
  int degenerate = 0;
  double max_distance = 0;
  double area_ratio = 0;
  bool ok = false;
};

// Both directions and the distortion.
//   polycube_to_model  P's triangles at polycube_on_model against M
//   model_to_polycube  M's triangles at model_on_polycube against P
//   distortion         map_distortion(polycube, polycube_on_model): T on P, T' on M
//   ok                 both directions ok (distortion is reported, not judged)
struct MapAudit {
  MapDirectionAudit polycube_to_model, model_to_polycube;
  DistortionStats distortion;
  bool ok = false;
};

// Audits one direction.
//   source  the triangulation being mapped (its connectivity; its positions are not used)
//   image   #V(source) by 3 positions of the images of its vertices
//   target  the closed, outward-oriented surface the images should lie on
// Throws std::invalid_argument for a source or target without faces, bad face indices,
// non-finite target vertices, a target of zero area, an image with the wrong number of rows or
// negative / non-finite tolerances.
MapDirectionAudit audit_map_direction(const TriMesh& source, const Eigen::MatrixX3d& image, const TriMesh& target,
                                      const MapAuditOptions& options = {});

// Audits a map between the model M and its polycube P from the images of both meshes' vertices.
//   model              M (closed, outward-oriented)
//   polycube           P's triangle mesh (closed, outward-oriented)
//   polycube_on_model  #V(P) by 3 images of P's vertices on M
//   model_on_polycube  #V(M) by 3 images of M's vertices on P
// Throws std::invalid_argument as audit_map_direction and map_distortion do.
MapAudit audit_map(const TriMesh& model, const TriMesh& polycube, const Eigen::MatrixX3d& polycube_on_model,
                   const Eigen::MatrixX3d& model_on_polycube, const MapAuditOptions& options = {});

}  // namespace polycube
