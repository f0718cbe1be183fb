#include "applications/quad/surface_projector.h"

#include "polycube/closest_point.h"
#include "polycube/mesh_topology.h"
#include "polycube/parallel.h"
#include "polycube/triangle_tree.h"

#include <boost/iterator/counting_iterator.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace polycube {

namespace {

using triangle_tree::Kernel;
using triangle_tree::Point;
using triangle_tree::Triangle;

// A triangle of the surface known by its face index.
class FacePrimitive {
 public:
  using Id = int;
  using Point = Kernel::Point_3;
  using Datum = Kernel::Triangle_3;

  FacePrimitive() = default;
  FacePrimitive(boost::counting_iterator<int> face, const std::vector<Triangle>* triangles)
      : face_(*face), triangles_(triangles) {}
  Id id() const { return face_; }
  const Datum& datum() const { return (*triangles_)[face_]; }
  Point reference_point() const { return (*triangles_)[face_].vertex(0); }

 private:
  int face_ = -1;
  const std::vector<Triangle>* triangles_ = nullptr;
};

using Tree = CGAL::AABB_tree<triangle_tree::ClosestPointTraits<FacePrimitive>>;

}  // namespace

struct SurfaceProjector::Impl {
  TriMesh surface;
  Eigen::MatrixX3d normals;
  Eigen::MatrixX3d vertex_normals;
  std::vector<Triangle> triangles;
  Tree tree;
  TriMesh sampled;  // empty: the surface
  // For the walks of closest_on_sheet: the face across each edge of a face (-1: none), the faces
  // round each vertex (CSR).
  Eigen::MatrixX3i across;
  CompressedLists ring;

  // The hit for a query whose closest point on the surface is `point`, on triangle `face`.
  SurfaceHit hit(const Eigen::Vector3d& query, const Eigen::Vector3d& point, int face) const;
};

SurfaceProjector::SurfaceProjector(const TriMesh& surface) : impl_(std::make_unique<Impl>()) {
  if (surface.num_faces() == 0) throw std::invalid_argument("cannot project onto a mesh without faces");
  impl_->surface = surface;
  impl_->normals = face_normals(surface);
  impl_->vertex_normals = Eigen::MatrixX3d::Zero(surface.num_vertices(), 3);
  for (int f = 0; f < surface.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d p = surface.V.row(surface.F(f, i));
      const Eigen::Vector3d u = surface.V.row(surface.F(f, (i + 1) % 3)).transpose() - p;
      const Eigen::Vector3d w = surface.V.row(surface.F(f, (i + 2) % 3)).transpose() - p;
      const double angle = std::atan2(u.cross(w).norm(), u.dot(w));
      impl_->vertex_normals.row(surface.F(f, i)) += angle * impl_->normals.row(f);
    }
  for (int v = 0; v < surface.num_vertices(); ++v) {
    const double length = impl_->vertex_normals.row(v).norm();
    if (length > 0) impl_->vertex_normals.row(v) /= length;
  }
  const auto point = [&](int v) { return Point(surface.V(v, 0), surface.V(v, 1), surface.V(v, 2)); };
  impl_->triangles.reserve(surface.num_faces());
  for (int f = 0; f < surface.num_faces(); ++f)
    impl_->triangles.emplace_back(point(surface.F(f, 0)), point(surface.F(f, 1)), point(surface.F(f, 2)));
  impl_->tree.insert(boost::counting_iterator<int>(0), boost::counting_iterator<int>(surface.num_faces()), &impl_->triangles);
  impl_->tree.build();
  impl_->tree.accelerate_distance_queries();
  const EdgeMap edges = build_edge_map(surface.F);
  impl_->across.resize(surface.num_faces(), 3);
  for (int f = 0; f < surface.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) {
      const int e = edges.FE(f, i);
      const int other = edges.EF(e, 0) == f ? edges.EF(e, 1) : edges.EF(e, 0);
      impl_->across(f, i) = edges.face_count[e] == 2 ? other : -1;
    }
  impl_->ring = vertex_faces(surface.F, surface.num_vertices());
}

SurfaceProjector::SurfaceProjector(const TriMesh& surface, const TriMesh& sampled) : SurfaceProjector(surface) {
  if (sampled.num_faces() == 0) throw std::invalid_argument("cannot sample a surface by a mesh without faces");
  impl_->sampled = sampled;
}

SurfaceProjector::~SurfaceProjector() = default;

SurfaceHit SurfaceProjector::closest(const Eigen::Vector3d& query) const {
  const Point q(query.x(), query.y(), query.z());
  const auto [point, face] = impl_->tree.closest_point_and_primitive(q);
  return impl_->hit(query, {point.x(), point.y(), point.z()}, face);
}

SurfaceHit SurfaceProjector::closest(const Eigen::Vector3d& query, const SurfaceHit& hint) const {
  if (hint.face < 0 || hint.face >= impl_->surface.num_faces()) return closest(query);
  // The tree search only visits boxes nearer than its starting point: the closest point on the
  // hint's sheet (a short walk) is a far tighter start than the hint itself.
  const SurfaceHit start = closest_on_sheet(query, hint);
  const Point q(query.x(), query.y(), query.z());
  const auto [point, face] =
      impl_->tree.closest_point_and_primitive(q, {Point(start.point.x(), start.point.y(), start.point.z()), start.face});
  if (face == start.face) return start;
  return impl_->hit(query, {point.x(), point.y(), point.z()}, face);
}

SurfaceHit SurfaceProjector::closest_on_sheet(const Eigen::Vector3d& query, const SurfaceHit& hint) const {
  const TriMesh& m = impl_->surface;
  if (hint.face < 0 || hint.face >= m.num_faces()) return closest(query);
  const auto on_face = [&](int f) {
    return closest_on_triangle(query, m.V.row(m.F(f, 0)), m.V.row(m.F(f, 1)), m.V.row(m.F(f, 2)));
  };
  int face = hint.face;
  TriangleClosest best = on_face(face);
  double best_distance = (best.point - query).squaredNorm();
  // Each step gets strictly nearer, so no face is visited twice.
  for (int step = 0; step < m.num_faces(); ++step) {
    int zeros = 0, zero = -1, nonzero = -1;
    for (int i = 0; i < 3; ++i) {
      if (best.bary[i] <= 0) {
        ++zeros;
        zero = i;
      } else {
        nonzero = i;
      }
    }
    if (zeros == 0) break;  // inside the face: a local minimum
    int next = -1;
    TriangleClosest next_closest;
    double next_distance = best_distance * (1 - 1e-12);
    const auto consider = [&](int g) {
      if (g < 0 || g == face) return;
      const TriangleClosest c = on_face(g);
      const double d = (c.point - query).squaredNorm();
      if (d < next_distance) {
        next = g;
        next_closest = c;
        next_distance = d;
      }
    };
    if (zeros == 1) {
      consider(impl_->across(face, (zero + 1) % 3));  // on the edge opposite corner `zero`
    } else {
      const int v = m.F(face, nonzero);  // at that corner
      for (const int* g = impl_->ring.first(v); g != impl_->ring.last(v); ++g) consider(*g);
    }
    if (next < 0) break;
    face = next;
    best = next_closest;
    best_distance = next_distance;
  }
  return impl_->hit(query, best.point, face);
}

SurfaceHit SurfaceProjector::Impl::hit(const Eigen::Vector3d& query, const Eigen::Vector3d& point, int face) const {
  SurfaceHit hit;
  hit.point = point;
  hit.face = face;
  hit.distance = (hit.point - query).norm();
  // Barycentric coordinates of the point in its triangle (areas of the opposite sub-triangles).
  const TriMesh& m = surface;
  const Eigen::Vector3d a = m.V.row(m.F(face, 0)), b = m.V.row(m.F(face, 1)), c = m.V.row(m.F(face, 2));
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double area = n.squaredNorm();
  if (area > 0) {
    const double wa = std::max(0.0, (c - b).cross(hit.point - b).dot(n) / area);
    const double wb = std::max(0.0, (a - c).cross(hit.point - c).dot(n) / area);
    const double wc = std::max(0.0, (b - a).cross(hit.point - a).dot(n) / area);
    hit.normal = wa * vertex_normals.row(m.F(face, 0)) + wb * vertex_normals.row(m.F(face, 1)) +
                 wc * vertex_normals.row(m.F(face, 2));
  }
  const double length = hit.normal.norm();
  hit.normal = length > 1e-12 ? (hit.normal / length).eval() : normals.row(face).transpose().eval();
  return hit;
}

std::vector<SurfaceHit> closest_to_vertices(const SurfaceProjector& surface, const TriMesh& points, bool on_sheet, int threads) {
  const int n = points.num_vertices();
  std::vector<SurfaceHit> hits(n);
  // The breadth-first order first (each vertex's hint: the vertex it was reached from; each
  // component's first vertex searched without one), then the searches depth by depth, each
  // depth's on the threads: every hint is a result of the depth before, so the answers are those
  // of the searches made one after the other.
  const CompressedLists ring = vertex_faces(points.F, n);
  std::vector<int> parent(n, -1), depth(n, -1), order;
  order.reserve(n);
  int deepest = 0;
  for (int root = 0; root < n; ++root) {
    if (depth[root] >= 0) continue;
    depth[root] = 0;
    const size_t first = order.size();
    order.push_back(root);
    for (size_t head = first; head < order.size(); ++head) {
      const int v = order[head];
      for (const int* f = ring.first(v); f != ring.last(v); ++f)
        for (int i = 0; i < 3; ++i) {
          const int w = points.F(*f, i);
          if (depth[w] >= 0) continue;
          depth[w] = depth[v] + 1;
          deepest = std::max(deepest, depth[w]);
          parent[w] = v;
          order.push_back(w);
        }
    }
  }
  std::vector<std::vector<int>> at_depth(deepest + 1);
  for (int v : order) at_depth[depth[v]].push_back(v);
  // A depth with few vertices is not worth the threads' start.
  constexpr int kParallelFrom = 512;
  for (const std::vector<int>& level : at_depth) {
    const auto search = [&](int k) {
      const int w = level[k];
      const Eigen::Vector3d x = points.V.row(w);
      hits[w] = parent[w] < 0 ? surface.closest(x)
                : on_sheet    ? surface.closest_on_sheet(x, hits[parent[w]])
                              : surface.closest(x, hits[parent[w]]);
    };
    const int count = static_cast<int>(level.size());
    parallel_range(count, count >= kParallelFrom ? threads : 1, search);
  }
  return hits;
}

SurfaceSamples sample_surface(const TriMesh& surface, double spacing) {
  if (!(spacing > 0)) throw std::invalid_argument("surface samples: spacing must be > 0, got " + std::to_string(spacing));
  SurfaceSamples samples;
  samples.points.reserve(surface.num_vertices());
  for (int v = 0; v < surface.num_vertices(); ++v) {
    samples.points.push_back(surface.V.row(v).transpose());
    samples.hint_vertex.push_back(v);
  }
  for (int f = 0; f < surface.num_faces(); ++f) {
    const Eigen::Vector3d a = surface.V.row(surface.F(f, 0)), b = surface.V.row(surface.F(f, 1)), c = surface.V.row(surface.F(f, 2));
    if (std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}) <= spacing) continue;
    samples.points.push_back((a + b + c) / 3);
    samples.hint_vertex.push_back(surface.F(f, 0));
  }
  const EdgeMap edges = build_edge_map(surface.F);
  for (int e = 0; e < edges.num_edges(); ++e) {
    const Eigen::Vector3d a = surface.V.row(edges.E(e, 0)), b = surface.V.row(edges.E(e, 1));
    const int parts = static_cast<int>(std::ceil((b - a).norm() / spacing));
    for (int k = 1; k < parts; ++k) {
      samples.points.push_back(a + (b - a) * (static_cast<double>(k) / parts));
      samples.hint_vertex.push_back(edges.E(e, 0));
    }
  }
  return samples;
}

std::vector<SurfaceHit> closest_to_samples(const SurfaceProjector& surface, const TriMesh& sampled, const SurfaceSamples& samples,
                                           double exact_beyond, int threads) {
  std::vector<SurfaceHit> hits = closest_to_vertices(surface, sampled, true, threads);
  const int nv = sampled.num_vertices(), n = static_cast<int>(samples.points.size());
  hits.resize(n);
  // Each point's walk starts from its vertex's (done above): independent of each other.
  parallel_range(n - nv, threads, [&](int i) {
    const int k = nv + i;
    hits[k] = surface.closest_on_sheet(samples.points[k], hits[samples.hint_vertex[k]]);
  });
  parallel_range(n, threads, [&](int k) {
    if (!(hits[k].distance <= exact_beyond)) hits[k] = surface.closest(samples.points[k], hits[k]);
  });
  return hits;
}

const TriMesh& SurfaceProjector::surface() const { return impl_->surface; }

const TriMesh& SurfaceProjector::sampled() const { return impl_->sampled.num_faces() > 0 ? impl_->sampled : impl_->surface; }

Eigen::Vector3d SurfaceProjector::face_normal(int f) const { return impl_->normals.row(f); }

}  // namespace polycube
