// Catmull–Clark subdivision of polygon control meshes (OpenSubdiv, behind this wrapper): the
// T-spline application refines the polycube-derived control quad mesh into a smooth surface.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace polycube {

// A polygon mesh with faces of any size.
//   V      #V by 3 vertex positions
//   faces  vertex indices of each face, counter-clockwise seen from outside, >= 3 each
struct PolyMesh {
  Eigen::MatrixX3d V;
  std::vector<std::vector<int>> faces;

  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_faces() const { return static_cast<int>(faces.size()); }
};

// Uniform Catmull–Clark refinement of control, `levels` times (0..10), with boundary vertices
// interpolated along boundary edges and at corners (OpenSubdiv VTX_BOUNDARY_EDGE_AND_CORNER).
// Returns the refined mesh: after one level or more every face is a quad, face orientation
// follows the control faces. Positions are the refined control points of the last level, or,
// with limit_positions, those points pushed onto the limit surface (requires levels >= 1).
// levels = 0 returns control unchanged.
// Throws MeshError if there are no faces, a face has fewer than 3 vertices or an index outside
// 0..#V-1, or OpenSubdiv rejects the topology (with its message); std::invalid_argument for
// levels outside 0..10, or limit_positions with levels = 0.
PolyMesh subdivide_catmull_clark(const PolyMesh& control, int levels, bool limit_positions = false);

}  // namespace polycube
