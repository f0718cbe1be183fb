#include "applications/quad/carry_grid.h"

#include "polycube/closest_point.h"
#include "polycube/errors.h"
#include "polycube/parallel.h"

#include <algorithm>
#include <array>
#include <exception>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace polycube {

QuadMesh carry_grid(const PolycubeGrid& grid, const SurfaceMap& map, const CarryOptions& options) {
  QuadMesh mesh;
  mesh.Q = grid.mesh.Q;
  const int nv = grid.mesh.num_vertices();
  mesh.V.resize(nv, 3);
  // Each vertex on the threads; the error (the map's own, or a non-finite image) of the lowest
  // failing vertex, whatever the threads.
  std::vector<std::exception_ptr> error(nv);
  parallel_range(nv, options.threads, [&](int v) {
    try {
      const Eigen::Vector3d p = map(grid.on_polycube[v]);
      if (!p.allFinite())
        throw AlgorithmError("the map sends grid vertex " + std::to_string(v) + " (triangle " +
                             std::to_string(grid.on_polycube[v].face) + " of P) to a non-finite point");
      mesh.V.row(v) = p;
    } catch (...) {
      error[v] = std::current_exception();
    }
  });
  for (const std::exception_ptr& e : error)
    if (e) std::rethrow_exception(e);
  return mesh;
}

SurfaceMap vertex_image_map(const TriMesh& polycube, const Eigen::MatrixX3d& images) {
  if (images.rows() != polycube.V.rows())
    throw std::invalid_argument("the map has " + std::to_string(images.rows()) + " vertex images for a polycube of " +
                                std::to_string(polycube.V.rows()) + " vertices");
  return [F = polycube.F, images](const SurfacePoint& p) -> Eigen::Vector3d {
    if (p.face < 0 || p.face >= F.rows()) throw std::invalid_argument("surface point on triangle " + std::to_string(p.face) + " of P");
    return p.bary[0] * images.row(F(p.face, 0)).transpose() + p.bary[1] * images.row(F(p.face, 1)).transpose() +
           p.bary[2] * images.row(F(p.face, 2)).transpose();
  };
}

std::vector<int> same_grid_vertices(const PolycubeGrid& from, const PolycubeGrid& to) {
  std::vector<int> same(to.mesh.num_vertices(), -1);
  if (from.mesh.num_vertices() == 0) return same;
  const Eigen::Vector3d low = from.mesh.V.colwise().minCoeff(), high = from.mesh.V.colwise().maxCoeff();
  const double tolerance = 1e-9 * std::max((high - low).norm(), 1e-300);
  // Buckets of twice the tolerance: a point's match is in its bucket or a neighbouring one.
  const auto key = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector3d k = ((x - low) / (2 * tolerance)).array().floor();
    return std::array<long long, 3>{static_cast<long long>(k.x()), static_cast<long long>(k.y()), static_cast<long long>(k.z())};
  };
  std::map<std::array<long long, 3>, std::vector<int>> buckets;
  for (int v = 0; v < from.mesh.num_vertices(); ++v) buckets[key(from.mesh.V.row(v).transpose())].push_back(v);
  for (int v = 0; v < to.mesh.num_vertices(); ++v) {
    const Eigen::Vector3d x = to.mesh.V.row(v);
    const auto k = key(x);
    for (int i = -1; i <= 1 && same[v] < 0; ++i)
      for (int j = -1; j <= 1 && same[v] < 0; ++j)
        for (int l = -1; l <= 1 && same[v] < 0; ++l) {
          const auto found = buckets.find({k[0] + i, k[1] + j, k[2] + l});
          if (found == buckets.end()) continue;
          for (int u : found->second)
            if ((from.mesh.V.row(u).transpose() - x).norm() <= tolerance) {
              same[v] = u;
              break;
            }
        }
  }
  return same;
}

RefinedCarry carry_refined_grid(const PolycubeGrid& grid, const SurfaceMap& map, const PolycubeGrid& from, const QuadMesh& quads,
                                const SurfaceProjector& model, const CarryOptions& options) {
  if (quads.Q != from.mesh.Q) throw std::invalid_argument("the finished quads do not have the refined grid's connectivity");
  const bool through_map = static_cast<bool>(map);
  RefinedCarry carried{through_map ? carry_grid(grid, map, options) : QuadMesh{Eigen::MatrixX3d::Zero(grid.mesh.num_vertices(), 3), grid.mesh.Q},
                       same_grid_vertices(from, grid)};
  QuadMesh& mesh = carried.mesh;
  // How far the relaxation and the fit moved each vertex of `from` from its image (without a
  // map: from the origin, so that the shift is the interpolated position itself).
  const Eigen::MatrixX3d moved = through_map ? Eigen::MatrixX3d(quads.V - carry_grid(from, map, options).V) : quads.V;
  const SurfaceProjector on_from(triangulate_quads(from.mesh));
  const TriMesh& t = on_from.surface();
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    if (carried.same[v] >= 0) {
      mesh.V.row(v) = quads.V.row(carried.same[v]);
      continue;
    }
    // An added vertex: its image, moved as the vertices of `from` round it were (barycentric in
    // from's triangles on P), back on the model.
    const Eigen::Vector3d x = grid.mesh.V.row(v);
    const int f = on_from.closest(x).face;
    const Eigen::Vector3d bary =
        closest_on_triangle(x, t.V.row(t.F(f, 0)), t.V.row(t.F(f, 1)), t.V.row(t.F(f, 2))).bary;
    Eigen::Vector3d shift = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) shift += bary[i] * moved.row(t.F(f, i)).transpose();
    mesh.V.row(v) = model.closest(mesh.V.row(v).transpose() + shift).point;
  }
  return carried;
}

SurfaceMap projected_map(SurfaceMap map, std::shared_ptr<const SurfaceProjector> surface) {
  return [map = std::move(map), surface = std::move(surface)](const SurfacePoint& p) -> Eigen::Vector3d {
    return surface->closest(map(p)).point;
  };
}

}  // namespace polycube
