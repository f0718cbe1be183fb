// Cross-sections of the sliced model on its cutting planes (§3.2, Fig. 3b–c): every contour as a
// closed polygon in the normalised xy frame, with its nesting (outer contours and holes), and the
// faces of the arrangement of each plane's contours that the quadtree labels cells with.
#pragma once

#include "polycube/slice.h"

#include <Eigen/Core>

#include <vector>

namespace polycube {

// Maps input coordinates to the normalised unit cube and back: p_normalised = (p - origin) / scale.
struct NormalisedFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // minimum corner of the bounding box
  double scale = 1;                                  // largest side of the bounding box
};

// One closed contour of the model on one plane.
//   plane     index into SlicedMesh::planes
//   local     index among the contours of its plane (PlaneSection::contours)
//   vertices  vertices of SlicedMesh::mesh in order
//   points    their normalised xy, ordered so that the inside of the model is on the left: outer
//             contours counter-clockwise, holes clockwise
//   area      signed area (normalised units): positive for outer contours, negative for holes
//   parent    local index of the innermost contour around it on the same plane, -1 if none
//   depth     number of contours around it (even for outer contours, odd for holes)
struct SectionContour {
  int plane = -1;
  int local = -1;
  std::vector<int> vertices;
  std::vector<Eigen::Vector2d> points;
  double area = 0;
  int parent = -1;
  int depth = 0;
};

// The contours of one plane and the faces of their arrangement: face 0 is the unbounded outside,
// face k + 1 the area just inside local contour k (and outside the contours nested in it). A face
// is solid (a region of the cross-section) iff its contour is an outer contour; the other faces
// are the outside and the holes.
//   z            plane height in input coordinates
//   contours     global contour ids (into CrossSections::contours) by local index
//   face_solid   per face
//   face_parent  per face: the face on the other side of its contour (-1 for face 0)
//   face_area    per face: its area in normalised units (face 0: 0)
struct PlaneSection {
  double z = 0;
  std::vector<int> contours;
  std::vector<char> face_solid;
  std::vector<int> face_parent;
  std::vector<double> face_area;

  int num_faces() const { return static_cast<int>(face_solid.size()); }
  // Local index of the contour separating faces a and b, -1 if no contour does.
  int contour_between(int a, int b) const {
    if (a == b || a < 0 || b < 0) return -1;
    if (face_parent[a] == b) return a - 1;
    if (face_parent[b] == a) return b - 1;
    return -1;
  }
};

// All cross-sections of a sliced model.
//   frame           the normalisation used for points
//   contours        every contour, grouped by plane (ascending), then by local index
//   planes          per plane of SlicedMesh::planes
//   vertex_contour  per vertex of SlicedMesh::mesh: the contour it lies on, -1 off the planes
//   piece_contours  per piece: the contour of each of its boundary loops, in loop order
struct CrossSections {
  NormalisedFrame frame;
  std::vector<SectionContour> contours;
  std::vector<PlaneSection> planes;
  std::vector<int> vertex_contour;
  std::vector<std::vector<int>> piece_contours;
};

// Extracts the contours (each is a loop of the piece below its plane and of the piece above it)
// and their nesting, by point-in-polygon tests between the contours of a plane.
// Throws AlgorithmError when the loops are inconsistent with a closed embedded surface (a loop
// seen from only one side, a plane of negative total area, an outer contour directly inside an
// outer contour — signs of a self-intersecting surface).
CrossSections cross_sections(const SlicedMesh& sliced, const NormalisedFrame& frame);

// Pairs of contour segments of one plane that cross (a contour crossing another or itself): a
// self-intersecting surface cut where it intersects itself. No axis-aligned approximation of
// such a section has its topology (regions overlap), so no refinement can repair it.
//   where  if given and the count is positive: a crossing point, in the normalised frame
int count_contour_crossings(const CrossSections& sections, int plane, Eigen::Vector2d* where = nullptr);

}  // namespace polycube
