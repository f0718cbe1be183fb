#include "polycube/image_untangle.h"

#include "polycube/max_min_affine.h"
#include "polycube/target_surface.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace polycube {

namespace {

// Ring radii, as fractions of the vertex's shortest image edge, and directions per ring.
constexpr std::array<double, 9> kRings = {0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5, 2.0};
constexpr int kDirections = 16;
// Rings farther than this many times the best shift found so far are not tried.
constexpr double kRingSlack = 1.5;
// The second kind of sweep moves the vertices within this many edges of a bad triangle.
constexpr int kOptimiseRings = 2;
// ... and only those whose smallest signed fan area is below this fraction of the fan's mean.
constexpr double kSqueezedFan = 0.25;

class Untangler {
 public:
  Untangler(const TriMesh& source, const Eigen::MatrixX3d& image, const TriMesh& target, const ImageUntangleOptions& options)
      : source_(source), surface_(target, "untangle_image"), input_(image), image_(image), face_(source.num_vertices()),
        star_(source.num_vertices()), bad_(source.num_faces()), room_(source.num_vertices()), shortest_(source.num_vertices()),
        edge_share_(options.max_edge_share), stamp_(source.num_vertices(), 0), no_move_stamp_(source.num_vertices(), -1),
        no_move_bound_(source.num_vertices(), 0.0), no_fan_move_stamp_(source.num_vertices(), -1) {
    for (int v = 0; v < source.num_vertices(); ++v) face_[v] = surface_.closest(point(v)).first;
    for (int f = 0; f < source.num_faces(); ++f) {
      for (int c = 0; c < 3; ++c) star_[source.F(f, c)].push_back(f);
      bad_[f] = judge(f);
    }
    for (int v = 0; v < source.num_vertices(); ++v) shortest_[v] = shortest_edge(v);
    input_face_ = face_;
    input_bad_ = bad_;
    set_room(options.max_shift);
  }

  // Back to the input images, with each image's room the larger of max_shift × the diagonal and
  // the edge share of its shortest input edge.
  void restart(double max_shift) {
    image_ = input_;
    face_ = input_face_;
    bad_ = input_bad_;
    set_room(max_shift);
    std::fill(no_move_stamp_.begin(), no_move_stamp_.end(), -1);
    std::fill(no_fan_move_stamp_.begin(), no_fan_move_stamp_.end(), -1);
  }

  int bad_count() const { return static_cast<int>(std::count(bad_.begin(), bad_.end(), true)); }
  const Eigen::MatrixX3d& image() const { return image_; }

  // One sweep of the second kind (see the header): every vertex within kOptimiseRings of a bad
  // triangle moves towards the point of its tangent plane where the smallest signed area of its
  // fan is largest; returns whether any vertex moved.
  bool optimise() {
    bool moved = false;
    for (int v : near_bad()) {
      const std::optional<Move> move = fan_move(v);
      if (!move) continue;
      place(move->vertex, move->point, move->face);
      moved = true;
    }
    return moved;
  }

  // One sweep over the triangles still bad; returns whether any vertex moved.
  bool sweep() {
    bool moved = false;
    for (int f = 0; f < source_.num_faces(); ++f) {
      if (!bad_[f]) continue;
      std::optional<Move> best;
      for (int c = 0; c < 3; ++c) {
        const std::optional<Move> move = best_move(source_.F(f, c), best ? best->shift : kInfinity);
        if (move && (!best || move->shift < best->shift)) best = move;
      }
      if (!best) continue;
      place(best->vertex, best->point, best->face);
      moved = true;
    }
    return moved;
  }

 private:
  static constexpr double kInfinity = std::numeric_limits<double>::infinity();

  struct Move {
    int vertex;
    Eigen::Vector3d point;
    int face;
    double shift;
  };

  struct Frame {
    Eigen::Vector3d normal, u, w;
  };

  Eigen::Vector3d point(int v) const { return image_.row(v).transpose(); }

  void set_room(double max_shift) {
    const double diagonal_room = max_shift * surface_.diagonal();
    for (int v = 0; v < source_.num_vertices(); ++v)
      room_[v] = std::max(diagonal_room, std::isfinite(shortest_[v]) ? edge_share_ * shortest_[v] : 0.0);
  }

  // The vertices within kOptimiseRings edges of a bad triangle, in index order.
  std::vector<int> near_bad() const {
    std::vector<int> depth(source_.num_vertices(), -1), frontier;
    for (int f = 0; f < source_.num_faces(); ++f)
      if (bad_[f])
        for (int c = 0; c < 3; ++c)
          if (int v = source_.F(f, c); depth[v] < 0) depth[v] = 0, frontier.push_back(v);
    for (int ring = 1; ring <= kOptimiseRings; ++ring) {
      std::vector<int> next;
      for (int v : frontier)
        for (int f : star_[v])
          for (int c = 0; c < 3; ++c)
            if (int w = source_.F(f, c); depth[w] < 0) depth[w] = ring, next.push_back(w);
      frontier = std::move(next);
    }
    std::vector<int> vertices;
    for (int v = 0; v < source_.num_vertices(); ++v)
      if (depth[v] >= 0) vertices.push_back(v);
    return vertices;
  }

  // The signed areas of v's fan with v at p, in the plane of `normal`: each triangle (p, q, r)
  // in the source's orientation gives ½ normal · ((q − p) × (r − p)).
  double smallest_fan_area(int v, const Eigen::Vector3d& p, const Eigen::Vector3d& normal) const {
    double smallest = kInfinity;
    for (int f : star_[v]) {
      const int k = source_.F(f, 0) == v ? 0 : (source_.F(f, 1) == v ? 1 : 2);
      const Eigen::Vector3d q = point(source_.F(f, (k + 1) % 3)), r = point(source_.F(f, (k + 2) % 3));
      smallest = std::min(smallest, 0.5 * normal.dot((q - p).cross(r - p)));
    }
    return smallest;
  }

  // The point p = old + x u + y w, |x|, |y| <= radius, where the smallest fan area is largest
  // (each fan area is affine in (x, y): max_min_affine.h).
  Eigen::Vector2d widest_fan_point(int v, const Eigen::Vector3d& old, const Frame& frame, double radius) const {
    std::vector<double> a;
    std::vector<Eigen::Vector2d> g;
    for (int f : star_[v]) {
      const int k = source_.F(f, 0) == v ? 0 : (source_.F(f, 1) == v ? 1 : 2);
      const Eigen::Vector3d q = point(source_.F(f, (k + 1) % 3)), r = point(source_.F(f, (k + 2) % 3));
      auto area = [&](const Eigen::Vector3d& p) { return 0.5 * frame.normal.dot((q - p).cross(r - p)); };
      a.push_back(area(old));
      g.emplace_back(area(old + frame.u) - a.back(), area(old + frame.w) - a.back());
    }
    return max_min_affine(a, g, radius).q;
  }

  // A move of v that raises the smallest signed area of its fan (in the tangent plane of its
  // closest face) without raising the bad triangles round it or turning a good one bad: towards
  // the widest-fan point within its shortest image edge, the whole, half or a quarter of the way.
  // A search that found none is not repeated while v's ring is unchanged.
  std::optional<Move> fan_move(int v) {
    if (no_fan_move_stamp_[v] == stamp_[v]) return std::nullopt;
    std::optional<Move> move = search_fan_move(v);
    if (!move) no_fan_move_stamp_[v] = stamp_[v];
    return move;
  }

  std::optional<Move> search_fan_move(int v) {
    const std::vector<int>& star = star_[v];
    const double shortest = shortest_edge(v);
    if (!std::isfinite(shortest)) return std::nullopt;
    const Frame frame = tangent_frame(v);
    const Eigen::Vector3d old = point(v), origin = input_.row(v).transpose();
    const double now = smallest_fan_area(v, old, frame.normal);
    // Only squeezed fans move: a fan whose smallest area is a fair share of the mean is left.
    double mean = 0;
    for (int f : star) {
      const Eigen::Vector3d a = point(source_.F(f, 0));
      mean += 0.5 * (point(source_.F(f, 1)) - a).cross(point(source_.F(f, 2)) - a).norm() / star.size();
    }
    if (now > kSqueezedFan * mean) return std::nullopt;
    const Eigen::Vector2d x = widest_fan_point(v, old, frame, shortest);
    std::vector<bool> before;
    const int bad_before = star_bad(v, before);
    for (double fraction : {1.0, 0.5, 0.25}) {
      const Eigen::Vector3d q = surface_.project(old + fraction * (x.x() * frame.u + x.y() * frame.w)).first;
      if ((q - origin).norm() > room_[v] || q == old) continue;
      // The gain must be real: a relative margin keeps the sweeps from creeping.
      if (!(smallest_fan_area(v, q, frame.normal) > now + 1e-9 * shortest * shortest)) continue;
      const int face = surface_.closest(q).first;
      if (trial(v, q, face, before, bad_before + 1))
        return Move{v, q, face, (q - old).norm()};
    }
    return std::nullopt;
  }

  // v's shortest non-zero image edge (+infinity if none).
  double shortest_edge(int v) const {
    double shortest = kInfinity;
    for (int f : star_[v])
      for (int c = 0; c < 3; ++c)
        if (const int w = source_.F(f, c); w != v) {
          const double length = (point(w) - point(v)).norm();
          if (length > 0) shortest = std::min(shortest, length);
        }
    return shortest;
  }

  // The unit normal of v's closest target face and two unit vectors spanning its plane.
  Frame tangent_frame(int v) const {
    Frame frame;
    frame.normal = surface_.area_vectors()[face_[v]].normalized();
    frame.u = frame.normal.cross(Eigen::Vector3d::UnitX());
    if (frame.u.norm() < 0.5) frame.u = frame.normal.cross(Eigen::Vector3d::UnitY());
    frame.u.normalize();
    frame.w = frame.normal.cross(frame.u);
    return frame;
  }

  // The bad flags of v's fan (in star order) and their number.
  int star_bad(int v, std::vector<bool>& bad) const {
    const std::vector<int>& star = star_[v];
    bad.assign(star.size(), false);
    int count = 0;
    for (size_t k = 0; k < star.size(); ++k) count += bad[k] = bad_[star[k]];
    return count;
  }

  // Whether v's image at q (closest face `face`) turns no triangle of its fan that was good
  // `before` bad and leaves fewer than `limit` bad ones; v's image is left where it was. The good
  // ones are judged first and the judging stops at the first verdict against: a triangle that
  // stays bad costs the audit's finer look (13 more closest points), so a move refused by a good
  // one is refused before them.
  bool trial(int v, const Eigen::Vector3d& q, int face, const std::vector<bool>& before, int limit) {
    const Eigen::Vector3d old = point(v);
    const int old_face = face_[v];
    image_.row(v) = q.transpose();
    face_[v] = face;
    const std::vector<int>& star = star_[v];
    bool accepted = true;
    for (size_t k = 0; k < star.size() && accepted; ++k)
      if (!before[k] && judge(star[k])) accepted = false;
    int bad = 0;
    for (size_t k = 0; k < star.size() && accepted; ++k)
      if (before[k] && judge(star[k]) && ++bad >= limit) accepted = false;
    image_.row(v) = old.transpose();
    face_[v] = old_face;
    return accepted;
  }

  bool judge(int f) const {
    const int a = source_.F(f, 0), b = source_.F(f, 1), c = source_.F(f, 2);
    return surface_.judge(point(a), point(b), point(c), face_[a], face_[b], face_[c]) != 0;
  }

  // v's image moved to p: its fan judged again, and v's and its neighbours' stamps raised.
  void place(int v, const Eigen::Vector3d& p, int face) {
    image_.row(v) = p.transpose();
    face_[v] = face;
    for (int f : star_[v]) {
      bad_[f] = judge(f);
      for (int c = 0; c < 3; ++c) ++stamp_[source_.F(f, c)];
    }
  }

  // The acceptable point round v's image closest to it (not farther than `bound`), if any. A
  // search that found none is not repeated while v's ring is unchanged and the bound no larger.
  std::optional<Move> best_move(int v, double bound) {
    if (no_move_stamp_[v] == stamp_[v] && bound <= no_move_bound_[v]) return std::nullopt;
    std::optional<Move> move = search_move(v, bound);
    if (!move) no_move_stamp_[v] = stamp_[v], no_move_bound_[v] = bound;
    return move;
  }

  std::optional<Move> search_move(int v, double bound) {
    std::vector<bool> before;
    const int bad_before = star_bad(v, before);
    if (bad_before == 0) return std::nullopt;
    const double shortest = shortest_edge(v);
    if (!std::isfinite(shortest)) return std::nullopt;
    const Frame frame = tangent_frame(v);
    const Eigen::Vector3d old = point(v), origin = input_.row(v).transpose();
    std::optional<Move> best;
    for (double ring : kRings) {
      const double radius = ring * shortest;
      if (radius > kRingSlack * std::min(bound, best ? best->shift : kInfinity)) break;
      for (int d = 0; d < kDirections; ++d) {
        const double angle = 2 * M_PI * d / kDirections;
        const Eigen::Vector3d q = surface_.project(old + radius * (std::cos(angle) * frame.u + std::sin(angle) * frame.w)).first;
        const double shift = (q - old).norm();
        if ((q - origin).norm() > room_[v] || shift == 0 || (best && shift >= best->shift) || shift >= bound) continue;
        // The face the audit finds for q (on an edge, the projection's face may be the other one).
        const int face = surface_.closest(q).first;
        if (trial(v, q, face, before, bad_before))
          best = Move{v, q, face, shift};
      }
    }
    return best;
  }

  const TriMesh& source_;
  TargetSurface surface_;
  const Eigen::MatrixX3d& input_;      // the images as the map gave them
  Eigen::MatrixX3d image_;
  std::vector<int> face_;               // closest target face of each image vertex
  std::vector<std::vector<int>> star_;  // source faces round each vertex
  std::vector<bool> bad_;               // per source face: flipped or degenerate image
  std::vector<double> room_;            // per image: how far it may move from input_
  std::vector<double> shortest_;        // per image: its shortest non-zero edge in the input
  std::vector<int> input_face_;         // face_ and bad_ for the input images
  std::vector<bool> input_bad_;
  double edge_share_;
  // A move's search depends on v's ring only: the images and closest faces of v and its
  // neighbours, the bad flags of its fan (functions of those) and v's fixed input and room. Each
  // vertex's stamp rises whenever it or a neighbour moves (place); a search that found no move
  // records the stamp it saw (and best_move its bound), and is skipped while that still holds.
  // restart() clears the records (the room changes). The same moves as searching every time.
  std::vector<long> stamp_;
  std::vector<long> no_move_stamp_;
  std::vector<double> no_move_bound_;
  std::vector<long> no_fan_move_stamp_;
};

}  // namespace

ImageUntangleResult untangle_image(const TriMesh& source, const Eigen::MatrixX3d& image, const TriMesh& target,
                                   const ImageUntangleOptions& options) {
  if (image.rows() != source.num_vertices() || !image.allFinite())
    throw std::invalid_argument("untangle_image: image needs one finite row per source vertex (" +
                                std::to_string(source.num_vertices()) + "), got " + std::to_string(image.rows()) + " rows");
  if (options.sweeps < 0 || !(options.max_shift >= 0) || !(options.max_edge_share >= 0) ||
      std::any_of(options.wider_shifts.begin(), options.wider_shifts.end(), [](double x) { return !(x >= 0); }))
    throw std::invalid_argument("untangle_image: sweeps, max_shift, max_edge_share and wider_shifts must be >= 0");
  Untangler untangler(source, image, target, options);
  ImageUntangleResult result;
  result.bad_before = untangler.bad_count();
  const double diagonal = bounding_box(target.V).diagonal();
  auto run = [&]() {
    for (int s = 0; s < options.sweeps && untangler.bad_count() > 0; ++s)
      if (!untangler.sweep() && !untangler.optimise()) break;
  };
  run();
  result.image = untangler.image();
  result.bad_after = untangler.bad_count();
  result.shift_allowed = options.max_shift;
  if (options.after_run && result.bad_before > 0) options.after_run(options.max_shift, result.bad_after);
  for (const double shift : options.wider_shifts) {
    if (result.bad_after == 0) break;
    untangler.restart(shift);
    run();
    if (options.after_run) options.after_run(shift, untangler.bad_count());
    if (!(untangler.bad_count() < result.bad_after)) break;  // more room brought nothing: stop
    result.image = untangler.image();
    result.bad_after = untangler.bad_count();
    result.shift_allowed = shift;
  }
  for (int v = 0; v < source.num_vertices(); ++v) {
    const double shift = (result.image.row(v) - image.row(v)).norm();
    if (shift > 0) {
      ++result.moved;
      result.max_shift = std::max(result.max_shift, diagonal > 0 ? shift / diagonal : shift);
    }
  }
  return result;
}

}  // namespace polycube
