#include "polycube/map_audit.h"

#include "polycube/parallel.h"
#include "polycube/target_surface.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace polycube {

namespace {

Eigen::Vector3d row(const Eigen::MatrixX3d& X, int i) { return X.row(i).transpose(); }

void check_faces(const TriMesh& mesh, int vertices, const char* what) {
  if (mesh.num_faces() == 0) throw std::invalid_argument(std::string("audit_map: ") + what + " has no faces");
  if (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= vertices)
    throw std::invalid_argument(std::string("audit_map: ") + what + " has a face index out of range [0, " +
                                std::to_string(vertices) + ")");
}

}  // namespace

MapDirectionAudit audit_map_direction(const TriMesh& source, const Eigen::MatrixX3d& image, const TriMesh& target,
                                      const MapAuditOptions& options) {
  if (!(options.surface_tolerance >= 0) || !std::isfinite(options.surface_tolerance) ||
      !(options.area_tolerance >= 0) || !std::isfinite(options.area_tolerance))
    throw std::invalid_argument("audit_map: tolerances must be finite and >= 0, got surface_tolerance=" +
                                std::to_string(options.surface_tolerance) +
                                ", area_tolerance=" + std::to_string(options.area_tolerance));
  const int nv = source.num_vertices();
  if (image.rows() != nv)
    throw std::invalid_argument("audit_map: image has " + std::to_string(image.rows()) + " rows, source has " +
                                std::to_string(nv) + " vertices");
  check_faces(source, nv, "source");
  check_faces(target, target.num_vertices(), "target");
  if (!target.V.allFinite()) throw std::invalid_argument("audit_map: target has non-finite vertices");

  const TargetSurface surface(target, "audit_map");
  const double target_area = surface.area();
  const double diagonal = surface.diagonal();

  // Closest target face of every image vertex (-1 when the vertex is not finite), and each
  // triangle's verdict, on the threads; then counted and summed in order.
  MapDirectionAudit audit;
  audit.triangles = source.num_faces();
  std::vector<int> vertex_face(nv, -1);
  std::vector<double> vertex_distance(nv, std::numeric_limits<double>::infinity());
  parallel_range(nv, options.threads, [&](int v) {
    if (!image.row(v).allFinite()) return;
    const auto [face, distance] = surface.closest(row(image, v));
    vertex_face[v] = face;
    vertex_distance[v] = diagonal > 0 ? distance / diagonal : distance;
  });
  for (int v = 0; v < nv; ++v) audit.max_distance = std::max(audit.max_distance, vertex_distance[v]);

  // Per face: -1 a corner not finite; else the verdict (0 good, 1 flipped, 2 degenerate).
  const int nf = source.num_faces();
  std::vector<int> verdict(nf, -1);
  std::vector<double> area(nf, 0);
  parallel_range(nf, options.threads, [&](int f) {
    const int corner[3] = {source.F(f, 0), source.F(f, 1), source.F(f, 2)};
    if (vertex_face[corner[0]] < 0 || vertex_face[corner[1]] < 0 || vertex_face[corner[2]] < 0) return;
    const Eigen::Vector3d a = row(image, corner[0]), b = row(image, corner[1]), c = row(image, corner[2]);
    area[f] = 0.5 * (b - a).cross(c - a).norm();
    // The target's outward normal near the triangle: the distinct faces closest to its centroid
    // and to its corners, area-weighted. Across a polycube edge the corners find both faces, and
    // a correctly oriented chord has a positive dot product with each of them.
    // (image_orientation.h: the faces nearest the centroid and corners, then a finer look.)
    verdict[f] = surface.judge(a, b, c, vertex_face[corner[0]], vertex_face[corner[1]], vertex_face[corner[2]]);
  });
  double image_area = 0;
  for (int f = 0; f < nf; ++f) {
    if (verdict[f] < 0) {
      ++audit.degenerate;
      continue;
    }
    image_area += area[f];
    audit.degenerate += verdict[f] == 2;
    audit.flipped += verdict[f] == 1;
  }
  audit.area_ratio = image_area / target_area;
  audit.ok = audit.flipped == 0 && audit.degenerate == 0 && audit.max_distance <= options.surface_tolerance &&
             std::abs(audit.area_ratio - 1) <= options.area_tolerance;
  return audit;
}

MapAudit audit_map(const TriMesh& model, const TriMesh& polycube, const Eigen::MatrixX3d& polycube_on_model,
                   const Eigen::MatrixX3d& model_on_polycube, const MapAuditOptions& options) {
  MapAudit audit;
  audit.polycube_to_model = audit_map_direction(polycube, polycube_on_model, model, options);
  audit.model_to_polycube = audit_map_direction(model, model_on_polycube, polycube, options);
  audit.distortion = map_distortion(polycube, polycube_on_model);
  audit.ok = audit.polycube_to_model.ok && audit.model_to_polycube.ok;
  return audit;
}

}  // namespace polycube
