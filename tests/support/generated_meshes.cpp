#include "support/generated_meshes.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace polycube::test {

namespace {

constexpr double kPi = 3.14159265358979323846;

TriMesh to_mesh(const std::vector<Eigen::Vector3d>& points, const std::vector<std::array<int, 3>>& triangles) {
  TriMesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t i = 0; i < points.size(); ++i) mesh.V.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  mesh.F.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (size_t f = 0; f < triangles.size(); ++f)
    for (int c = 0; c < 3; ++c) mesh.F(static_cast<Eigen::Index>(f), c) = triangles[f][c];
  return mesh;
}

std::uint64_t pair_key(int a, int b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

std::uint64_t undirected_key(int a, int b) { return a < b ? pair_key(a, b) : pair_key(b, a); }

// ---- implicit surfaces ---------------------------------------------------------------------------

// An implicit surface {p : value(p) = 0}, negative inside, with |gradient| close to 1 near the
// surface (a signed distance up to blending), and a box that contains it.
struct Implicit {
  // Value at p; writes the gradient to *gradient when given.
  std::function<double(const Eigen::Vector3d& p, Eigen::Vector3d* gradient)> evaluate;
  Eigen::Vector3d box_min, box_max;

  double value(const Eigen::Vector3d& p) const { return evaluate(p, nullptr); }

  Eigen::Vector3d gradient(const Eigen::Vector3d& p) const {
    Eigen::Vector3d g;
    evaluate(p, &g);
    return g;
  }

  // Newton steps along the gradient onto the zero set (the point starts close to it).
  Eigen::Vector3d project(Eigen::Vector3d p) const {
    for (int it = 0; it < 3; ++it) {
      Eigen::Vector3d g;
      const double v = evaluate(p, &g);
      const double g2 = g.squaredNorm();
      if (g2 < 1e-12) break;
      p -= v * g / g2;
    }
    return p;
  }
};

struct Segment {
  Eigen::Vector3d a, b;
};

// Vector from the closest point of s to p.
Eigen::Vector3d offset_from_segment(const Eigen::Vector3d& p, const Segment& s) {
  const Eigen::Vector3d ab = s.b - s.a;
  const double t = std::clamp((p - s.a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return p - (s.a + t * ab);
}

Implicit ellipsoid() {
  const Eigen::Vector3d axes(1.2, 0.9, 0.7);
  Implicit s;
  // Scaled so that the gradient is close to unit length on the surface.
  s.evaluate = [axes](const Eigen::Vector3d& p, Eigen::Vector3d* gradient) {
    const Eigen::Vector3d q = p.cwiseQuotient(axes);
    const double length = q.norm();
    if (gradient) *gradient = length > 0 ? Eigen::Vector3d(0.9 * (q / length).cwiseQuotient(axes)) : Eigen::Vector3d::Zero();
    return (length - 1.0) * 0.9;
  };
  s.box_min = -axes;
  s.box_max = axes;
  return s;
}

// Tube of radius `radius` around the edges of g unit cells (side `cell`) of a grid in the plane
// z = 0, filled row by row. A row-major filled set of cells is simply connected, so the edge graph
// has exactly g independent cycles and the tube surface has genus g. Collinear edges are merged
// into one segment so that straight tubes have no blending bumps; junctions are blended with a
// log-sum-exp smooth minimum of the segment distances.
Implicit grid_graph_tube(int genus) {
  const double cell = 1.2, radius = 0.3, blend = 0.06;
  const int rows = genus <= 3 ? 1 : 2;
  const int cols = (genus + rows - 1) / rows;
  auto filled = [&](int row, int col) {
    return row >= 0 && row < rows && col >= 0 && col < cols && row * cols + col < genus;
  };
  std::vector<Segment> segments;
  // Horizontal line y = j*cell touches cells of rows j-1 and j.
  for (int j = 0; j <= rows; ++j) {
    int lo = cols, hi = -1;
    for (int c = 0; c < cols; ++c)
      if (filled(j - 1, c) || filled(j, c)) lo = std::min(lo, c), hi = std::max(hi, c);
    if (hi >= lo) segments.push_back({{lo * cell, j * cell, 0}, {(hi + 1) * cell, j * cell, 0}});
  }
  // Vertical line x = i*cell touches cells of columns i-1 and i.
  for (int i = 0; i <= cols; ++i) {
    int lo = rows, hi = -1;
    for (int r = 0; r < rows; ++r)
      if (filled(r, i - 1) || filled(r, i)) lo = std::min(lo, r), hi = std::max(hi, r);
    if (hi >= lo) segments.push_back({{i * cell, lo * cell, 0}, {i * cell, (hi + 1) * cell, 0}});
  }
  // Centre the graph at the origin.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
  for (const Segment& s : segments) {
    lo = lo.cwiseMin(s.a).cwiseMin(s.b);
    hi = hi.cwiseMax(s.a).cwiseMax(s.b);
  }
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  for (Segment& s : segments) s.a -= centre, s.b -= centre;

  Implicit s;
  // value = -blend * log(sum_i exp(-d_i / blend)) - radius, evaluated relative to the nearest
  // segment for stability; its gradient is the softmin-weighted mean of the unit offsets.
  s.evaluate = [segments, radius, blend](const Eigen::Vector3d& p, Eigen::Vector3d* gradient) {
    double dmin = 1e300;
    for (const Segment& segment : segments) dmin = std::min(dmin, offset_from_segment(p, segment).norm());
    double sum = 0;
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    for (const Segment& segment : segments) {
      const Eigen::Vector3d offset = offset_from_segment(p, segment);
      const double d = offset.norm();
      const double w = std::exp(-(d - dmin) / blend);
      sum += w;
      if (gradient && d > 0) weighted += w * offset / d;
    }
    if (gradient) *gradient = weighted / sum;
    return dmin - blend * std::log(sum) - radius;
  };
  // The smooth minimum lies at most blend*log(#segments) below the true minimum distance, so the
  // surface bulges out by up to that much where segments meet.
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(radius + blend * std::log(double(segments.size())));
  s.box_min = lo - centre - pad;
  s.box_max = hi - centre + pad;
  return s;
}

// ---- marching tetrahedra -------------------------------------------------------------------------

// Polygonises the zero set of `surface` over a grid of cubes (side h), each cut into the six
// tetrahedra of the Freudenthal (Kuhn) subdivision, which matches across cube faces. Grid values
// are nudged away from exactly zero, so the piecewise-linear zero set is a closed 2-manifold;
// vertices on the same grid edge are shared through the edge's node pair. Triangles are oriented
// combinatorially from the node signs (outside = positive), not from their possibly tiny normals.
TriMesh marching_tetrahedra(const Implicit& surface, int resolution) {
  const Eigen::Vector3d extent = surface.box_max - surface.box_min;
  const double h = extent.maxCoeff() / resolution;
  const int margin = 2;
  Eigen::Vector3i cells;
  for (int d = 0; d < 3; ++d) cells[d] = static_cast<int>(std::ceil(extent[d] / h)) + 2 * margin;
  const Eigen::Vector3d origin =
      0.5 * (surface.box_min + surface.box_max) - 0.5 * h * cells.cast<double>();
  const int nx = cells[0] + 1, ny = cells[1] + 1, nz = cells[2] + 1;
  auto node_id = [&](int i, int j, int k) { return i + nx * (j + ny * k); };
  auto node_grid = [&](int id) { return Eigen::Vector3i(id % nx, (id / nx) % ny, id / (nx * ny)); };
  auto node_position = [&](int id) -> Eigen::Vector3d { return origin + h * node_grid(id).cast<double>(); };

  std::vector<double> values(static_cast<size_t>(nx) * ny * nz);
  const double nudge = 1e-7 * h;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        double v = surface.value(origin + h * Eigen::Vector3d(i, j, k));
        if (std::abs(v) < nudge) v = nudge;
        values[node_id(i, j, k)] = v;
      }

  // The surface must not reach the grid's outer nodes, or it would be cut open there.
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        if ((i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1) && values[node_id(i, j, k)] < 0)
          throw std::logic_error("marching_tetrahedra: the surface leaves the bounding box it declared");

  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
  std::unordered_map<std::uint64_t, int> edge_vertex;
  auto vertex_on = [&](int a, int b) {
    auto [it, inserted] = edge_vertex.emplace(undirected_key(a, b), static_cast<int>(points.size()));
    if (inserted) {
      const double fa = values[a], fb = values[b];
      const double t = fa / (fa - fb);
      points.push_back(node_position(a) + t * (node_position(b) - node_position(a)));
    }
    return it->second;
  };
  // Orientation of four grid nodes, exact in integer grid coordinates.
  auto orient = [&](int o, int a, int b, int c) {
    const Eigen::Vector3i go = node_grid(o);
    const Eigen::Vector3i u = node_grid(a) - go, v = node_grid(b) - go, w = node_grid(c) - go;
    return u.dot(v.cross(w));
  };

  // Freudenthal subdivision: tetrahedra 0 -> e_a -> e_a + e_b -> 7 over the axis permutations.
  static const int kPermutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k + 1 < nz; ++k)
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i)
        for (const auto& perm : kPermutations) {
          std::array<int, 4> tet;
          Eigen::Vector3i step(0, 0, 0);
          tet[0] = node_id(i, j, k);
          for (int s = 0; s < 3; ++s) {
            step[perm[s]] = 1;
            tet[s + 1] = node_id(i + step[0], j + step[1], k + step[2]);
          }
          std::array<int, 4> inside, outside;
          int n_in = 0, n_out = 0;
          for (int node : tet) (values[node] < 0 ? inside[n_in++] : outside[n_out++]) = node;
          if (n_in == 0 || n_out == 0) continue;
          if (n_in == 1 || n_out == 1) {
            // The triangle cuts the edges at the lone node; it faces away from an inside node
            // and towards an outside one.
            const bool lone_inside = n_in == 1;
            const int lone = lone_inside ? inside[0] : outside[0];
            std::array<int, 3> others = lone_inside ? std::array<int, 3>{outside[0], outside[1], outside[2]}
                                                    : std::array<int, 3>{inside[0], inside[1], inside[2]};
            const int det = orient(lone, others[0], others[1], others[2]);
            if ((det > 0) != lone_inside) std::swap(others[1], others[2]);
            triangles.push_back({vertex_on(lone, others[0]), vertex_on(lone, others[1]), vertex_on(lone, others[2])});
          } else {
            // Quad on edges ac, ad, bd, bc (a, b inside; c, d outside), oriented like its
            // edge-midpoint parallelogram relative to the inside -> outside direction.
            const int a = inside[0], b = inside[1], c = outside[0], d = outside[1];
            const Eigen::Vector3i ga = node_grid(a), gb = node_grid(b), gc = node_grid(c), gd = node_grid(d);
            // Twice the midpoints: ac, ad, bd, bc.
            const Eigen::Vector3i m0 = ga + gc, m1 = ga + gd, m2 = gb + gd, m3 = gb + gc;
            const Eigen::Vector3i normal = (m2 - m0).cross(m3 - m1);
            const Eigen::Vector3i direction = (gc + gd) - (ga + gb);
            std::array<int, 4> quad = {vertex_on(a, c), vertex_on(a, d), vertex_on(b, d), vertex_on(b, c)};
            if (normal.dot(direction) < 0) std::swap(quad[1], quad[3]);
            // Split along the shorter diagonal.
            if ((points[quad[0]] - points[quad[2]]).squaredNorm() <= (points[quad[1]] - points[quad[3]]).squaredNorm()) {
              triangles.push_back({quad[0], quad[1], quad[2]});
              triangles.push_back({quad[0], quad[2], quad[3]});
            } else {
              triangles.push_back({quad[1], quad[2], quad[3]});
              triangles.push_back({quad[1], quad[3], quad[0]});
            }
          }
        }
  return to_mesh(points, triangles);
}

// ---- mesh improvement ----------------------------------------------------------------------------

double corner_angle(const Eigen::Vector3d& at, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d u = p - at, v = q - at;
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

// Flips edges of a closed, oriented 2-manifold whose two opposite angles sum to more than pi
// (intrinsic Delaunay criterion), unless the new edge already exists or the flip would fold
// the surface. Each flip strictly improves the Delaunay energy, so the passes terminate; the
// pass bound only guards against rounding ping-pong. Returns the number of flips.
int delaunay_flips(const Eigen::MatrixX3d& V, Eigen::MatrixX3i& F) {
  // Directed half-edge (u, v) -> face containing u -> v.
  std::unordered_map<std::uint64_t, int> face_of;
  std::unordered_set<std::uint64_t> edges;
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      face_of[pair_key(F(f, c), F(f, (c + 1) % 3))] = f;
      edges.insert(undirected_key(F(f, c), F(f, (c + 1) % 3)));
    }
  auto opposite = [&](int f, int u, int v) {
    for (int c = 0; c < 3; ++c)
      if (F(f, c) != u && F(f, c) != v) return F(f, c);
    return -1;
  };
  int flips = 0;
  for (int pass = 0; pass < 100; ++pass) {
    int pass_flips = 0;
    for (int f = 0; f < F.rows(); ++f)
      for (int c = 0; c < 3; ++c) {
        const int u = F(f, c), v = F(f, (c + 1) % 3);
        const auto it = face_of.find(pair_key(v, u));
        if (it == face_of.end()) continue;
        const int g = it->second;
        const int a = opposite(f, u, v), b = opposite(g, v, u);
        const Eigen::Vector3d pu = V.row(u), pv = V.row(v), pa = V.row(a), pb = V.row(b);
        if (corner_angle(pa, pu, pv) + corner_angle(pb, pv, pu) <= kPi + 1e-9) continue;
        if (edges.count(undirected_key(a, b))) continue;
        // New faces (u, b, a) and (b, v, a) must face the same way as the old pair.
        const Eigen::Vector3d old_normal = (pv - pu).cross(pa - pu) + (pu - pv).cross(pb - pv);
        const Eigen::Vector3d n1 = (pb - pu).cross(pa - pu), n2 = (pv - pb).cross(pa - pb);
        if (n1.dot(old_normal) <= 0 || n2.dot(old_normal) <= 0) continue;
        for (const auto& [x, y] : {std::pair{u, v}, {v, a}, {a, u}}) face_of.erase(pair_key(x, y));
        for (const auto& [x, y] : {std::pair{v, u}, {u, b}, {b, v}}) face_of.erase(pair_key(x, y));
        edges.erase(undirected_key(u, v));
        edges.insert(undirected_key(a, b));
        F.row(f) << u, b, a;
        F.row(g) << b, v, a;
        for (int k = 0; k < 3; ++k) {
          face_of[pair_key(F(f, k), F(f, (k + 1) % 3))] = f;
          face_of[pair_key(F(g, k), F(g, (k + 1) % 3))] = g;
        }
        ++pass_flips;
        break;  // row f changed: continue with the next face
      }
    flips += pass_flips;
    if (pass_flips == 0) break;
  }
  return flips;
}

// Moves every vertex part of the way to the mean of its neighbours within the tangent plane of
// the implicit surface, then projects it back onto the surface.
void tangential_smoothing(const Implicit& surface, Eigen::MatrixX3d& V, const Eigen::MatrixX3i& F, int iterations) {
  std::vector<std::vector<int>> neighbours(V.rows());
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) neighbours[F(f, c)].push_back(F(f, (c + 1) % 3));
  const double step = 0.5;
  for (int it = 0; it < iterations; ++it) {
    Eigen::MatrixX3d next = V;
    for (int v = 0; v < V.rows(); ++v) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int w : neighbours[v]) mean += V.row(w).transpose();
      mean /= static_cast<double>(neighbours[v].size());
      const Eigen::Vector3d p = V.row(v);
      Eigen::Vector3d n = surface.gradient(p);
      if (n.norm() > 0) n.normalize();
      Eigen::Vector3d move = mean - p;
      move -= move.dot(n) * n;
      next.row(v) = surface.project(p + step * move).transpose();
    }
    V = next;
  }
}

// Marching tetrahedra leaves slivers where the surface passes close to grid nodes; alternating
// Delaunay flips (better connectivity) with tangential smoothing (even spacing) removes them.
// The schedule is fixed, not a convergence loop, so the result is deterministic; it brings the
// smallest angle above 10 degrees for genus 0..10 at resolutions 16..96 (measured).
TriMesh polygonise(const Implicit& surface, int resolution) {
  TriMesh mesh = marching_tetrahedra(surface, resolution);
  for (int round = 0; round < 6; ++round) {
    delaunay_flips(mesh.V, mesh.F);
    tangential_smoothing(surface, mesh.V, mesh.F, 5);
  }
  delaunay_flips(mesh.V, mesh.F);
  return mesh;
}

void add_tetrahedron(std::vector<Eigen::Vector3d>& points, std::vector<std::array<int, 3>>& triangles,
                     const std::array<Eigen::Vector3d, 4>& corners, bool reuse_first = false) {
  // Corners must be positively oriented; faces then point outward.
  const int base = static_cast<int>(points.size()) - (reuse_first ? 1 : 0);
  auto id = [&](int i) { return (reuse_first && i == 0) ? 0 : base + i; };
  for (int i = reuse_first ? 1 : 0; i < 4; ++i) points.push_back(corners[i]);
  triangles.push_back({id(0), id(2), id(1)});
  triangles.push_back({id(0), id(1), id(3)});
  triangles.push_back({id(0), id(3), id(2)});
  triangles.push_back({id(1), id(2), id(3)});
}

}  // namespace

TriMesh make_torus(double R, double r, int nu, int nv) {
  if (!(r > 0) || !(R > r) || nu < 3 || nv < 3)
    throw std::invalid_argument("make_torus: need R > r > 0 and nu, nv >= 3, got R=" + std::to_string(R) +
                                ", r=" + std::to_string(r) + ", nu=" + std::to_string(nu) +
                                ", nv=" + std::to_string(nv));
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double u = 2 * kPi * i / nu, v = 2 * kPi * j / nv;
      points.emplace_back((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v));
    }
  auto id = [&](int i, int j) { return (i % nu) + nu * (j % nv); };
  // d/du x d/dv points outward, so (i,j) -> (i+1,j) -> (i+1,j+1) is counter-clockwise outside.
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return to_mesh(points, triangles);
}

TriMesh make_genus_surface(int genus, int resolution) {
  if (genus < 0 || resolution < 16)
    throw std::invalid_argument("make_genus_surface: need genus >= 0 and resolution >= 16, got genus=" +
                                std::to_string(genus) + ", resolution=" + std::to_string(resolution));
  return polygonise(genus == 0 ? ellipsoid() : grid_graph_tube(genus), resolution);
}

TriMesh make_cube() {
  TriMesh mesh;
  mesh.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) mesh.V.row(i) << (i & 1 ? 1 : -1), (i & 2 ? 1 : -1), (i & 4 ? 1 : -1);
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  mesh.F.resize(12, 3);
  for (int q = 0; q < 6; ++q) {
    mesh.F.row(2 * q) << faces[q][0], faces[q][1], faces[q][2];
    mesh.F.row(2 * q + 1) << faces[q][0], faces[q][2], faces[q][3];
  }
  return mesh;
}

TriMesh make_sphere(int subdivisions) {
  if (subdivisions < 0)
    throw std::invalid_argument("make_sphere: need subdivisions >= 0, got " + std::to_string(subdivisions));
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> points = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : points) p.normalize();
  std::vector<std::array<int, 3>> triangles = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::unordered_map<std::uint64_t, int> midpoint;
    auto mid = [&](int a, int b) {
      auto [it, inserted] = midpoint.emplace(undirected_key(a, b), static_cast<int>(points.size()));
      if (inserted) points.push_back((points[a] + points[b]).normalized());
      return it->second;
    };
    std::vector<std::array<int, 3>> finer;
    finer.reserve(4 * triangles.size());
    for (const auto& [a, b, c] : triangles) {
      const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      finer.push_back({a, ab, ca});
      finer.push_back({b, bc, ab});
      finer.push_back({c, ca, bc});
      finer.push_back({ab, bc, ca});
    }
    triangles = std::move(finer);
  }
  return to_mesh(points, triangles);
}

TriMesh open_cylinder() {
  const int around = 8, rings = 3;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < around; ++i) {
      const double u = 2 * kPi * i / around;
      points.emplace_back(std::cos(u), std::sin(u), -1.0 + j);
    }
  auto id = [&](int i, int j) { return (i % around) + around * j; };
  for (int j = 0; j + 1 < rings; ++j)
    for (int i = 0; i < around; ++i) {
      triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return to_mesh(points, triangles);
}

TriMesh two_tetrahedra() {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
  add_tetrahedron(points, triangles, {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}});
  add_tetrahedron(points, triangles, {{{3, 0, 0}, {4, 0, 0}, {3, 1, 0}, {3, 0, 1}}});
  return to_mesh(points, triangles);
}

TriMesh nonmanifold_edge() {
  // Equator a, b, c counter-clockwise seen from above; d above, e below.
  const std::vector<Eigen::Vector3d> points = {
      {1, 0, 0}, {-0.5, 0.8660254037844386, 0}, {-0.5, -0.8660254037844386, 0}, {0, 0, 1}, {0, 0, -1}};
  const std::vector<std::array<int, 3>> triangles = {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {1, 0, 4},
                                                     {2, 1, 4}, {0, 2, 4}, {0, 1, 2}};
  return to_mesh(points, triangles);
}

TriMesh nonmanifold_vertex() {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
  add_tetrahedron(points, triangles, {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}});
  // Point reflection of the first one (swap two corners to keep positive orientation).
  add_tetrahedron(points, triangles, {{{0, 0, 0}, {0, -1, 0}, {-1, 0, 0}, {0, 0, -1}}}, /*reuse_first=*/true);
  return to_mesh(points, triangles);
}

TriMesh flipped_face_tetrahedron() {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
  add_tetrahedron(points, triangles, {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}});
  std::swap(triangles[3][1], triangles[3][2]);
  return to_mesh(points, triangles);
}

TriMesh make_rod(double radius, double length, int n) {
  TriMesh rod;
  rod.V.resize(2 * n + 2, 3);
  for (int end = 0; end < 2; ++end)
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      rod.V.row(end * n + i) << radius * std::cos(a), radius * std::sin(a), end * length;
    }
  rod.V.row(2 * n) << 0, 0, 0;
  rod.V.row(2 * n + 1) << 0, 0, length;
  rod.F.resize(4 * n, 3);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    rod.F.row(4 * i) << i, j, n + j;
    rod.F.row(4 * i + 1) << i, n + j, n + i;
    rod.F.row(4 * i + 2) << 2 * n, j, i;
    rod.F.row(4 * i + 3) << 2 * n + 1, n + i, n + j;
  }
  return rod;
}

TriMesh make_pipe(double outer, double inner, double length, int n, int rows) {
  TriMesh m;
  const int ring = n * (rows + 1);  // vertices per wall
  m.V.resize(2 * ring, 3);
  for (int wall = 0; wall < 2; ++wall)
    for (int j = 0; j <= rows; ++j)
      for (int i = 0; i < n; ++i) {
        const double r = wall == 0 ? outer : inner, t = 2 * kPi * i / n;
        m.V.row(wall * ring + j * n + i) << r * std::cos(t), r * std::sin(t), length * j / rows;
      }
  std::vector<Eigen::RowVector3i> faces;
  // A quad a, b, c, d counter-clockwise seen from outside.
  const auto quad = [&faces](int a, int b, int c, int d) {
    faces.emplace_back(a, b, c);
    faces.emplace_back(a, c, d);
  };
  for (int i = 0; i < n; ++i) {
    const int i1 = (i + 1) % n;
    for (int j = 0; j < rows; ++j) {
      quad(j * n + i, j * n + i1, (j + 1) * n + i1, (j + 1) * n + i);                                 // outer wall
      quad(ring + j * n + i, ring + (j + 1) * n + i, ring + (j + 1) * n + i1, ring + j * n + i1);     // inner wall
    }
    quad(i, ring + i, ring + i1, i1);                                                                  // end at z = 0
    quad(rows * n + i, rows * n + i1, ring + rows * n + i1, ring + rows * n + i);                      // end at z = length
  }
  m.F.resize(static_cast<int>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) m.F.row(static_cast<int>(f)) = faces[f];
  return m;
}

TriMesh make_tube(double radius, double height, int n, int rows) {
  TriMesh m;
  m.V.resize(n * (rows + 1), 3);
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i < n; ++i)
      m.V.row(j * n + i) << radius * std::cos(2 * kPi * i / n), radius * std::sin(2 * kPi * i / n), height * j / rows;
  m.F.resize(2 * n * rows, 3);
  int f = 0;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * n + i, b = j * n + (i + 1) % n, c = b + n, d = a + n;
      if ((i + j) % 2 == 0) {
        m.F.row(f++) << a, b, c;
        m.F.row(f++) << a, c, d;
      } else {
        m.F.row(f++) << a, b, d;
        m.F.row(f++) << b, c, d;
      }
    }
  return m;
}

}  // namespace polycube::test
