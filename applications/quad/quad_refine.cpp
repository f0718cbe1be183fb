#include "applications/quad/quad_refine.h"

#include "polycube/closest_point.h"
#include "polycube/errors.h"
#include "polycube/parallel.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <utility>

namespace polycube {

namespace {
// The point on triangle f of `mesh` closest to x, as a surface point.
SurfacePoint surface_point(const TriMesh& mesh, int f, const Eigen::Vector3d& x) {
  const TriangleClosest closest = closest_on_triangle(x, mesh.V.row(mesh.F(f, 0)).transpose(), mesh.V.row(mesh.F(f, 1)).transpose(),
                                                      mesh.V.row(mesh.F(f, 2)).transpose());
  SurfacePoint point;
  point.face = f;
  point.bary = closest.bary;
  if (!point.bary.allFinite()) {  // a degenerate image triangle: its corner nearest x
    int nearest = 0;
    for (int i = 1; i < 3; ++i)
      if ((mesh.V.row(mesh.F(f, i)).transpose() - x).squaredNorm() < (mesh.V.row(mesh.F(f, nearest)).transpose() - x).squaredNorm())
        nearest = i;
    point.bary = Eigen::Vector3d::Unit(nearest);
  }
  return point;
}
}  // namespace

PreimageLocator::PreimageLocator(const TriMesh& polycube, const SurfaceMap& to_model, int threads)
    : on_polycube_(std::make_unique<SurfaceProjector>(polycube)) {
  const int nv = polycube.num_vertices();
  std::vector<SurfacePoint> at_vertex(nv);
  for (int f = 0; f < polycube.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) {
      SurfacePoint& p = at_vertex[polycube.F(f, i)];
      p.face = f;
      p.bary = Eigen::Vector3d::Unit(i);
    }
  TriMesh images;
  images.F = polycube.F;
  images.V.resize(nv, 3);
  parallel_range(nv, threads, [&](int v) {
    if (at_vertex[v].face >= 0)
      images.V.row(v) = to_model(at_vertex[v]).transpose();
    else
      images.V.row(v) = polycube.V.row(v);  // on no triangle: never a closest point's corner
  });
  if (!images.V.allFinite()) throw AlgorithmError("the map sends a vertex of P to a non-finite point");
  on_images_ = std::make_unique<SurfaceProjector>(images);
}

SurfacePoint PreimageLocator::preimage(const Eigen::Vector3d& x) const {
  return surface_point(on_images_->surface(), on_images_->closest(x).face, x);
}

SurfacePoint PreimageLocator::on_polycube(const Eigen::Vector3d& p) const {
  return surface_point(on_polycube_->surface(), on_polycube_->closest(p).face, p);
}

QuadMiss find_quad_misses(const PolycubeGrid& grid, const QuadMesh& quads, const SurfaceProjector& model,
                          const PreimageLocator& locator, double distance, double cell_size, int threads) {
  const TriMesh& surface = model.sampled();
  const SurfaceProjector on_quads(triangulate_quads(quads));
  // Points of M (its vertices, centroids of long triangles, points along long edges, a quarter
  // cell apart).
  const SurfaceSamples sampled = sample_surface(surface, cell_size / 4);
  const std::vector<Eigen::Vector3d>& samples = sampled.points;
  // Points of the quads, on M and on P: centres, the centroids of the two triangles the measure
  // splits each into (a quad the fit stretched bends: its centre lies on neither; without them
  // armadillo and spool ended 0.517 % off the model), and midpoints of edges (each once).
  std::vector<Eigen::Vector3d> quad_points, quad_points_on_p;
  for (int q = 0; q < quads.num_quads(); ++q) {
    Eigen::Vector3d on_model = Eigen::Vector3d::Zero(), on_p = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i) {
      on_model += quads.V.row(quads.Q(q, i)).transpose() / 4;
      on_p += grid.mesh.V.row(grid.mesh.Q(q, i)).transpose() / 4;
    }
    quad_points.push_back(on_model);
    quad_points_on_p.push_back(on_p);
    for (const auto& t : quad_triangle_corners(quads, q)) {
      Eigen::Vector3d m = Eigen::Vector3d::Zero(), p = Eigen::Vector3d::Zero();
      for (int i : t) {
        m += quads.V.row(quads.Q(q, i)).transpose() / 3;
        p += grid.mesh.V.row(grid.mesh.Q(q, i)).transpose() / 3;
      }
      quad_points.push_back(m);
      quad_points_on_p.push_back(p);
    }
    for (int i = 0; i < 4; ++i) {
      const int u = quads.Q(q, i), w = quads.Q(q, (i + 1) % 4);
      if (u > w) continue;
      quad_points.push_back((quads.V.row(u) + quads.V.row(w)).transpose() / 2);
      quad_points_on_p.push_back((grid.mesh.V.row(u) + grid.mesh.V.row(w)).transpose() / 2);
    }
  }
  const int ns = static_cast<int>(samples.size()), nq = static_cast<int>(quad_points.size());
  // Per candidate: its distance and its point of P (set when a miss).
  std::vector<double> miss(ns + nq, 0);
  std::vector<SurfacePoint> where(ns + nq);
  // A model point's second place: on P under the point of the quads closest to it (the quad
  // that cuts across it), where the preimage through the chords may lie off the quads' lines.
  std::vector<SurfacePoint> under_quad(ns);
  const TriMesh& quad_triangles = on_quads.surface();
  // The model's points on the quads' sheet by walks (many times faster than the tree), the whole
  // search only for those a walk leaves beyond `distance` (a walk is never nearer than the closest
  // point).
  const std::vector<SurfaceHit> near = closest_to_samples(on_quads, surface, sampled, distance, threads);
  parallel_range(ns + nq, threads, [&](int k) {
    if (k < ns) {
      const SurfaceHit& hit = near[k];
      miss[k] = hit.distance;
      if (miss[k] > distance) {
        where[k] = locator.preimage(samples[k]);
        const SurfacePoint on_quad = surface_point(quad_triangles, hit.face, hit.point);
        Eigen::Vector3d on_p = Eigen::Vector3d::Zero();
        for (int i = 0; i < 3; ++i) on_p += on_quad.bary[i] * grid.mesh.V.row(quad_triangles.F(hit.face, i)).transpose();
        under_quad[k] = locator.on_polycube(on_p);
      }
    } else {
      miss[k] = model.closest(quad_points[k - ns]).distance;
      if (miss[k] > distance) where[k] = locator.on_polycube(quad_points_on_p[k - ns]);
    }
  });
  QuadMiss result;
  std::vector<int> order;
  for (int k = 0; k < ns + nq; ++k) {
    result.farthest = std::max(result.farthest, miss[k]);
    if (miss[k] > distance) order.push_back(k);
  }
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return miss[x] > miss[y]; });
  for (int k : order) {
    result.points.push_back(where[k]);
    result.distances.push_back(miss[k]);
    if (k < ns) {
      result.points.push_back(under_quad[k]);
      result.distances.push_back(miss[k]);
    }
  }
  return result;
}

}  // namespace polycube
