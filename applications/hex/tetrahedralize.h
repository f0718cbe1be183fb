// Filling a closed surface with tetrahedra (TetGen, behind this wrapper): the volume mesh on
// which the hex-meshing application solves the volumetric harmonic map.
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

namespace polycube {

// A tetrahedral mesh.
//   V  #V by 3 vertex positions
//   T  #T by 4 vertex indices per tetrahedron, positively oriented:
//      (V(b)-V(a)) x (V(c)-V(a)) . (V(d)-V(a)) > 0 for T.row = (a, b, c, d)
struct TetMesh {
  Eigen::MatrixX3d V;
  Eigen::MatrixX4i T;

  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_tets() const { return static_cast<int>(T.rows()); }
};

struct TetrahedralizeOptions {
  double max_volume = 0;   // largest tetrahedron volume; 0: no limit. Only met by tets without a
                           // surface vertex: the surface is never split, so tets next to it may
                           // be larger
  double min_ratio = 1.5;  // bound on radius-edge ratio (quality refinement); 0: no refinement,
                           // otherwise >= 1 (TetGen may not terminate below about 1.1)
  bool quiet = true;       // false lets TetGen print its statistics to stdout
};

// Constrained Delaunay tetrahedralization of the solid bounded by surface, keeping the surface:
// no Steiner points are put on it, so the first #surface.V rows of the result are surface.V
// unchanged (interior Steiner points follow) and the boundary faces of the result are exactly
// surface.F.
//   surface  closed, outward-oriented, non-self-intersecting triangle mesh
// Throws MeshError if surface is empty, has out-of-range indices, non-finite coordinates, edges
// not shared by exactly two faces, zero-area faces or two vertices at one position;
// AlgorithmError if the surface intersects itself (found first by TetGen's detector, naming
// faces) or TetGen fails otherwise; std::invalid_argument for bad options.
// Caution: TetGen 1.5 crashes (double free) instead of throwing when it stops with an error, so
// the checks above run first; an input passing them that TetGen still rejects (e.g. features far
// below its tolerance) can end the process.
TetMesh tetrahedralize(const TriMesh& surface, const TetrahedralizeOptions& options = {});

}  // namespace polycube
