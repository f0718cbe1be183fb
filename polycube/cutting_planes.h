// The horizontal cutting planes of §3.2: one between every two consecutive levels of critical
// points, and more wherever two planes are farther apart than d_z.
#pragma once

#include "polycube/critical_points.h"
#include "polycube/mesh.h"

#include <Eigen/Core>

#include <vector>

namespace polycube {

struct CuttingPlaneOptions {
  // Largest distance between adjacent planes, in the units of the model scaled to the unit cube
  // (largest bounding-box side 1). §3.2's d_z.
  double dz = 0.08;
  // Critical points whose heights differ by at most this fraction of the model height belong to
  // one level (§3.2 uses 0.01).
  double level_merge = 0.01;
  // Also keep the gaps between the lowest (highest) vertex and the first (last) plane below dz.
  // §3.2 only subdivides between planes; true gives the end caps the same resolution.
  bool split_end_gaps = true;
  // Planes so that no slab is long against its sections: wherever the gap between two planes
  // (or between an end of the z range and its plane) exceeds girth_ratio times the longest
  // contour on the planes bounding it, the gap is split evenly into parts at most girth_spacing
  // times that length, up to girth_max_planes planes in all. Why: a piece's disk maps crowd
  // exponentially in its length over its girth, and P's piece, whose squares the quadtree keeps,
  // is not as thin as the model's: a rod of radius 0.001 and length 1 had pieces 13 times as long
  // as their contours at d_z 0.08, and its map folded thousands of triangles; at d_z 0.01 (1.6
  // times) it met the contract in 6 s. The longest contour, not the shortest: a thin part beside
  // a thick one (femur's canal, 1e-2 of the gap) would bring planes through the whole model,
  // which cost femur's orientation search 5 times its time for the same quads; where the whole
  // section is thin, planes are cheap. 0: never.
  double girth_ratio = 4;
  double girth_spacing = 1;
  int girth_max_planes = 1000;
  // The mesh is a copy whose x, y, z are a model's times these (map --equalise-axes scales a long
  // or flat model's axes towards equal spreads); the girth rule measures gaps and contours on that
  // model, whose map the copy's is taken back to: the planes pin the map level by level, and a
  // copy's slab that is short against its section can be long on the model.
  Eigen::Vector3d length_scales = Eigen::Vector3d::Ones();
};

// Planes in input coordinates and in normalised height (z - z_min) / (largest bounding-box side).
//   z, z_normalised   ascending, strictly inside the z range of the mesh
//   levels            distinct levels of critical points (including the lowest and highest vertex)
//   level_planes      planes between consecutive levels (levels - 1)
//   spacing_planes    planes added so that no gap exceeds dz
struct CuttingPlanes {
  std::vector<double> z;
  std::vector<double> z_normalised;
  int levels = 0;
  int level_planes = 0;
  int spacing_planes = 0;
  int girth_planes = 0;  // planes added for the girth rule (CuttingPlaneOptions::girth_ratio)
};

// Per plane (ascending heights), the length of its longest contour: the level set of z on the
// mesh (triangles crossing the height, joined across the edges they share). 0 for a plane that
// meets no triangle. Lengths are measured with the coordinates divided by scales (a scaled copy's
// contours measured on its model: CuttingPlaneOptions::length_scales).
std::vector<double> longest_contours(const TriMesh& mesh, const std::vector<double>& z,
                                     const Eigen::Vector3d& scales = Eigen::Vector3d::Ones());

// Sorts the critical points (minima, saddles, maxima) and the lowest and highest vertex by z and
// merges them into levels: sorted heights closer than level_merge * height join one level.
// Between consecutive levels goes one plane, at the middle of the gap between the top of the
// lower level and the bottom of the upper one (§3.2 takes the midpoint of representative
// points; the gap keeps the plane clear of every critical point). Gaps wider than dz get
// floor(gap / dz) more planes, evenly spaced (§3.2). Each plane is then moved a little (within a
// quarter of its spacing, and for spacing planes within half the slack dz - spacing, so that no
// gap exceeds dz) to the height farthest from any vertex (place_plane), so no vertex lies on a
// plane.
//   mesh      the mesh whose vertices the critical points index
//   critical  critical points of the harmonic function
// Then the girth rule (CuttingPlaneOptions::girth_ratio) adds planes where the sections are thin.
// Throws std::invalid_argument for non-positive dz, negative level_merge or bad girth options, MeshError for a mesh
// with no height.
CuttingPlanes cutting_planes(const TriMesh& mesh, const CriticalPoints& critical, const CuttingPlaneOptions& options = {});

}  // namespace polycube
