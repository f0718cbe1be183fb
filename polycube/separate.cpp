#include "polycube/separate.h"

#include "polycube/barycentric.h"
#include "polycube/cgal_bridge.h"
#include "polycube/errors.h"
#include "polycube/triangle_geometry.h"
#include "polycube/triangle_tree.h"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <chrono>
#include <map>
#include <string>

namespace polycube {

namespace {

// The model's cotangent weights per vertex, as (neighbour, weight) with negative weights clamped
// to 0, summed over the edge's two faces.
std::vector<std::map<int, double>> cotangent_weights(const TriMesh& mesh) {
  std::vector<std::map<int, double>> w(mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int i = mesh.F(f, k), j = mesh.F(f, (k + 1) % 3), o = mesh.F(f, (k + 2) % 3);
      const double a = (mesh.V.row(i) - mesh.V.row(j)).norm();
      const double b = (mesh.V.row(j) - mesh.V.row(o)).norm();
      const double c = (mesh.V.row(o) - mesh.V.row(i)).norm();
      const double half_cot = 0.5 * cotan_opposite(a, b, c);
      w[i][j] += half_cot;
      w[j][i] += half_cot;
    }
  }
  for (auto& row : w)
    for (auto& [j, value] : row) value = std::max(value, 0.0);
  return w;
}

// Lumped vertex areas (a third of each face's area).
Eigen::VectorXd vertex_areas(const TriMesh& mesh) {
  Eigen::VectorXd m = Eigen::VectorXd::Zero(mesh.num_vertices());
  const Eigen::VectorXd a = face_areas(mesh);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) m[mesh.F(f, k)] += a[f] / 3;
  return m;
}

}  // namespace

std::vector<std::pair<int, int>> self_intersecting_faces(const TriMesh& mesh) {
  const cgal::SurfaceMesh sm = cgal::to_surface_mesh(mesh);  // faces keep their indices
  std::vector<std::pair<cgal::SurfaceMesh::Face_index, cgal::SurfaceMesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(pairs));
  std::vector<std::pair<int, int>> out;
  out.reserve(pairs.size());
  for (const auto& [a, b] : pairs) out.emplace_back(static_cast<int>(a.idx()), static_cast<int>(b.idx()));
  return out;
}

Separation separate_self_intersections(const TriMesh& model, const SeparationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Separation out;
  out.mesh = model;
  std::vector<std::pair<int, int>> pairs = self_intersecting_faces(model);
  out.pairs_before = static_cast<int>(pairs.size());
  if (pairs.empty()) return out;
  const int n = model.num_vertices();
  const double diagonal = bounding_box(model.V).diagonal();
  const double t = options.step * diagonal * diagonal;
  const std::vector<std::map<int, double>> w = cotangent_weights(model);
  TriMesh& mesh = out.mesh;
  while (!pairs.empty()) {
    if (out.rounds >= options.max_rounds)
      throw AlgorithmError("the model intersects itself (" + std::to_string(out.pairs_before) + " face pairs) and " +
                           std::to_string(pairs.size()) + " pairs still intersect after " + std::to_string(out.rounds) +
                           " rounds of local smoothing");
    // The region: the intersecting faces' vertices, grown by rings.
    std::vector<char> in(n, 0);
    for (const auto& [a, b] : pairs)
      for (int f : {a, b})
        for (int k = 0; k < 3; ++k) in[mesh.F(f, k)] = 1;
    for (int ring = 0; ring < options.rings + out.rounds; ++ring) {
      std::vector<char> grown = in;
      for (int v = 0; v < n; ++v)
        if (in[v])
          for (const auto& [j, weight] : w[v]) grown[j] = 1;
      in.swap(grown);
    }
    std::vector<int> index(n, -1), free;
    for (int v = 0; v < n; ++v)
      if (in[v]) {
        index[v] = static_cast<int>(free.size());
        free.push_back(v);
      }
    const Eigen::VectorXd m = vertex_areas(mesh);
    std::vector<Eigen::Triplet<double>> entries;
    Eigen::MatrixX3d rhs(free.size(), 3);
    for (size_t r = 0; r < free.size(); ++r) {
      const int v = free[r];
      double diagonal_entry = m[v];
      rhs.row(r) = m[v] * mesh.V.row(v);
      for (const auto& [j, weight] : w[v]) {
        diagonal_entry += t * weight;
        if (index[j] >= 0)
          entries.emplace_back(static_cast<int>(r), index[j], -t * weight);
        else
          rhs.row(r) += t * weight * mesh.V.row(j);
      }
      entries.emplace_back(static_cast<int>(r), static_cast<int>(r), diagonal_entry);
    }
    Eigen::SparseMatrix<double> K(static_cast<int>(free.size()), static_cast<int>(free.size()));
    K.setFromTriplets(entries.begin(), entries.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(K);
    if (solver.info() != Eigen::Success) throw AlgorithmError("separate_self_intersections: the smoothing system cannot be factorised");
    const Eigen::MatrixX3d x = solver.solve(rhs);
    for (size_t r = 0; r < free.size(); ++r) mesh.V.row(free[r]) = x.row(r);
    ++out.rounds;
    pairs = self_intersecting_faces(mesh);
  }
  for (int v = 0; v < n; ++v) {
    const double shift = (mesh.V.row(v) - model.V.row(v)).norm();
    if (shift > 0) ++out.moved_vertices;
    out.max_shift = std::max(out.max_shift, diagonal > 0 ? shift / diagonal : 0.0);
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

Eigen::MatrixX3d to_original_surface(const TriMesh& copy, const TriMesh& original, const Eigen::MatrixX3d& points) {
  if (copy.num_faces() != original.num_faces() || copy.F != original.F)
    throw std::invalid_argument("to_original_surface: the copy and the original have different faces");
  using namespace triangle_tree;
  const std::vector<Triangle> triangles = triangles_of(copy);
  Tree tree(triangles.begin(), triangles.end());
  tree.accelerate_distance_queries();
  Eigen::MatrixX3d out(points.rows(), 3);
  for (int i = 0; i < points.rows(); ++i) {
    const auto [closest, id] = tree.closest_point_and_primitive(Point(points(i, 0), points(i, 1), points(i, 2)));
    out.row(i) = to_original_point(copy, original, static_cast<int>(id - triangles.begin()), Eigen::Vector3d(closest.x(), closest.y(), closest.z()));
  }
  return out;
}

Eigen::Vector3d to_original_point(const TriMesh& copy, const TriMesh& original, int f, const Eigen::Vector3d& x) {
  const Eigen::Vector3d bary = clamp_bary(barycentric3(copy.V.row(copy.F(f, 0)), copy.V.row(copy.F(f, 1)), copy.V.row(copy.F(f, 2)), x));
  return bary[0] * original.V.row(original.F(f, 0)).transpose() + bary[1] * original.V.row(original.F(f, 1)).transpose() +
         bary[2] * original.V.row(original.F(f, 2)).transpose();
}

}  // namespace polycube
