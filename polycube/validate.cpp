#include "polycube/validate.h"

#include "polycube/cgal_bridge.h"
#include "polycube/errors.h"
#include "polycube/mesh_topology.h"
#include "polycube/separate.h"

#include <CGAL/AABB_segment_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <queue>
#include <set>
#include <sstream>

namespace polycube {

namespace PMP = CGAL::Polygon_mesh_processing;

namespace {

// "1 face", "2 faces", "3 vertices".
std::string plural(int n, const std::string& word) {
  std::string form = word;
  if (n != 1) {
    const std::string vertex = "vertex";
    if (form.size() >= vertex.size() && form.compare(form.size() - vertex.size(), vertex.size(), vertex) == 0)
      form.replace(form.size() - 2, 2, "ices");
    else
      form += "s";
  }
  return std::to_string(n) + " " + form;
}

// Triangulates one polygon (indices into soup.points) and appends its triangles. Quads split
// along the shorter diagonal; larger polygons use CGAL's minimal-area hole triangulation, which
// stays valid for non-convex and non-planar polygons, with a fan as the last resort.
void triangulate_polygon(const PolygonSoup& soup, const std::vector<int>& polygon,
                         std::vector<std::array<int, 3>>& triangles) {
  const int n = static_cast<int>(polygon.size());
  if (n == 3) {
    triangles.push_back({polygon[0], polygon[1], polygon[2]});
    return;
  }
  auto point = [&](int k) -> const Eigen::Vector3d& { return soup.points[polygon[k]]; };
  if (n == 4) {
    if ((point(0) - point(2)).squaredNorm() <= (point(1) - point(3)).squaredNorm()) {
      triangles.push_back({polygon[0], polygon[1], polygon[2]});
      triangles.push_back({polygon[0], polygon[2], polygon[3]});
    } else {
      triangles.push_back({polygon[0], polygon[1], polygon[3]});
      triangles.push_back({polygon[1], polygon[2], polygon[3]});
    }
    return;
  }
  std::vector<cgal::Point> polyline;
  for (int k = 0; k < n; ++k) polyline.emplace_back(point(k).x(), point(k).y(), point(k).z());
  std::vector<CGAL::Triple<int, int, int>> patch;
  PMP::triangulate_hole_polyline(polyline, std::back_inserter(patch));
  if (static_cast<int>(patch.size()) == n - 2) {
    for (const auto& t : patch) triangles.push_back({polygon[t.first], polygon[t.second], polygon[t.third]});
    return;
  }
  for (int k = 1; k + 1 < n; ++k) triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
}

Eigen::MatrixX3i to_matrix(const std::vector<std::array<int, 3>>& triangles) {
  Eigen::MatrixX3i F(triangles.size(), 3);
  for (size_t f = 0; f < triangles.size(); ++f) F.row(f) << triangles[f][0], triangles[f][1], triangles[f][2];
  return F;
}

// The triangles without exact duplicates (the same corner set), the first of each kept.
std::vector<std::array<int, 3>> unique_faces(const std::vector<std::array<int, 3>>& triangles) {
  std::set<std::array<int, 3>> seen;
  std::vector<std::array<int, 3>> unique;
  for (const auto& t : triangles) {
    std::array<int, 3> key = t;
    std::sort(key.begin(), key.end());
    if (seen.insert(key).second) unique.push_back(t);
  }
  return unique;
}

// What a seam repair is judged by: boundary edges, and non-manifold edges (where there are none,
// non-manifold vertices, which are only counted on edge-manifold faces). Faces with the same
// corners count once (the duplicates a welded soup may hold are removed after the repairs).
struct SeamDefects {
  long long boundary = 0;
  long long nonmanifold = 0;
};

SeamDefects seam_defects(const std::vector<std::array<int, 3>>& triangles, int num_vertices) {
  const Eigen::MatrixX3i F = to_matrix(unique_faces(triangles));
  const EdgeMap map = build_edge_map(F);
  SeamDefects d;
  d.boundary = (map.face_count.array() == 1).count();
  d.nonmanifold = (map.face_count.array() > 2).count();
  if (d.nonmanifold == 0) d.nonmanifold = count_nonmanifold_vertices(F, num_vertices);
  return d;
}

// A repair of seams is kept only when it leaves fewer boundary edges and no more non-manifold
// edges or vertices (so an open mesh whose boundary touches itself is not pinched shut).
bool seams_better(const SeamDefects& after, const SeamDefects& before) {
  return after.boundary < before.boundary && after.nonmanifold <= before.nonmanifold;
}

// Per boundary edge of the triangles (an edge of one face): that face, and the edge's corner in it
// (the edge runs from corner i to corner i + 1).
std::vector<std::pair<int, int>> boundary_edges_of(const std::vector<std::array<int, 3>>& triangles) {
  const Eigen::MatrixX3i F = to_matrix(triangles);
  const EdgeMap map = build_edge_map(F);
  std::vector<std::pair<int, int>> edges;
  for (int f = 0; f < F.rows(); ++f)
    for (int i = 0; i < 3; ++i)
      if (map.face_count[map.FE(f, i)] == 1) edges.emplace_back(f, i);
  return edges;
}

// Boundary vertices at exactly the position of another boundary vertex merged into the first of
// them: a surface written one triangle at a time (a soup), or a seam written twice (a UV or normal
// split of an exporter). Faces left with a repeated corner are dropped. Kept when seams_better;
// returns the vertices merged (0 when nothing changed).
int weld_boundary_vertices(std::vector<std::array<int, 3>>& triangles, const std::vector<Eigen::Vector3d>& points) {
  const std::vector<std::pair<int, int>> edges = boundary_edges_of(triangles);
  if (edges.empty()) return 0;
  std::vector<int> boundary;
  for (const auto& [f, i] : edges) boundary.push_back(triangles[f][i]);
  std::sort(boundary.begin(), boundary.end());
  boundary.erase(std::unique(boundary.begin(), boundary.end()), boundary.end());
  const auto key = [&](int v) { return std::array<double, 3>{points[v].x(), points[v].y(), points[v].z()}; };
  std::map<std::array<double, 3>, int> first;
  std::vector<int> target(points.size());
  for (size_t v = 0; v < target.size(); ++v) target[v] = static_cast<int>(v);
  int merged = 0;
  for (int v : boundary) {  // ascending: the first of a group keeps its index
    const auto [it, inserted] = first.emplace(key(v), v);
    if (!inserted) {
      target[v] = it->second;
      ++merged;
    }
  }
  if (merged == 0) return 0;
  std::vector<std::array<int, 3>> welded;
  welded.reserve(triangles.size());
  for (auto t : triangles) {
    for (int& v : t) v = target[v];
    if (t[0] != t[1] && t[1] != t[2] && t[2] != t[0]) welded.push_back(t);
  }
  const int n = static_cast<int>(points.size());
  if (!seams_better(seam_defects(welded, n), seam_defects(triangles, n))) return 0;
  triangles = std::move(welded);
  return merged;
}

// T-junctions: a boundary vertex inside a boundary edge of another face, within `tolerance` (one
// side of a seam has a vertex that the other side lacks). The face of that edge is split at the
// vertex (a fan at its opposite corner; the vertex does not move), in rounds while that finds
// some. Kept when seams_better; returns the faces split (0 when nothing changed).
int split_t_junctions(std::vector<std::array<int, 3>>& triangles, const std::vector<Eigen::Vector3d>& points,
                      double tolerance) {
  using K = CGAL::Simple_cartesian<double>;
  using Segments = std::vector<K::Segment_3>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_segment_primitive<K, Segments::const_iterator>>>;
  const int n = static_cast<int>(points.size());
  const SeamDefects before = seam_defects(triangles, n);
  if (before.boundary == 0) return 0;
  std::vector<std::array<int, 3>> split = triangles;
  int faces_split = 0;
  for (int round = 0; round < 8; ++round) {
    const std::vector<std::pair<int, int>> edges = boundary_edges_of(split);
    Segments segments;
    std::vector<int> boundary;
    const auto point = [&](int v) { return K::Point_3(points[v].x(), points[v].y(), points[v].z()); };
    for (const auto& [f, i] : edges) {
      const int a = split[f][i], b = split[f][(i + 1) % 3];
      segments.emplace_back(point(a), point(b));
      boundary.push_back(a);
    }
    std::sort(boundary.begin(), boundary.end());
    boundary.erase(std::unique(boundary.begin(), boundary.end()), boundary.end());
    const Tree tree(segments.cbegin(), segments.cend());
    // Per face, the vertices inside its one split edge this round, by their place along it.
    std::map<int, std::pair<int, std::vector<std::pair<double, int>>>> cuts;  // face -> (corner, (t, vertex))
    std::vector<Tree::Primitive_id> hits;
    for (int v : boundary) {
      const Eigen::Vector3d& p = points[v];
      hits.clear();
      tree.all_intersected_primitives(CGAL::Bbox_3(p.x() - tolerance, p.y() - tolerance, p.z() - tolerance,
                                                   p.x() + tolerance, p.y() + tolerance, p.z() + tolerance),
                                      std::back_inserter(hits));
      for (const auto& hit : hits) {
        const auto [f, i] = edges[hit - segments.cbegin()];
        const int a = split[f][i], b = split[f][(i + 1) % 3];
        if (v == a || v == b || v == split[f][(i + 2) % 3]) continue;
        const Eigen::Vector3d ab = points[b] - points[a];
        const double t = (p - points[a]).dot(ab) / ab.squaredNorm();
        if (!(t > 0 && t < 1) || (points[a] + t * ab - p).norm() > tolerance) continue;
        if ((p - points[a]).norm() <= tolerance || (p - points[b]).norm() <= tolerance) continue;
        auto& cut = cuts[f];
        if (cut.second.empty()) cut.first = i;
        if (cut.first == i) cut.second.emplace_back(t, v);  // another edge of the face: next round
      }
    }
    if (cuts.empty()) break;
    std::vector<char> replaced(split.size(), 0);
    std::vector<std::array<int, 3>> added;
    for (auto& [f, cut] : cuts) {
      auto& [i, along] = cut;
      std::sort(along.begin(), along.end());
      along.erase(std::unique(along.begin(), along.end(), [](const auto& x, const auto& y) { return x.second == y.second; }),
                  along.end());
      const int a = split[f][i], b = split[f][(i + 1) % 3], c = split[f][(i + 2) % 3];
      int from = a;
      for (const auto& [t, v] : along) {
        added.push_back({from, v, c});
        from = v;
      }
      added.push_back({from, b, c});
      replaced[f] = 1;
      ++faces_split;
    }
    std::vector<std::array<int, 3>> next;
    next.reserve(split.size() + added.size());
    for (size_t f = 0; f < split.size(); ++f)
      if (!replaced[f]) next.push_back(split[f]);
    next.insert(next.end(), added.begin(), added.end());
    split = std::move(next);
  }
  if (faces_split == 0 || !seams_better(seam_defects(split, n), before)) return 0;
  triangles = std::move(split);
  return faces_split;
}

// Keeps the rows of F marked in keep.
Eigen::MatrixX3i select_faces(const Eigen::MatrixX3i& F, const std::vector<char>& keep) {
  Eigen::MatrixX3i out(std::count(keep.begin(), keep.end(), 1), 3);
  int row = 0;
  for (int f = 0; f < F.rows(); ++f)
    if (keep[f]) out.row(row++) = F.row(f);
  return out;
}

// Drops vertices no face uses and renumbers the faces; returns how many were dropped.
int remove_unreferenced_vertices(TriMesh& mesh) {
  std::vector<int> new_index(mesh.num_vertices(), -1);
  int count = 0;
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) {
      int& slot = new_index[mesh.F(f, i)];
      if (slot < 0) slot = count++;
    }
  const int removed = mesh.num_vertices() - count;
  if (removed == 0) {
    // Indices may still be permuted by first use; keep the input order when nothing is removed.
    return 0;
  }
  // Keep the input order of the surviving vertices.
  int next = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (new_index[v] >= 0) new_index[v] = next++;
  Eigen::MatrixX3d V(count, 3);
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (new_index[v] >= 0) V.row(new_index[v]) = mesh.V.row(v);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) mesh.F(f, i) = new_index[mesh.F(f, i)];
  mesh.V = std::move(V);
  return removed;
}

// Gives every face the orientation of its neighbours across manifold edges (breadth first from
// the first face of each component). Returns the number of faces flipped; sets orientable to
// false when a face would need both orientations.
int orient_consistently(Eigen::MatrixX3i& F, bool& orientable) {
  const EdgeMap map = build_edge_map(F);
  const int nf = static_cast<int>(F.rows());
  // Direction of edge e in face f: true when the face runs from E(e,0) to E(e,1).
  auto runs_forward = [&](int f, int e) {
    for (int i = 0; i < 3; ++i)
      if (map.FE(f, i) == e) return F(f, i) == map.E(e, 0);
    return false;
  };
  std::vector<int> flip(nf, -1);
  orientable = true;
  for (int seed = 0; seed < nf; ++seed) {
    if (flip[seed] >= 0) continue;
    flip[seed] = 0;
    std::queue<int> queue;
    queue.push(seed);
    while (!queue.empty()) {
      const int f = queue.front();
      queue.pop();
      for (int i = 0; i < 3; ++i) {
        const int e = map.FE(f, i);
        if (map.face_count[e] != 2) continue;
        const int g = map.EF(e, 0) == f ? map.EF(e, 1) : map.EF(e, 0);
        // Neighbours agree when they run the shared edge in opposite directions.
        const bool same_direction = runs_forward(f, e) == runs_forward(g, e);
        const int wanted = flip[f] ^ (same_direction ? 1 : 0);
        if (flip[g] < 0) {
          flip[g] = wanted;
          queue.push(g);
        } else if (flip[g] != wanted) {
          orientable = false;
        }
      }
    }
  }
  if (!orientable) return 0;
  int flipped = 0;
  for (int f = 0; f < nf; ++f)
    if (flip[f] == 1) {
      std::swap(F(f, 1), F(f, 2));
      ++flipped;
    }
  return flipped;
}

// Flips every closed component whose enclosed volume is negative; returns faces flipped.
int orient_outward(TriMesh& mesh) {
  Eigen::VectorXi component;
  const int count = connected_components(mesh.F, mesh.num_vertices(), &component);
  std::vector<double> volume(count, 0.0);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    volume[component[f]] += a.dot(b.cross(c));
  }
  int flipped = 0;
  for (int f = 0; f < mesh.num_faces(); ++f)
    if (volume[component[f]] < 0) {
      std::swap(mesh.F(f, 1), mesh.F(f, 2));
      ++flipped;
    }
  return flipped;
}

// A closed surface enclosing at most this times its bounding-box diagonal cubed lies on itself
// (a sheet closed by --fill-holes onto its own back, a flat pillow): no cross-section of it has
// an inside. A plate 1 × 1 × 0.001 encloses 3.5e-4 of its diagonal cubed.
constexpr double kFlatVolume = 1e-9;

// Faces of zero area: their corners exactly on a line, or the smallest altitude (twice the area
// over the longest edge) at most min_altitude.
int count_zero_area_faces(const TriMesh& mesh, double min_altitude) {
  int count = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    auto p = [&](int i) { return cgal::Point(mesh.V(mesh.F(f, i), 0), mesh.V(mesh.F(f, i), 1), mesh.V(mesh.F(f, i), 2)); };
    if (CGAL::collinear(p(0), p(1), p(2))) {
      ++count;
      continue;
    }
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    if ((b - a).cross(c - a).norm() <= min_altitude * longest) ++count;
  }
  return count;
}

// The altitude below which a face of mesh counts as zero-area; -1 (exactly collinear faces only)
// when the diagonal is out of range, whose products of lengths would overflow or underflow.
double zero_altitude(const TriMesh& mesh) {
  const double diagonal = bounding_box(mesh.V).diagonal();
  return diagonal >= kSmallestDiagonal && diagonal <= kLargestDiagonal ? kZeroAltitude * diagonal : -1;
}

// Closes every boundary loop of a manifold, oriented mesh; returns the number of loops filled.
int fill_holes(TriMesh& mesh) {
  cgal::SurfaceMesh sm = cgal::to_surface_mesh(mesh);
  std::vector<cgal::SurfaceMesh::Halfedge_index> loops;
  std::set<cgal::SurfaceMesh::Halfedge_index> seen;
  for (auto h : sm.halfedges()) {
    if (!sm.is_border(h) || seen.count(h)) continue;
    loops.push_back(h);
    for (auto g : CGAL::halfedges_around_face(h, sm)) seen.insert(g);
  }
  for (auto h : loops) {
    std::vector<cgal::SurfaceMesh::Face_index> new_faces;
    std::vector<cgal::SurfaceMesh::Vertex_index> new_vertices;
    PMP::triangulate_and_refine_hole(sm, h, std::back_inserter(new_faces), std::back_inserter(new_vertices));
  }
  mesh = cgal::to_tri_mesh(sm);
  return static_cast<int>(loops.size());
}

// Removes zero-area faces by CGAL's edge collapses and flips, on a copy; the copy replaces the
// mesh only when it is still a manifold with the same boundary and no zero-area face is left.
// Exactly collinear faces first; then those with an altitude at most min_altitude: their edges
// no longer than 4 × min_altitude collapsed (needles), the long edge under a corner within
// min_altitude of it flipped (caps).
bool remove_degenerate_faces(TriMesh& mesh, double min_altitude) {
  try {
    cgal::SurfaceMesh sm = cgal::to_surface_mesh(mesh);
    if (!PMP::remove_degenerate_faces(sm)) return false;
    // A flip can leave a new zero-area face, which the next call takes (issue945e.stl of
    // OpenSCAD's tests: 9 faces, 2 left after the first call, none after the second).
    for (int round = 0, left = count_zero_area_faces(cgal::to_tri_mesh(sm), min_altitude); left > 0 && round < 8; ++round) {
      PMP::experimental::remove_almost_degenerate_faces(sm, -0.5, 1.0, 4 * min_altitude,
                                                        CGAL::parameters::flip_triangle_height_threshold(min_altitude));
      sm.collect_garbage();
      const int now = count_zero_area_faces(cgal::to_tri_mesh(sm), min_altitude);
      if (now >= left) break;
      left = now;
    }
    TriMesh repaired = cgal::to_tri_mesh(sm);
    const EdgeMap map = build_edge_map(repaired.F);
    const EdgeMap before = build_edge_map(mesh.F);
    const auto boundary = [](const EdgeMap& m) { return (m.face_count.array() == 1).count(); };
    if ((map.face_count.array() > 2).any() || boundary(map) != boundary(before)) return false;
    if (count_nonmanifold_vertices(repaired.F, repaired.num_vertices()) > 0) return false;
    if (count_zero_area_faces(repaired, min_altitude) > 0) return false;
    mesh = std::move(repaired);
    return true;
  } catch (const std::exception&) {
    return false;  // CGAL refused (e.g. a non-manifold configuration): leave the mesh as it was
  }
}

}  // namespace

PreparedMesh prepare_mesh(const PolygonSoup& soup, const PrepareOptions& options) {
  PreparedMesh result;
  MeshDiagnosis& d = result.diagnosis;
  d.input_vertices = static_cast<int>(soup.points.size());
  d.input_polygons = static_cast<int>(soup.polygons.size());

  const int np = d.input_vertices;
  for (int v = 0; v < np; ++v)
    if (!soup.points[v].allFinite())
      throw InputError("vertex " + std::to_string(v) + " has a non-finite coordinate");

  // Triangulate; drop repeated corners inside a polygon first.
  std::vector<std::array<int, 3>> triangles;
  int polygons_split = 0, collapsed_polygons = 0;
  for (size_t p = 0; p < soup.polygons.size(); ++p) {
    std::vector<int> polygon;
    for (int v : soup.polygons[p]) {
      if (v < 0 || v >= np)
        throw InputError("face " + std::to_string(p) + " refers to vertex " + std::to_string(v) + ", but there are " +
                         std::to_string(np) + " vertices");
      if (polygon.empty() || polygon.back() != v) polygon.push_back(v);
    }
    while (polygon.size() > 1 && polygon.front() == polygon.back()) polygon.pop_back();
    std::vector<int> sorted = polygon;
    std::sort(sorted.begin(), sorted.end());
    if (polygon.size() < 3 || std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
      ++collapsed_polygons;  // a repeated corner: the face covers no area as a polygon
      continue;
    }
    if (polygon.size() > 3) ++polygons_split;
    triangulate_polygon(soup, polygon, triangles);
  }
  if (polygons_split > 0)
    result.repairs.push_back("triangulated " + plural(polygons_split, "polygon") + " with more than 3 corners");
  if (collapsed_polygons > 0)
    result.repairs.push_back("removed " + plural(collapsed_polygons, "face") + " with repeated corners");

  // Seams: copies of one point on a boundary merged, then T-junctions split (both only where the
  // mesh has a boundary, so a closed mesh is never touched).
  if (const int welded = weld_boundary_vertices(triangles, soup.points); welded > 0)
    result.repairs.push_back("merged " + plural(welded, "boundary vertex") + " into others at the same position");
  {
    BoundingBox box;
    box.min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    box.max = -box.min;
    for (const auto& t : triangles)
      for (int v : t) {
        box.min = box.min.cwiseMin(soup.points[v]);
        box.max = box.max.cwiseMax(soup.points[v]);
      }
    const double tolerance = kTJunctionTolerance * box.diagonal();
    if (std::isfinite(tolerance) && tolerance > 0)
      if (const int split = split_t_junctions(triangles, soup.points, tolerance); split > 0)
        result.repairs.push_back("split " + plural(split, "face") + " at T-junctions (a boundary vertex inside another face's edge)");
  }

  // Drop exact duplicates (same corner set), keeping the first.
  {
    std::vector<std::array<int, 3>> unique = unique_faces(triangles);
    const int duplicates = static_cast<int>(triangles.size() - unique.size());
    if (duplicates > 0) result.repairs.push_back("removed " + plural(duplicates, "duplicate face"));
    triangles = std::move(unique);
  }

  TriMesh& mesh = result.mesh;
  mesh.V.resize(np, 3);
  for (int v = 0; v < np; ++v) mesh.V.row(v) = soup.points[v].transpose();
  mesh.F = to_matrix(triangles);
  if (const int removed = remove_unreferenced_vertices(mesh); removed > 0)
    result.repairs.push_back("removed " + plural(removed, "unreferenced vertex"));
  // Far from the origin, moved there before anything adds up products of positions (the outward
  // orientation's signed volume, the stages' contour areas). Along an axis on which the model is
  // far, each coordinate is within a factor 2 of the centre's, so the difference is exact
  // (Sterbenz); along the others it is rounded once.
  if (mesh.num_vertices() > 0 && options.centre_beyond_diagonals > 0) {
    const BoundingBox box = bounding_box(mesh.V);
    const Eigen::Vector3d centre = (box.min + box.max) / 2;
    if (std::isfinite(box.diagonal()) && centre.norm() > options.centre_beyond_diagonals * box.diagonal()) {
      result.offset = centre;
      mesh.V.rowwise() -= centre.transpose();
      std::ostringstream moved;
      moved << "moved the model to the origin (its centre lies " << std::setprecision(3) << centre.norm() / box.diagonal()
            << " diagonals away); outputs are moved back";
      result.repairs.push_back(moved.str());
    }
  }

  if (mesh.num_faces() == 0) {
    d.problems.push_back("no faces");
    d.bbox = bounding_box(mesh.V);
    d.vertices = mesh.num_vertices();
    return result;
  }

  // Orientation across manifold edges.
  EdgeMap map = build_edge_map(mesh.F);
  d.nonmanifold_edges = static_cast<int>((map.face_count.array() > 2).count());
  if (const int flipped = orient_consistently(mesh.F, d.orientable); flipped > 0)
    result.repairs.push_back("flipped " + plural(flipped, "face") + " to orient the surface consistently");

  if (options.largest_component) {
    Eigen::VectorXi component;
    const int count = connected_components(mesh.F, mesh.num_vertices(), &component);
    if (count > 1) {
      std::vector<int> size(count, 0);
      for (int f = 0; f < mesh.num_faces(); ++f) ++size[component[f]];
      const int largest = static_cast<int>(std::max_element(size.begin(), size.end()) - size.begin());
      std::vector<char> keep(mesh.num_faces());
      for (int f = 0; f < mesh.num_faces(); ++f) keep[f] = component[f] == largest;
      mesh.F = select_faces(mesh.F, keep);
      remove_unreferenced_vertices(mesh);
      result.repairs.push_back("kept the largest of " + plural(count, "component") + " (" +
                               std::to_string(size[largest]) + " faces)");
    }
  }

  const bool repairable = d.orientable && d.nonmanifold_edges == 0 &&
                          count_nonmanifold_vertices(mesh.F, mesh.num_vertices()) == 0;
  if (options.fill_holes && repairable) {
    if (const int loops = static_cast<int>(boundary_loops(mesh.F).size()); loops > 0) {
      fill_holes(mesh);
      const int left = static_cast<int>(boundary_loops(mesh.F).size());
      if (left < loops)
        result.repairs.push_back("filled " + plural(loops - left, "hole") + (left > 0 ? " of " + std::to_string(loops) : ""));
    }
  }

  if (const double min_altitude = zero_altitude(mesh); const int zero_area = count_zero_area_faces(mesh, min_altitude)) {
    if (repairable && remove_degenerate_faces(mesh, min_altitude))
      result.repairs.push_back("removed " + plural(zero_area, "zero-area face") + " by edge collapses and flips");
  }

  // Diagnose the result.
  map = build_edge_map(mesh.F);
  d.vertices = mesh.num_vertices();
  d.faces = mesh.num_faces();
  d.edges = map.num_edges();
  d.nonmanifold_edges = static_cast<int>((map.face_count.array() > 2).count());
  d.boundary_edges = static_cast<int>((map.face_count.array() == 1).count());
  d.nonmanifold_vertices = count_nonmanifold_vertices(mesh.F, mesh.num_vertices());
  d.components = connected_components(mesh.F, mesh.num_vertices());
  d.boundary_loops = d.boundary_edges > 0 ? static_cast<int>(boundary_loops(mesh.F).size()) : 0;
  d.degenerate_faces = count_zero_area_faces(mesh, zero_altitude(mesh));
  d.euler = d.vertices - d.edges + d.faces;
  d.bbox = bounding_box(mesh.V);
  d.bbox.min += result.offset;  // the input's
  d.bbox.max += result.offset;

  double volume = std::numeric_limits<double>::quiet_NaN();  // of a closed, outward mesh
  if (d.manifold() && d.orientable) {
    d.genus = genus(mesh.F, mesh.num_vertices());
    if (d.closed()) {
      if (const int flipped = orient_outward(mesh); flipped > 0)
        result.repairs.push_back("reversed the orientation of " + plural(flipped, "face") + " to face outward");
      volume = signed_volume(mesh);
    }
    if (options.check_self_intersections) {
      d.self_intersections = static_cast<int>(self_intersecting_faces(mesh).size());
    }
  }

  // Every face of zero area (all vertices at one place, or on a line) is removed above.
  if (d.faces == 0) d.problems.push_back("no faces of non-zero area");
  // Squared areas and lengths must stay normal doubles (a coordinate of 1e300: the diagonal is
  // infinite and every later stage divides by it).
  const bool size_in_range = d.bbox.diagonal() >= kSmallestDiagonal && d.bbox.diagonal() <= kLargestDiagonal;
  if (d.faces > 0 && !size_in_range) {
    std::ostringstream size;
    size << "bounding-box diagonal " << d.bbox.diagonal() << " is outside " << kSmallestDiagonal << " .. " << kLargestDiagonal
         << " (scale the model)";
    d.problems.push_back(size.str());
  }
  if (d.nonmanifold_edges > 0)
    d.problems.push_back(plural(d.nonmanifold_edges, "non-manifold edge") + " (more than two faces on an edge)");
  if (d.nonmanifold_vertices > 0)
    d.problems.push_back(plural(d.nonmanifold_vertices, "non-manifold vertex") + " (faces around it form several fans)");
  if (!d.orientable) d.problems.push_back("not orientable (no consistent face orientation exists)");
  if (d.boundary_edges > 0)
    d.problems.push_back("open surface: " + plural(d.boundary_loops, "boundary loop") + " (" +
                         plural(d.boundary_edges, "boundary edge") +
                         (!options.fill_holes ? "; --fill-holes closes them)"
                          : repairable        ? "; --fill-holes could not close them)"
                                              : "; --fill-holes needs a manifold, oriented mesh)"));
  if (d.components > 1)
    d.problems.push_back(plural(d.components, "connected component") + " (--largest-component keeps the largest)");
  if (d.degenerate_faces > 0) d.problems.push_back(plural(d.degenerate_faces, "zero-area face") + " that could not be removed");
  if (d.faces > 0 && size_in_range && volume <= kFlatVolume * std::pow(d.bbox.diagonal(), 3))
    d.problems.push_back("the closed surface encloses no volume (its sides lie on each other: a flat or doubled sheet)");
  if (d.self_intersections > 0)
    d.warnings.push_back(plural(d.self_intersections, "pair") + " of self-intersecting faces (tolerated: the map is intrinsic)");
  return result;
}

void require_mappable(const MeshDiagnosis& diagnosis) {
  if (diagnosis.valid()) return;
  std::ostringstream message;
  message << "mesh is not mappable: ";
  for (size_t i = 0; i < diagnosis.problems.size(); ++i) message << (i ? "; " : "") << diagnosis.problems[i];
  throw MeshError(message.str());
}

}  // namespace polycube
