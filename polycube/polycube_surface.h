// The polycube surface P of §3.2 as a triangle mesh: each Q_i extruded from the middle below its
// plane to the middle above it (the model's lowest / highest point at the ends), joined by the
// horizontal faces Q_{i-1} Δ Q_i (the paper's CSG), merged into maximal planar faces and
// triangulated without T-junctions.
#pragma once

#include "polycube/contour_sections.h"
#include "polycube/mesh.h"
#include "polycube/quadtree_section.h"

#include <Eigen/Core>

#include <vector>

namespace polycube {

// A maximal planar face of the polycube.
//   axis        0, 1, 2 for x, y, z: the face lies in a plane of constant coordinate `axis`
//   sign        +1 / -1: the outward normal is sign * e_axis
//   coordinate  of that plane, input frame
//   area        input units
struct PolycubeFace {
  int axis = 0;
  int sign = 1;
  double coordinate = 0;
  double area = 0;
};

// A polycube edge: a straight segment between two polycube vertices along which two faces meet.
//   vertices  mesh vertices along it, from one end to the other (ends are polycube vertices)
//   axis      direction 0, 1, 2
//   faces     the two polycube faces on its sides
struct PolycubeEdge {
  std::vector<int> vertices;
  int axis = 0;
  int faces[2] = {-1, -1};
};

// One boundary loop of Q_i: corners in input xy, the region of Q_i on the left (outer loops
// counter-clockwise, holes clockwise), and the model contour (CrossSections id) it stands for.
struct SectionPolygon {
  std::vector<Eigen::Vector2d> points;
  int contour = -1;
};

// The polycube, in the input's coordinate frame.
//   mesh        closed, outward-oriented triangle mesh; every triangle lies in one polycube face
//   face_axis   per triangle: +-1, +-2, +-3 for a normal along +-x, +-y, +-z
//   face_patch  per triangle: its polycube face (index into faces)
//   faces       maximal planar faces
//   edges       polycube edges (each between two faces, split at every polycube vertex)
//   vertices    mesh vertices that are polycube vertices (where edges end), ascending
//   corners     those where edges of all three axis directions meet, ascending
//   sections    per plane: the loops of Q_i
//   levels      heights of the horizontal levels: the model's bottom, the midpoints between
//               consecutive planes, the model's top
//   spacing     largest distance between consecutive mesh vertices along polycube edges (the
//               interior lattice spacing h of the faces)
struct Polycube {
  TriMesh mesh;
  Eigen::VectorXi face_axis;
  Eigen::VectorXi face_patch;
  std::vector<PolycubeFace> faces;
  std::vector<PolycubeEdge> edges;
  std::vector<int> vertices;
  std::vector<int> corners;
  std::vector<std::vector<SectionPolygon>> sections;
  std::vector<double> levels;
  double spacing = 0;
};

struct PolycubeSurfaceOptions {
  // About how many mesh vertices to make (>= 1): fixes the spacing h of the boundary and interior
  // points. Vertices at polycube corners and on short edges come on top.
  int target_vertices = 10000;
  // Heights (input frame) no mesh vertex may have: the cutting planes, so that slicing P by them
  // meets no vertex.
  std::vector<double> avoid_z;
};

// Builds P from the quadtrees of all planes (leaves[i] approximates sections.planes[i]), the
// model's lowest and highest z. Faces are the 4-connected components of equal orientation on
// each axis-aligned plane; every polycube edge is split into equal parts of length <= h shared by
// its two faces; each face is triangulated by a constrained Delaunay triangulation of those
// boundary points and a square lattice of spacing h inside it (kept h/2 away from the boundary),
// so there are no T-junctions. Throws AlgorithmError if the stacked quadtrees do not bound a
// closed oriented surface (each edge must border exactly two faces, in opposite directions) —
// which the slab checks exclude beforehand.
Polycube build_polycube_surface(const CrossSections& sections, const std::vector<std::vector<QuadLeaf>>& leaves,
                                double z_min, double z_max, const PolycubeSurfaceOptions& options = {});

}  // namespace polycube
