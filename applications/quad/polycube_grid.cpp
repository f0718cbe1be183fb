#include "applications/quad/polycube_grid.h"

#include "applications/quad/surface_projector.h"
#include "polycube/disjoint_sets.h"
#include "polycube/errors.h"
#include "polycube/parallel.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <queue>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>

namespace polycube {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kIndexBits = 21;             // level indices per axis < 2^21 in a packed vertex key
constexpr double kInsideTolerance = 1e-9;  // barycentric slack for points on triangle edges

// Axis, outward sign and plane level of one triangle of P.
struct TriangleLabel {
  int axis = 0;
  int sign = 1;
  int level = -1;
};

// A cell between consecutive levels on a face plane: plane `level` of `axis`, intervals i and j
// of the two other axes (axis+1, axis+2 mod 3), with the outward sign of the face covering it.
struct LevelCell {
  int axis, level, i, j, sign;
  bool operator<(const LevelCell& o) const {
    return std::tie(axis, level, i, j, sign) < std::tie(o.axis, o.level, o.i, o.j, o.sign);
  }
  bool operator==(const LevelCell& o) const { return !(*this < o) && !(o < *this); }
  bool same_place(const LevelCell& o) const { return axis == o.axis && level == o.level && i == o.i && j == o.j; }
};

std::uint64_t pack(const std::array<int, 3>& index) {
  return (static_cast<std::uint64_t>(index[0]) << (2 * kIndexBits)) | (static_cast<std::uint64_t>(index[1]) << kIndexBits) |
         static_cast<std::uint64_t>(index[2]);
}

// Exact position as a hash key: vertices computed on different cells agree to the last bit.
struct PositionKey {
  std::array<std::uint64_t, 3> bits;
  bool operator==(const PositionKey& o) const { return bits == o.bits; }
};
struct PositionHash {
  size_t operator()(const PositionKey& k) const {
    std::uint64_t h = k.bits[0] * 0x9E3779B97F4A7C15ULL;
    h ^= k.bits[1] + 0x9E3779B97F4A7C15ULL + (h << 6) + (h >> 2);
    h ^= k.bits[2] + 0x9E3779B97F4A7C15ULL + (h << 6) + (h >> 2);
    return static_cast<size_t>(h);
  }
};
PositionKey position_key(const Eigen::Vector3d& p) {
  PositionKey key;
  for (int a = 0; a < 3; ++a) {
    const double x = p[a] == 0 ? 0.0 : p[a];  // -0 and +0 are one point
    std::memcpy(&key.bits[a], &x, sizeof x);
  }
  return key;
}

// Sorted values, those within tolerance of the first of a run merged into it.
std::vector<double> merge_values(std::vector<double> values, double tolerance) {
  std::sort(values.begin(), values.end());
  std::vector<double> merged;
  for (double x : values)
    if (merged.empty() || x - merged.back() > tolerance) merged.push_back(x);
  return merged;
}

// Index of the value of sorted within tolerance of x, or -1.
int nearest_index(const std::vector<double>& sorted, double x, double tolerance) {
  const auto it = std::lower_bound(sorted.begin(), sorted.end(), x);
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (auto c : {it, it == sorted.begin() ? it : it - 1}) {
    if (c == sorted.end()) continue;
    const double d = std::abs(*c - x);
    if (d < best_distance) {
      best_distance = d;
      best = static_cast<int>(c - sorted.begin());
    }
  }
  return best_distance <= tolerance ? best : -1;
}

// Barycentric coordinates of p in the 2D triangle (a, b, c) (non-degenerate).
Eigen::Vector3d barycentric_2d(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                               const Eigen::Vector2d& c) {
  const auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) { return u.x() * v.y() - u.y() * v.x(); };
  const double area = cross(b - a, c - a);
  return {cross(b - p, c - p) / area, cross(c - p, a - p) / area, cross(a - p, b - p) / area};
}

// The triangle of P in the coordinates (axis+1, axis+2) of its plane.
std::array<Eigen::Vector2d, 3> triangle_2d(const TriMesh& mesh, int f, int axis) {
  const int b = (axis + 1) % 3, c = (axis + 2) % 3;
  std::array<Eigen::Vector2d, 3> t;
  for (int i = 0; i < 3; ++i) t[i] = {mesh.V(mesh.F(f, i), b), mesh.V(mesh.F(f, i), c)};
  return t;
}

// Indices [first, last) of sorted values within [lo, hi].
std::pair<int, int> index_range(const std::vector<double>& sorted, double lo, double hi) {
  return {static_cast<int>(std::lower_bound(sorted.begin(), sorted.end(), lo) - sorted.begin()),
          static_cast<int>(std::upper_bound(sorted.begin(), sorted.end(), hi) - sorted.begin())};
}

std::vector<TriangleLabel> label_triangles(const TriMesh& mesh) {
  std::vector<TriangleLabel> labels(mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double length = n.norm();
    if (!(length > 0) || !std::isfinite(length))
      throw MeshError("polycube triangle " + std::to_string(f) + " is degenerate (zero area)");
    int axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    const double off = std::max(std::abs(n[(axis + 1) % 3]), std::abs(n[(axis + 2) % 3])) / length;
    if (off > 1e-6) {
      std::ostringstream message;
      message << "polycube triangle " << f << " is not axis-aligned: normal (" << n.x() / length << ", "
              << n.y() / length << ", " << n.z() / length << ")";
      throw MeshError(message.str());
    }
    labels[f].axis = axis;
    labels[f].sign = n[axis] > 0 ? 1 : -1;
  }
  return labels;
}

// How many parts a chord of this width gets for size h.
long long parts(double width, double h) { return std::max(1LL, std::llround(width / h)); }

// Rectangles on P: corners (vertex ids, counter-clockwise from outside), the plane and the
// extents in level indices: [i0, i1] x [j0, j1] of axes (axis+1, axis+2).
struct Rectangle {
  std::array<int, 4> corner;
  int axis, sign, level, i0, i1, j0, j1;
};

// Corners of the rectangle [i0, i1] x [j0, j1] on a plane, counter-clockwise seen from the
// outward side: (e_b, e_c) turns counter-clockwise seen from +e_a since e_b × e_c = e_a.
std::array<std::array<int, 3>, 4> rectangle_corners(int axis, int sign, int level, int i0, int i1, int j0, int j1) {
  const int b = (axis + 1) % 3, c = (axis + 2) % 3;
  std::array<std::array<int, 3>, 4> corners;
  const int is[4] = {i0, i1, i1, i0}, js[4] = {j0, j0, j1, j1};
  for (int k = 0; k < 4; ++k) {
    corners[k][axis] = level;
    corners[k][b] = is[k];
    corners[k][c] = js[k];
  }
  if (sign < 0) std::swap(corners[1], corners[3]);
  return corners;
}

// Undirected edges of a set of quads: each must have exactly two quads (else AlgorithmError).
struct QuadEdges {
  std::vector<std::array<int, 4>> quad_edge;  // per quad: edge of side k (corner k to k+1)
  std::vector<std::array<int, 2>> edge_quad;  // per edge: its two quads
  std::vector<std::array<int, 2>> edge_side;  // per edge: the side index in each of them
  std::vector<std::array<int, 2>> ends;       // per edge: its vertices
};

QuadEdges quad_edges_of(const std::vector<Rectangle>& quads, const std::string& what) {
  QuadEdges e;
  std::map<std::pair<int, int>, int> id;
  e.quad_edge.resize(quads.size());
  for (size_t q = 0; q < quads.size(); ++q)
    for (int k = 0; k < 4; ++k) {
      const int u = quads[q].corner[k], v = quads[q].corner[(k + 1) % 4];
      const auto key = std::make_pair(std::min(u, v), std::max(u, v));
      auto [it, inserted] = id.emplace(key, static_cast<int>(e.ends.size()));
      if (inserted) {
        e.ends.push_back({key.first, key.second});
        e.edge_quad.push_back({static_cast<int>(q), -1});
        e.edge_side.push_back({k, -1});
      } else {
        if (e.edge_quad[it->second][1] >= 0)
          throw AlgorithmError(what + " is not a 2-manifold: an edge has more than two cells");
        e.edge_quad[it->second][1] = static_cast<int>(q);
        e.edge_side[it->second][1] = k;
      }
      e.quad_edge[q][k] = it->second;
    }
  for (size_t k = 0; k < e.ends.size(); ++k)
    if (e.edge_quad[k][1] < 0)
      throw AlgorithmError(what + " is not closed: an edge has one cell (P's face boundaries are not on its planes)");
  return e;
}

// Level lines that can go: closed loops through vertices of valence 4, straight on (the edge
// opposite the incoming one), never along a polycube edge (where the two cells' planes differ).
// Returns per edge whether it is removed, and the number of loops.
std::vector<char> free_loop_edges(const std::vector<Rectangle>& cells, const QuadEdges& e, int num_vertices, int* loops) {
  const int ne = static_cast<int>(e.ends.size());
  std::vector<int> valence(num_vertices, 0);
  for (const Rectangle& r : cells)
    for (int v : r.corner) ++valence[v];
  std::vector<std::vector<int>> edges_at(num_vertices);
  for (int k = 0; k < ne; ++k) {
    edges_at[e.ends[k][0]].push_back(k);
    edges_at[e.ends[k][1]].push_back(k);
  }
  const auto feature = [&](int k) {
    const Rectangle &p = cells[e.edge_quad[k][0]], &q = cells[e.edge_quad[k][1]];
    return p.axis != q.axis || p.sign != q.sign;
  };
  const auto side_of = [&](int q, int k) {
    const auto& s = e.quad_edge[q];
    return s[0] == k || s[1] == k || s[2] == k || s[3] == k;
  };
  // The edge straight on from edge k through vertex v, or -1 at an irregular vertex.
  const auto opposite = [&](int k, int v) {
    if (valence[v] != 4) return -1;
    int found = -1, count = 0;
    for (int f : edges_at[v])
      if (f != k && !side_of(e.edge_quad[k][0], f) && !side_of(e.edge_quad[k][1], f)) {
        found = f;
        ++count;
      }
    return count == 1 ? found : -1;
  };
  std::vector<char> visited(ne, 0), removed(ne, 0);
  *loops = 0;
  std::vector<int> line, vertices;
  for (int start = 0; start < ne; ++start) {
    if (visited[start] || feature(start)) continue;
    // Walk on from start's second end until the line closes or ends.
    line.assign(1, start);
    vertices.assign(1, e.ends[start][1]);
    bool closed = false, free = true;
    int current = start, v = e.ends[start][1];
    for (int steps = 0; steps <= ne; ++steps) {
      const int next = opposite(current, v);
      if (next < 0) break;
      if (next == start) {
        closed = true;
        break;
      }
      line.push_back(next);
      v = e.ends[next][0] == v ? e.ends[next][1] : e.ends[next][0];
      vertices.push_back(v);
      current = next;
    }
    for (int k : line) {
      visited[k] = 1;
      free = free && !feature(k);
    }
    if (!closed) continue;  // an open line ends at corners: needed (its other part is walked later)
    std::sort(vertices.begin(), vertices.end());
    if (std::adjacent_find(vertices.begin(), vertices.end()) != vertices.end()) free = false;
    if (!free) continue;
    ++*loops;
    for (int k : line) removed[k] = 1;
  }
  return removed;
}

// P's axes (rows, right-handed) in its file's coordinates: the identity for a polycube whose
// triangles are exactly axis-aligned; otherwise the directions of its face normals (a polycube
// written in a turned frame), from the largest triangle and the largest one across it, refined
// as the nearest rotation to the area-weighted normals grouped by axis.
Eigen::Matrix3d polycube_frame(const TriMesh& mesh) {
  const int nf = mesh.num_faces();
  Eigen::MatrixX3d n(nf, 3);
  bool aligned = true;
  int largest = 0;
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    n.row(f) = (b - a).cross(c - a);
    aligned = aligned && (n.row(f).array() != 0).count() <= 1;
    if (n.row(f).squaredNorm() > n.row(largest).squaredNorm()) largest = f;
  }
  if (aligned) return Eigen::Matrix3d::Identity();
  Eigen::Matrix3d axes;
  axes.row(0) = n.row(largest).normalized();
  int across = -1;
  for (int f = 0; f < nf; ++f)
    if (n.row(f).squaredNorm() > 0 && std::abs(n.row(f).normalized().dot(axes.row(0))) < 0.5 &&
        (across < 0 || n.row(f).squaredNorm() > n.row(across).squaredNorm()))
      across = f;
  if (across < 0) throw MeshError("polycube has no faces across its largest face's normal");
  const Eigen::Vector3d e0 = axes.row(0).transpose(), m = n.row(across).transpose();
  axes.row(1) = (m - m.dot(e0) * e0).normalized();
  axes.row(2) = e0.cross(axes.row(1).transpose()).transpose();
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (int f = 0; f < nf; ++f) {
    const double length = n.row(f).norm();
    if (!(length > 0)) continue;
    const Eigen::Vector3d projections = axes * n.row(f).transpose() / length;
    int k = 0;
    projections.cwiseAbs().maxCoeff(&k);
    sum.row(k) += (projections[k] > 0 ? 0.5 : -0.5) * n.row(f);  // area-weighted unit normal
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d frame = svd.matrixU() * svd.matrixV().transpose();
  if (frame.determinant() < 0) frame = axes;  // a degenerate refinement: keep the first guess
  return frame;
}

}  // namespace

std::vector<int> cone_vertices(const TriMesh& mesh, double tolerance) {
  Eigen::VectorXd angle = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d p = mesh.V.row(mesh.F(f, i));
      const Eigen::Vector3d u = mesh.V.row(mesh.F(f, (i + 1) % 3)) - p.transpose();
      const Eigen::Vector3d v = mesh.V.row(mesh.F(f, (i + 2) % 3)) - p.transpose();
      angle[mesh.F(f, i)] += std::atan2(u.cross(v).norm(), u.dot(v));
    }
  std::vector<int> referenced(mesh.num_vertices(), 0);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) referenced[mesh.F(f, i)] = 1;
  std::vector<int> cones;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (referenced[v] && std::abs(angle[v] - 2 * kPi) > tolerance) cones.push_back(v);
  return cones;
}

PolycubeGrid build_polycube_grid(const TriMesh& polycube, const PolycubeGridOptions& options, const SurfaceMap& size_map) {
  const auto start = std::chrono::steady_clock::now();
  if (!(options.cell_size >= 0) || !std::isfinite(options.cell_size))
    throw std::invalid_argument("cell size must be finite and >= 0, got " + std::to_string(options.cell_size));
  if (options.cell_size == 0 && options.target_quads < 1)
    throw std::invalid_argument("target quad count must be >= 1, got " + std::to_string(options.target_quads));
  if (polycube.num_faces() == 0) throw MeshError("polycube has no triangles");

  // A polycube written in a turned frame (e.g. the model's principal axes) is gridded in its own
  // axes and turned back at the end.
  PolycubeGrid grid;
  grid.frame = polycube_frame(polycube);
  const bool turned = !grid.frame.isIdentity(0);
  TriMesh turned_polycube;
  if (turned) {
    turned_polycube.F = polycube.F;
    turned_polycube.V = polycube.V * grid.frame.transpose();
  }
  const TriMesh& mesh = turned ? turned_polycube : polycube;
  const double diagonal = bounding_box(mesh.V).diagonal();
  const double tolerance = options.merge_tolerance * diagonal;
  std::vector<TriangleLabel> labels = label_triangles(mesh);

  // 1. Levels: the face planes of each axis. Every polycube edge along axis b lies on planes of
  //    the two other axes, and every polycube vertex on a plane of each axis (an edge along b
  //    ends only where a face of axis b starts), so face boundaries are on level lines.
  for (int a = 0; a < 3; ++a) {
    std::vector<double> planes;
    for (int f = 0; f < mesh.num_faces(); ++f)
      if (labels[f].axis == a)
        for (int i = 0; i < 3; ++i) planes.push_back(mesh.V(mesh.F(f, i), a));
    grid.levels[a] = merge_values(planes, tolerance);
    if (grid.levels[a].size() < 2) throw MeshError("polycube has fewer than two face planes across an axis");
    if (grid.levels[a].size() >= (size_t{1} << kIndexBits)) throw MeshError("polycube has too many face planes");
  }
  for (int f = 0; f < mesh.num_faces(); ++f) {
    labels[f].level = nearest_index(grid.levels[labels[f].axis], mesh.V(mesh.F(f, 0), labels[f].axis), 2 * tolerance);
    if (labels[f].level < 0) throw MeshError("polycube triangle " + std::to_string(f) + " is not flat");
  }
  std::array<std::vector<double>, 3> centres;
  for (int a = 0; a < 3; ++a)
    for (size_t i = 0; i + 1 < grid.levels[a].size(); ++i) centres[a].push_back((grid.levels[a][i] + grid.levels[a][i + 1]) / 2);

  // 2. Level cells covered by faces: a cell lies wholly inside or outside every face (face
  //    boundaries are on level lines), so its centre, far from any boundary, decides.
  std::vector<LevelCell> level_cells;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const TriangleLabel& label = labels[f];
    const int a = label.axis, b = (a + 1) % 3, c = (a + 2) % 3;
    const std::array<Eigen::Vector2d, 3> t = triangle_2d(mesh, f, a);
    const Eigen::Vector2d lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]), hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
    const auto [i0, i1] = index_range(centres[b], lo.x(), hi.x());
    const auto [j0, j1] = index_range(centres[c], lo.y(), hi.y());
    for (int i = i0; i < i1; ++i)
      for (int j = j0; j < j1; ++j)
        if (barycentric_2d({centres[b][i], centres[c][j]}, t[0], t[1], t[2]).minCoeff() >= -kInsideTolerance)
          level_cells.push_back({a, label.level, i, j, label.sign});
  }
  std::sort(level_cells.begin(), level_cells.end());
  level_cells.erase(std::unique(level_cells.begin(), level_cells.end()), level_cells.end());
  for (size_t k = 1; k < level_cells.size(); ++k)
    if (level_cells[k].same_place(level_cells[k - 1])) {
      const char* names = "xyz";
      throw AlgorithmError(std::string("faces of P with opposite normals overlap on the plane ") +
                           names[level_cells[k].axis] + " = " + std::to_string(grid.levels[level_cells[k].axis][level_cells[k].level]));
    }
  grid.level_cells = static_cast<long long>(level_cells.size());

  // The level layout: cells as rectangles, corners keyed by level indices.
  std::unordered_map<std::uint64_t, int> level_vertex;
  std::vector<std::array<int, 3>> level_index;
  const auto level_vertex_id = [&](const std::array<int, 3>& index) {
    const auto [it, inserted] = level_vertex.emplace(pack(index), static_cast<int>(level_index.size()));
    if (inserted) level_index.push_back(index);
    return it->second;
  };
  std::vector<Rectangle> cells;
  cells.reserve(level_cells.size());
  for (const LevelCell& l : level_cells) {
    Rectangle r{{}, l.axis, l.sign, l.level, l.i, l.i + 1, l.j, l.j + 1};
    const auto corners = rectangle_corners(l.axis, l.sign, l.level, l.i, l.i + 1, l.j, l.j + 1);
    for (int k = 0; k < 4; ++k) r.corner[k] = level_vertex_id(corners[k]);
    cells.push_back(r);
  }

  // 3. Remove free loops: merge the cells on both sides of their edges into rectangles.
  if (options.remove_free_loops) {
    const QuadEdges edges = quad_edges_of(cells, "the level grid on P");
    const std::vector<char> removed = free_loop_edges(cells, edges, static_cast<int>(level_index.size()), &grid.free_loops);
    DisjointSets blocks(static_cast<int>(cells.size()));
    for (size_t k = 0; k < edges.ends.size(); ++k)
      if (removed[k]) blocks.unite(edges.edge_quad[k][0], edges.edge_quad[k][1]);
    std::map<int, Rectangle> merged;
    std::map<int, long long> members;
    for (size_t q = 0; q < cells.size(); ++q) {
      const Rectangle& r = cells[q];
      const int root = blocks.find(static_cast<int>(q));
      auto [it, inserted] = merged.emplace(root, r);
      ++members[root];
      Rectangle& m = it->second;
      if (inserted) continue;
      if (m.axis != r.axis || m.sign != r.sign || m.level != r.level)
        throw AlgorithmError("removing free loops merged cells of different faces of P");
      m.i0 = std::min(m.i0, r.i0);
      m.i1 = std::max(m.i1, r.i1);
      m.j0 = std::min(m.j0, r.j0);
      m.j1 = std::max(m.j1, r.j1);
    }
    std::vector<Rectangle> blocks_list;
    for (auto& [root, m] : merged) {
      if (static_cast<long long>(m.i1 - m.i0) * (m.j1 - m.j0) != members[root])
        throw AlgorithmError("removing free loops left a cell that is not a rectangle");
      const auto corners = rectangle_corners(m.axis, m.sign, m.level, m.i0, m.i1, m.j0, m.j1);
      for (int k = 0; k < 4; ++k) m.corner[k] = level_vertex_id(corners[k]);
      blocks_list.push_back(m);
    }
    cells = std::move(blocks_list);
  }
  const QuadEdges edges = quad_edges_of(cells, "the quad layout on P");
  const int num_cells = static_cast<int>(cells.size());

  // Layout positions and side lengths.
  const auto level_point = [&](const std::array<int, 3>& index) {
    return Eigen::Vector3d(grid.levels[0][index[0]], grid.levels[1][index[1]], grid.levels[2][index[2]]);
  };
  {
    std::vector<int> used;
    for (const Rectangle& r : cells) used.insert(used.end(), r.corner.begin(), r.corner.end());
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    grid.layout.V.resize(used.size(), 3);
    for (size_t v = 0; v < used.size(); ++v) grid.layout.V.row(v) = level_point(level_index[used[v]]);
    grid.layout.Q.resize(num_cells, 4);
    for (int s = 0; s < num_cells; ++s)
      for (int k = 0; k < 4; ++k)
        grid.layout.Q(s, k) = static_cast<int>(std::lower_bound(used.begin(), used.end(), cells[s].corner[k]) - used.begin());
  }

  // 4. Chords: sides k and k+2 of a cell, and the two sides of a shared edge, split alike.
  DisjointSets slots(2 * num_cells);
  for (size_t k = 0; k < edges.ends.size(); ++k)
    slots.unite(2 * edges.edge_quad[k][0] + edges.edge_side[k][0] % 2, 2 * edges.edge_quad[k][1] + edges.edge_side[k][1] % 2);
  std::vector<int> chord_of(2 * num_cells);
  std::vector<double> width;
  {
    std::map<int, int> id;
    for (int slot = 0; slot < 2 * num_cells; ++slot) {
      const auto [it, inserted] = id.emplace(slots.find(slot), static_cast<int>(id.size()));
      chord_of[slot] = it->second;
      const int s = slot / 2, d = slot % 2;
      const double length = (level_point(level_index[cells[s].corner[d + 1]]) - level_point(level_index[cells[s].corner[d]])).norm();
      if (inserted) width.push_back(length);
      if (std::abs(width[it->second] - length) > 1e-6 * diagonal)
        throw AlgorithmError("a chord of the quad layout on P changes width");
    }
  }
  const int num_chords = static_cast<int>(width.size());
  grid.chords = num_chords;

  // Points of P as surface points: the closest triangle (distance 0 up to rounding), with
  // barycentric coordinates in its plane.
  const SurfaceProjector on_p(mesh);
  const auto off_p = [&](const Eigen::Vector3d& p, double distance) {
    return AlgorithmError("grid point (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " + std::to_string(p.z()) +
                          ") is " + std::to_string(distance) + " away from P");
  };
  // A point too far from P gets face -1 (`distance` set): the callers, on several threads, throw
  // off_p for the first such point in order.
  const auto try_surface_point = [&](const Eigen::Vector3d& p, double& distance) {
    const SurfaceHit hit = on_p.closest(p);
    SurfacePoint point;
    if (hit.distance > 1e-6 * diagonal) {
      distance = hit.distance;
      return point;
    }
    const int a = labels[hit.face].axis;
    const std::array<Eigen::Vector2d, 3> t = triangle_2d(mesh, hit.face, a);
    const Eigen::Vector3d bary = barycentric_2d({p[(a + 1) % 3], p[(a + 2) % 3]}, t[0], t[1], t[2]).cwiseMax(0.0);
    point.face = hit.face;
    point.bary = bary / bary.sum();
    return point;
  };

  // Widths measured through the map: the longest image of the chord's layout edges.
  if (size_map) {
    grid.sized_through_map = true;
    const int ne = static_cast<int>(edges.ends.size());
    const int samples = static_cast<int>(std::clamp<long long>(400000 / std::max(1, ne), 1, 8));
    // Each edge's length through the map on the threads; then, in order, the checks and maxima.
    std::vector<double> edge_length(ne, 0), off(ne, 0);
    std::vector<Eigen::Vector3d> off_point(ne);
    parallel_range(ne, options.threads, [&](int k) {
      const Eigen::Vector3d a = level_point(level_index[edges.ends[k][0]]), b = level_point(level_index[edges.ends[k][1]]);
      double length = 0;
      Eigen::Vector3d previous = Eigen::Vector3d::Zero();
      for (int i = 0; i <= samples; ++i) {
        const Eigen::Vector3d x = i == 0 ? a : i == samples ? b : (a + (b - a) * (static_cast<double>(i) / samples)).eval();
        const SurfacePoint point = try_surface_point(x, off[k]);
        if (point.face < 0) {
          off_point[k] = x;
          return;
        }
        const Eigen::Vector3d next = size_map(point);
        if (i > 0) length += (next - previous).norm();
        previous = next;
      }
      edge_length[k] = length;
    });
    std::vector<double> measured(num_chords, 0);
    for (int k = 0; k < ne; ++k) {
      if (off[k] > 0) throw off_p(off_point[k], off[k]);
      if (!std::isfinite(edge_length[k])) throw AlgorithmError("the map sends a layout edge of P to non-finite points");
      double& m = measured[chord_of[2 * edges.edge_quad[k][0] + edges.edge_side[k][0] % 2]];
      m = std::max(m, edge_length[k]);
    }
    for (int c = 0; c < num_chords; ++c) width[c] = std::max(measured[c], 1e-12 * width[c]);
  }

  // 5. Parts per chord. With a size h: round(width / h), at least 1. With a target count: the h
  //    whose uniform count is closest (the count Σ over cells of parts · parts is non-increasing
  //    in h, so bisection finds it); then, because many chords have equal widths (P's quadtree
  //    cells are dyadic) and jump together, chords are re-chosen one at a time: from
  //    floor(width / h), the chord with the widest step gets one part more while that brings
  //    the count closer to the target.
  std::vector<long long> part(num_chords, 1);
  const auto count_parts = [&] {
    double total = 0;
    for (int s = 0; s < num_cells; ++s)
      total += static_cast<double>(part[chord_of[2 * s]]) * static_cast<double>(part[chord_of[2 * s + 1]]);
    return total;
  };
  const auto count = [&](double h) {
    for (int k = 0; k < num_chords; ++k) part[k] = parts(width[k], h);
    return count_parts();
  };
  const double widest = *std::max_element(width.begin(), width.end());
  if (!(widest > 0)) throw MeshError("polycube is flat");
  double h = options.cell_size;
  if (h > 0) {
    count(h);
  } else {
    const double target = options.target_quads;
    double hi = 4 * widest;  // every chord one part: the fewest quads
    if (count(hi) >= target) {
      h = hi;
    } else {
      double lo = hi;
      for (int k = 0; k < 200 && count(lo) < target; ++k) lo /= 2;
      for (int k = 0; k < 100 && hi / lo > 1 + 1e-12; ++k) {
        const double mid = std::sqrt(lo * hi);
        (count(mid) >= target ? lo : hi) = mid;
      }
      h = std::abs(count(lo) - target) <= std::abs(count(hi) - target) ? lo : hi;

      std::vector<std::vector<int>> cells_of(num_chords);
      for (int s = 0; s < num_cells; ++s) {
        cells_of[chord_of[2 * s]].push_back(s);
        if (chord_of[2 * s + 1] != chord_of[2 * s]) cells_of[chord_of[2 * s + 1]].push_back(s);
      }
      for (int k = 0; k < num_chords; ++k) part[k] = std::max(1LL, static_cast<long long>(width[k] / h));
      double total = count_parts();
      using Entry = std::pair<double, int>;  // (step, chord): widest step first, then lowest id
      std::priority_queue<Entry, std::vector<Entry>, std::function<bool(const Entry&, const Entry&)>> queue(
          [](const Entry& x, const Entry& y) { return x.first != y.first ? x.first < y.first : x.second > y.second; });
      for (int k = 0; k < num_chords; ++k) queue.emplace(width[k] / part[k], k);
      while (total < target && !queue.empty()) {
        const int k = queue.top().second;
        queue.pop();
        double delta = 0;
        for (int s : cells_of[k]) {
          const double before = static_cast<double>(part[chord_of[2 * s]]) * static_cast<double>(part[chord_of[2 * s + 1]]);
          ++part[k];
          delta += static_cast<double>(part[chord_of[2 * s]]) * static_cast<double>(part[chord_of[2 * s + 1]]) - before;
          --part[k];
        }
        if (total + delta - target > target - total) break;  // overshooting further than we are
        ++part[k];
        total += delta;
        queue.emplace(width[k] / part[k], k);
      }
    }
  }
  // Refinement: per chord the cut fractions of its width (ascending along the width's axis, the
  // same in every cell of the chord: a chord keeps its axis and its interval of it across P's
  // edges), equal parts, then halved where asked.
  std::vector<std::vector<double>> cuts(num_chords);
  for (int k = 0; k < num_chords; ++k) {
    cuts[k].resize(part[k] + 1);
    for (long long i = 0; i <= part[k]; ++i) cuts[k][i] = static_cast<double>(i) / static_cast<double>(part[k]);
  }
  // The slot of cell s whose sides run along axis (a + 1) % 3 (side 0 for an outward +e_a cell).
  const auto slot_along_b = [&](int s) { return 2 * s + (cells[s].sign > 0 ? 0 : 1); };
  std::map<std::pair<int, double>, int> last_round_cuts;  // of the last round: (chord, cut) -> its point
  if (!options.refine_rounds.empty()) {
    // A chord whose width is not one interval of one axis in all its cells (not expected: the
    // sides it crosses are parallel to P's edges it crosses) keeps equal parts, which read the
    // same either way.
    std::vector<char> refinable(num_chords, 1);
    {
      std::vector<std::array<double, 3>> extent(num_chords, {-1, 0, 0});  // axis, lo, hi
      for (int s = 0; s < num_cells; ++s) {
        const Rectangle& r = cells[s];
        const int b = (r.axis + 1) % 3, c = (r.axis + 2) % 3;
        const std::array<double, 3> along_b = {double(b), grid.levels[b][r.i0], grid.levels[b][r.i1]};
        const std::array<double, 3> along_c = {double(c), grid.levels[c][r.j0], grid.levels[c][r.j1]};
        for (const auto& [slot, e] : {std::make_pair(slot_along_b(s), along_b), std::make_pair(slot_along_b(s) ^ 1, along_c)}) {
          std::array<double, 3>& known = extent[chord_of[slot]];
          if (known[0] < 0) known = e;
          else if (known != e) refinable[chord_of[slot]] = 0;
        }
      }
    }
    std::map<std::array<int, 3>, std::vector<int>> cells_on_plane;  // (axis, sign, level) -> cells
    for (int s = 0; s < num_cells; ++s) cells_on_plane[{cells[s].axis, cells[s].sign, cells[s].level}].push_back(s);
    const double budget = options.refine_max_quads > 0 ? static_cast<double>(options.refine_max_quads)
                                                       : std::numeric_limits<double>::infinity();
    bool full = false;
    for (const std::vector<GridRefinement>& round : options.refine_rounds) {
      std::map<std::pair<int, double>, int>& inserted = last_round_cuts;  // (chord, cut) added this round -> by which point
      inserted.clear();
      for (size_t n = 0; n < round.size(); ++n) {
        if (full) break;
        const SurfacePoint& point = round[n].point;
        if (point.face < 0 || point.face >= mesh.num_faces())
          throw std::invalid_argument("refinement point on triangle " + std::to_string(point.face) + " of a polycube with " +
                                      std::to_string(mesh.num_faces()));
        if (round[n].halvings < 1 || round[n].halvings > 30)
          throw std::invalid_argument("refinement halvings must be 1..30, got " + std::to_string(round[n].halvings));
        Eigen::Vector3d x = Eigen::Vector3d::Zero();
        for (int i = 0; i < 3; ++i) x += point.bary[i] * mesh.V.row(mesh.F(point.face, i)).transpose();
        const TriangleLabel& label = labels[point.face];
        const int a = label.axis, b = (a + 1) % 3, c = (a + 2) % 3;
        const auto plane = cells_on_plane.find({a, label.sign, label.level});
        if (plane == cells_on_plane.end()) continue;
        const auto by_other = [&](int k, double cut) {
          const auto it = inserted.find({k, cut});
          return it != inserted.end() && it->second != static_cast<int>(n);
        };
        for (int s : plane->second) {
          const Rectangle& r = cells[s];
          const double B0 = grid.levels[b][r.i0], B1 = grid.levels[b][r.i1], C0 = grid.levels[c][r.j0], C1 = grid.levels[c][r.j1];
          if (x[b] < B0 - tolerance || x[b] > B1 + tolerance || x[c] < C0 - tolerance || x[c] > C1 + tolerance) continue;
          const int slot_b = slot_along_b(s);
          std::vector<std::pair<int, double>> added;
          for (const auto& [slot, t] : {std::make_pair(slot_b, (x[b] - B0) / (B1 - B0)), std::make_pair(slot_b ^ 1, (x[c] - C0) / (C1 - C0))}) {
            const int k = chord_of[slot];
            if (!refinable[k]) continue;
            std::vector<double>& cut = cuts[k];
            for (int halving = 0; halving < round[n].halvings; ++halving) {
              const int i = std::clamp(static_cast<int>(std::upper_bound(cut.begin(), cut.end(), t) - cut.begin()) - 1, 0,
                                       static_cast<int>(cut.size()) - 2);
              if (by_other(k, cut[i]) || by_other(k, cut[i + 1])) break;  // halved by another point this round
              const double middle = (cut[i] + cut[i + 1]) / 2;
              if (!(middle > cut[i] && middle < cut[i + 1])) break;  // as fine as doubles go
              cut.insert(cut.begin() + i + 1, middle);
              ++part[k];
              added.emplace_back(k, middle);
              inserted[{k, middle}] = static_cast<int>(n);
            }
          }
          if (!added.empty() && count_parts() > budget) {  // over the budget: undo this point, stop
            for (const auto& [k, middle] : added) {
              cuts[k].erase(std::find(cuts[k].begin(), cuts[k].end(), middle));
              --part[k];
              inserted.erase({k, middle});
            }
            full = true;
          } else {
            grid.refined_parts += static_cast<int>(added.size());
          }
          break;
        }
      }
    }
    for (int k = 0; k < num_chords; ++k) part[k] = static_cast<long long>(cuts[k].size()) - 1;
  }

  const double quads = count_parts();
  if (quads > static_cast<double>(options.max_quads))
    throw AlgorithmError("cell size " + std::to_string(h) + " gives " + std::to_string(static_cast<long long>(quads)) +
                         " quads, more than the limit " + std::to_string(options.max_quads));
  grid.cell_size = h;

  // 6. Quads: each cell split into parts x parts. Coordinates along an axis are computed from the
  //    cell's level values in ascending order, so a vertex on a shared side comes out bit-equal
  //    from both cells and is keyed by its position.
  std::unordered_map<PositionKey, int, PositionHash> vertex_of;
  vertex_of.reserve(static_cast<size_t>(quads) + 16);
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 4>> quad_list;
  std::vector<int> axis_list, cell_list, refined_by_list;
  quad_list.reserve(static_cast<size_t>(quads));
  grid.cell_parts.resize(num_cells, 2);
  const auto vertex = [&](const Eigen::Vector3d& p) {
    const auto [it, inserted] = vertex_of.emplace(position_key(p), static_cast<int>(points.size()));
    if (inserted) points.push_back(p);
    return it->second;
  };
  const auto split = [](double lo, double hi, const std::vector<double>& cut, long long i) {
    return i + 1 == static_cast<long long>(cut.size()) ? hi : lo + (hi - lo) * cut[i];
  };
  std::vector<int> row;
  for (int s = 0; s < num_cells; ++s) {
    const Rectangle& r = cells[s];
    const int a = r.axis, b = (a + 1) % 3, c = (a + 2) % 3;
    grid.cell_parts(s, 0) = static_cast<int>(part[chord_of[2 * s]]);
    grid.cell_parts(s, 1) = static_cast<int>(part[chord_of[2 * s + 1]]);
    // Side 0 runs along b for an outward +e_a cell, along c for -e_a (rectangle_corners).
    const long long nb = r.sign > 0 ? grid.cell_parts(s, 0) : grid.cell_parts(s, 1);
    const long long nc = r.sign > 0 ? grid.cell_parts(s, 1) : grid.cell_parts(s, 0);
    const double B0 = grid.levels[b][r.i0], B1 = grid.levels[b][r.i1], C0 = grid.levels[c][r.j0], C1 = grid.levels[c][r.j1];
    row.assign((nb + 1) * (nc + 1), -1);
    for (long long i = 0; i <= nb; ++i)
      for (long long j = 0; j <= nc; ++j) {
        Eigen::Vector3d p;
        p[a] = grid.levels[a][r.level];
        p[b] = split(B0, B1, cuts[chord_of[slot_along_b(s)]], i);
        p[c] = split(C0, C1, cuts[chord_of[slot_along_b(s) ^ 1]], j);
        row[i * (nc + 1) + j] = vertex(p);
      }
    for (long long i = 0; i < nb; ++i)
      for (long long j = 0; j < nc; ++j) {
        std::array<int, 4> q = {row[i * (nc + 1) + j], row[(i + 1) * (nc + 1) + j], row[(i + 1) * (nc + 1) + j + 1],
                                row[i * (nc + 1) + j + 1]};
        if (r.sign < 0) std::swap(q[1], q[3]);
        quad_list.push_back(q);
        axis_list.push_back(r.sign * (a + 1));
        cell_list.push_back(s);
        int by = -1;
        if (!last_round_cuts.empty()) {
          const int kb = chord_of[slot_along_b(s)], kc = chord_of[slot_along_b(s) ^ 1];
          for (const auto& [k, cut] : {std::make_pair(kb, cuts[kb][i]), std::make_pair(kb, cuts[kb][i + 1]),
                                       std::make_pair(kc, cuts[kc][j]), std::make_pair(kc, cuts[kc][j + 1])}) {
            const auto it = last_round_cuts.find({k, cut});
            if (it != last_round_cuts.end()) by = std::max(by, it->second);
          }
        }
        refined_by_list.push_back(by);
      }
  }
  const int nv = static_cast<int>(points.size()), nq = static_cast<int>(quad_list.size());
  grid.mesh.V.resize(nv, 3);
  for (int v = 0; v < nv; ++v) grid.mesh.V.row(v) = points[v];
  grid.mesh.Q.resize(nq, 4);
  grid.quad_axis.resize(nq);
  grid.quad_cell.resize(nq);
  grid.quad_refined_by = Eigen::Map<const Eigen::VectorXi>(refined_by_list.data(), nq);
  for (int q = 0; q < nq; ++q) {
    for (int k = 0; k < 4; ++k) grid.mesh.Q(q, k) = quad_list[q][k];
    grid.quad_axis[q] = axis_list[q];
    grid.quad_cell[q] = cell_list[q];
  }

  // The guarantee, checked: a closed, oriented 2-manifold (no T-junctions).
  const QuadTopology topology = quad_topology(grid.mesh);
  if (!topology.closed_manifold())
    throw AlgorithmError("quad grid on P is not a closed oriented 2-manifold: " + std::to_string(topology.boundary_edges) +
                         " boundary edges, " + std::to_string(topology.nonmanifold_edges) + " non-manifold edges, " +
                         std::to_string(topology.misoriented_edges) + " misoriented edges, " +
                         std::to_string(topology.nonmanifold_vertices) + " non-manifold vertices");

  // 7. Each vertex as a point of P.
  grid.on_polycube.resize(nv);
  std::vector<double> off(nv, 0);
  parallel_range(nv, options.threads, [&](int v) { grid.on_polycube[v] = try_surface_point(grid.mesh.V.row(v).transpose(), off[v]); });
  for (int v = 0; v < nv; ++v)
    if (off[v] > 0) throw off_p(grid.mesh.V.row(v).transpose(), off[v]);

  // 8. Corners: P's cone points, each a grid vertex (a layout corner).
  std::vector<std::pair<int, int>> corners;
  for (int c : cone_vertices(mesh)) {
    std::array<int, 3> index;
    for (int a = 0; a < 3; ++a) index[a] = nearest_index(grid.levels[a], mesh.V(c, a), 2 * tolerance);
    const auto it = index[0] < 0 || index[1] < 0 || index[2] < 0 ? vertex_of.end() : vertex_of.find(position_key(level_point(index)));
    if (it == vertex_of.end())
      throw AlgorithmError("corner vertex " + std::to_string(c) + " of P is not a vertex of the quad grid");
    corners.emplace_back(it->second, c);
  }
  std::sort(corners.begin(), corners.end());
  for (const auto& [g, c] : corners) {
    grid.corners.push_back(g);
    grid.corner_polycube_vertex.push_back(c);
  }
  if (turned) {
    grid.mesh.V = grid.mesh.V * grid.frame;
    grid.layout.V = grid.layout.V * grid.frame;
  }
  grid.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return grid;
}

}  // namespace polycube
