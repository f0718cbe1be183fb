// Internal to the map (not for applications): what build_polycube_map keeps per piece pair to
// evaluate φ and φ⁻¹ anywhere (PolycubeMap::to_model / to_polycube) and to overlay the two disk
// triangulations (map_overlay.h).
#pragma once

#include "polycube/disk_locator.h"
#include "polycube/piece_disk.h"
#include "polycube/piece_mesh.h"
#include "polycube/polycube_map.h"

#include <Eigen/Core>

#include <memory>
#include <utility>
#include <vector>

namespace polycube {

// One side (model or polycube) of a piece pair.
struct SideDisk {
  PieceMesh piece;
  TriMesh work;                            // the piece, its inner edges split if slits needed room
  std::vector<int> work_face_parent;       // per work face: the piece face it lies in
  std::vector<int> loop_contour;          // per loop: the contour (CrossSections id)
  std::vector<Slit> slits;
  DiskEmbedding disk;
  std::unique_ptr<DiskLocator> locator;
  std::vector<int> vertex_copy;            // per piece vertex: a disk vertex copying it
  std::vector<std::vector<int>> faces_of;  // per piece face: the disk faces inside it
};

struct PiecePair {
  SideDisk model, polycube;
};

class PolycubeMapData {
 public:
  TriMesh model;
  TriMesh polycube;
  int polycube_sliced_vertices = 0;  // vertices of P's sliced mesh (P's own come first, same ids)
  Eigen::VectorXi model_face_origin, polycube_face_origin;   // sliced face -> input face
  std::vector<PiecePair> pairs;
  std::vector<std::pair<int, int>> model_face_local, polycube_face_local;  // sliced face -> (pair, local face)
  std::vector<std::vector<int>> model_sliced_faces_of, polycube_sliced_faces_of;  // input face -> sliced faces

  // Maps a point of `from` (sliced face + 3D position) through its pair's disks to `to`.
  SurfacePoint carry(bool from_polycube, int input_face, const Eigen::Vector3d& x) const;
};

}  // namespace polycube
