#include "polycube/mesh.h"

#include <Eigen/Geometry>

#include <limits>

namespace polycube {

BoundingBox bounding_box(const Eigen::MatrixX3d& V) {
  BoundingBox box;
  box.min.setConstant(std::numeric_limits<double>::infinity());
  box.max.setConstant(-std::numeric_limits<double>::infinity());
  if (V.rows() > 0) {
    box.min = V.colwise().minCoeff().transpose();
    box.max = V.colwise().maxCoeff().transpose();
  }
  return box;
}

Eigen::VectorXd face_areas(const TriMesh& mesh) {
  Eigen::VectorXd areas(mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0));
    const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1));
    const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2));
    areas[f] = 0.5 * (b - a).cross(c - a).norm();
  }
  return areas;
}

Eigen::MatrixX3d face_normals(const TriMesh& mesh) {
  Eigen::MatrixX3d normals(mesh.num_faces(), 3);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0));
    const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1));
    const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    normals.row(f) = len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
  }
  return normals;
}

double surface_area(const TriMesh& mesh) { return face_areas(mesh).sum(); }

double signed_volume(const TriMesh& mesh) {
  double volume = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0));
    const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1));
    const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2));
    volume += a.dot(b.cross(c));
  }
  return volume / 6.0;
}

}  // namespace polycube
