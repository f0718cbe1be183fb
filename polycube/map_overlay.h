// The map φ: P → M made exact on a triangulation (issue 5): the common refinement of the two
// disk triangulations of every piece pair.
//
// Per piece pair, φ is (disk map of M_j)⁻¹ ∘ (disk map of P_j) (polycube_map.h): both disk maps
// are embeddings onto the same convex polygon, so φ is affine on every cell of the overlay of
// the two disk triangulations (each cell is the intersection of one P_j disk triangle and one
// M_j disk triangle, a convex polygon). Triangulating every cell and carrying its corners to
// both surfaces gives a triangulation of P on which the sampled map IS φ: every image triangle
// lies in one face of M with the orientation of that face (both disk triangles are positively
// oriented), and the images tile M exactly (the cells tile M_j's disk). Sampling φ at P's own
// vertices only (PolycubeMap::polycube_on_model_xyz) loses both where φ bends inside a triangle
// of P — at M's edges and at the preimages of M's vertices, where φ behaves like z^α.
//
// The pieces' overlays are glued into one closed mesh: vertices of P's sliced mesh by their ids,
// points of the disks' common boundary (contours and slits, both of whose sides carry the same
// points) by their position on P, everything inside a disk by what made it (a vertex of either
// disk, or a crossing of an edge of each).
#pragma once

#include "polycube/mesh.h"
#include "polycube/polycube_map.h"

#include <Eigen/Core>

#include <vector>

namespace polycube {

// The overlay.
//   polycube      P's surface triangulated by the cells: P's own vertices first with their ids
//                 (every vertex of Polycube::mesh is a vertex of a disk), the rest appended
//   face_parent   per face: the face of Polycube::mesh it lies in
//   face_image    per face: the face of the model its image lies in
//   on_model      per vertex: φ(v) as a point of the model (a face and barycentric coordinates)
//   on_model_xyz  the same as positions
//   cells         convex cells made (each triangulated by a fan)
//   zero_area_cells  cells of zero area in the disk (a corner of one disk exactly on an edge of
//                 the other), triangulated all the same: their neighbours share their corners
//   collapsed     edges collapsed to remove cells too small for the audit (image or P area at
//                 or below 1e-12 of the total): the shorter end merged into the other where the
//                 mesh stays manifold and every moved triangle keeps its plane and model face,
//                 those not tiny their orientation (tiny ones may turn by at most the audit's
//                 degenerate area: they are removed in turn)
//   flipped_edges edges flipped to remove the tiny cells no collapse could: both faces in one face
//                 of P and one of the model, both new triangles positive and not tiny on both
//   uncovered_faces  P disk triangles whose cells do not sum to their area (to 1e-9): 0 unless
//                 the walk over M's disk triangles missed some (a defect; the tests assert 0)
struct MapOverlay {
  TriMesh polycube;
  Eigen::VectorXi face_parent;
  Eigen::VectorXi face_image;
  std::vector<SurfacePoint> on_model;
  Eigen::MatrixX3d on_model_xyz;
  long long cells = 0;
  long long zero_area_cells = 0;
  long long uncovered_faces = 0;
  int collapsed = 0;
  int flipped_edges = 0;
  double seconds = 0;
};

// Builds the overlay of every piece pair of `map` and glues them. Throws AlgorithmError if the
// glued mesh is not closed (an edge without exactly two faces).
MapOverlay overlay_map(const PolycubeMap& map);

}  // namespace polycube
