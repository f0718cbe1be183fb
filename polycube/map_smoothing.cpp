#include "polycube/map_smoothing.h"

#include "polycube/barycentric.h"
#include "polycube/closest_point.h"
#include "polycube/map_audit.h"
#include "polycube/max_min_affine.h"

#include "polycube/mesh_topology.h"
#include "polycube/parallel.h"
#include "polycube/target_surface.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
#include <queue>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace polycube {

namespace {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Clock = std::chrono::steady_clock;

constexpr double kPi = 3.141592653589793;
constexpr double kTwoPi = 2 * kPi;

Vec3 row(const Eigen::MatrixX3d& X, int i) { return X.row(i).transpose(); }


using Closest = TriangleClosest;

using Lists = CompressedLists;

// ---------------------------------------------------------------------------------------------
// A closed triangle mesh with what the smoothing asks of it: adjacency across edges, intrinsic
// angle sums, normals, and local closest points.
class Surface {
 public:
  explicit Surface(const TriMesh& mesh) : mesh_(mesh), faces_of_(vertex_faces(mesh.F, mesh.num_vertices())) {
    const int nv = mesh.num_vertices(), nf = mesh.num_faces();
    if (nf == 0) throw std::invalid_argument("smooth_map: a mesh has no faces");
    const EdgeMap edges = build_edge_map(mesh.F);
    for (int e = 0; e < edges.num_edges(); ++e)
      if (edges.face_count[e] != 2) throw std::invalid_argument("smooth_map: a mesh is not closed and manifold (an edge has " + std::to_string(edges.face_count[e]) + " faces)");
    across_.resize(nf, 3);
    for (int f = 0; f < nf; ++f)
      for (int i = 0; i < 3; ++i) {
        const int e = edges.FE(f, (i + 1) % 3);  // FE(f, j) runs from corner j to j + 1: opposite corner j + 2
        across_(f, i) = edges.EF(e, 0) == f ? edges.EF(e, 1) : edges.EF(e, 0);
      }
    angle_sum_.assign(nv, 0);
    area_vector_.resize(nf);
    vertex_normal_ = Eigen::MatrixX3d::Zero(nv, 3);
    for (int f = 0; f < nf; ++f) {
      const Vec3 p[3] = {corner(f, 0), corner(f, 1), corner(f, 2)};
      area_vector_[f] = (p[1] - p[0]).cross(p[2] - p[0]);
      for (int i = 0; i < 3; ++i) {
        const Vec3 u = p[(i + 1) % 3] - p[i], w = p[(i + 2) % 3] - p[i];
        angle_sum_[mesh.F(f, i)] += std::atan2(u.cross(w).norm(), u.dot(w));
        vertex_normal_.row(mesh.F(f, i)) += area_vector_[f].transpose();
      }
    }
    for (int v = 0; v < nv; ++v) {
      const double n = vertex_normal_.row(v).norm();
      if (n > 0) vertex_normal_.row(v) /= n;
    }
  }

  const TriMesh& mesh() const { return mesh_; }
  const Eigen::MatrixX3i& across() const { return across_; }
  const Lists& faces_of() const { return faces_of_; }
  double angle_sum(int v) const { return angle_sum_[v]; }
  const Vec3& area_vector(int f) const { return area_vector_[f]; }

  Vec3 corner(int f, int i) const { return row(mesh_.V, mesh_.F(f, i)); }
  Vec3 position(const SurfacePoint& p) const {
    return p.bary[0] * corner(p.face, 0) + p.bary[1] * corner(p.face, 1) + p.bary[2] * corner(p.face, 2);
  }

  // Unit normal at a point: vertex normals interpolated (a tangent plane that turns smoothly
  // across edges).
  Vec3 normal(const SurfacePoint& p) const {
    Vec3 n = Vec3::Zero();
    for (int i = 0; i < 3; ++i) n += p.bary[i] * row(vertex_normal_, mesh_.F(p.face, i));
    const double len = n.norm();
    return len > 0 ? Vec3(n / len) : Vec3(area_vector_[p.face].normalized());
  }

  // Per-thread work space of project (and of the moves that call it).
  struct Scratch {
    std::vector<int> stamp, queue;
    std::vector<TriangleClosest> closest;  // t's closest point on each queued face
    int current = 0;
    std::vector<char> good;
  };

  // The closest point to t on the part of the surface within |t - position(from)| of t that is
  // connected to from's face through faces meeting that ball: a local projection, which never
  // jumps to another sheet that passes nearby in space.
  SurfacePoint project(const Vec3& t, const SurfacePoint& from, Scratch& scratch) const {
    std::vector<int>& stamp = scratch.stamp;
    std::vector<int>& queue = scratch.queue;
    int& current = scratch.current;
    if (stamp.size() != static_cast<size_t>(across_.rows())) stamp.assign(across_.rows(), 0);
    const double d0 = (t - position(from)).squaredNorm();
    const double radius2 = d0 * (1 + 1e-12) + 1e-300;
    if (++current == 0) {
      std::fill(stamp.begin(), stamp.end(), 0);
      current = 1;
    }
    std::vector<TriangleClosest>& closest = scratch.closest;
    queue.assign(1, from.face);
    closest.assign(1, closest_on_triangle(t, corner(from.face, 0), corner(from.face, 1), corner(from.face, 2)));
    stamp[from.face] = current;
    SurfacePoint best = from;
    double best_d2 = d0;
    for (size_t k = 0; k < queue.size() && k < kMaxVisited; ++k) {
      const int f = queue[k];
      const Closest c = closest[k];  // (a copy: the loop below appends)
      const double d2 = (c.point - t).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best.face = f;
        best.bary = c.bary;
      }
      for (int i = 0; i < 3; ++i) {
        const int g = across_(f, i);
        if (stamp[g] == current) continue;
        stamp[g] = current;
        const Closest cg = closest_on_triangle(t, corner(g, 0), corner(g, 1), corner(g, 2));
        if ((cg.point - t).squaredNorm() <= radius2) {
          queue.push_back(g);
          closest.push_back(cg);
        }
      }
    }
    return best;
  }

 private:
  static constexpr size_t kMaxVisited = 4096;
  const TriMesh& mesh_;
  Lists faces_of_;
  Eigen::MatrixX3i across_;
  std::vector<double> angle_sum_;
  std::vector<Vec3> area_vector_;
  Eigen::MatrixX3d vertex_normal_;
};

// ---------------------------------------------------------------------------------------------
// A chart of the model around one of its vertices c: the triangles within a few steps of c laid
// out in the plane, each vertex once. Around c it is the geodesic polar map (the exact unfolding
// of the triangles, nearest first across edges), conformally flattened at c, z ↦ z^(2π/Θ) with Θ
// the angle sum at c, so that the triangles round c are drawn whole and in proportion. A vertex
// reached again along another path (round other curved vertices) keeps its first place; a triangle
// that would come out inverted is left out, so the laid-out triangles form an oriented PL chart.
class Chart {
 public:
  explicit Chart(const Surface& surface)
      : S_(surface), vertex_stamp_(surface.mesh().num_vertices(), 0), radius_(surface.mesh().num_vertices()),
        angle_(surface.mesh().num_vertices()), position_(surface.mesh().num_vertices()), face_stamp_(surface.mesh().num_faces(), 0),
        depth_(surface.mesh().num_faces(), 0), sheet_stamp_(surface.mesh().num_vertices(), 0), sheet_turns_(surface.mesh().num_vertices()),
        sheet_position_(surface.mesh().num_vertices()) {}

  // Lays out the triangles within `depth` steps across edges of the centre's star.
  void build(int centre, int depth) {
    if (++stamp_ == 0) {
      std::fill(vertex_stamp_.begin(), vertex_stamp_.end(), 0);
      std::fill(face_stamp_.begin(), face_stamp_.end(), 0);
      std::fill(sheet_stamp_.begin(), sheet_stamp_.end(), 0);
      stamp_ = 1;
    }
    centre_ = centre;
    cone_angle_ = S_.angle_sum(centre);
    triangles_.clear();
    place_seed(*S_.faces_of().first(centre));
    grow(depth);
  }

  bool in_chart(int f) const { return face_stamp_[f] == stamp_; }
  const std::vector<int>& triangles() const { return triangles_; }
  const Vec2& position(int v) const { return position_[v]; }
  Vec2 point(const SurfacePoint& p) const {
    const TriMesh& m = S_.mesh();
    return p.bary[0] * position_[m.F(p.face, 0)] + p.bary[1] * position_[m.F(p.face, 1)] + p.bary[2] * position_[m.F(p.face, 2)];
  }

 private:
  struct Unfolding {
    int corner = -1;
    Vec2 position;      // unscaled, in the sheet of angle `reference`
    double reference = 0;
    double length = 0;  // of the shared edge
  };

  Vec3 xyz(int v) const { return row(S_.mesh().V, v); }

  Vec2 chart_position(double r, double theta) const {
    const double k = kTwoPi / cone_angle_;
    const double rho = unit_ * std::pow(r / unit_, k);
    return Vec2(rho * std::cos(theta * k), rho * std::sin(theta * k));
  }

  void set(int v, double r, double theta) {
    vertex_stamp_[v] = stamp_;
    sheet_stamp_[v] = 0;
    radius_[v] = r;
    angle_[v] = theta;
    position_[v] = chart_position(r, theta);
  }

  // The seed (centre, u, w) counter-clockwise: u at angle 0, w at the centre's angle.
  void place_seed(int f) {
    const TriMesh& m = S_.mesh();
    int i = 0;
    while (m.F(f, i) != centre_) ++i;
    const int u = m.F(f, (i + 1) % 3), w = m.F(f, (i + 2) % 3);
    const Vec3 c = xyz(centre_), du = xyz(u) - c, dw = xyz(w) - c;
    unit_ = 0.5 * (du.norm() + dw.norm());
    set(centre_, 0, 0);
    set(u, du.norm(), 0);
    set(w, dw.norm(), std::atan2(du.cross(dw).norm(), du.dot(dw)));
    face_stamp_[f] = stamp_;
    depth_[f] = 0;
    triangles_.push_back(f);
  }

  // v's unscaled position in the sheet of angle `reference`; the last one asked of each vertex is
  // kept (every unfolding asks for its edge's two ends, and grow() unfolds each triangle twice).
  Vec2 sheet_position(int v, double reference) {
    if (radius_[v] == 0) return Vec2::Zero();
    const double turns = std::round((reference - angle_[v]) / cone_angle_);
    if (sheet_stamp_[v] == stamp_ && sheet_turns_[v] == turns) return sheet_position_[v];
    const double theta = angle_[v] + cone_angle_ * turns;
    sheet_stamp_[v] = stamp_;
    sheet_turns_[v] = turns;
    return sheet_position_[v] = Vec2(radius_[v] * std::cos(theta), radius_[v] * std::sin(theta));
  }

  // g unfolded across its edge shared with the placed triangle f.
  Unfolding unfolding(int f, int g) {
    const TriMesh& m = S_.mesh();
    Unfolding u;
    int ic = 0;
    while (ic < 3 && S_.across()(g, ic) != f) ++ic;
    if (ic == 3) return u;
    const int a = m.F(g, (ic + 1) % 3), b = m.F(g, (ic + 2) % 3), c = m.F(g, ic);
    u.reference = radius_[a] > 0 ? angle_[a] : angle_[b];
    const Vec2 pa = sheet_position(a, u.reference), pb = sheet_position(b, u.reference);
    const Vec3 A = xyz(a), B = xyz(b), C = xyz(c);
    const Vec3 d3 = B - A;
    u.length = d3.norm();
    const double s = (C - A).dot(d3) / u.length;
    const double h = ((C - A) - (C - A).dot(d3) / (u.length * u.length) * d3).norm();
    const Vec2 e = (pb - pa).normalized();
    u.position = pa + s * e + h * Vec2(-e.y(), e.x());  // (c, a, b) counter-clockwise: c left of a → b
    u.corner = c;
    return u;
  }

  bool unfold(int f, int g, int depth) {
    const Unfolding u = unfolding(f, g);
    if (u.corner < 0) return false;
    const int c = u.corner;
    const double r = u.position.norm();
    double theta = std::atan2(u.position.y(), u.position.x());
    theta += kTwoPi * std::round((u.reference - theta) / kTwoPi);
    theta = std::fmod(theta, cone_angle_);
    if (theta < 0) theta += cone_angle_;
    const bool placed_now = vertex_stamp_[c] != stamp_;
    if (placed_now) set(c, r, theta);
    const TriMesh& m = S_.mesh();
    const Vec2 p0 = position_[m.F(g, 0)], p1 = position_[m.F(g, 1)], p2 = position_[m.F(g, 2)];
    if (!(cross2(p1 - p0, p2 - p0) > 1e-12 * u.length * u.length)) {
      if (placed_now) vertex_stamp_[c] = 0;
      return false;
    }
    face_stamp_[g] = stamp_;
    depth_[g] = depth;
    triangles_.push_back(g);
    return true;
  }

  void grow(int max_depth) {
    struct Entry {
      double key;
      int parent, face, depth;
      bool operator<(const Entry& o) const { return key > o.key; }
    };
    std::priority_queue<Entry> queue;
    auto push_neighbours = [&](int f) {
      for (int i = 0; i < 3; ++i) {
        const int g = S_.across()(f, i);
        if (face_stamp_[g] == stamp_ || depth_[f] + 1 > max_depth) continue;
        const Unfolding u = unfolding(f, g);
        if (u.corner >= 0) queue.push({u.position.norm(), f, g, depth_[f] + 1});
      }
    };
    for (size_t k = 0; k < triangles_.size(); ++k) push_neighbours(triangles_[k]);
    while (!queue.empty()) {
      const Entry e = queue.top();
      queue.pop();
      if (face_stamp_[e.face] != stamp_ && unfold(e.parent, e.face, e.depth)) push_neighbours(e.face);
    }
  }

  const Surface& S_;
  int stamp_ = 0;
  std::vector<int> vertex_stamp_;
  std::vector<double> radius_, angle_;
  std::vector<Vec2> position_;
  std::vector<int> face_stamp_, depth_;
  std::vector<int> triangles_;
  std::vector<int> sheet_stamp_;  // sheet_position's last answer per vertex, valid at stamp_
  std::vector<double> sheet_turns_;
  std::vector<Vec2> sheet_position_;
  int centre_ = -1;
  double cone_angle_ = kTwoPi;
  double unit_ = 1;
};

// ---------------------------------------------------------------------------------------------
// The polycube's vertex fans: neighbours counter-clockwise (seen from outside), the face between
// neighbour k and k + 1, and the cotangent weight ½ (cot α + cot β) of each spoke in P's metric.
struct Fan {
  std::vector<int> neighbours;
  std::vector<int> faces;  // faces[k] = (v, neighbours[k], neighbours[k + 1])
  std::vector<double> weights;
};

std::vector<Fan> polycube_fans(const TriMesh& P) {
  const int nv = P.num_vertices();
  struct Corner {
    int vertex, from, to, face;
  };
  std::vector<Corner> corners;
  corners.reserve(3 * P.num_faces());
  for (int f = 0; f < P.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) corners.push_back({P.F(f, i), P.F(f, (i + 1) % 3), P.F(f, (i + 2) % 3), f});
  std::sort(corners.begin(), corners.end(), [](const Corner& a, const Corner& b) { return a.vertex != b.vertex ? a.vertex < b.vertex : a.from < b.from; });
  std::vector<int> begin(nv + 1, 0);
  for (const Corner& c : corners) ++begin[c.vertex + 1];
  for (int v = 0; v < nv; ++v) begin[v + 1] += begin[v];
  auto cot_at = [&](int f, int i) {
    const Vec3 a = row(P.V, P.F(f, i)), b = row(P.V, P.F(f, (i + 1) % 3)), c = row(P.V, P.F(f, (i + 2) % 3));
    const Vec3 u = b - a, w = c - a;
    return u.dot(w) / std::max(u.cross(w).norm(), 1e-300);
  };
  std::vector<Fan> fans(nv);
  for (int v = 0; v < nv; ++v) {
    const int n = begin[v + 1] - begin[v];
    auto error = [&]() { return std::invalid_argument("smooth_map: the polycube is not a closed manifold at vertex " + std::to_string(v)); };
    if (n < 3) throw error();
    auto find = [&](int from) -> const Corner* {
      auto it = std::lower_bound(corners.begin() + begin[v], corners.begin() + begin[v + 1], from, [](const Corner& c, int x) { return c.from < x; });
      return it != corners.begin() + begin[v + 1] && it->from == from ? &*it : nullptr;
    };
    Fan& fan = fans[v];
    const Corner* c = &corners[begin[v]];
    for (int k = 0; k < n; ++k) {
      fan.neighbours.push_back(c->from);
      fan.faces.push_back(c->face);
      c = find(c->to);
      if (!c) throw error();
    }
    if (c != &corners[begin[v]]) throw error();
    fan.weights.assign(n, 0);
    for (int k = 0; k < n; ++k) {
      // Face k = (v, n_k, n_k+1): its angle at n_k+1 faces the spoke to n_k, its angle at n_k the
      // spoke to n_k+1.
      const int f = fan.faces[k];
      int i_v = 0;
      while (P.F(f, i_v) != v) ++i_v;
      fan.weights[k] += 0.5 * cot_at(f, (i_v + 2) % 3);
      fan.weights[(k + 1) % n] += 0.5 * cot_at(f, (i_v + 1) % 3);
    }
  }
  return fans;
}

// Greedy colouring of P's vertices so that two vertices of a colour are more than two edges apart.
std::vector<std::vector<int>> distance_two_colours(const std::vector<Fan>& fans) {
  const int nv = static_cast<int>(fans.size());
  std::vector<int> colour(nv, -1);
  std::vector<int> used;  // colour -> last vertex that saw it taken nearby
  std::vector<std::vector<int>> colours;
  for (int v = 0; v < nv; ++v) {
    for (int u : fans[v].neighbours) {
      if (colour[u] >= 0) used[colour[u]] = v;
      for (int z : fans[u].neighbours)
        if (colour[z] >= 0) used[colour[z]] = v;
    }
    int c = 0;
    while (c < static_cast<int>(used.size()) && used[c] == v) ++c;
    if (c == static_cast<int>(used.size())) {
      used.push_back(-1);
      colours.emplace_back();
    }
    colour[v] = c;
    colours[c].push_back(v);
  }
  return colours;
}

// ---------------------------------------------------------------------------------------------
// φ at P's vertices, moved one vertex at a time (Gauss–Seidel) towards the minimiser of the
// Dirichlet energy of φ: P → M in P's metric — the energy whose ratio to the image area is
// exactly ε_angle — and never so that a good image triangle turns bad.
class ForwardMap {
 public:
  ForwardMap(const Surface& model, const TriMesh& P, const std::vector<Fan>& fans, const std::vector<SurfacePoint>& start)
      : M_(model), P_(P), fans_(fans), y_(start) {
    const int nv = P.num_vertices();
    Y_.resize(nv);
    N_.resize(nv);
    for (int v = 0; v < nv; ++v) {
      Y_[v] = M_.position(y_[v]);
      N_[v] = M_.normal(y_[v]);
    }
    double area = 0;
    for (int f = 0; f < model.mesh().num_faces(); ++f) area += 0.5 * model.area_vector(f).norm();
    min_area_ = kMinAreaFraction * area / std::max(1, P.num_faces());
    good_.resize(P.num_faces());
    for (int f = 0; f < P.num_faces(); ++f) good_[f] = triangle_good(f, -1, Vec3::Zero(), Vec3::Zero(), -1);
    winding_ok_.resize(nv);
    for (int v = 0; v < nv; ++v) winding_ok_[v] = winds_once(v, -1, Vec3::Zero(), Vec3::Zero());
    frozen_.assign(nv, 0);
    moved_.assign(nv, 0);
  }

  const std::vector<SurfacePoint>& images() const { return y_; }
  const std::vector<char>& moved() const { return moved_; }
  void freeze(const std::vector<char>& frozen) { frozen_ = frozen; }
  void set_relaxation(double relaxation) { relaxation_ = relaxation; }
  // Vertices of bad triangles first try an untangling move (see move).
  void set_untangle(bool untangle) { untangle_ = untangle; }

  // Vertices of bad image triangles.
  std::vector<char> bad_vertices() const {
    std::vector<char> out(P_.num_vertices(), 0);
    for (int f = 0; f < P_.num_faces(); ++f)
      if (!good_[f])
        for (int i = 0; i < 3; ++i) out[P_.F(f, i)] = 1;
    return out;
  }

  // One pass over the vertices, colour by colour; the vertices of one colour are at least three
  // edges apart (nothing one move reads is written by another), so they move in parallel and the
  // result does not depend on the number of threads. Returns the number of accepted moves.
  int sweep(const std::vector<std::vector<int>>& colours, int threads, int& rejected) {
    const int nthreads = threads_for(threads);
    if (scratch_.size() < static_cast<size_t>(nthreads)) scratch_.resize(nthreads);
    int moves = 0;
    for (const std::vector<int>& colour : colours) {
      std::vector<int> moved(nthreads, 0), refused(nthreads, 0);
      std::vector<int> parts(nthreads);
      std::iota(parts.begin(), parts.end(), 0);
      parallel_for_each(parts, nthreads, "part", [&](int part) {
        const size_t begin = colour.size() * part / nthreads, end = colour.size() * (part + 1) / nthreads;
        for (size_t k = begin; k < end; ++k)
          if (!frozen_[colour[k]]) moved[part] += move(colour[k], refused[part], scratch_[part]);
      });
      moves += std::accumulate(moved.begin(), moved.end(), 0);
      rejected += std::accumulate(refused.begin(), refused.end(), 0);
    }
    return moves;
  }

 private:
  static constexpr double kMinAreaFraction = 1e-6;

  // Is P's face f a good image triangle (with vertex `moved` placed at Ym, Nm on model face fm):
  // not degenerate, facing along the model's normal at each corner and along the summed area
  // vectors of its corners' faces (the audit's test without its centroid term)?
  bool triangle_good(int f, int moved, const Vec3& Ym, const Vec3& Nm, int fm) const {
    Vec3 Y[3], N[3];
    int faces[3];
    for (int i = 0; i < 3; ++i) {
      const int u = P_.F(f, i);
      const bool m = u == moved;
      Y[i] = m ? Ym : Y_[u];
      N[i] = m ? Nm : N_[u];
      faces[i] = m ? fm : y_[u].face;
    }
    const Vec3 n = (Y[1] - Y[0]).cross(Y[2] - Y[0]);
    if (0.5 * n.norm() <= min_area_) return false;
    for (int i = 0; i < 3; ++i)
      if (n.dot(N[i]) <= 0) return false;
    Vec3 sum = M_.area_vector(faces[0]);
    if (faces[1] != faces[0]) sum += M_.area_vector(faces[1]);
    if (faces[2] != faces[0] && faces[2] != faces[1]) sum += M_.area_vector(faces[2]);
    return n.dot(sum) > 0;
  }

  // Does the image of v's fan wind exactly once around v's image in the model's tangent plane
  // there (with vertex `moved` at Ym, Nm)?
  bool winds_once(int v, int moved, const Vec3& Ym, const Vec3& Nm) const {
    const Vec3 c = v == moved ? Ym : Y_[v];
    const Vec3 n = v == moved ? Nm : N_[v];
    const Vec3 e1 = n.unitOrthogonal(), e2 = n.cross(e1);
    const Fan& fan = fans_[v];
    // Winding number of the fan's polygon about the origin by crossings of the +x axis (Sunday).
    auto at = [&](size_t k) {
      const int u = fan.neighbours[k % fan.neighbours.size()];
      const Vec3 d = (u == moved ? Ym : Y_[u]) - c;
      return Vec2(d.dot(e1), d.dot(e2));
    };
    int winding = 0;
    Vec2 p = at(0);
    for (size_t k = 1; k <= fan.neighbours.size(); ++k) {
      const Vec2 q = at(k);
      const double left = cross2(q - p, -p);  // > 0: the origin lies left of p → q
      if (p.y() <= 0) {
        if (q.y() > 0 && left > 0) ++winding;
      } else if (q.y() <= 0 && left < 0) {
        --winding;
      }
      p = q;
    }
    return winding == 1;
  }

  // Moves v towards the cotangent-weighted average of its neighbours' images (the minimiser of
  // the energy in v's image alone), over-relaxed, projected onto the model near v's image; if
  // that spoils a triangle or a fan, the full, half and quarter step are tried instead. When
  // untangling, a vertex of a bad triangle first tries the kernel point of its projected link
  // (kernel_point), taken only if it leaves fewer bad triangles round v and spoils none.
  int move(int v, int& rejected, Surface::Scratch& scratch) {
    const Fan& fan = fans_[v];
    const size_t n = fan.faces.size();
    std::vector<char>& new_good = scratch.good;
    new_good.resize(n);
    const Vec3 start = Y_[v];
    // Tries to move v to `target` projected onto the surface, `steps` of the way in turn; with
    // `fewer_bad`, a move must also leave fewer bad triangles around v than now.
    auto try_move = [&](const Vec3& target, const double* steps, int step_count, int fewer_bad) {
      for (int k_step = 0; k_step < step_count; ++k_step) {
        const SurfacePoint p = M_.project(start + steps[k_step] * (target - start), y_[v], scratch);
        const Vec3 Yn = M_.position(p);
        if (Yn == start) return false;  // nowhere to go on the surface
        const Vec3 Nn = M_.normal(p);
        bool ok = true;
        int bad = 0;
        for (size_t k = 0; k < n && ok; ++k) {
          new_good[k] = triangle_good(fan.faces[k], v, Yn, Nn, p.face);
          bad += !new_good[k];
          if (!new_good[k] && good_[fan.faces[k]]) ok = false;
        }
        if (ok && fewer_bad >= 0 && bad >= fewer_bad) ok = false;
        if (ok && winding_ok_[v] && !winds_once(v, v, Yn, Nn)) ok = false;
        for (size_t k = 0; k < n && ok; ++k) {
          const int u = fan.neighbours[k];
          if (winding_ok_[u] && !winds_once(u, v, Yn, Nn)) ok = false;
        }
        if (!ok) continue;
        y_[v] = p;
        Y_[v] = Yn;
        N_[v] = Nn;
        moved_[v] = 1;
        for (size_t k = 0; k < n; ++k) good_[fan.faces[k]] = new_good[k];
        winding_ok_[v] = winds_once(v, -1, Vec3::Zero(), Vec3::Zero());
        for (int u : fan.neighbours) winding_ok_[u] = winds_once(u, -1, Vec3::Zero(), Vec3::Zero());
        return true;
      }
      return false;
    };
    // A vertex of a bad triangle first tries the point of its link's kernel in its tangent plane
    // (where the smallest triangle of its fan is largest): an untangling move.
    int bad_now = 0;
    for (size_t k = 0; k < n; ++k) bad_now += !good_[fan.faces[k]];
    if (bad_now > 0 && untangle_) {
      Vec3 target;
      if (kernel_point(v, target)) {
        const double steps[3] = {1.0, 0.5, 0.25};
        if (try_move(target, steps, 3, bad_now)) return 1;
      }
    }
    // Towards the cotangent-weighted average of the neighbours' images, over-relaxed.
    Vec3 target = Vec3::Zero();
    double total = 0;
    for (size_t k = 0; k < fan.neighbours.size(); ++k) {
      target += fan.weights[k] * Y_[fan.neighbours[k]];
      total += fan.weights[k];
    }
    if (!(total > 0)) return 0;
    target /= total;
    if (!((target - start).squaredNorm() > 1e-24 * min_area_ / kMinAreaFraction)) return 0;
    const double steps[4] = {relaxation_, 1.0, 0.5, 0.25};
    if (try_move(target, relaxation_ == 1.0 ? steps + 1 : steps, relaxation_ == 1.0 ? 3 : 4, -1)) return 1;
    ++rejected;
    return 0;
  }

  // The point q of v's tangent plane (at its image) that maximises the smallest signed area of the
  // triangles (q, p_k, p_k+1), p_k the neighbours' images projected on that plane: a linear
  // programme in (q, t) solved by its vertices (three active constraints). False if that area is
  // not positive (the projected link is not star-shaped).
  bool kernel_point(int v, Vec3& target) const {
    const Fan& fan = fans_[v];
    const size_t n = fan.neighbours.size();
    if (n < 3 || n > 24) return false;
    const Vec3 c = Y_[v], normal = N_[v];
    const Vec3 e1 = normal.unitOrthogonal(), e2 = normal.cross(e1);
    std::vector<Vec2> p(n);
    for (size_t k = 0; k < n; ++k) {
      const Vec3 d = Y_[fan.neighbours[k]] - c;
      p[k] = Vec2(d.dot(e1), d.dot(e2));
    }
    // Twice the signed area of (q, p_k, p_k+1) is linear in q: a_k + g_k · q with
    // a_k = cross2(p_k, p_k+1), g_k = (p_k.y - p_k+1.y, p_k+1.x - p_k.x).
    std::vector<double> a(n);
    std::vector<Vec2> g(n);
    for (size_t k = 0; k < n; ++k) {
      const Vec2& u = p[k];
      const Vec2& w = p[(k + 1) % n];
      a[k] = cross2(u, w);
      g[k] = Vec2(u.y() - w.y(), w.x() - u.x());
    }
    const MaxMinPoint best = max_min_affine(a, g);
    if (!(best.value > 0)) return false;
    target = c + best.q.x() * e1 + best.q.y() * e2;
    return true;
  }

  const Surface& M_;
  const TriMesh& P_;
  const std::vector<Fan>& fans_;
  std::vector<SurfacePoint> y_;
  std::vector<Vec3> Y_, N_;
  std::vector<char> good_, winding_ok_, frozen_, moved_;
  double min_area_ = 0;
  std::vector<Surface::Scratch> scratch_;
  double relaxation_ = 1;
  bool untangle_ = false;
};

// ---------------------------------------------------------------------------------------------
// Solves x = Σ bᵢ yᵢ + s Σ bᵢ nᵢ for (b, s), starting from the projection along the chord's
// normal: the point of the chord (y0, y1, y2) whose linearly interpolated normal passes through x.
// Chords sharing an edge agree on it, so these normal prisms tile the space around the chords
// without gaps or overlaps. False if Newton does not converge.
bool normal_prism_coordinates(const Vec3 y[3], const Vec3 n[3], const Vec3& x, Vec3& bary) {
  const Vec3 normal = (y[1] - y[0]).cross(y[2] - y[0]);
  const double nn = normal.squaredNorm();
  if (!(nn > 0)) return false;
  const Vec3 q = x - (x - y[0]).dot(normal) / nn * normal;
  bary = Vec3((y[2] - y[1]).cross(q - y[1]).dot(normal) / nn, (y[0] - y[2]).cross(q - y[2]).dot(normal) / nn, 0);
  bary[2] = 1 - bary[0] - bary[1];
  Vec3 N = bary[0] * n[0] + bary[1] * n[1] + bary[2] * n[2];
  double s = (x - q).dot(N) / std::max(N.squaredNorm(), 1e-300);
  const double scale = std::sqrt(std::sqrt(nn));
  for (int it = 0; it < 30; ++it) {
    N = bary[0] * n[0] + bary[1] * n[1] + bary[2] * n[2];
    const Vec3 F = bary[0] * y[0] + bary[1] * y[1] + bary[2] * y[2] + s * N - x;
    if (F.norm() <= 1e-12 * scale) return true;
    Eigen::Matrix3d J;
    J.col(0) = (y[0] - y[2]) + s * (n[0] - n[2]);
    J.col(1) = (y[1] - y[2]) + s * (n[1] - n[2]);
    J.col(2) = N;
    const Vec3 step = J.fullPivLu().solve(F);
    if (!step.allFinite()) return false;
    bary[0] -= step[0];
    bary[1] -= step[1];
    bary[2] = 1 - bary[0] - bary[1];
    s -= step[2];
    if (bary.cwiseAbs().maxCoeff() > 1e3) return false;
  }
  return false;
}

// φ⁻¹ at the model's vertices from φ at P's vertices (y: P's vertex images on the model). Where no
// corner of the P triangle that held φ⁻¹(w) moved, φ⁻¹(w) stays. Elsewhere w is located among P's
// triangles drawn on the model (corners at their images, points of model faces) by a walk over
// P's triangles from the one that held φ⁻¹(w), always across the edge w lies beyond, until one
// contains w: first in the normal-prism coordinates of the chords, consistent across shared edges;
// where that fails (Newton does not converge, the walk meets a chord facing away), in the chart of
// the model centred at w, which measures the model intrinsically, walking and then trying every P
// triangle with a corner in the chart, in ever larger charts. The barycentrics give φ⁻¹(w) on P.
// Walking from the old answer keeps the search on the right sheet: never a triangle that merely
// passes near w in space. `missed` flags the model vertices found nowhere (they keep φ⁻¹(w)).
std::vector<SurfacePoint> locate_model_vertices(const Surface& M, const Surface& P, const std::vector<SurfacePoint>& y,
                                                const std::vector<char>& moved, const std::vector<SurfacePoint>& old, int threads,
                                                std::vector<char>& missed, int& relocated) {
  const TriMesh& PM = P.mesh();
  std::vector<std::pair<int, int>> imaged;
  imaged.reserve(y.size());
  for (size_t v = 0; v < y.size(); ++v) imaged.emplace_back(y[v].face, static_cast<int>(v));
  const Lists images_in(M.mesh().num_faces(), imaged);  // per model face: P vertices imaged in it
  std::vector<SurfacePoint> out(old);
  std::vector<char> changed(M.mesh().num_vertices(), 0);
  std::vector<Vec3> Y(y.size()), N(y.size());
  for (size_t v = 0; v < y.size(); ++v) {
    Y[v] = M.position(y[v]);
    N[v] = M.normal(y[v]);
  }
  missed.assign(M.mesh().num_vertices(), 0);
  // One part per thread (each with its chart's work space), vertices interleaved.
  const int nthreads = threads_for(threads);
  std::vector<int> parts(nthreads);
  std::iota(parts.begin(), parts.end(), 0);
  constexpr std::array<int, 4> kChartDepths = {4, 8, 16, 40};
  parallel_for_each(parts, nthreads, "part", [&](int part) {
    Chart chart(M);
    std::vector<int> tested(PM.num_faces(), -1);
    int search = 0;
    // The least depth of a chart of w that can hold a P triangle whole (its three corners imaged
    // in faces of the chart), or kChartDepths.back() + 1: a chart of depth d holds only faces
    // within d steps across edges of its seed face (Chart::build), so in a shallower one neither
    // the walk nor the search below can find w. Breadth-first from the seed face. (A coarse
    // model's vertices imaged on a fine P are mostly farther than any chart reaches from the P
    // vertices they are located for: their charts were built and searched in vain.)
    std::vector<int> ball_stamp(M.mesh().num_faces(), 0);
    std::vector<int> frontier, next;
    int ball = 0;
    auto least_depth = [&](int w) {
      const int max_depth = kChartDepths.back();
      ++ball;
      const int seed = *M.faces_of().first(w);
      frontier.assign(1, seed);
      ball_stamp[seed] = ball;
      for (int d = 0; d <= max_depth; ++d) {
        for (const int f : frontier)
          for (const int* v = images_in.first(f); v != images_in.last(f); ++v)
            for (const int* t = P.faces_of().first(*v); t != P.faces_of().last(*v); ++t)
              if (ball_stamp[y[PM.F(*t, 0)].face] == ball && ball_stamp[y[PM.F(*t, 1)].face] == ball &&
                  ball_stamp[y[PM.F(*t, 2)].face] == ball)
                return d;
        if (d == max_depth) break;
        next.clear();
        for (const int f : frontier)
          for (int i = 0; i < 3; ++i) {
            const int g = M.across()(f, i);
            if (ball_stamp[g] == ball) continue;
            ball_stamp[g] = ball;
            next.push_back(g);
          }
        frontier.swap(next);
      }
      return max_depth + 1;
    };
    auto corners = [&](int T, Vec2& a, Vec2& b, Vec2& c) {
      const int i = PM.F(T, 0), j = PM.F(T, 1), k = PM.F(T, 2);
      if (!chart.in_chart(y[i].face) || !chart.in_chart(y[j].face) || !chart.in_chart(y[k].face)) return false;
      a = chart.point(y[i]);
      b = chart.point(y[j]);
      c = chart.point(y[k]);
      return cross2(b - a, c - a) > 0;
    };
    for (int w = part; w < M.mesh().num_vertices(); w += nthreads) {
      const int T0 = old[w].face;
      if (!moved[PM.F(T0, 0)] && !moved[PM.F(T0, 1)] && !moved[PM.F(T0, 2)]) continue;
      changed[w] = 1;
      bool found = false;
      // Walks over P's triangles from T0 towards w: `coordinates(T, bary)` gives w's barycentrics
      // in T (false where they cannot be had); stops in the triangle where all are >= 0.
      auto walk = [&](int steps, auto&& coordinates) {
        int T = T0;
        for (int step = 0; step < steps; ++step) {
          Vec3 bary;
          if (!coordinates(T, bary)) return false;
          int lowest = 0;
          for (int i = 1; i < 3; ++i)
            if (bary[i] < bary[lowest]) lowest = i;
          if (bary[lowest] >= -1e-12) {
            out[w].face = T;
            out[w].bary = clamp_bary(bary);
            return true;
          }
          T = P.across()(T, lowest);
        }
        return false;
      };
      // First the walk with the chords' normal-prism coordinates (consistent across P's edges).
      const Vec3 x = row(M.mesh().V, w);
      found = walk(200, [&](int T, Vec3& bary) {
        Vec3 yy[3], nn[3];
        for (int i = 0; i < 3; ++i) {
          yy[i] = Y[PM.F(T, i)];
          nn[i] = N[PM.F(T, i)];
        }
        return (yy[1] - yy[0]).cross(yy[2] - yy[0]).dot(nn[0] + nn[1] + nn[2]) > 0 && normal_prism_coordinates(yy, nn, x, bary);
      });
      const int least = found ? 0 : least_depth(w);
      for (const int depth : kChartDepths) {
        if (found) break;
        if (depth < least) continue;
        chart.build(w, depth);
        const Vec2 target = chart.position(w);
        found = walk(1000, [&](int T, Vec3& bary) {
          Vec2 a, b, c;
          if (!corners(T, a, b, c)) return false;
          bary = barycentric2(a, b, c, target);
          return true;
        });
        if (found) break;
        // The walk left the chart or met an inverted triangle: every P triangle with a corner
        // imaged in the chart.
        int best = -1;
        double best_min = -INFINITY;
        Vec3 best_bary = Vec3::Zero();
        Vec2 a, b, c;
        ++search;
        for (int f : chart.triangles())
          for (const int* v = images_in.first(f); v != images_in.last(f); ++v)
            for (const int* t = P.faces_of().first(*v); t != P.faces_of().last(*v); ++t) {
              if (tested[*t] == search) continue;
              tested[*t] = search;
              if (!corners(*t, a, b, c)) continue;
              const Vec3 bary = barycentric2(a, b, c, target);
              if (bary.minCoeff() > best_min) {
                best_min = bary.minCoeff();
                best = *t;
                best_bary = bary;
              }
            }
        if (best >= 0 && best_min >= -1e-9) {
          out[w].face = best;
          out[w].bary = clamp_bary(best_bary);
          found = true;
          break;
        }
      }
      if (!found) missed[w] = 1;
    }
  });
  relocated = std::accumulate(changed.begin(), changed.end(), 0);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Flipped triangles exactly as the audit (map_audit.cpp) calls them, one flag per triangle: the
// image triangle degenerate, or its normal against the area-weighted normals of the distinct
// target faces closest to its centroid and corners, and then closest to points spread over it
// (image_orientation.h).
class AuditTarget : public TargetSurface {
 public:
  explicit AuditTarget(const TriMesh& target) : TargetSurface(target, "smooth_map") {}

  // Per triangle of F placed at `image`: flipped or degenerate? `on` (optional, #V(image)) are the
  // images as points of the target, whose faces seed the closest-point queries (the answers are
  // the audit's: a seed only speeds up the search).
  // With `previous` (the flags of an earlier placement) and `changed` (per vertex of the image:
  // moved since then), only the triangles with a changed corner are judged again; the others
  // keep their flags (a triangle's flag depends on its corners' images alone).
  std::vector<char> flipped(const Eigen::MatrixX3i& F, const Eigen::MatrixX3d& image, const std::vector<SurfacePoint>* on,
                            int threads, const std::vector<char>* previous = nullptr, const std::vector<char>* changed = nullptr) const {
    const bool partial = previous && changed;
    std::vector<char> recheck(F.rows(), 1), needed(image.rows(), 1);
    if (partial) {
      std::fill(needed.begin(), needed.end(), 0);
      for (int f = 0; f < F.rows(); ++f) {
        recheck[f] = (*changed)[F(f, 0)] || (*changed)[F(f, 1)] || (*changed)[F(f, 2)];
        if (recheck[f])
          for (int i = 0; i < 3; ++i) needed[F(f, i)] = 1;
      }
    }
    std::vector<int> vertex_face(image.rows(), -1);
    parallel_range(static_cast<int>(image.rows()), threads, [&](int v) {
      if (!needed[v]) return;
      // A point well inside a face lies on no other (closed, self-intersection-free target).
      const int seed = on && has_area((*on)[v].face) ? (*on)[v].face : -1;
      vertex_face[v] = seed >= 0 && (*on)[v].bary.minCoeff() > 1e-9 ? seed : closest_face(row(image, v), seed);
    });
    std::vector<char> out = partial ? *previous : std::vector<char>(F.rows(), 0);
    parallel_range(static_cast<int>(F.rows()), threads, [&](int f) {
      if (recheck[f])
        out[f] = judge(row(image, F(f, 0)), row(image, F(f, 1)), row(image, F(f, 2)), vertex_face[F(f, 0)], vertex_face[F(f, 1)],
                       vertex_face[F(f, 2)]) != 0;
    });
    return out;
  }
};

int count(const std::vector<char>& flags) { return static_cast<int>(std::count(flags.begin(), flags.end(), 1)); }

Eigen::MatrixX3d positions(const TriMesh& mesh, const std::vector<SurfacePoint>& points) {
  Eigen::MatrixX3d X(points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i) X.row(i) = surface_position(mesh, points[i]).transpose();
  return X;
}

// Most alternations of the untangling phases (each an inverse and a forward phase).
constexpr int kUntanglePasses = 4;
// Most rounds of an untangling phase.
constexpr int kUntangleRounds = 3;

// One phase of the smoothing: rounds of Gauss–Seidel sweeps moving the images of the source
// mesh's vertices on the target (ForwardMap), then the target's vertices relocated among the
// source's triangles drawn on the target, judged in both directions as the audit judges them.
// The forward phase moves P's vertices on M; the inverse phase M's vertices on P (M's fans and
// cotangent weights, P as the surface), which untangles M → P flips where the forward phase left
// them, by the same moves and guards with the roles of the meshes swapped.
struct PhaseInput {
  const Surface* source = nullptr;  // the mesh whose vertex images move
  const Surface* target = nullptr;  // the surface they move on
  const AuditTarget* source_audit = nullptr;
  const AuditTarget* target_audit = nullptr;
  const std::vector<Fan>* fans = nullptr;  // of the source
  const std::vector<std::vector<int>>* colours = nullptr;
  // The map the phase starts from, in both directions, and its flips.
  std::vector<SurfacePoint> on_target, on_source;
  Eigen::MatrixX3d on_target_xyz, on_source_xyz;
  std::vector<char> flipped_forward, flipped_backward;  // source → target, target → source
  std::vector<char> frozen;                              // source vertices that may not move
  bool untangle = false;                                 // untangling moves first (ForwardMap::move)
  // Keep the round with the fewest flips in all even if one direction is worse than at the start
  // (the caller judges the outcome); otherwise neither direction may be worse.
  bool relaxed = false;
};

struct PhaseResult {
  std::vector<SurfacePoint> on_target, on_source;
  Eigen::MatrixX3d on_target_xyz, on_source_xyz;
  std::array<int, 2> flipped{0, 0};  // source → target, target → source
  std::vector<char> flags_forward, flags_backward;  // per triangle: flipped or degenerate
  int sweeps = 0, moves = 0, rejected = 0, rounds = 0, frozen = 0, relocated = 0;
  bool found = false;  // a round no worse than the start in either direction
};

bool same_point(const SurfacePoint& a, const SurfacePoint& b) { return a.face == b.face && a.bary == b.bary; }

PhaseResult run_phase(const PhaseInput& in, const MapSmoothingOptions& options) {
  const TriMesh& S = in.source->mesh();
  const TriMesh& T = in.target->mesh();
  const int before_f = count(in.flipped_forward), before_b = count(in.flipped_backward);
  PhaseResult result, best;
  int best_flips = -1;
  std::vector<char> frozen = in.frozen;
  const int rounds = in.untangle ? std::min(options.rounds, kUntangleRounds) : options.rounds;
  // The previous round's end (its images and flags), for judging only what a round changed.
  std::vector<SurfacePoint> last_on_target, last_on_source;
  std::vector<char> last_flipped_f, last_flipped_b;
  for (int round = 0; round < rounds; ++round) {
    ForwardMap forward(*in.target, S, *in.fans, in.on_target);
    forward.freeze(frozen);
    forward.set_relaxation(options.relaxation);
    forward.set_untangle(in.untangle);
    for (int s = 0; s < options.sweeps; ++s) {
      const int moves = forward.sweep(*in.colours, options.threads, result.rejected);
      result.moves += moves;
      ++result.sweeps;
      if (moves == 0) break;
    }
    std::vector<char> missed;
    result.on_target = forward.images();
    result.on_target_xyz = positions(T, result.on_target);
    result.on_source = locate_model_vertices(*in.target, *in.source, result.on_target, forward.moved(), in.on_source, options.threads,
                                             missed, result.relocated);
    result.on_source_xyz = positions(S, result.on_source);
    // Only triangles with a corner whose image changed are judged again: since the phase's start
    // in the first round, since the previous round's end in the later ones (a triangle's flag
    // depends on its corners' images alone; later rounds differ from the previous one only round
    // the vertices frozen since).
    const bool from_start = round == 0;
    const std::vector<SurfacePoint>& forward_base = from_start ? in.on_target : last_on_target;
    const std::vector<SurfacePoint>& backward_base = from_start ? in.on_source : last_on_source;
    std::vector<char> moved_source(S.num_vertices(), 0), moved_target(T.num_vertices(), 0);
    for (int v = 0; v < S.num_vertices(); ++v) moved_source[v] = !same_point(result.on_target[v], forward_base[v]);
    for (int w = 0; w < T.num_vertices(); ++w) moved_target[w] = !same_point(result.on_source[w], backward_base[w]);
    const std::vector<char> flipped_f = in.target_audit->flipped(S.F, result.on_target_xyz, &result.on_target, options.threads,
                                                                 from_start ? &in.flipped_forward : &last_flipped_f, &moved_source);
    const std::vector<char> flipped_b = in.source_audit->flipped(T.F, result.on_source_xyz, &result.on_source, options.threads,
                                                                 from_start ? &in.flipped_backward : &last_flipped_b, &moved_target);
    last_on_target = result.on_target;
    last_on_source = result.on_source;
    last_flipped_f = flipped_f;
    last_flipped_b = flipped_b;
    result.frozen = count(frozen);
    result.rounds = round + 1;
    result.flipped = {count(flipped_f), count(flipped_b)};
    result.flags_forward = flipped_f;
    result.flags_backward = flipped_b;
    // The round with the fewest flips in all, and no more than the start's in either direction.
    const bool acceptable = in.relaxed ? result.flipped[0] + result.flipped[1] < before_f + before_b
                                       : result.flipped[0] <= before_f && result.flipped[1] <= before_b;
    if (acceptable && (best_flips < 0 || result.flipped[0] + result.flipped[1] < best_flips)) {
      best_flips = result.flipped[0] + result.flipped[1];
      best = result;
      best.found = true;
    }
    // No flip left in either direction: later rounds (more vertices frozen) can only smooth less.
    if (best.found && best_flips == 0) break;
    // Freeze, for the next round (which starts from the phase's start again), the tangles the
    // sweeps left and every place where this round is worse than the start: a triangle of either
    // direction flipped that was not, or a target vertex that could not be located. Frozen
    // vertices keep their start images and the target vertices over them theirs, so frozen
    // regions keep the start map in both directions, whose directions agree.
    // (Freezing just the corners of those triangles, not rings around them, keeps the most
    // smoothing: on the dev meshes rings of 1–2 left 10–40 % more flips.)
    std::vector<char> trouble = round == 0 ? forward.bad_vertices() : std::vector<char>(S.num_vertices(), 0);
    bool worse = false;
    auto mark = [&](int f) {
      for (int i = 0; i < 3; ++i) trouble[S.F(f, i)] = 1;
      worse = true;
    };
    for (int f = 0; f < S.num_faces(); ++f)
      if (flipped_f[f] && !in.flipped_forward[f]) mark(f);
    for (int t = 0; t < T.num_faces(); ++t)
      if (flipped_b[t] && !in.flipped_backward[t])
        for (int i = 0; i < 3; ++i) {
          mark(result.on_source[T.F(t, i)].face);
          mark(in.on_source[T.F(t, i)].face);
        }
    for (int w = 0; w < T.num_vertices(); ++w)
      if (missed[w]) mark(in.on_source[w].face);
    if (!worse && round > 0) break;
    bool grew = false;
    for (int v = 0; v < S.num_vertices(); ++v)
      if (trouble[v] && !frozen[v]) frozen[v] = grew = true;
    if (!grew) break;
  }
  if (!best.found) {
    // Every round was worse than the start somewhere: the start.
    best = result;
    best.on_target = in.on_target;
    best.on_target_xyz = in.on_target_xyz;
    best.on_source = in.on_source;
    best.on_source_xyz = in.on_source_xyz;
    best.frozen = S.num_vertices();
    best.relocated = 0;
    best.flipped = {before_f, before_b};
    best.flags_forward = in.flipped_forward;
    best.flags_backward = in.flipped_backward;
  }
  best.sweeps = result.sweeps;
  best.moves = result.moves;
  best.rejected = result.rejected;
  best.rounds = result.rounds;
  return best;
}

// Vertices within `rings` edges of a flipped triangle of F.
std::vector<char> near_flips(const TriMesh& mesh, const std::vector<Fan>& fans, const std::vector<char>& flipped, int rings) {
  std::vector<char> near(mesh.num_vertices(), 0);
  std::vector<int> front;
  for (int f = 0; f < mesh.num_faces(); ++f)
    if (flipped[f])
      for (int i = 0; i < 3; ++i)
        if (!near[mesh.F(f, i)]) {
          near[mesh.F(f, i)] = 1;
          front.push_back(mesh.F(f, i));
        }
  for (int r = 0; r < rings; ++r) {
    std::vector<int> next;
    for (int v : front)
      for (int u : fans[v].neighbours)
        if (!near[u]) {
          near[u] = 1;
          next.push_back(u);
        }
    front = std::move(next);
  }
  return near;
}

}  // namespace

MapSmoothingResult smooth_map(const TriMesh& model, const Polycube& polycube, const PolycubeMap& map, const MapSmoothingOptions& options) {
  const auto start = Clock::now();
  const TriMesh& P = polycube.mesh;
  if (static_cast<int>(map.polycube_on_model.size()) != P.num_vertices() || static_cast<int>(map.model_on_polycube.size()) != model.num_vertices() ||
      map.polycube_on_model_xyz.rows() != P.num_vertices() || map.model_on_polycube_xyz.rows() != model.num_vertices())
    throw std::invalid_argument("smooth_map: the map has " + std::to_string(map.polycube_on_model.size()) + " / " +
                                std::to_string(map.model_on_polycube.size()) + " images, the meshes " + std::to_string(P.num_vertices()) +
                                " / " + std::to_string(model.num_vertices()) + " vertices");
  if (options.sweeps < 0 || options.rounds < 1 || !(options.relaxation >= 1 && options.relaxation < 2) || options.untangle_rings < 0)
    throw std::invalid_argument("smooth_map: sweeps must be >= 0, rounds >= 1, relaxation in [1, 2) and untangle_rings >= 0, got " +
                                std::to_string(options.sweeps) + ", " + std::to_string(options.rounds) + ", " +
                                std::to_string(options.relaxation) + ", " + std::to_string(options.untangle_rings));
  for (const SurfacePoint& p : map.polycube_on_model)
    if (p.face < 0 || p.face >= model.num_faces()) throw std::invalid_argument("smooth_map: an image on the model has face " + std::to_string(p.face));
  for (const SurfacePoint& p : map.model_on_polycube)
    if (p.face < 0 || p.face >= P.num_faces()) throw std::invalid_argument("smooth_map: an image on the polycube has face " + std::to_string(p.face));

  const Surface model_surface(model), polycube_surface(P);
  const std::vector<Fan> fans = polycube_fans(P);
  const std::vector<std::vector<int>> colours = distance_two_colours(fans);
  const AuditTarget model_target(model), polycube_target(P);

  // Phase 1: P's vertices move on M.
  PhaseInput forward;
  forward.source = &polycube_surface;
  forward.target = &model_surface;
  forward.source_audit = &polycube_target;
  forward.target_audit = &model_target;
  forward.fans = &fans;
  forward.colours = &colours;
  forward.on_target = map.polycube_on_model;
  forward.on_target_xyz = map.polycube_on_model_xyz;
  forward.on_source = map.model_on_polycube;
  forward.on_source_xyz = map.model_on_polycube_xyz;
  forward.flipped_forward = model_target.flipped(P.F, map.polycube_on_model_xyz, &map.polycube_on_model, options.threads);
  forward.flipped_backward = polycube_target.flipped(model.F, map.model_on_polycube_xyz, &map.model_on_polycube, options.threads);
  forward.frozen.assign(P.num_vertices(), 0);
  const PhaseResult first = run_phase(forward, options);

  MapSmoothingResult result;
  result.flipped_before = {count(forward.flipped_forward), count(forward.flipped_backward)};
  result.polycube_on_model = first.on_target;
  result.polycube_on_model_xyz = first.on_target_xyz;
  result.model_on_polycube = first.on_source;
  result.model_on_polycube_xyz = first.on_source_xyz;
  result.flipped_after = first.flipped;
  result.sweeps = first.sweeps;
  result.moves = first.moves;
  result.rejected = first.rejected;
  result.rounds = first.rounds;
  result.frozen = first.found ? first.frozen : P.num_vertices();
  result.relocated = first.relocated;

  // Then, while flips remain and it helps (step 4 of the header): passes of untangling phases
  // restricted to the vertices near the flipped triangles, M's vertices moving on P (near M → P
  // flips; P's vertices over them relocated), then P's vertices moving on M (near P → M flips).
  // A pass is kept only if it lowers the flips in all and neither direction gets worse.
  if (options.sweeps > 0 && options.untangle_rings > 0 && result.flipped_after[0] + result.flipped_after[1] > 0) {
    const std::vector<Fan> model_fans = polycube_fans(model);
    const std::vector<std::vector<int>> model_colours = distance_two_colours(model_fans);
    // The map in both directions and its flips {P → M, M → P}.
    struct State {
      std::vector<SurfacePoint> polycube_on_model, model_on_polycube;
      Eigen::MatrixX3d polycube_on_model_xyz, model_on_polycube_xyz;
      std::array<int, 2> flipped{0, 0};
      std::vector<char> flags_pm, flags_mp;  // per triangle of P / of M: flipped or degenerate
      int total() const { return flipped[0] + flipped[1]; }
    };
    // One untangling phase from `state` on one side; false if it was not kept.
    auto untangle = [&](State& state, bool inverse_side, bool relaxed, int rings) {
      if (state.flipped[inverse_side ? 1 : 0] == 0) return false;
      PhaseInput in;
      in.source = inverse_side ? &model_surface : &polycube_surface;
      in.target = inverse_side ? &polycube_surface : &model_surface;
      in.source_audit = inverse_side ? &model_target : &polycube_target;
      in.target_audit = inverse_side ? &polycube_target : &model_target;
      in.fans = inverse_side ? &model_fans : &fans;
      in.colours = inverse_side ? &model_colours : &colours;
      in.on_target = inverse_side ? state.model_on_polycube : state.polycube_on_model;
      in.on_target_xyz = inverse_side ? state.model_on_polycube_xyz : state.polycube_on_model_xyz;
      in.on_source = inverse_side ? state.polycube_on_model : state.model_on_polycube;
      in.on_source_xyz = inverse_side ? state.polycube_on_model_xyz : state.model_on_polycube_xyz;
      const TriMesh& S = in.source->mesh();
      in.flipped_forward = inverse_side ? state.flags_mp : state.flags_pm;
      in.flipped_backward = inverse_side ? state.flags_pm : state.flags_mp;
      const std::vector<char> near = near_flips(S, *in.fans, in.flipped_forward, rings);
      in.untangle = true;
      in.relaxed = relaxed;
      in.frozen.resize(S.num_vertices());
      for (int v = 0; v < S.num_vertices(); ++v) in.frozen[v] = !near[v];
      const PhaseResult phase = run_phase(in, options);
      result.untangle_sweeps += phase.sweeps;
      result.untangle_moves += phase.moves;
      if (!phase.found || phase.flipped[0] + phase.flipped[1] >= state.total()) return false;
      (inverse_side ? state.model_on_polycube : state.polycube_on_model) = phase.on_target;
      (inverse_side ? state.model_on_polycube_xyz : state.polycube_on_model_xyz) = phase.on_target_xyz;
      (inverse_side ? state.polycube_on_model : state.model_on_polycube) = phase.on_source;
      (inverse_side ? state.polycube_on_model_xyz : state.model_on_polycube_xyz) = phase.on_source_xyz;
      state.flipped = inverse_side ? std::array<int, 2>{phase.flipped[1], phase.flipped[0]} : phase.flipped;
      state.flags_pm = inverse_side ? phase.flags_backward : phase.flags_forward;
      state.flags_mp = inverse_side ? phase.flags_forward : phase.flags_backward;
      return true;
    };
    State current{result.polycube_on_model, result.model_on_polycube, result.polycube_on_model_xyz, result.model_on_polycube_xyz,
                  result.flipped_after, first.flags_forward, first.flags_backward};
    auto better = [](const State& a, const State& b) {
      return a.flipped[0] <= b.flipped[0] && a.flipped[1] <= b.flipped[1] && a.total() < b.total();
    };
    // The vertices within r rings of the flipped triangles move. (Trying 0, 1, r, 2r, 3r + 1 and
    // 5r rings per pass and keeping the best, as an earlier version did, left about the same flips
    // on the dev meshes — anchor 1 / 24 → 0 / 22, cow 5 / 10 → 2 / 9, rotor 45 / 28 → 43 / 24 — at
    // three times the time: anchor 8 → 33 s.)
    const int rings = options.untangle_rings;
    for (int pass = 0; pass < kUntanglePasses && current.total() > 0; ++pass) {
      // First M's vertices with the P → M direction allowed to get worse, then P's vertices to
      // repair it: kept if the pair leaves neither direction worse. Otherwise each side on its
      // own, never worse in either direction.
      bool kept_pass = false;
      for (const bool relaxed : {true, false}) {
        State trial = current;
        int kept = untangle(trial, true, relaxed, rings);
        kept += untangle(trial, false, false, rings);
        if (kept == 0 || !better(trial, current)) continue;
        current = std::move(trial);
        result.untangle_phases += kept;
        kept_pass = true;
        break;
      }
      if (!kept_pass) break;
    }
    result.polycube_on_model = std::move(current.polycube_on_model);
    result.model_on_polycube = std::move(current.model_on_polycube);
    result.polycube_on_model_xyz = std::move(current.polycube_on_model_xyz);
    result.model_on_polycube_xyz = std::move(current.model_on_polycube_xyz);
    result.flipped_after = current.flipped;
  }
  // Kept when it removes flips or lowers ε_angle, its aim; otherwise the input is returned.
  result.distortion_before = map_distortion(P, map.polycube_on_model_xyz);
  result.distortion_after = map_distortion(P, result.polycube_on_model_xyz);
  if (!(result.flipped_after[0] + result.flipped_after[1] < result.flipped_before[0] + result.flipped_before[1] ||
        result.distortion_after.eps_angle < result.distortion_before.eps_angle)) {
    result.kept = false;
    result.polycube_on_model = map.polycube_on_model;
    result.model_on_polycube = map.model_on_polycube;
    result.polycube_on_model_xyz = map.polycube_on_model_xyz;
    result.model_on_polycube_xyz = map.model_on_polycube_xyz;
    result.flipped_after = result.flipped_before;
  }
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace polycube
