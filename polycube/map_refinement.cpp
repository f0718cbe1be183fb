#include "polycube/map_refinement.h"

#include "polycube/image_orientation.h"
#include "polycube/map_quality.h"
#include "polycube/mesh_topology.h"
#include "polycube/parallel.h"
#include "polycube/target_surface.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace polycube {

namespace {

using Vec3 = Eigen::Vector3d;
using Clock = std::chrono::steady_clock;

// Edges crossing a cutting plane are split on it when that is at least this far from their ends
// (as a fraction of their length); otherwise at their midpoint.
constexpr double kPlaneSplitMin = 0.1;

// A split at the model's edges is undone when its triangles' angle distortion weighted by image
// area (as in ε_angle) exceeds that of the triangles it split plus this times the area it adds.
constexpr double kMaxSplitDistortion = 3;

Vec3 row(const Eigen::MatrixX3d& X, int i) { return X.row(i).transpose(); }

// The audit's judgement of image triangles on the model (TargetSurface: the audit's closest
// faces and verdict), and closest points as points of a target face.
class AuditTarget : public TargetSurface {
 public:
  explicit AuditTarget(const TriMesh& target) : TargetSurface(target, "refine_map_sampling") {}

  // The closest point of the target to p, as a point of a target face.
  SurfacePoint closest_point(const TriMesh& target, const Vec3& p) const {
    const auto [x, face] = project(p);
    SurfacePoint out;
    out.face = face;
    const Vec3 a = row(target.V, target.F(face, 0)), b = row(target.V, target.F(face, 1)), c = row(target.V, target.F(face, 2));
    const Vec3 n = (b - a).cross(c - a);
    const double nn = n.squaredNorm();
    out.bary = Vec3((c - b).cross(x - b).dot(n) / nn, (a - c).cross(x - c).dot(n) / nn, 0);
    out.bary[2] = 1 - out.bary[0] - out.bary[1];
    out.bary = out.bary.cwiseMax(0.0);
    out.bary /= out.bary.sum();
    return out;
  }
};

double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) { return 0.5 * (b - a).cross(c - a).norm(); }

uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

// The refined triangulation of P and the map sampled at its vertices. Triangle t has corners
// tri[t], neighbour adj[t][i] across its edge from corner i to i + 1, and lies in the unrefined
// face parent[t], where its corners have barycentric coordinates bary[t].
struct Sampling {
  std::vector<Vec3> position;
  std::vector<SurfacePoint> origin;  // per vertex: on the unrefined P
  std::vector<SurfacePoint> image;   // per vertex: φ on the model
  std::vector<Vec3> image_xyz;
  std::vector<int> image_face;       // per vertex: the model face closest to its image (audit's)
  std::vector<double> image_distance;  // per vertex: its image's distance from the model
  std::vector<std::array<int, 3>> tri, adj;
  std::vector<std::array<Vec3, 3>> bary;
  std::vector<int> parent, level;
  std::vector<char> state;           // per triangle: 0 good, 1 flipped, 2 degenerate, -1 unknown
  std::vector<std::pair<uint64_t, int>> splits;  // (edge, its new vertex), in order
  int bisections = 0;
};

// A point splitting an edge: the parameter from its smaller vertex id and the image of φ there.
struct SplitPoint {
  double s = 0.5;
  Vec3 position = Vec3::Zero();
  SurfacePoint origin;
  SurfacePoint image;
  Vec3 image_xyz = Vec3::Zero();
};

// The map to sample: a point of the base P (the mesh being refined) to a point of the model.
using Evaluator = std::function<SurfacePoint(const SurfacePoint&)>;

// Where the image of a P edge crosses an edge of the model, for a map known at P's vertices.
// A chord between images on two model faces that meet at an angle cuts across the model and
// loses area (a CAD part's sharp edges: a finely meshed cube lost 1.7 % of its area, a
// tetrahedron 19 %, in their finished maps). Splitting such a P edge where its image crosses the model's edge, with the
// new image exactly on that edge, and again on the halves while they cross, leaves chords that lie
// in one closed model face each: there the sampled map is exact. The image path between images
// in faces round a common model vertex is read as the straight line of those faces unfolded
// about the vertex (the shortest path over them, when it turns less than π round the vertex).
class ModelEdgeCrossing {
 public:
  struct Crossing {
    double s = 0;  // parameter along the P edge, from its first end
    SurfacePoint image;
    Vec3 image_xyz = Vec3::Zero();
  };

  explicit ModelEdgeCrossing(const TriMesh& model)
      : model_(model), edges_(build_edge_map(model.F)), around_(vertex_faces(model.F, model.num_vertices())) {}

  // The first crossing of the image path from ya to yb with a model edge: for a face A holding ya
  // and a face B holding yb (each point's faces: its face, and those round the edge or vertex it
  // lies on) with a common vertex p, the straight line from ya to yb over the faces round p
  // unfolded into a plane, the way round p that turns less than π, where it leaves A. None when a
  // face holds both points (the chord lies on the model), when they share no vertex, when both
  // ways turn π or more, or when the line leaves the faces round p or meets the edge near an end
  // of the P edge. (Where the faces are coplanar the split gains no area; the caller ranks splits
  // by their gain.)
  std::optional<Crossing> crossing(const SurfacePoint& ya, const SurfacePoint& yb) const {
    const std::vector<int> fa = closure(ya), fb = closure(yb);
    for (int f : fa)
      if (std::find(fb.begin(), fb.end(), f) != fb.end()) return std::nullopt;
    const Vec3 a = surface_position(model_, ya), b = surface_position(model_, yb);
    std::optional<Crossing> best;
    double best_turn = kPi;
    for (int A : fa)
      for (int i = 0; i < 3; ++i) {
        const int p = model_.F(A, i);
        for (const int* f = around_.first(p); f != around_.last(p); ++f) {
          if (std::find(fb.begin(), fb.end(), *f) == fb.end()) continue;
          for (const int direction : {1, -1}) {
            double turn = 0;
            const std::optional<Crossing> c = unfold(a, b, A, i, *f, direction, turn);
            if (c && turn < best_turn) {
              best_turn = turn;
              best = c;
            }
          }
        }
      }
    return best;
  }

 private:
  static constexpr double kPi = 3.14159265358979323846;

  // The faces whose closure holds the point.
  std::vector<int> closure(const SurfacePoint& y) const {
    constexpr double kZero = 1e-12;
    int zeros = 0, nonzero = 0;
    for (int k = 0; k < 3; ++k) {
      if (y.bary[k] <= kZero) ++zeros;
      else nonzero = k;
    }
    if (zeros == 0) return {y.face};
    if (zeros >= 2) return std::vector<int>(around_.first(model_.F(y.face, nonzero)), around_.last(model_.F(y.face, nonzero)));
    int k = 0;
    while (y.bary[k] > kZero) ++k;
    const int e = edges_.FE(y.face, (k + 1) % 3);  // the edge opposite corner k
    const int other = edges_.EF(e, 0) == y.face ? edges_.EF(e, 1) : edges_.EF(e, 0);
    return other < 0 ? std::vector<int>{y.face} : std::vector<int>{y.face, other};
  }

  // Unsigned angle at P between the directions to x and y.
  static double angle(const Vec3& P, const Vec3& x, const Vec3& y) {
    const Vec3 u = x - P, v = y - P;
    return std::atan2(u.cross(v).norm(), u.dot(v));
  }

  // The walk round p = F(A, i) from A to B, counter-clockwise about the outward normals
  // (direction 1) or clockwise (-1). Faces are unfolded into one plane, each turned about the edge
  // it shares with the previous one: p at the origin, A's edge the walk does not leave by along
  // angle 0. `turn` is the angle at p from a to b in that plane; the line from a to b crosses A's
  // exit edge when it is below π.
  std::optional<Crossing> unfold(const Vec3& a, const Vec3& b, int A, int i, int B, int direction, double& turn) const {
    constexpr double kEnd = 1e-3;  // nearest a split may come to an end of the P edge
    const int p = model_.F(A, i);
    const Vec3 P = row(model_.V, p);
    auto at = [&](int v) { return Vec3(row(model_.V, v)); };
    const int start = model_.F(A, direction > 0 ? (i + 1) % 3 : (i + 2) % 3);
    const int exit = model_.F(A, direction > 0 ? (i + 2) % 3 : (i + 1) % 3);
    const double theta_a = angle(P, at(start), at(exit));
    const double phi_a = angle(P, at(start), a);
    double offset = theta_a;  // angle of the current face's exit edge
    double beta = 0;          // b's angle
    int f = A, entry = exit;
    for (int steps = 0;; ++steps) {
      if (offset - phi_a >= kPi || steps > 64) return std::nullopt;
      // The face across f's edge from p to `entry`.
      int j = 0;
      while (j < 3 && !((model_.F(f, j) == p && model_.F(f, (j + 1) % 3) == entry) || (model_.F(f, j) == entry && model_.F(f, (j + 1) % 3) == p))) ++j;
      if (j == 3) return std::nullopt;  // not a manifold fan round p (validation rules it out)
      const int e = edges_.FE(f, j);
      const int g = edges_.EF(e, 0) == f ? edges_.EF(e, 1) : edges_.EF(e, 0);
      if (g < 0 || g == A) return std::nullopt;
      int gk = 0;
      while (model_.F(g, gk) != p) ++gk;
      const int u = model_.F(g, (gk + 1) % 3), w = model_.F(g, (gk + 2) % 3);
      const int next = u == entry ? w : u;
      if (g == B) {
        beta = offset + angle(P, at(entry), b);
        break;
      }
      offset += angle(P, at(entry), at(next));
      f = g;
      entry = next;
    }
    turn = beta - phi_a;
    if (!(turn > 0 && turn < kPi)) return std::nullopt;
    const double ra = (a - P).norm(), rb = (b - P).norm();
    const Eigen::Vector2d a2(ra * std::cos(phi_a), ra * std::sin(phi_a)), b2(rb * std::cos(beta), rb * std::sin(beta));
    const Eigen::Vector2d d(std::cos(theta_a), std::sin(theta_a));
    auto cross2 = [](const Eigen::Vector2d& x, const Eigen::Vector2d& y) { return x.x() * y.y() - x.y() * y.x(); };
    const double denominator = cross2(d, b2 - a2);
    if (denominator == 0) return std::nullopt;
    Crossing out;
    out.s = -cross2(d, a2) / denominator;
    if (!(out.s > kEnd && out.s < 1 - kEnd)) return std::nullopt;
    const double r = d.dot(a2 + out.s * (b2 - a2));
    const double length = (at(exit) - P).norm();
    if (!(r > 0 && r < length)) return std::nullopt;  // the line leaves the faces round p
    out.image.face = A;
    out.image.bary = Vec3::Zero();
    out.image.bary[i] = 1 - r / length;
    out.image.bary[direction > 0 ? (i + 2) % 3 : (i + 1) % 3] = r / length;
    out.image_xyz = P + (r / length) * (at(exit) - P);
    return out;
  }

  const TriMesh& model_;
  EdgeMap edges_;
  CompressedLists around_;
};

class Refiner {
 public:
  // frozen: per face of `polycube`, 1 if it must not be split.
  Refiner(const TriMesh& model, const Polycube& polycube, const std::vector<double>& planes, const PolycubeMap& map, Evaluator evaluate,
          const std::vector<char>& frozen, const MapRefinementOptions& options, bool cross_model_edges)
      : model_(model), evaluate_(std::move(evaluate)), options_(options), target_(model), planes_(planes), frozen_(frozen) {
    if (cross_model_edges) crossing_.emplace(model);
    std::sort(planes_.begin(), planes_.end());
    const TriMesh& P = polycube.mesh;
    Sampling& s = now_;
    const int nv = P.num_vertices(), nf = P.num_faces();
    s.position.resize(nv);
    s.origin.resize(nv);
    s.image = map.polycube_on_model;
    s.image_xyz.resize(nv);
    for (int v = 0; v < nv; ++v) {
      s.position[v] = row(P.V, v);
      s.image_xyz[v] = row(map.polycube_on_model_xyz, v);
    }
    s.tri.resize(nf);
    s.adj.resize(nf);
    s.bary.resize(nf);
    s.parent.resize(nf);
    s.level.assign(nf, 0);
    s.state.assign(nf, -1);
    std::unordered_map<uint64_t, std::pair<int, int>> half;  // directed edge (a, b) -> (face, corner)
    half.reserve(3 * nf);
    for (int f = 0; f < nf; ++f) {
      s.parent[f] = f;
      for (int i = 0; i < 3; ++i) {
        s.tri[f][i] = P.F(f, i);
        s.bary[f][i] = Vec3::Unit(i);
        s.origin[P.F(f, i)] = SurfacePoint{f, Vec3::Unit(i)};
        half[directed(P.F(f, i), P.F(f, (i + 1) % 3))] = {f, i};
      }
    }
    for (int f = 0; f < nf; ++f)
      for (int i = 0; i < 3; ++i) {
        const auto it = half.find(directed(P.F(f, (i + 1) % 3), P.F(f, i)));
        if (it == half.end()) throw std::invalid_argument("refine_map_sampling: the polycube mesh is not closed");
        s.adj[f][i] = it->second.first;
      }
    s.image_face.assign(nv, -1);
    s.image_distance.assign(nv, 0);
    parallel_range(nv, options.threads, [&](int v) { std::tie(s.image_face[v], s.image_distance[v]) = target_.closest(s.image_xyz[v]); });
    judge_unknown();
  }

  // Bad (flipped or degenerate) triangles and the total image area of the current sampling.
  std::pair<int, double> measure() const {
    int bad = 0;
    double area = 0;
    for (size_t t = 0; t < now_.tri.size(); ++t) {
      bad += now_.state[t] != 0;
      area += image_area(static_cast<int>(t));
    }
    return {bad, area};
  }

  MapDirectionAudit audit() const {
    MapDirectionAudit a;
    a.triangles = static_cast<int>(now_.tri.size());
    double area = 0;
    for (size_t t = 0; t < now_.tri.size(); ++t) {
      a.flipped += now_.state[t] == 1;
      a.degenerate += now_.state[t] == 2;
      area += image_area(static_cast<int>(t));
    }
    for (double d : now_.image_distance) a.max_distance = std::max(a.max_distance, d);
    if (target_.diagonal() > 0) a.max_distance /= target_.diagonal();
    a.area_ratio = area / target_.area();
    const MapAuditOptions audit_options;
    a.ok = a.flipped == 0 && a.degenerate == 0 && a.max_distance <= audit_options.surface_tolerance &&
           std::abs(a.area_ratio - 1) <= audit_options.area_tolerance;
    return a;
  }

  // One round: marks the bad triangles and those whose refinement gains the most missing area,
  // refines each once. Returns false when nothing could be marked (or the budget is spent).
  bool round(int max_vertices) {
    const bool crossed = crossing_ && split_at_model_edges(max_vertices);
    const auto [bad, area] = measure();
    const double missing = target_.area() - area;
    std::vector<int> marked;
    for (size_t t = 0; t < now_.tri.size(); ++t)
      if (now_.state[t] != 0 && now_.level[t] < options_.max_level && failed_[t] != version_[t]) marked.push_back(static_cast<int>(t));
    const size_t bad_marked = marked.size();
    if (!crossed && std::abs(missing) > options_.area_tolerance * target_.area()) {
      // Gain of splitting each triangle into four at φ of its edge midpoints; the largest gains
      // first, as many as cover the missing area down to half the tolerance.
      const int nt = static_cast<int>(now_.tri.size());
      prepare_splits(nt);
      std::vector<double> gain(nt, 0);
      parallel_range(nt, options_.threads, [&](int t) { gain[t] = split_gain(t); });
      std::vector<int> order(nt);
      std::iota(order.begin(), order.end(), 0);
      std::sort(order.begin(), order.end(), [&](int a, int b) { return gain[a] != gain[b] ? gain[a] > gain[b] : a < b; });
      const double need = missing > 0 ? missing - 0.5 * options_.area_tolerance * target_.area() : 0;
      double sum = 0;
      for (int t : order) {
        if (sum >= need || gain[t] <= 0) break;
        if (now_.level[t] >= options_.max_level || now_.state[t] != 0 || failed_[t] == version_[t]) continue;
        marked.push_back(t);
        sum += gain[t];
      }
    }
    if (marked.empty()) return crossed;
    // Marked triangles are identified by their slot and the slot's version: a slot refined by the
    // closure of an earlier one counts as refined.
    std::vector<int> version_at(marked.size());
    for (size_t k = 0; k < marked.size(); ++k) version_at[k] = version_[marked[k]];
    prepare_splits(static_cast<int>(now_.tri.size()), &marked);
    bool any = false;
    for (size_t k = 0; k < marked.size(); ++k) {
      if (static_cast<int>(now_.position.size()) >= max_vertices) break;
      if (version_[marked[k]] != version_at[k]) continue;
      any |= refine(marked[k], k < bad_marked);
    }
    judge_unknown();
    return any || crossed;
  }

  // While P's image falls short of the model's area by more than the tolerance: splits the P
  // edges whose images cross a model edge between faces at an angle (ModelEdgeCrossing), the
  // largest area gains first, until the missing area is covered down to half the tolerance. A
  // split is undone if its four triangles end with more bad ones than its two had, or with more
  // angle distortion than the area it adds is worth (below). Returns whether any split was kept.
  bool split_at_model_edges(int max_vertices) {
    const double missing = target_.area() - measure().second;
    if (missing <= options_.area_tolerance * target_.area()) return false;
    struct Candidate {
      double gain = 0;
      int t = -1, i = -1, u = -1, version_t = 0, version_u = 0;
      SplitPoint point;
    };
    const int nt = static_cast<int>(now_.tri.size());
    std::vector<Candidate> found(3 * static_cast<size_t>(nt));
    parallel_range(nt, options_.threads, [&](int t) {
      for (int i = 0; i < 3; ++i) {
        const int a = now_.tri[t][i], b = now_.tri[t][(i + 1) % 3];
        if (a > b) continue;  // each edge once, from the triangle where it runs up in vertex ids
        const auto crossing = crossing_->crossing(now_.image[a], now_.image[b]);
        if (!crossing) continue;
        Candidate& c = found[3 * static_cast<size_t>(t) + i];
        c.t = t;
        c.i = i;
        c.u = now_.adj[t][i];
        c.version_t = version_[t];
        c.version_u = version_[c.u];
        c.point.s = crossing->s;  // from a, the smaller id
        c.point.position = now_.position[a] + crossing->s * (now_.position[b] - now_.position[a]);
        c.point.origin.face = now_.parent[t];
        c.point.origin.bary = (1 - crossing->s) * now_.bary[t][i] + crossing->s * now_.bary[t][(i + 1) % 3];
        c.point.image = crossing->image;
        c.point.image_xyz = crossing->image_xyz;
        const Vec3& m = crossing->image_xyz;
        for (const int side : {t, now_.adj[t][i]}) {
          const auto& corner = now_.tri[side];
          int k = 0;
          while (corner[k] == a || corner[k] == b) ++k;
          const Vec3 &ya = now_.image_xyz[a], &yb = now_.image_xyz[b], &yc = now_.image_xyz[corner[k]];
          c.gain += triangle_area(ya, m, yc) + triangle_area(m, yb, yc) - triangle_area(ya, yb, yc);
        }
      }
    });
    std::vector<Candidate> candidates;
    for (Candidate& c : found)
      if (c.t >= 0 && c.gain > 1e-12 * target_.area()) candidates.push_back(std::move(c));
    std::sort(candidates.begin(), candidates.end(),
              [](const Candidate& x, const Candidate& y) { return x.gain != y.gain ? x.gain > y.gain : x.t != y.t ? x.t < y.t : x.i < y.i; });
    const double need = missing - 0.5 * options_.area_tolerance * target_.area();
    double gained = 0;
    version_.resize(now_.tri.size(), 0);
    bool any = false;
    for (const Candidate& c : candidates) {
      if (gained >= need || static_cast<int>(now_.position.size()) >= max_vertices) break;
      // Each triangle is split once per round at most (the next round finds the edges of the
      // halves), so the candidate's triangles are as they were found.
      if (version_[c.t] != c.version_t || version_[c.u] != c.version_u) continue;
      journal_.clear();
      bisect(c.t, c.i, &c.point);
      const Undo& r = journal_.back();
      const int bad_before = (r.state_t != 0) + (r.state_u != 0);
      int bad_after = 0;
      double weighted_after = 0, area_after = 0;
      for (const int slot : {r.t, r.u, r.t2, r.u2}) {
        judge(slot);
        bad_after += now_.state[slot] != 0;
        weighted_after += weighted_distortion(now_.tri[slot]);
        area_after += image_area(slot);
      }
      // The angle distortion weighted by image area, as ε_angle weighs it: the split may add
      // area at up to kMaxSplitDistortion, not distort what was there (the unfoldings of
      // neighbouring splits need not agree, and a sliver on P with a fat image costs its P area
      // times its stretch squared).
      double weighted_before = 0, area_before = 0;
      for (const std::array<int, 3>& corner : {r.tri_t, r.tri_u}) {
        weighted_before += weighted_distortion(corner);
        area_before += triangle_area(now_.image_xyz[corner[0]], now_.image_xyz[corner[1]], now_.image_xyz[corner[2]]);
      }
      if (bad_after > bad_before || weighted_after > weighted_before + kMaxSplitDistortion * std::max(0.0, area_after - area_before)) {
        undo_last();
        continue;
      }
      failed_.resize(now_.tri.size(), -1);
      gained += c.gain;
      any = true;
    }
    journal_.clear();
    return any;
  }

  Sampling& sampling() { return now_; }

 private:
  // The image area times the angle distortion (ε_angle's summand) of the triangle with these
  // corners: 0 for a zero-area image, +infinity for a zero-area triangle of P with an image.
  double weighted_distortion(const std::array<int, 3>& corner) const {
    const Vec3 p[3] = {now_.position[corner[0]], now_.position[corner[1]], now_.position[corner[2]]};
    const Vec3 q[3] = {now_.image_xyz[corner[0]], now_.image_xyz[corner[1]], now_.image_xyz[corner[2]]};
    const double area = triangle_area(q[0], q[1], q[2]);
    return area > 0 ? area * triangle_angle_distortion(p, q) : 0.0;
  }

  static uint64_t directed(int a, int b) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
  }

  double image_area(int t) const {
    const auto& c = now_.tri[t];
    return triangle_area(now_.image_xyz[c[0]], now_.image_xyz[c[1]], now_.image_xyz[c[2]]);
  }

  // Judges every triangle whose state is unknown, as the audit would.
  void judge_unknown() {
    std::vector<int> todo;
    for (size_t t = 0; t < now_.tri.size(); ++t)
      if (now_.state[t] < 0) todo.push_back(static_cast<int>(t));
    version_.resize(now_.tri.size(), 0);
    failed_.resize(now_.tri.size(), -1);
    parallel_range(static_cast<int>(todo.size()), options_.threads, [&](int k) {
      const auto& c = now_.tri[todo[k]];
      now_.state[todo[k]] = static_cast<char>(target_.judge(now_.image_xyz[c[0]], now_.image_xyz[c[1]], now_.image_xyz[c[2]],
                                                            now_.image_face[c[0]], now_.image_face[c[1]], now_.image_face[c[2]]));
    });
  }

  // Where edge (a, b) is split, as the parameter from the smaller vertex id (so that both
  // triangles of the edge agree) and the position: where it crosses a cutting plane, exactly on
  // the plane (φ is glued there from two pieces' maps: its strongest kink, which chords across it
  // never resolve at any scale) unless that is near an end; otherwise its midpoint.
  std::pair<double, Vec3> split_parameter(int a, int b) const {
    if (a > b) std::swap(a, b);
    const Vec3& pa = now_.position[a];
    const Vec3& pb = now_.position[b];
    const double lo = std::min(pa.z(), pb.z()), hi = std::max(pa.z(), pb.z());
    double best_s = 0.5, best_z = NAN;
    for (auto it = std::upper_bound(planes_.begin(), planes_.end(), lo); it != planes_.end() && *it < hi; ++it) {
      const double s = (*it - pa.z()) / (pb.z() - pa.z());
      if (s >= kPlaneSplitMin && s <= 1 - kPlaneSplitMin && (std::isnan(best_z) || std::abs(s - 0.5) < std::abs(best_s - 0.5))) {
        best_s = s;
        best_z = *it;
      }
    }
    Vec3 p = pa + best_s * (pb - pa);
    if (!std::isnan(best_z)) p.z() = best_z;
    return {best_s, p};
  }

  // The split point of triangle t's edge i (from corner i to i + 1), with φ there (evaluated once
  // per edge and kept until the edge is split).
  SplitPoint split_point(int t, int i) const {
    const int a = now_.tri[t][i], b = now_.tri[t][(i + 1) % 3];
    SplitPoint p;
    std::tie(p.s, p.position) = split_parameter(a, b);
    const double from_a = a < b ? p.s : 1 - p.s;  // parameter from a towards b
    p.origin.face = now_.parent[t];
    p.origin.bary = (1 - from_a) * now_.bary[t][i] + from_a * now_.bary[t][(i + 1) % 3];
    p.image = evaluate_(p.origin);
    p.image_xyz = surface_position(model_, p.image);
    return p;
  }

  // Evaluates φ at the split points of every edge of triangles [0, nt) (or of `only`) not yet known.
  void prepare_splits(int nt, const std::vector<int>* only = nullptr) {
    std::vector<std::pair<int, int>> todo;  // (triangle, edge)
    std::vector<uint64_t> keys;
    auto add = [&](int t) {
      for (int i = 0; i < 3; ++i) {
        const uint64_t key = edge_key(now_.tri[t][i], now_.tri[t][(i + 1) % 3]);
        if (cache_.count(key)) continue;
        cache_[key] = SplitPoint{};  // placeholder, filled below
        todo.emplace_back(t, i);
        keys.push_back(key);
      }
    };
    if (only)
      for (int t : *only) add(t);
    else
      for (int t = 0; t < nt; ++t) add(t);
    std::vector<SplitPoint> points(todo.size());
    parallel_range(static_cast<int>(todo.size()), options_.threads, [&](int k) { points[k] = split_point(todo[k].first, todo[k].second); });
    for (size_t k = 0; k < todo.size(); ++k) cache_[keys[k]] = points[k];
  }

  const SplitPoint& cached_split(int t, int i) {
    const uint64_t key = edge_key(now_.tri[t][i], now_.tri[t][(i + 1) % 3]);
    auto it = cache_.find(key);
    if (it == cache_.end()) it = cache_.emplace(key, split_point(t, i)).first;
    return it->second;
  }

  // Chord area gained by splitting triangle t into four at its split points (known for all edges).
  double split_gain(int t) const {
    const auto& c = now_.tri[t];
    Vec3 m[3];
    for (int i = 0; i < 3; ++i) m[i] = cache_.at(edge_key(c[i], c[(i + 1) % 3])).image_xyz;
    const Vec3 &y0 = now_.image_xyz[c[0]], &y1 = now_.image_xyz[c[1]], &y2 = now_.image_xyz[c[2]];
    return triangle_area(y0, m[0], m[2]) + triangle_area(m[0], y1, m[1]) + triangle_area(m[2], m[1], y2) +
           triangle_area(m[0], m[1], m[2]) - triangle_area(y0, y1, y2);
  }

  // Edge order for the longest-edge bisection: length, then vertex ids (a strict total order, so
  // every propagation path ends).
  bool longer(int a0, int b0, int a1, int b1) const {
    const double l0 = (now_.position[a0] - now_.position[b0]).squaredNorm();
    const double l1 = (now_.position[a1] - now_.position[b1]).squaredNorm();
    if (l0 != l1) return l0 > l1;
    return edge_key(a0, b0) > edge_key(a1, b1);
  }

  int longest_edge(int t) const {
    const auto& c = now_.tri[t];
    int best = 0;
    for (int i = 1; i < 3; ++i)
      if (longer(c[i], c[(i + 1) % 3], c[best], c[(best + 1) % 3])) best = i;
    return best;
  }

  // Rivara's longest-edge bisection of triangle t: bisects terminal edges of t's longest-edge
  // propagation path until t itself is bisected. Kept only if the triangles it split end with
  // fewer bad ones (t bad) or no more (t good) than they had; otherwise undone, and t is not
  // tried again until a neighbour's refinement changes it.
  bool refine(int t, bool t_bad) {
    journal_.clear();
    const int base = static_cast<int>(now_.tri.size());
    const int version = version_[t];
    while (version_[t] == version) {
      int current = t;
      for (;;) {
        const int i = longest_edge(current);
        const int u = now_.adj[current][i];
        const int j = longest_edge(u);
        if (frozen_[now_.parent[current]] || frozen_[now_.parent[u]]) {
          while (!journal_.empty()) undo_last();
          failed_[t] = version_[t];
          return false;
        }
        if (now_.tri[u][j] == now_.tri[current][(i + 1) % 3] && now_.tri[u][(j + 1) % 3] == now_.tri[current][i]) {
          bisect(current, i);
          break;
        }
        current = u;
      }
    }
    std::unordered_map<int, char> before;  // pre-existing slots split: their state before
    std::vector<int> touched;
    for (const Undo& r : journal_) {
      for (const auto& [slot, state] : {std::pair<int, char>{r.t, r.state_t}, std::pair<int, char>{r.u, r.state_u}})
        if (slot < base) before.emplace(slot, state);
      for (int slot : {r.t, r.u, r.t2, r.u2}) touched.push_back(slot);
    }
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    int bad_before = 0, bad_after = 0;
    for (const auto& [slot, state] : before) bad_before += state != 0;
    for (int slot : touched) {
      if (now_.state[slot] < 0) judge(slot);
      bad_after += now_.state[slot] != 0;
    }
    if (t_bad ? bad_after < bad_before : bad_after <= bad_before) {
      failed_.resize(now_.tri.size(), -1);
      return true;
    }
    while (!journal_.empty()) undo_last();
    failed_[t] = version_[t];
    return false;
  }

  void judge(int t) {
    const auto& c = now_.tri[t];
    now_.state[t] = static_cast<char>(target_.judge(now_.image_xyz[c[0]], now_.image_xyz[c[1]], now_.image_xyz[c[2]],
                                                    now_.image_face[c[0]], now_.image_face[c[1]], now_.image_face[c[2]]));
  }

  // Undoes the last bisection of the open transaction.
  void undo_last() {
    Sampling& s = now_;
    const Undo r = journal_.back();
    journal_.pop_back();
    s.tri[r.t] = r.tri_t;
    s.adj[r.t] = r.adj_t;
    s.bary[r.t] = r.bary_t;
    s.level[r.t] = r.level_t;
    s.state[r.t] = r.state_t;
    version_[r.t] = r.version_t;
    s.tri[r.u] = r.tri_u;
    s.adj[r.u] = r.adj_u;
    s.bary[r.u] = r.bary_u;
    s.level[r.u] = r.level_u;
    s.state[r.u] = r.state_u;
    version_[r.u] = r.version_u;
    relink(r.n_bc, r.b, r.c, r.t);
    relink(r.n_ad, r.a, r.d, r.u);
    for (int k = 0; k < 2; ++k) {
      s.tri.pop_back();
      s.adj.pop_back();
      s.bary.pop_back();
      s.parent.pop_back();
      s.level.pop_back();
      s.state.pop_back();
      version_.pop_back();
    }
    s.position.pop_back();
    s.origin.pop_back();
    s.image.pop_back();
    s.image_xyz.pop_back();
    s.image_face.pop_back();
    s.image_distance.pop_back();
    s.splits.pop_back();
    --s.bisections;
    if (r.restore_split) cache_[edge_key(r.a, r.b)] = r.split;
  }

  // Sets the neighbour of triangle n across its edge (b, a) — the edge (a, b) of another — to t.
  void relink(int n, int a, int b, int t) {
    for (int k = 0; k < 3; ++k)
      if (now_.tri[n][k] == b && now_.tri[n][(k + 1) % 3] == a) {
        now_.adj[n][k] = t;
        return;
      }
  }

  // Splits edge i of triangle t (from corner i to i + 1) and the triangle across it.
  // given: the point to split at instead of the edge's usual split point.
  void bisect(int t, int i, const SplitPoint* given = nullptr) {
    Sampling& s = now_;
    const int a = s.tri[t][i], b = s.tri[t][(i + 1) % 3], c = s.tri[t][(i + 2) % 3];
    const int u = s.adj[t][i];
    int j = 0;
    while (!(s.tri[u][j] == b && s.tri[u][(j + 1) % 3] == a)) ++j;
    const int d = s.tri[u][(j + 2) % 3];
    // The edge's usual split point, restored if this bisection is undone.
    SplitPoint saved;
    bool restore = true;
    if (given) {
      const auto it = cache_.find(edge_key(a, b));
      restore = it != cache_.end();
      if (restore) saved = it->second;
    } else {
      saved = cached_split(t, i);
    }
    const SplitPoint p = given ? *given : saved;
    cache_.erase(edge_key(a, b));
    const double from_a = a < b ? p.s : 1 - p.s;

    const int m = static_cast<int>(s.position.size());
    s.position.push_back(p.position);
    s.origin.push_back(p.origin);
    s.image.push_back(p.image);
    s.image_xyz.push_back(p.image_xyz);
    const auto [face, distance] = target_.closest(p.image_xyz);
    s.image_face.push_back(face);
    s.image_distance.push_back(distance);
    s.splits.emplace_back(edge_key(a, b), m);
    ++s.bisections;

    const std::array<Vec3, 3> bt = {s.bary[t][i], s.bary[t][(i + 1) % 3], s.bary[t][(i + 2) % 3]};  // a, b, c
    const std::array<Vec3, 3> bu = {s.bary[u][j], s.bary[u][(j + 1) % 3], s.bary[u][(j + 2) % 3]};  // b, a, d
    const Vec3 mt = (1 - from_a) * bt[0] + from_a * bt[1];
    const Vec3 mu = (1 - from_a) * bu[1] + from_a * bu[0];
    const int n_bc = s.adj[t][(i + 1) % 3], n_ca = s.adj[t][(i + 2) % 3];
    const int n_ad = s.adj[u][(j + 1) % 3], n_db = s.adj[u][(j + 2) % 3];

    const int t2 = static_cast<int>(s.tri.size()), u2 = t2 + 1;
    journal_.push_back(Undo{t, u, t2, u2, n_bc, n_ad, a, b, c, d, s.tri[t], s.tri[u], s.adj[t], s.adj[u], s.bary[t], s.bary[u],
                            s.level[t], s.level[u], s.state[t], s.state[u], version_[t], version_[u], saved, restore});
    s.tri.resize(t2 + 2);
    s.adj.resize(t2 + 2);
    s.bary.resize(t2 + 2);
    s.parent.push_back(s.parent[t]);
    s.parent.push_back(s.parent[u]);
    const int lt = s.level[t] + 1, lu = s.level[u] + 1;
    s.level[t] = lt;
    s.level[u] = lu;
    s.level.push_back(lt);
    s.level.push_back(lu);
    s.state[t] = s.state[u] = -1;
    s.state.push_back(-1);
    s.state.push_back(-1);
    version_[t]++;
    version_[u]++;
    version_.push_back(0);
    version_.push_back(0);

    // t = (a, m, c), t2 = (m, b, c), u = (b, m, d), u2 = (m, a, d).
    s.tri[t] = {a, m, c};
    s.bary[t] = {bt[0], mt, bt[2]};
    s.tri[t2] = {m, b, c};
    s.bary[t2] = {mt, bt[1], bt[2]};
    s.tri[u] = {b, m, d};
    s.bary[u] = {bu[0], mu, bu[2]};
    s.tri[u2] = {m, a, d};
    s.bary[u2] = {mu, bu[1], bu[2]};
    s.adj[t] = {u2, t2, n_ca};
    s.adj[t2] = {u, n_bc, t};
    s.adj[u] = {t2, u2, n_db};
    s.adj[u2] = {t, n_ad, u};
    relink(n_bc, b, c, t2);
    relink(n_ad, a, d, u2);
  }

  const TriMesh& model_;
  Evaluator evaluate_;
  const MapRefinementOptions& options_;
  const AuditTarget target_;
  std::vector<double> planes_;
  const std::vector<char>& frozen_;
  std::optional<ModelEdgeCrossing> crossing_;  // set: P edges are also split where their images cross sharp model edges
  Sampling now_;
  std::vector<int> version_;                        // per triangle slot: bumped when it is split
  std::unordered_map<uint64_t, SplitPoint> cache_;  // per unsplit edge: its split point, once evaluated
  std::vector<int> failed_;                         // per slot: its version when its refinement was undone
  // One bisection of the open refinement: what it changed, to undo it.
  struct Undo {
    int t, u, t2, u2, n_bc, n_ad, a, b, c, d;
    std::array<int, 3> tri_t, tri_u, adj_t, adj_u;
    std::array<Vec3, 3> bary_t, bary_u;
    int level_t, level_u;
    char state_t, state_u;
    int version_t, version_u;
    SplitPoint split;
    bool restore_split;
  };
  std::vector<Undo> journal_;
};

// The refined Polycube: the unrefined one with the sampling's mesh, per-triangle labels of the
// parent triangles, and the new vertices on the polycube edges.
Polycube refined_polycube(const Polycube& unrefined, const Sampling& s) {
  Polycube out = unrefined;
  const int nv = static_cast<int>(s.position.size()), nf = static_cast<int>(s.tri.size());
  out.mesh.V.resize(nv, 3);
  for (int v = 0; v < nv; ++v) out.mesh.V.row(v) = s.position[v].transpose();
  out.mesh.F.resize(nf, 3);
  out.face_axis.resize(nf);
  out.face_patch.resize(nf);
  for (int t = 0; t < nf; ++t) {
    for (int i = 0; i < 3; ++i) out.mesh.F(t, i) = s.tri[t][i];
    out.face_axis[t] = unrefined.face_axis[s.parent[t]];
    out.face_patch[t] = unrefined.face_patch[s.parent[t]];
  }
  std::unordered_map<uint64_t, int> split_of(s.splits.begin(), s.splits.end());
  out.spacing = 0;
  for (PolycubeEdge& edge : out.edges) {
    std::vector<int> vertices;
    // Expands segment (a, b) into the vertices now on it, a excluded.
    auto expand = [&](auto&& self, int a, int b) -> void {
      const auto it = split_of.find(edge_key(a, b));
      if (it == split_of.end()) {
        vertices.push_back(b);
        return;
      }
      self(self, a, it->second);
      self(self, it->second, b);
    };
    vertices.push_back(edge.vertices.front());
    for (size_t k = 0; k + 1 < edge.vertices.size(); ++k) expand(expand, edge.vertices[k], edge.vertices[k + 1]);
    for (size_t k = 0; k + 1 < vertices.size(); ++k)
      out.spacing = std::max(out.spacing, (s.position[vertices[k + 1]] - s.position[vertices[k]]).norm());
    edge.vertices = std::move(vertices);
  }
  return out;
}

// φ⁻¹ at the model's vertices as points of the refined triangles: the refined triangle of the
// same unrefined face that contains the point best, same position.
std::vector<SurfacePoint> reexpress(const std::vector<SurfacePoint>& on_unrefined, const Sampling& s, int unrefined_faces) {
  std::vector<std::vector<int>> children(unrefined_faces);
  for (size_t t = 0; t < s.tri.size(); ++t) children[s.parent[t]].push_back(static_cast<int>(t));
  std::vector<SurfacePoint> out(on_unrefined.size());
  for (size_t w = 0; w < on_unrefined.size(); ++w) {
    const SurfacePoint& p = on_unrefined[w];
    double best = -INFINITY;
    for (int t : children[p.face]) {
      Eigen::Matrix3d B;
      for (int i = 0; i < 3; ++i) B.col(i) = s.bary[t][i];
      const Vec3 lambda = B.fullPivLu().solve(p.bary);
      if (lambda.minCoeff() > best) {
        best = lambda.minCoeff();
        out[w].face = t;
        out[w].bary = lambda;
      }
    }
    Vec3& b = out[w].bary;
    b = b.cwiseMax(0.0);
    b /= b.sum();
  }
  return out;
}

}  // namespace

namespace {

// Attempts with more of P frozen when the refinement turns M → P triangles bad.
constexpr int kModelToPolycubeAttempts = 3;

TriMesh mesh_of(const Sampling& s) {
  TriMesh mesh;
  mesh.V.resize(static_cast<int>(s.position.size()), 3);
  for (size_t v = 0; v < s.position.size(); ++v) mesh.V.row(static_cast<int>(v)) = s.position[v].transpose();
  mesh.F.resize(static_cast<int>(s.tri.size()), 3);
  for (size_t t = 0; t < s.tri.size(); ++t)
    for (int i = 0; i < 3; ++i) mesh.F(static_cast<int>(t), i) = s.tri[t][i];
  return mesh;
}

// Per triangle of `source` placed at `image`: bad (flipped or degenerate) as the audit judges it
// against `target`.
std::vector<char> verdicts(const AuditTarget& target, const TriMesh& source, const Eigen::MatrixX3d& image, int threads) {
  std::vector<int> face(source.num_vertices());
  parallel_range(source.num_vertices(), threads, [&](int v) { face[v] = target.closest(row(image, v)).first; });
  std::vector<char> out(source.num_faces());
  parallel_range(source.num_faces(), threads, [&](int f) {
    out[f] = target.judge(row(image, source.F(f, 0)), row(image, source.F(f, 1)), row(image, source.F(f, 2)), face[source.F(f, 0)],
                          face[source.F(f, 1)], face[source.F(f, 2)]) != 0;
  });
  return out;
}

// Both entry points: checks, then rounds of refinement of `polycube` sampling `evaluate`, whose
// values at P's vertices are `map`'s.
// cross_model_edges: P edges are also split where their images cross a model edge (the map is
// known at the vertices only, so the image path may be read so).
MapRefinementResult refine_sampling(const char* name, const TriMesh& model, const Polycube& polycube, const std::vector<double>& planes,
                                    const PolycubeMap& map, const Evaluator& evaluate, const MapRefinementOptions& options,
                                    bool cross_model_edges) {
  const auto start = Clock::now();
  const TriMesh& P = polycube.mesh;
  const std::string fn = std::string(name) + ": ";
  if (static_cast<int>(map.polycube_on_model.size()) != P.num_vertices() || static_cast<int>(map.model_on_polycube.size()) != model.num_vertices() ||
      map.polycube_on_model_xyz.rows() != P.num_vertices() || map.model_on_polycube_xyz.rows() != model.num_vertices())
    throw std::invalid_argument(fn + "the map has " + std::to_string(map.polycube_on_model.size()) + " / " +
                                std::to_string(map.model_on_polycube.size()) + " images, the meshes " + std::to_string(P.num_vertices()) +
                                " / " + std::to_string(model.num_vertices()) + " vertices");
  for (const SurfacePoint& p : map.polycube_on_model)
    if (p.face < 0 || p.face >= model.num_faces())
      throw std::invalid_argument(fn + "an image on the model has face " + std::to_string(p.face));
  for (const SurfacePoint& p : map.model_on_polycube)
    if (p.face < 0 || p.face >= P.num_faces())
      throw std::invalid_argument(fn + "an image on the polycube has face " + std::to_string(p.face));
  if (!(options.area_tolerance >= 0) || !(options.max_vertex_factor >= 1) || options.min_vertex_budget < 0 || options.max_rounds < 0 ||
      options.max_level < 0)
    throw std::invalid_argument(fn + "need area_tolerance >= 0, max_vertex_factor >= 1, min_vertex_budget >= 0, "
                                "max_rounds >= 0, max_level >= 0; got " + std::to_string(options.area_tolerance) + ", " +
                                std::to_string(options.max_vertex_factor) + ", " + std::to_string(options.min_vertex_budget) + ", " +
                                std::to_string(options.max_rounds) + ", " + std::to_string(options.max_level));

  MapRefinementResult result;
  result.vertices_before = P.num_vertices();
  result.triangles_before = P.num_faces();
  auto bad = [](const MapDirectionAudit& a) { return a.flipped + a.degenerate; };
  // Fewest bad triangles first, then the area's distance beyond the tolerance, then fewer vertices.
  auto score = [&](const std::pair<int, double>& m) {
    const double ratio = m.second / surface_area(model);
    return std::make_pair(m.first, std::max(0.0, std::abs(ratio - 1) - options.area_tolerance));
  };
  const int max_vertices = static_cast<int>(std::max(options.max_vertex_factor * P.num_vertices(),
                                                     static_cast<double>(P.num_vertices()) + options.min_vertex_budget));
  // The M → P samples keep their positions, but the audit judges their chords against the P
  // triangles closest to them (area-weighted normals), which the refinement changes: a chord
  // whose normal is positive against one nearby P face and negative against another can change
  // its verdict. Where M → P triangles turn bad, the unrefined faces closest to them (and their
  // neighbours) are frozen and the refinement runs again, a few times at most.
  std::vector<char> frozen(P.num_faces(), 0);
  std::vector<std::vector<int>> faces_at(P.num_vertices());
  for (int f = 0; f < P.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) faces_at[P.F(f, i)].push_back(f);
  // The input's M → P verdicts, computed when first needed.
  std::vector<char> base_verdict;
  int m_input = 0;
  auto input_verdicts = [&]() {
    if (!base_verdict.empty()) return;
    const AuditTarget base_target(P);
    base_verdict = verdicts(base_target, model, map.model_on_polycube_xyz, options.threads);
    m_input = static_cast<int>(std::count(base_verdict.begin(), base_verdict.end(), 1));
  };
  int p_input = 0;
  // The best attempt: admissible (P → M no worse; M → P no worse or both together fewer), then
  // fewest bad triangles of both directions, then the area nearest the tolerance.
  Sampling best;
  bool improved = false;
  std::tuple<int, double, int> best_key{0, 0.0, 0};  // (P → M + M → P bad, area excess, P → M bad)
  for (int attempt = 0;; ++attempt) {
    Refiner refiner(model, polycube, planes, map, evaluate, frozen, options, cross_model_edges);
    if (attempt == 0) {
      result.before = refiner.audit();
      p_input = bad(result.before);
    }
    const std::pair<int, double> refiner_start = refiner.measure();
    auto attempt_score = score(refiner_start);
    Sampling attempt_best;
    bool attempt_improved = false;
    int rounds = 0;
    while (rounds < options.max_rounds && (attempt_score.first > 0 || attempt_score.second > 0)) {
      if (static_cast<int>(refiner.sampling().position.size()) >= max_vertices) break;
      if (!refiner.round(max_vertices)) break;
      ++rounds;
      const auto now = score(refiner.measure());
      if (now < attempt_score) {
        attempt_score = now;
        attempt_best = refiner.sampling();
        attempt_improved = true;
      }
    }
    result.rounds += rounds;
    if (!attempt_improved) break;
    if (attempt == 0) {
      input_verdicts();
      const auto start_score = score(refiner_start);
      best_key = {p_input + m_input, start_score.second, p_input};
    }
    // M → P verdicts per model triangle against the refined P.
    const TriMesh refined = mesh_of(attempt_best);
    const AuditTarget refined_target(refined);
    const std::vector<char> verdict = verdicts(refined_target, model, map.model_on_polycube_xyz, options.threads);
    const int m_bad = static_cast<int>(std::count(verdict.begin(), verdict.end(), 1));
    const int p_bad = attempt_score.first;
    const std::tuple<int, double, int> key{p_bad + m_bad, attempt_score.second, p_bad};
    int frozen_now = 0;
    for (int f = 0; f < model.num_faces(); ++f) {
      if (!verdict[f] || base_verdict[f]) continue;
      const Vec3 a = row(map.model_on_polycube_xyz, model.F(f, 0)), b = row(map.model_on_polycube_xyz, model.F(f, 1)),
                 c = row(map.model_on_polycube_xyz, model.F(f, 2));
      for (const Vec3& x : {a, b, c, Vec3((a + b + c) / 3)}) {
        const int parent = attempt_best.parent[refined_target.closest(x).first];
        for (int i = 0; i < 3; ++i)
          for (int g : faces_at[P.F(parent, i)]) frozen_now += !frozen[g], frozen[g] = 1;
      }
    }
    if (p_bad <= p_input && (m_bad <= m_input || p_bad + m_bad < p_input + m_input) && key < best_key) {
      best_key = key;
      best = std::move(attempt_best);
      improved = true;
    }
    if (frozen_now == 0 || attempt == kModelToPolycubeAttempts) break;
    result.frozen_faces += frozen_now;
  }

  result.polycube_origin.resize(P.num_vertices());
  if (improved) {
    // Kept only if P → M got no worse and either M → P got no worse or both directions together
    // have fewer bad triangles, judged by the audit itself.
    result.model_to_polycube_before = audit_map_direction(model, map.model_on_polycube_xyz, P);
    result.model_to_polycube_after = audit_map_direction(model, map.model_on_polycube_xyz, mesh_of(best));
    const int p_before = bad(result.before), p_after = std::get<2>(best_key);
    const int m_before = bad(result.model_to_polycube_before), m_after = bad(result.model_to_polycube_after);
    if (!(p_after <= p_before && (p_after + m_after < p_before + m_before || m_after <= m_before))) {
      improved = false;
      result.model_to_polycube_rejected = true;
    }
  }
  if (!improved) {
    // Unchanged: the input sampling.
    result.polycube = polycube;
    result.map = map;
    result.map.data.reset();
    for (int f = 0; f < P.num_faces(); ++f)
      for (int i = 0; i < 3; ++i) result.polycube_origin[P.F(f, i)] = SurfacePoint{f, Vec3::Unit(i)};
    result.face_origin = Eigen::VectorXi::LinSpaced(P.num_faces(), 0, P.num_faces() - 1);
    result.after = result.before;
    result.model_to_polycube_after = result.model_to_polycube_before;
  } else {
    Sampling& s = best;
    result.refined = true;
    result.bisections = s.bisections;
    result.polycube = refined_polycube(polycube, s);
    result.polycube_origin = s.origin;
    result.face_origin.resize(static_cast<int>(s.parent.size()));
    for (size_t t = 0; t < s.parent.size(); ++t) result.face_origin[static_cast<int>(t)] = s.parent[t];
    PolycubeMap& out = result.map;
    out.polycube_on_model = s.image;
    out.polycube_on_model_xyz.resize(static_cast<int>(s.image_xyz.size()), 3);
    for (size_t v = 0; v < s.image_xyz.size(); ++v) out.polycube_on_model_xyz.row(static_cast<int>(v)) = s.image_xyz[v].transpose();
    out.model_on_polycube = reexpress(map.model_on_polycube, s, P.num_faces());
    out.model_on_polycube_xyz = map.model_on_polycube_xyz;
    out.pieces = map.pieces;
    out.contours = map.contours;
    out.seconds = map.seconds;
    result.after = audit_map_direction(result.polycube.mesh, out.polycube_on_model_xyz, model);
  }
  result.vertices_after = result.polycube.mesh.num_vertices();
  result.triangles_after = result.polycube.mesh.num_faces();
  result.converged = result.after.flipped == 0 && result.after.degenerate == 0 &&
                     std::abs(result.after.area_ratio - 1) <= options.area_tolerance;
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace

MapRefinementResult refine_map_sampling(const TriMesh& model, const PolycubeResult& polycube, const PolycubeMap& map,
                                        const MapRefinementOptions& options) {
  if (!map.data) throw std::invalid_argument("refine_map_sampling: the map has no data to evaluate φ with");
  return refine_sampling("refine_map_sampling", model, polycube.polycube, polycube.planes_z, map,
                         [&map](const SurfacePoint& p) { return map.to_model(p); }, options, false);
}

MapRefinementResult refine_vertex_map_sampling(const TriMesh& model, const Polycube& polycube, const std::vector<double>& planes_z,
                                               const PolycubeMap& samples, const MapRefinementOptions& options) {
  if (samples.polycube_on_model_xyz.rows() != polycube.mesh.num_vertices())
    throw std::invalid_argument("refine_vertex_map_sampling: " + std::to_string(samples.polycube_on_model_xyz.rows()) +
                                " images for " + std::to_string(polycube.mesh.num_vertices()) + " vertices");
  const AuditTarget surface(model);
  const TriMesh& P = polycube.mesh;
  const Eigen::MatrixX3d& Y = samples.polycube_on_model_xyz;
  auto evaluate = [&](const SurfacePoint& p) {
    const Vec3 chord = p.bary[0] * row(Y, P.F(p.face, 0)) + p.bary[1] * row(Y, P.F(p.face, 1)) + p.bary[2] * row(Y, P.F(p.face, 2));
    return surface.closest_point(model, chord);
  };
  // The bisections alone first; where they leave the area short, again with the splits at the
  // model's edges too (ModelEdgeCrossing), and the better of the two: fewer bad triangles of both
  // directions together, then of P → M, then the area nearer the tolerance.
  MapRefinementResult result = refine_sampling("refine_vertex_map_sampling", model, polycube, planes_z, samples, evaluate, options, false);
  if (std::abs(result.after.area_ratio - 1) > options.area_tolerance) {
    MapRefinementResult crossed = refine_sampling("refine_vertex_map_sampling", model, polycube, planes_z, samples, evaluate, options, true);
    auto key = [&](const MapRefinementResult& r) {
      const MapDirectionAudit m = audit_map_direction(model, samples.model_on_polycube_xyz, r.polycube.mesh);
      const int p_bad = r.after.flipped + r.after.degenerate;
      return std::make_tuple(p_bad + m.flipped + m.degenerate, p_bad, std::max(0.0, std::abs(r.after.area_ratio - 1) - options.area_tolerance));
    };
    if (key(crossed) < key(result)) {
      crossed.rounds += result.rounds;
      crossed.seconds += result.seconds;
      result = std::move(crossed);
    }
  }
  result.map.pieces = samples.pieces;
  return result;
}

}  // namespace polycube
