// Exact slicing of a closed mesh by horizontal planes into the pieces M_i of §3 step (iii):
// the parts of the surface between consecutive planes, each a list of triangles of a refined
// mesh whose boundary loops lie exactly on the planes.
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

#include <vector>

namespace polycube {

// One connected part of the surface between two consecutive planes.
//   faces           faces of SlicedMesh::mesh, ascending
//   boundary_loops  closed contours as vertex cycles of SlicedMesh::mesh, oriented like the
//                   piece's faces (the piece is on the left); each lies on one plane
//   loop_plane      per loop, the index (into SlicedMesh::planes) of its plane: always
//                   plane_below or plane_above
//   plane_below, plane_above  the planes bounding the slab of the piece; -1 below the first /
//                   above the last plane
//   euler           V - E + F of the piece
//   genus           (2 - euler - #loops) / 2
struct Piece {
  std::vector<int> faces;
  std::vector<std::vector<int>> boundary_loops;
  std::vector<int> loop_plane;
  int plane_below = -1;
  int plane_above = -1;
  int euler = 0;
  int genus = 0;
};

// The refined mesh and its pieces.
//   mesh          the input with every face crossed by a plane split along it: the input
//                 vertices first (unchanged, same ids), then the vertices created on planes
//                 (z exactly the plane height), ascending by crossed edge
//   face_origin   #F(mesh): the input face each refined face lies in
//   face_piece    #F(mesh): the piece of each face
//   pieces        ordered by slab (bottom up), then by first face
//   planes        the planes used: the requested ones sorted, duplicates and planes outside
//                 the open z range of the mesh dropped, planes at a vertex height moved off it
//   nudged_planes how many planes were at a vertex height and were moved
struct SlicedMesh {
  TriMesh mesh;
  Eigen::VectorXi face_origin;
  Eigen::VectorXi face_piece;
  std::vector<Piece> pieces;
  std::vector<double> planes;
  int input_vertices = 0;
  int nudged_planes = 0;
};

// Cuts the mesh along the planes z = planes_z[k]. Each crossed edge gets one new vertex per
// plane, shared by both its faces, at the exact plane height; each face is split into the convex
// polygons between consecutive planes, each triangulated by the fan with the best worst
// triangle, so no triangle straddles a plane and none is degenerate. Planes at or outside the
// lowest and highest vertex are dropped; a plane at a vertex height (within 1e-9 of the mesh
// height) is moved, by at most a quarter of the distance to its neighbouring planes, to the
// height farthest from any vertex (place_plane), so contours never pass through or next to a
// vertex and every piece boundary is a set of disjoint simple loops. Pieces are the connected components of faces in the same slab, joined
// across edges.
//   mesh      closed, edge-manifold, consistently oriented triangle mesh
//   planes_z  heights in the coordinates of mesh, any order
// Throws MeshError if an edge of the mesh does not have exactly two faces.
SlicedMesh slice_mesh(const TriMesh& mesh, const std::vector<double>& planes_z);

}  // namespace polycube
