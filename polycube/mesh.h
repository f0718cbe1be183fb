// Plain mesh types shared by every stage, and small geometric helpers on them.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace polycube {

// A triangle mesh.
//   V  #V by 3 vertex positions
//   F  #F by 3 vertex indices per triangle, counter-clockwise seen from outside
struct TriMesh {
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i F;

  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_faces() const { return static_cast<int>(F.rows()); }
};

// What a file holds before validation: points and polygons of any size, indices unchecked.
struct PolygonSoup {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::vector<int>> polygons;
};

// Axis-aligned bounding box of V (min and max corner). Empty V gives min = +inf, max = -inf.
struct BoundingBox {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
  Eigen::Vector3d extent() const { return max - min; }
  double diagonal() const { return (max - min).norm(); }
};
BoundingBox bounding_box(const Eigen::MatrixX3d& V);

// Per-face area, #F entries.
Eigen::VectorXd face_areas(const TriMesh& mesh);

// Per-face unit normal (zero rows for degenerate faces), #F by 3.
Eigen::MatrixX3d face_normals(const TriMesh& mesh);

// Total surface area.
double surface_area(const TriMesh& mesh);

// Signed enclosed volume (divergence theorem); positive for an outward-oriented closed mesh.
double signed_volume(const TriMesh& mesh);

}  // namespace polycube
