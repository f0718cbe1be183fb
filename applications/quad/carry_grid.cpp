#include "applications/quad/carry_grid.h"

#include "polycube/errors.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace polycube {

QuadMesh carry_grid(const PolycubeGrid& grid, const SurfaceMap& map, const CarryOptions& options) {
  QuadMesh mesh;
  mesh.Q = grid.mesh.Q;
  const int nv = grid.mesh.num_vertices();
  mesh.V.resize(nv, 3);
  int threads = options.threads > 0 ? options.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::max(1, std::min(threads, nv / 256 + 1));

  std::atomic<int> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&] {
    try {
      for (int begin; (begin = next.fetch_add(256)) < nv;)
        for (int v = begin; v < std::min(nv, begin + 256); ++v) {
          const Eigen::Vector3d p = map(grid.on_polycube[v]);
          if (!p.allFinite())
            throw AlgorithmError("the map sends grid vertex " + std::to_string(v) + " (triangle " +
                                 std::to_string(grid.on_polycube[v].face) + " of P) to a non-finite point");
          mesh.V.row(v) = p;
        }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = nv;
    }
  };
  if (threads == 1) {
    work();
  } else {
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(work);
    for (std::thread& t : pool) t.join();
  }
  if (failure) std::rethrow_exception(failure);
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

SurfaceMap projected_map(SurfaceMap map, std::shared_ptr<const SurfaceProjector> surface) {
  return [map = std::move(map), surface = std::move(surface)](const SurfacePoint& p) -> Eigen::Vector3d {
    return surface->closest(map(p)).point;
  };
}

}  // namespace polycube
