#include "polycube/map_overlay.h"

#include "polycube/barycentric.h"
#include "polycube/closest_point.h"
#include "polycube/errors.h"
#include "polycube/image_orientation.h"
#include "polycube/map_audit.h"
#include "polycube/mesh_topology.h"
#include "polycube/polycube_map_data.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

namespace polycube {

namespace {

// What made a vertex of a cell: a vertex of the P disk (kind 0, a), a vertex of the M disk
// (kind 1, a), or the crossing of P disk edge (a, b) with M disk edge (c, d) (kind 2; a < b, c < d).
struct Tag {
  int kind = 0, a = -1, b = -1, c = -1, d = -1;
  bool operator==(const Tag& o) const { return kind == o.kind && a == o.a && b == o.b && c == o.c && d == o.d; }
};

// The line a cell edge lies on: an edge of the P disk (side 0) or of the M disk (side 1), ends sorted.
struct Support {
  int side = 0, u = -1, v = -1;
};

struct Corner {
  Eigen::Vector2d uv;
  Tag tag;
};

using ExactPoint = CGAL::Exact_predicates_inexact_constructions_kernel::Point_2;

int orientation(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const CGAL::Orientation o = CGAL::orientation(ExactPoint(a.x(), a.y()), ExactPoint(b.x(), b.y()), ExactPoint(c.x(), c.y()));
  return o == CGAL::LEFT_TURN ? 1 : (o == CGAL::RIGHT_TURN ? -1 : 0);
}

// Sign of (b - a) × (c - d), exactly (a filter, then rationals).
int cross_sign(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  const double x1 = b.x() - a.x(), y1 = b.y() - a.y(), x2 = c.x() - d.x(), y2 = c.y() - d.y();
  const double value = x1 * y2 - y1 * x2;
  const double bound = 1e-14 * (std::abs(x1 * y2) + std::abs(y1 * x2) + (std::abs(a.x()) + std::abs(b.x()) + std::abs(a.y()) + std::abs(b.y())) *
                                                                             (std::abs(c.x()) + std::abs(d.x()) + std::abs(c.y()) + std::abs(d.y())));
  if (std::abs(value) > bound) return value > 0 ? 1 : -1;
  using Q = CGAL::Exact_rational;
  const Q exact = (Q(b.x()) - Q(a.x())) * (Q(c.y()) - Q(d.y())) - (Q(b.y()) - Q(a.y())) * (Q(c.x()) - Q(d.x()));
  return CGAL::sign(exact);
}

// The disks' vertex positions the clipping reads.
struct Disks {
  const Eigen::MatrixX2d& p;  // P disk uv
  const Eigen::MatrixX2d& m;  // M disk uv
};

// Clips the convex polygon `poly` (counter-clockwise; its edge i runs from corner i to i + 1 on
// supports[i]) by the closed half-plane left of the edge from s0 to s1 of the M disk triangle it
// is being clipped by. Which side each corner is on is decided exactly from what made it, never
// from its rounded position, so that neighbouring cells agree about every point:
//   - a vertex of T: the orientation test (the disks' shared boundary points lie exactly on
//     the lines through them);
//   - a vertex of the triangle: on the line if it is one of its ends, inside otherwise;
//   - a crossing of T's edge (a, b) with the line of another edge (v, w) of the triangle, v
//     shared with this one: it lies at t = f(v) / (f(v) − f(w)) along v → w, f the orientation
//     against a → b, inside when t > 0 (on the line at t = 0).
void clip(std::vector<Corner>& poly, std::vector<Support>& supports, const Disks& disks, int s0, int s1) {
  const int n = static_cast<int>(poly.size());
  if (n == 0) return;
  const Eigen::Vector2d p0 = disks.m.row(s0), p1 = disks.m.row(s1);
  const Eigen::Vector2d direction = p1 - p0;
  const Support line{1, std::min(s0, s1), std::max(s0, s1)};
  std::vector<double> side(n);
  std::vector<int> sign(n);
  bool all_in = true;
  for (int i = 0; i < n; ++i) {
    const Tag& tag = poly[i].tag;
    side[i] = cross2(direction, poly[i].uv - p0);
    if (tag.kind == 0) {
      sign[i] = orientation(p0, p1, poly[i].uv);
    } else if (tag.kind == 1) {
      sign[i] = (tag.a == s0 || tag.a == s1) ? 0 : 1;
    } else if (tag.c == line.u && tag.d == line.v) {
      sign[i] = 0;
    } else {
      const int v = (tag.c == s0 || tag.c == s1) ? tag.c : tag.d, w = v == tag.c ? tag.d : tag.c;
      const Eigen::Vector2d a = disks.p.row(tag.a), b = disks.p.row(tag.b), pv = disks.m.row(v), pw = disks.m.row(w);
      const int fv = orientation(a, b, pv);
      // sign(f(v) − f(w)) = sign((b − a) × (v − w)).
      sign[i] = fv == 0 ? 0 : fv * cross_sign(a, b, pv, pw);
    }
    all_in = all_in && sign[i] >= 0;
  }
  if (all_in) return;
  std::vector<Corner> out;
  std::vector<Support> out_supports;
  const auto crossing = [&](int i, int j) {
    Corner x;
    const double denominator = side[i] - side[j];
    const double t = denominator != 0 ? std::clamp(side[i] / denominator, 0.0, 1.0) : 0.5;
    x.uv = poly[i].uv + t * (poly[j].uv - poly[i].uv);
    const Support& e = supports[i];
    if (e.side == 0) {
      x.tag = Tag{2, e.u, e.v, line.u, line.v};
    } else {
      // Two edges of the same M disk triangle meet at their common vertex.
      const int common = (e.u == line.u || e.u == line.v) ? e.u : e.v;
      x.tag = Tag{1, common};
      x.uv = disks.m.row(common);
    }
    return x;
  };
  // A corner on the line (the disks share their boundary points, ends of edges of both) is where
  // the polygon leaves or enters the half-plane: no crossing is made next to it.
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const bool in_i = sign[i] >= 0, in_j = sign[j] >= 0;
    if (in_i) {
      out.push_back(poly[i]);
      out_supports.push_back(supports[i]);
      if (!in_j) {
        if (sign[i] == 0) {
          out_supports.back() = line;
        } else {
          out.push_back(crossing(i, j));
          out_supports.push_back(line);
        }
      }
    } else if (in_j && sign[j] != 0) {
      out.push_back(crossing(i, j));
      out_supports.push_back(supports[i]);
    }
  }
  poly = std::move(out);
  supports = std::move(out_supports);
}

struct KeyHash {
  size_t operator()(const std::array<int, 6>& k) const {
    size_t h = 1469598103934665603ull;
    for (int x : k) h = (h ^ static_cast<size_t>(static_cast<unsigned>(x))) * 1099511628211ull;
    return h;
  }
};

// Points of P welded by position (the disks' common boundary): a hash grid of cell `tolerance`.
class PositionWeld {
 public:
  explicit PositionWeld(double tolerance) : tolerance_(tolerance) {}
  // The id of a point within the tolerance of x, or `fresh` (then recorded for x).
  int find_or_add(const Eigen::Vector3d& x, int fresh) {
    const std::array<long long, 3> cell = cell_of(x);
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          const auto it = grid_.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
          if (it == grid_.end()) continue;
          for (const auto& [p, id] : it->second)
            if ((p - x).norm() <= tolerance_) return id;
        }
    grid_[cell].emplace_back(x, fresh);
    return fresh;
  }

 private:
  std::array<long long, 3> cell_of(const Eigen::Vector3d& x) const {
    return {static_cast<long long>(std::floor(x.x() / tolerance_)), static_cast<long long>(std::floor(x.y() / tolerance_)),
            static_cast<long long>(std::floor(x.z() / tolerance_))};
  }
  double tolerance_;
  std::map<std::array<long long, 3>, std::vector<std::pair<Eigen::Vector3d, int>>> grid_;
};

// The point of disk face f at disk position uv, on the surface the disk was cut from.
Eigen::Vector3d on_surface(const DiskEmbedding& disk, int f, const Eigen::Vector2d& uv) {
  const Eigen::Vector3d w =
      clamp_bary(barycentric2(disk.uv.row(disk.mesh.F(f, 0)), disk.uv.row(disk.mesh.F(f, 1)), disk.uv.row(disk.mesh.F(f, 2)), uv));
  return w[0] * disk.mesh.V.row(disk.mesh.F(f, 0)).transpose() + w[1] * disk.mesh.V.row(disk.mesh.F(f, 1)).transpose() +
         w[2] * disk.mesh.V.row(disk.mesh.F(f, 2)).transpose();
}

// Cells too small for the audit (image or P area at or below kTinyArea of the total): their
// shortest edges collapsed, the removed end never one of P's own vertices, only where the mesh
// stays a manifold (link condition) and every triangle moved stays in its P face's plane and in
// its model face (to a tenth of the audit's in-face tolerance); a moved triangle that is not tiny
// must keep its orientation on both and not become tiny, a tiny one must not turn over by more
// than the audit's degenerate area (a cluster of tiny cells where an edge of P, an edge of the
// model and a cutting plane meet merges step by step: cheese had 10 image triangles below the
// audit's area when tiny ones had to shrink too). Passes repeat while collapses are made, at
// most 20. Then the tiny cells left get an edge flipped (longest first) where both faces lie in
// one face of P and one face of the model and both new triangles are positive and not tiny on
// both (the two tile the same quadrilateral of P and of the model, so the tiling and areas are
// kept; the map is then affine on the pair's union instead of on each). What is left is mostly
// the map's own crowding: whole P triangles squeezed to 1e-19 of the model's area (bull) are
// beyond any flip. (Flips across two P triangles of one plane, allowed down to the audit's
// degenerate area, removed some of those on cow and bull, but changed which exact sampling of
// cow's untangled clean: 0 / 1 instead of 0 / 0; not kept.) Counts in out.collapsed and
// out.flipped_edges.
constexpr double kTinyArea = 1e-12;

void collapse_tiny_cells(MapOverlay& out, int own, const TriMesh& P, const TriMesh& M) {
  TriMesh& R = out.polycube;
  const Eigen::MatrixX3d& image = out.on_model_xyz;
  const int nv = R.num_vertices();
  const auto area_vector = [](const auto& X, int a, int b, int c) -> Eigen::Vector3d {
    const Eigen::Vector3d x = X.row(a), y = X.row(b), z = X.row(c);
    return 0.5 * (y - x).cross(z - x);
  };
  // Unit normals of P's and M's faces, and their total areas.
  const auto normals = [&](const TriMesh& mesh, double& area) {
    std::vector<Eigen::Vector3d> unit(mesh.num_faces());
    area = 0;
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const Eigen::Vector3d v = area_vector(mesh.V, mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2));
      area += v.norm();
      unit[f] = v.normalized();
    }
    return unit;
  };
  double p_area = 0, m_area = 0;
  const std::vector<Eigen::Vector3d> p_normal = normals(P, p_area), m_normal = normals(M, m_area);
  const double tiny_p = kTinyArea * p_area, tiny_m = kTinyArea * m_area;
  const double degenerate_p = kAuditDegenerateArea * p_area, degenerate_m = kAuditDegenerateArea * m_area;
  const double plane_tolerance = 1e-12 * (P.V.colwise().maxCoeff() - P.V.colwise().minCoeff()).norm();
  const double in_face = 0.1 * kInFaceTolerance * (M.V.colwise().maxCoeff() - M.V.colwise().minCoeff()).norm();
  const auto tiny = [&](int f) {
    return area_vector(R.V, R.F(f, 0), R.F(f, 1), R.F(f, 2)).norm() <= tiny_p ||
           area_vector(image, R.F(f, 0), R.F(f, 1), R.F(f, 2)).norm() <= tiny_m;
  };
  std::vector<std::vector<int>> around(nv);
  for (int f = 0; f < R.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) around[R.F(f, k)].push_back(f);
  std::vector<char> dead(R.num_faces(), 0);
  std::vector<int> neighbours_r, neighbours_k;
  const auto neighbours = [&](int v, std::vector<int>& list) {
    list.clear();
    for (int f : around[v])
      if (!dead[f])
        for (int k = 0; k < 3; ++k)
          if (R.F(f, k) != v) list.push_back(R.F(f, k));
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  };
  // Removes r into k if every condition holds.
  const auto try_collapse = [&](int r, int k) {
    if (r < own) return false;
    neighbours(r, neighbours_r);
    neighbours(k, neighbours_k);
    int common = 0, shared_faces = 0;
    for (int x : neighbours_r) common += std::binary_search(neighbours_k.begin(), neighbours_k.end(), x);
    for (int f : around[r])
      if (!dead[f] && (R.F(f, 0) == k || R.F(f, 1) == k || R.F(f, 2) == k)) ++shared_faces;
    if (shared_faces != 2 || common != 2) return false;
    for (int f : around[r]) {
      if (dead[f] || R.F(f, 0) == k || R.F(f, 1) == k || R.F(f, 2) == k) continue;
      int c[3] = {R.F(f, 0), R.F(f, 1), R.F(f, 2)};
      for (int& x : c)
        if (x == r) x = k;
      const int parent = out.face_parent[f];
      if (std::abs((R.V.row(k) - P.V.row(P.F(parent, 0))).dot(p_normal[parent])) > plane_tolerance) return false;
      const Eigen::Vector3d on_p = area_vector(R.V, c[0], c[1], c[2]), on_m = area_vector(image, c[0], c[1], c[2]);
      const Eigen::Vector3d old_p = area_vector(R.V, R.F(f, 0), R.F(f, 1), R.F(f, 2)), old_m = area_vector(image, R.F(f, 0), R.F(f, 1), R.F(f, 2));
      if (old_p.norm() > tiny_p && old_m.norm() > tiny_m) {
        // A triangle that is not tiny keeps its orientation and stays not tiny.
        if (!(on_p.dot(p_normal[parent]) > tiny_p)) return false;
        if (!(on_m.norm() > tiny_m)) return false;
        if (!(on_m.dot(m_normal[out.face_image[f]]) > 0)) return false;
      } else {
        // A tiny one (to be removed in turn) may stay tiny, but not turn over by more than the
        // audit's degenerate area (it would count as flipped).
        if (!(on_p.dot(p_normal[parent]) > -degenerate_p) || !(on_m.dot(m_normal[out.face_image[f]]) > -degenerate_m)) return false;
      }
      // And it stays in its model face (the audit then judges it by that face alone).
      const int mf = out.face_image[f];
      const Eigen::Vector3d y = image.row(k);
      if ((closest_on_triangle(y, M.V.row(M.F(mf, 0)), M.V.row(M.F(mf, 1)), M.V.row(M.F(mf, 2))).point - y).norm() > in_face) return false;
    }
    for (int f : around[r]) {
      if (dead[f]) continue;
      if (R.F(f, 0) == k || R.F(f, 1) == k || R.F(f, 2) == k) {
        dead[f] = 1;
        continue;
      }
      for (int i = 0; i < 3; ++i)
        if (R.F(f, i) == r) R.F(f, i) = k;
      around[k].push_back(f);
    }
    around[r].clear();
    return true;
  };
  // Passes over the tiny faces (at most 20, while some step succeeds): per face, `step(f, i)` on
  // its edges i (from corner i to i + 1) by their length on both surfaces, shortest first or
  // longest first, until one succeeds. Returns the successes.
  const auto sweep = [&](bool longest_first, const auto& step) {
    int total = 0;
    for (int pass = 0; pass < 20; ++pass) {
      int made = 0;
      for (int f = 0; f < R.num_faces(); ++f) {
        if (dead[f] || !tiny(f)) continue;
        std::array<std::pair<double, int>, 3> edges;
        for (int i = 0; i < 3; ++i) {
          const int a = R.F(f, i), b = R.F(f, (i + 1) % 3);
          const double length = (R.V.row(a) - R.V.row(b)).norm() + (image.row(a) - image.row(b)).norm();
          edges[i] = {longest_first ? -length : length, i};
        }
        std::sort(edges.begin(), edges.end());
        for (const auto& [length, i] : edges)
          if (step(f, i)) {
            ++made;
            break;
          }
      }
      total += made;
      if (made == 0) break;
    }
    return total;
  };
  // Collapses first, each edge tried both ways.
  const int collapses = sweep(false, [&](int f, int i) {
    const int a = R.F(f, i), b = R.F(f, (i + 1) % 3);
    return try_collapse(a, b) || try_collapse(b, a);
  });
  // The tiny cells left: edge flips.
  const int flips = sweep(true, [&](int f, int i) {
    const int a = R.F(f, i), b = R.F(f, (i + 1) % 3), c = R.F(f, (i + 2) % 3);
    int g = -1, d = -1;
    for (int h : around[a]) {
      if (dead[h] || h == f) continue;
      for (int k = 0; k < 3; ++k)
        if (R.F(h, k) == b && R.F(h, (k + 1) % 3) == a) {
          g = h;
          d = R.F(h, (k + 2) % 3);
        }
    }
    if (g < 0 || out.face_parent[g] != out.face_parent[f] || out.face_image[g] != out.face_image[f]) return false;
    neighbours(c, neighbours_r);
    if (std::binary_search(neighbours_r.begin(), neighbours_r.end(), d)) return false;  // edge c-d exists
    const int pf = out.face_parent[f], mf = out.face_image[f];
    bool ok = true;
    for (const auto& t : {std::array<int, 3>{c, a, d}, std::array<int, 3>{d, b, c}}) {
      const Eigen::Vector3d on_p = area_vector(R.V, t[0], t[1], t[2]), on_m = area_vector(image, t[0], t[1], t[2]);
      ok = ok && on_p.dot(p_normal[pf]) > tiny_p && on_m.dot(m_normal[mf]) > tiny_m;
    }
    if (!ok) return false;
    R.F.row(f) << c, a, d;
    R.F.row(g) << d, b, c;
    // f left b and gained d, g left a and gained c.
    around[b].erase(std::find(around[b].begin(), around[b].end(), f));
    around[a].erase(std::find(around[a].begin(), around[a].end(), g));
    around[d].push_back(f);
    around[c].push_back(g);
    return true;
  });
  out.collapsed = collapses;
  out.flipped_edges = flips;
  if (collapses + flips == 0) return;
  // Compaction: live faces, used vertices (P's own keep their ids: never removed).
  std::vector<int> new_id(nv, -1);
  int next = 0;
  for (int v = 0; v < nv; ++v)
    if (v < own || !around[v].empty()) new_id[v] = next++;
  TriMesh compact;
  compact.V.resize(next, 3);
  Eigen::MatrixX3d compact_image(next, 3);
  std::vector<SurfacePoint> compact_on_model(next);
  for (int v = 0; v < nv; ++v)
    if (new_id[v] >= 0) {
      compact.V.row(new_id[v]) = R.V.row(v);
      compact_image.row(new_id[v]) = image.row(v);
      compact_on_model[new_id[v]] = out.on_model[v];
    }
  int live = 0;
  for (int f = 0; f < R.num_faces(); ++f) live += !dead[f];
  compact.F.resize(live, 3);
  Eigen::VectorXi parent(live), image_face(live);
  for (int f = 0, g = 0; f < R.num_faces(); ++f)
    if (!dead[f]) {
      for (int i = 0; i < 3; ++i) compact.F(g, i) = new_id[R.F(f, i)];
      parent[g] = out.face_parent[f];
      image_face[g] = out.face_image[f];
      ++g;
    }
  out.polycube = std::move(compact);
  out.on_model_xyz = std::move(compact_image);
  out.on_model = std::move(compact_on_model);
  out.face_parent = std::move(parent);
  out.face_image = std::move(image_face);
}

}  // namespace

MapOverlay overlay_map(const PolycubeMap& map) {
  const auto start = std::chrono::steady_clock::now();
  if (!map.data) throw std::invalid_argument("overlay_map: the map has no pieces (not built by build_polycube_map)");
  const PolycubeMapData& data = *map.data;
  const TriMesh& P = data.polycube;
  const TriMesh& M = data.model;
  const int own = P.num_vertices();
  Eigen::Vector3d lo = P.V.colwise().minCoeff(), hi = P.V.colwise().maxCoeff();
  PositionWeld weld(1e-9 * (hi - lo).norm());

  MapOverlay out;
  std::vector<Eigen::Vector3d> on_polycube(own, Eigen::Vector3d::Constant(NAN));
  std::vector<SurfacePoint> on_model(own);
  std::vector<char> seen(own, 0);
  std::unordered_map<std::array<int, 6>, int, KeyHash> keyed;
  std::vector<Eigen::Vector3i> faces;
  std::vector<int> face_parent, face_image;

  // P's own vertices on the disks' boundaries first, so that welding by position keeps their ids.
  for (const PiecePair& pair : data.pairs) {
    const DiskEmbedding& pd = pair.polycube.disk;
    for (int p = 0; p < pd.mesh.num_vertices(); ++p) {
      const int o = pd.vertex_origin[p];
      if (!pd.fixed[p] || o < 0 || o >= pair.polycube.piece.mesh.num_vertices()) continue;
      const int g = pair.polycube.piece.vertex_to_global[o];
      if (g < own) weld.find_or_add(pd.mesh.V.row(p), g);
    }
  }
  for (int j = 0; j < static_cast<int>(data.pairs.size()); ++j) {
    const PiecePair& pair = data.pairs[j];
    const SideDisk& PS = pair.polycube;
    const SideDisk& MS = pair.model;
    const DiskEmbedding& pd = PS.disk;
    const DiskEmbedding& md = MS.disk;
    if (!MS.locator || pd.mesh.num_faces() == 0) continue;
    const EdgeMap m_edges = build_edge_map(md.mesh.F);
    std::vector<int> stamp(md.mesh.num_faces(), -1);
    const int piece_vertices = PS.piece.mesh.num_vertices();

    // The output vertex of a cell corner (in P disk face t and M disk face s).
    const auto vertex_of = [&](const Tag& tag, const Eigen::Vector2d& uv, int t, int s) {
      // On the disks' common boundary (contours, slits): welded by position. Inside: by origin.
      const bool boundary = (tag.kind == 0 && pd.fixed[tag.a]) || (tag.kind == 1 && md.fixed[tag.a]);
      std::array<int, 6> key{};
      int id = -1;
      if (!boundary) {
        if (tag.kind == 0) {
          const int o = pd.vertex_origin[tag.a];
          const int g = o >= 0 && o < piece_vertices ? PS.piece.vertex_to_global[o] : -1;
          if (g >= 0 && g < own) id = g;
          else if (g >= 0) key = {0, g, 0, 0, 0, 0};
          else key = {1, j, o, tag.a, 0, 0};
        } else if (tag.kind == 1) {
          key = {2, j, tag.a, 0, 0, 0};
        } else {
          key = {3, j, tag.a, tag.b, tag.c, tag.d};
        }
        if (id >= 0 && seen[id]) return id;
        if (id < 0) {
          const auto it = keyed.find(key);
          if (it != keyed.end()) return it->second;
        }
      }
      // Where the corner is on both surfaces.
      const Eigen::Vector3d x = tag.kind == 0 ? Eigen::Vector3d(pd.mesh.V.row(tag.a)) : on_surface(pd, t, uv);
      const int next = static_cast<int>(on_polycube.size());
      if (boundary) id = weld.find_or_add(x, next);
      if (id >= 0 && id < next && seen[id]) return id;
      const Eigen::Vector3d y = tag.kind == 1 ? Eigen::Vector3d(md.mesh.V.row(tag.a)) : on_surface(md, s, uv);
      SurfacePoint image;
      image.face = data.model_face_origin[MS.piece.face_to_global[MS.work_face_parent[md.face_origin[s]]]];
      image.bary = clamp_bary(barycentric3(M.V.row(M.F(image.face, 0)), M.V.row(M.F(image.face, 1)), M.V.row(M.F(image.face, 2)), y));
      if (id < 0 || id == next) {
        id = next;
        on_polycube.push_back(x);
        on_model.push_back(image);
        seen.push_back(1);
        if (!boundary) keyed.emplace(key, id);
      } else {
        on_polycube[id] = P.V.row(id);
        on_model[id] = image;
        seen[id] = 1;
      }
      return id;
    };

    const Disks disks{pd.uv, md.uv};
    std::vector<Corner> poly;
    std::vector<Support> supports;
    std::vector<int> queue;
    for (int t = 0; t < pd.mesh.num_faces(); ++t) {
      const int a = pd.mesh.F(t, 0), b = pd.mesh.F(t, 1), c = pd.mesh.F(t, 2);
      const Eigen::Vector2d ua = pd.uv.row(a), ub = pd.uv.row(b), uc = pd.uv.row(c);
      const int parent = data.polycube_face_origin[PS.piece.face_to_global[PS.work_face_parent[pd.face_origin[t]]]];
      Eigen::Vector3d w;
      const int seed = MS.locator->locate((ua + ub + uc) / 3, w);
      if (seed < 0) continue;
      double covered = 0;
      const double t_area = cross2(ub - ua, uc - ua);
      queue.assign(1, seed);
      stamp[seed] = t;
      for (size_t q = 0; q < queue.size(); ++q) {
        const int s = queue[q];
        poly = {{ua, Tag{0, a}}, {ub, Tag{0, b}}, {uc, Tag{0, c}}};
        supports = {{0, std::min(a, b), std::max(a, b)}, {0, std::min(b, c), std::max(b, c)}, {0, std::min(c, a), std::max(c, a)}};
        for (int k = 0; k < 3 && !poly.empty(); ++k) {
          const int s0 = md.mesh.F(s, k), s1 = md.mesh.F(s, (k + 1) % 3);
          clip(poly, supports, disks, s0, s1);
        }
        // Consecutive corners with the same origin are one.
        std::vector<Corner> cell;
        for (const Corner& corner : poly)
          if (cell.empty() || !(cell.back().tag == corner.tag)) cell.push_back(corner);
        while (cell.size() > 1 && cell.back().tag == cell.front().tag) cell.pop_back();
        if (cell.size() < 3) continue;
        double area = 0;
        for (size_t i = 0; i < cell.size(); ++i) area += cross2(cell[i].uv, cell[(i + 1) % cell.size()].uv);
        if (!(area > 0)) ++out.zero_area_cells;  // kept: its neighbours share its corners
        ++out.cells;
        covered += area;
        // The neighbours across S's edges may overlap T too.
        for (int k = 0; k < 3; ++k) {
          const int e = m_edges.FE(s, k);
          for (int side = 0; side < 2; ++side) {
            const int r = m_edges.EF(e, side);
            if (r >= 0 && stamp[r] != t) {
              stamp[r] = t;
              queue.push_back(r);
            }
          }
        }
        std::vector<int> ids(cell.size());
        for (size_t i = 0; i < cell.size(); ++i) ids[i] = vertex_of(cell[i].tag, cell[i].uv, t, s);
        // A fan from the corner whose triangles' smallest area is largest.
        const int n = static_cast<int>(cell.size());
        int apex = 0;
        double best = -INFINITY;
        for (int r = 0; r < n; ++r) {
          double worst = INFINITY;
          for (int i = 1; i + 1 < n; ++i)
            worst = std::min(worst, cross2(cell[(r + i) % n].uv - cell[r].uv, cell[(r + i + 1) % n].uv - cell[r].uv));
          if (worst > best) {
            best = worst;
            apex = r;
          }
        }
        for (int i = 1; i + 1 < n; ++i) {
          const int u = ids[apex], v = ids[(apex + i) % n], x = ids[(apex + i + 1) % n];
          if (u == v || v == x || x == u) continue;
          faces.emplace_back(u, v, x);
          face_parent.push_back(parent);
          face_image.push_back(data.model_face_origin[MS.piece.face_to_global[MS.work_face_parent[md.face_origin[s]]]]);
        }
      }
      // The cells of T tile it (doubled areas); a gap means the walk missed M's triangles.
      if (!(std::abs(covered - t_area) <= 1e-9 * t_area + 1e-14)) ++out.uncovered_faces;
    }
  }

  const int nv = static_cast<int>(on_polycube.size());
  for (int v = 0; v < own; ++v)
    if (!seen[v]) throw AlgorithmError("overlay: vertex " + std::to_string(v) + " of the polycube is in no cell");
  out.polycube.V.resize(nv, 3);
  out.on_model_xyz.resize(nv, 3);
  for (int v = 0; v < nv; ++v) {
    out.polycube.V.row(v) = on_polycube[v];
    out.on_model_xyz.row(v) = surface_position(M, on_model[v]);
  }
  out.on_model = std::move(on_model);
  out.polycube.F.resize(static_cast<int>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) out.polycube.F.row(static_cast<int>(f)) = faces[f];
  out.face_parent = Eigen::Map<const Eigen::VectorXi>(face_parent.data(), static_cast<int>(face_parent.size()));
  out.face_image = Eigen::Map<const Eigen::VectorXi>(face_image.data(), static_cast<int>(face_image.size()));
  collapse_tiny_cells(out, own, P, M);
  const EdgeMap edges = build_edge_map(out.polycube.F);
  int open = 0;
  for (int e = 0; e < edges.num_edges(); ++e) open += edges.face_count[e] != 2;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (open > 0)
    throw AlgorithmError("overlay: " + std::to_string(open) + " of " + std::to_string(edges.num_edges()) +
                         " edges do not have exactly two faces");
  return out;
}

}  // namespace polycube
