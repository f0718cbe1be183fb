#include "polycube/contour_sections.h"

#include "polycube/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace polycube {

namespace {

double signed_area(const std::vector<Eigen::Vector2d>& polygon) {
  double twice = 0;
  const size_t n = polygon.size();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = polygon[i];
    const Eigen::Vector2d& q = polygon[(i + 1) % n];
    twice += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * twice;
}

// Crossing-number test; the contours of a plane are disjoint, so a vertex of one is never on
// another (up to self-intersections of the input).
bool inside(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p) {
  bool in = false;
  const size_t n = polygon.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (p.x() < x) in = !in;
    }
  }
  return in;
}

struct Box2 {
  Eigen::Vector2d min, max;
  bool contains(const Eigen::Vector2d& p) const {
    return p.x() >= min.x() && p.x() <= max.x() && p.y() >= min.y() && p.y() <= max.y();
  }
};

}  // namespace

CrossSections cross_sections(const SlicedMesh& sliced, const NormalisedFrame& frame) {
  CrossSections result;
  result.frame = frame;
  const int num_planes = static_cast<int>(sliced.planes.size());
  result.planes.resize(num_planes);
  for (int p = 0; p < num_planes; ++p) result.planes[p].z = sliced.planes[p];
  result.vertex_contour.assign(sliced.mesh.num_vertices(), -1);
  const Eigen::MatrixX3d& V = sliced.mesh.V;

  // Contours from the pieces below their plane; their loops have the piece (below) on the left,
  // which puts the inside of the cross-section on the right: reverse them. Contours are numbered
  // by plane, then by their lexicographically smallest point, so that the numbering of a plane's
  // contours does not depend on the other planes.
  std::vector<SectionContour> raw;
  std::vector<Eigen::Vector2d> smallest;
  for (const Piece& piece : sliced.pieces)
    for (size_t l = 0; l < piece.boundary_loops.size(); ++l) {
      if (piece.loop_plane[l] != piece.plane_above) continue;
      SectionContour contour;
      contour.plane = piece.loop_plane[l];
      contour.vertices.assign(piece.boundary_loops[l].rbegin(), piece.boundary_loops[l].rend());
      contour.points.reserve(contour.vertices.size());
      Eigen::Vector2d low(std::numeric_limits<double>::infinity(), 0);
      for (int v : contour.vertices) {
        const Eigen::Vector2d q((V(v, 0) - frame.origin.x()) / frame.scale, (V(v, 1) - frame.origin.y()) / frame.scale);
        contour.points.push_back(q);
        if (q.x() < low.x() || (q.x() == low.x() && q.y() < low.y())) low = q;
      }
      contour.area = signed_area(contour.points);
      raw.push_back(std::move(contour));
      smallest.push_back(low);
    }
  std::vector<int> order(raw.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (raw[a].plane != raw[b].plane) return raw[a].plane < raw[b].plane;
    if (smallest[a].x() != smallest[b].x()) return smallest[a].x() < smallest[b].x();
    return smallest[a].y() < smallest[b].y();
  });
  std::vector<std::vector<int>> plane_contours(num_planes);
  for (int i : order) {
    const int id = static_cast<int>(result.contours.size());
    for (int v : raw[i].vertices) result.vertex_contour[v] = id;
    plane_contours[raw[i].plane].push_back(id);
    result.contours.push_back(std::move(raw[i]));
  }

  // Loops of every piece, matched through their vertices (each plane vertex is on one contour).
  result.piece_contours.resize(sliced.pieces.size());
  std::vector<int> seen_from_above(result.contours.size(), 0);
  for (size_t p = 0; p < sliced.pieces.size(); ++p) {
    const Piece& piece = sliced.pieces[p];
    for (size_t l = 0; l < piece.boundary_loops.size(); ++l) {
      const int c = result.vertex_contour[piece.boundary_loops[l].front()];
      if (c < 0)
        throw AlgorithmError("cross_sections: loop " + std::to_string(l) + " of piece " + std::to_string(p) +
                             " is not the loop of any piece below its plane");
      if (piece.loop_plane[l] == piece.plane_below) ++seen_from_above[c];
      result.piece_contours[p].push_back(c);
    }
  }
  for (size_t c = 0; c < result.contours.size(); ++c)
    if (seen_from_above[c] != 1)
      throw AlgorithmError("cross_sections: contour " + std::to_string(c) + " on plane " +
                           std::to_string(result.contours[c].plane) + " bounds " +
                           std::to_string(seen_from_above[c]) + " pieces above it, expected 1");

  // Nesting per plane.
  for (int p = 0; p < num_planes; ++p) {
    PlaneSection& section = result.planes[p];
    section.contours = plane_contours[p];
    const int k = static_cast<int>(section.contours.size());
    std::vector<Box2> boxes(k);
    double total = 0;
    for (int i = 0; i < k; ++i) {
      SectionContour& c = result.contours[section.contours[i]];
      c.local = i;
      boxes[i].min = boxes[i].max = c.points.front();
      for (const Eigen::Vector2d& q : c.points) {
        boxes[i].min = boxes[i].min.cwiseMin(q);
        boxes[i].max = boxes[i].max.cwiseMax(q);
      }
      total += c.area;
    }
    if (k > 0 && !(total > 0))
      throw AlgorithmError("cross_sections: the contours of plane " + std::to_string(p) +
                           " enclose a total area of " + std::to_string(total) + ", expected a positive one");
    for (int i = 0; i < k; ++i) {
      SectionContour& c = result.contours[section.contours[i]];
      double parent_area = 0;
      for (int j = 0; j < k; ++j) {
        if (j == i) continue;
        const SectionContour& d = result.contours[section.contours[j]];
        if (std::abs(d.area) <= std::abs(c.area) || !boxes[j].contains(c.points.front())) continue;
        if (!inside(d.points, c.points.front())) continue;
        ++c.depth;
        if (c.parent < 0 || std::abs(d.area) < parent_area) {
          c.parent = j;
          parent_area = std::abs(d.area);
        }
      }
      const bool outer = c.area > 0;
      if (outer != (c.depth % 2 == 0))
        throw AlgorithmError("cross_sections: contour " + std::to_string(section.contours[i]) + " on plane " +
                             std::to_string(p) + " is " + (outer ? "an outer contour" : "a hole") +
                             " at nesting depth " + std::to_string(c.depth) +
                             " (inconsistent nesting: self-intersecting surface?)");
    }
    section.face_solid.assign(k + 1, 0);
    section.face_parent.assign(k + 1, -1);
    section.face_area.assign(k + 1, 0.0);
    for (int i = 0; i < k; ++i) {
      const SectionContour& c = result.contours[section.contours[i]];
      section.face_solid[i + 1] = c.area > 0;
      section.face_parent[i + 1] = c.parent + 1;
      section.face_area[i + 1] += std::abs(c.area);
      if (c.parent >= 0) section.face_area[c.parent + 1] -= std::abs(c.area);
    }
    section.face_area[0] = 0;
  }
  return result;
}

int count_contour_crossings(const CrossSections& sections, int plane, Eigen::Vector2d* where) {
  // Segments (contour, index) bucketed into a uniform grid by their bounding boxes; pairs in a
  // common cell are tested, neighbours along one contour skipped.
  struct Segment {
    int contour, index;
    Eigen::Vector2d a, b;
  };
  std::vector<Segment> segments;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const int c : sections.planes.at(plane).contours) {
    const std::vector<Eigen::Vector2d>& points = sections.contours[c].points;
    const int n = static_cast<int>(points.size());
    for (int k = 0; k < n; ++k) {
      segments.push_back({c, k, points[k], points[(k + 1) % n]});
      lo = lo.cwiseMin(points[k]);
      hi = hi.cwiseMax(points[k]);
    }
  }
  if (segments.size() < 2) return 0;
  const int cells = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(segments.size()))), 1, 1024);
  const Eigen::Vector2d size = ((hi - lo) / cells).cwiseMax(1e-300);
  auto cell_of = [&](const Eigen::Vector2d& p, int axis) {
    return std::clamp(static_cast<int>((p[axis] - lo[axis]) / size[axis]), 0, cells - 1);
  };
  std::vector<std::vector<int>> bucket(static_cast<size_t>(cells) * cells);
  for (size_t s = 0; s < segments.size(); ++s) {
    const Segment& g = segments[s];
    const Eigen::Vector2d a = g.a.cwiseMin(g.b), b = g.a.cwiseMax(g.b);
    for (int i = cell_of(a, 0); i <= cell_of(b, 0); ++i)
      for (int j = cell_of(a, 1); j <= cell_of(b, 1); ++j) bucket[static_cast<size_t>(i) * cells + j].push_back(static_cast<int>(s));
  }
  auto orientation = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    const double d = (q.x() - p.x()) * (r.y() - p.y()) - (q.y() - p.y()) * (r.x() - p.x());
    return (d > 0) - (d < 0);
  };
  std::vector<std::pair<int, int>> crossing;
  for (const std::vector<int>& in : bucket)
    for (size_t x = 0; x < in.size(); ++x)
      for (size_t y = x + 1; y < in.size(); ++y) {
        const Segment &g = segments[in[x]], &h = segments[in[y]];
        if (g.contour == h.contour) {
          const int n = static_cast<int>(sections.contours[g.contour].points.size());
          const int d = std::abs(g.index - h.index);
          if (d <= 1 || d == n - 1) continue;
        }
        if (orientation(g.a, g.b, h.a) * orientation(g.a, g.b, h.b) < 0 && orientation(h.a, h.b, g.a) * orientation(h.a, h.b, g.b) < 0)
          crossing.emplace_back(std::min(in[x], in[y]), std::max(in[x], in[y]));
      }
  std::sort(crossing.begin(), crossing.end());
  crossing.erase(std::unique(crossing.begin(), crossing.end()), crossing.end());
  if (!crossing.empty() && where) {
    const Segment &g = segments[crossing.front().first], &h = segments[crossing.front().second];
    const Eigen::Vector2d r = g.b - g.a, q = h.b - h.a;
    const double t = ((h.a - g.a).x() * q.y() - (h.a - g.a).y() * q.x()) / (r.x() * q.y() - r.y() * q.x());
    *where = g.a + t * r;
  }
  return static_cast<int>(crossing.size());
}

}  // namespace polycube
