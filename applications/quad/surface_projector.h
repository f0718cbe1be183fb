// Closest points on a triangle mesh (CGAL AABB tree behind this wrapper): places carried grid
// vertices on the model and keeps relaxed vertices on it.
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace polycube {

// The closest point of the surface to a query.
//   point     on the surface
//   face      triangle of the surface holding it
//   distance  from the query
//   normal    unit surface normal there, interpolated from the angle-weighted vertex normals of the
//             triangle (continuous across edges, so a point on a crease gets the mean direction
//             of the faces meeting there instead of one face's normal)
struct SurfaceHit {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int face = -1;
  double distance = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

// Precomputes the search tree once; queries are const and may run on several threads. Keeps its
// own copy of the surface.
class SurfaceProjector {
 public:
  // Throws std::invalid_argument for a mesh without faces.
  explicit SurfaceProjector(const TriMesh& surface);
  // The same, and `sampled`: another triangulation of the same surface (the model as read, when
  // `surface` is its split_long_edges copy, whose interpolated normals stay true inside the
  // model's large flat triangles) that sampled() hands to those who sample the surface (the fit,
  // the refinement's misses, the measure): its vertices and points along its long edges, as
  // many as the model as read has, not the copy's.
  SurfaceProjector(const TriMesh& surface, const TriMesh& sampled);
  ~SurfaceProjector();
  SurfaceProjector(const SurfaceProjector&) = delete;
  SurfaceProjector& operator=(const SurfaceProjector&) = delete;

  SurfaceHit closest(const Eigen::Vector3d& query) const;
  // The same, starting the search from a known surface point (a previous hit near the query, as
  // for a vertex that moves a little): faster, same answer.
  SurfaceHit closest(const Eigen::Vector3d& query, const SurfaceHit& hint) const;
  // The closest point on the sheet of a known surface point (a previous hit near the query, as
  // for a vertex that moves a little): a walk over the faces from the hint's, on across the edge
  // or round the vertex where the current face's closest point lies, while that gets strictly
  // nearer. A local minimum of the distance: the closest point when nothing else of the surface
  // is nearer than the hint's sheet, and never a jump to another sheet (the far side of a thin
  // part). Several times faster than the tree for small moves. No hint (face -1): closest.
  SurfaceHit closest_on_sheet(const Eigen::Vector3d& query, const SurfaceHit& hint) const;

  const TriMesh& surface() const;
  // The triangulation to sample the surface by: `sampled` as given, else the surface.
  const TriMesh& sampled() const;
  // Unit outward normal of triangle f (zero for a degenerate one).
  Eigen::Vector3d face_normal(int f) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The closest points on `surface` of all of `points`' vertices, each search starting from a
// neighbour's result (breadth-first over points' triangles): exact (the hinted search of
// SurfaceProjector::closest, the same answers as without hints, faster) or, with on_sheet, the
// walks of closest_on_sheet alone (never nearer than the exact answer; many times faster). The
// searches of one breadth-first depth run on `threads` threads (0: one per hardware thread); the
// answers do not depend on it.
std::vector<SurfaceHit> closest_to_vertices(const SurfaceProjector& surface, const TriMesh& points, bool on_sheet, int threads = 1);

// Points of a surface a coarser mesh on it must come near: its vertices first (point v is vertex
// v), then the centroids of its triangles longer than `spacing` and points along its edges longer
// than that, at most `spacing` apart (a coarse CAD mesh is missed between its vertices, along its
// creases). hint_vertex: per point, a vertex of the surface next to it (point v: v itself), whose
// closest point may start the point's search.
struct SurfaceSamples {
  std::vector<Eigen::Vector3d> points;
  std::vector<int> hint_vertex;
};
// spacing may be +infinity (the vertices alone). Throws std::invalid_argument for spacing <= 0.
SurfaceSamples sample_surface(const TriMesh& surface, double spacing);

// The closest points on `surface` of all the samples: walks on the sheet (closest_on_sheet; the
// vertices in breadth-first order as closest_to_vertices takes them, the other points each from
// its hint vertex's result), then, on `threads` threads (0: one per hardware thread), the whole
// search for the points a walk leaves farther than `exact_beyond`. So which points lie beyond
// it is exact, and their hits are; 0: every hit exact; +infinity: the walks alone (never nearer
// than the exact answer).
std::vector<SurfaceHit> closest_to_samples(const SurfaceProjector& surface, const TriMesh& sampled, const SurfaceSamples& samples,
                                           double exact_beyond, int threads = 1);

}  // namespace polycube
