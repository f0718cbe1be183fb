// build_polycube_grid: on synthetic polycubes (voxel unions with uneven spacing, genus 0..2, a
// saddle where edges of only two directions meet) and on polycubes built from the test meshes,
// the grid is an all-quad, closed, oriented, connected 2-manifold with P's Euler characteristic;
// every quad is an axis-aligned rectangle on P; the quads tile P exactly; a vertex has valence 4
// except at P's cone points, where valence × 90° is P's total angle; the vertices' surface points
// reproduce their positions; the count follows the target; the result is scale-invariant and the
// same from a polycube read back from disk.
#include "applications/quad/carry_grid.h"
#include "applications/quad/polycube_grid.h"
#include "applications/quad/quad_quality.h"
#include "applications/quad/quad_templates.h"
#include "applications/quad/surface_projector.h"

#include "formats/mesh_io.h"
#include "polycube/closest_point.h"
#include "polycube/errors.h"
#include "polycube/mesh_topology.h"
#include "polycube/polycube_build.h"
#include "polycube/topology.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace polycube {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The surface of a union of boxes of a rectilinear grid (lines xs, ys, zs), each voxel face on
// the boundary split into four triangles around its centre (so P's triangulation has vertices
// that are on no level), outward-oriented.
TriMesh voxel_polycube(const std::array<std::vector<double>, 3>& lines,
                       const std::function<bool(int, int, int)>& filled) {
  const std::array<int, 3> n = {static_cast<int>(lines[0].size()) - 1, static_cast<int>(lines[1].size()) - 1,
                                static_cast<int>(lines[2].size()) - 1};
  const auto inside = [&](std::array<int, 3> c) {
    for (int a = 0; a < 3; ++a)
      if (c[a] < 0 || c[a] >= n[a]) return false;
    return filled(c[0], c[1], c[2]);
  };
  std::map<std::tuple<int, int, int>, int> corner_id;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> faces;
  const auto corner = [&](std::array<int, 3> c) {
    const auto key = std::make_tuple(c[0], c[1], c[2]);
    auto it = corner_id.find(key);
    if (it != corner_id.end()) return it->second;
    points.emplace_back(lines[0][c[0]], lines[1][c[1]], lines[2][c[2]]);
    return corner_id[key] = static_cast<int>(points.size()) - 1;
  };
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j)
      for (int k = 0; k < n[2]; ++k) {
        if (!filled(i, j, k)) continue;
        for (int a = 0; a < 3; ++a)
          for (int s : {-1, 1}) {
            std::array<int, 3> c = {i, j, k};
            c[a] += s;
            if (inside(c)) continue;
            const int b = (a + 1) % 3, d = (a + 2) % 3;
            std::array<int, 4> q;
            const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
            for (int m = 0; m < 4; ++m) {
              std::array<int, 3> p = {i, j, k};
              if (s > 0) p[a] += 1;
              p[b] += du[m];
              p[d] += dv[m];
              q[m] = corner(p);
            }
            if (s < 0) std::swap(q[1], q[3]);
            Eigen::Vector3d centre = Eigen::Vector3d::Zero();
            for (int m = 0; m < 4; ++m) centre += points[q[m]] / 4;
            points.push_back(centre);
            const int mid = static_cast<int>(points.size()) - 1;
            for (int m = 0; m < 4; ++m) faces.emplace_back(q[m], q[(m + 1) % 4], mid);
          }
      }
  TriMesh mesh;
  mesh.V.resize(points.size(), 3);
  for (size_t v = 0; v < points.size(); ++v) mesh.V.row(v) = points[v];
  mesh.F.resize(faces.size(), 3);
  for (size_t f = 0; f < faces.size(); ++f) mesh.F.row(f) = faces[f];
  return mesh;
}

struct Shape {
  std::string name;
  TriMesh mesh;
  int genus;
};

std::vector<Shape> synthetic_shapes() {
  std::vector<Shape> shapes;
  shapes.push_back({"box 1x2x3", voxel_polycube({{{0, 1}, {0, 2}, {0, 3}}}, [](int, int, int) { return true; }), 0});
  // An L-shaped layer on a single box under one of its arms' junction: the vertex in the middle
  // is a saddle (6 quads) where edges of only two directions meet.
  shapes.push_back({"saddle", voxel_polycube({{{0, 1, 2.5}, {0, 0.8, 2}, {0, 1.2, 2}}}, [](int i, int j, int k) {
                      return k == 1 ? !(i == 1 && j == 0) : (i == 0 && j == 0);
                    }), 0});
  shapes.push_back({"stairs", voxel_polycube({{{0, 1, 2, 3}, {0, 1}, {0, 1, 2, 3}}}, [](int i, int, int k) { return k <= i; }), 0});
  shapes.push_back({"ring", voxel_polycube({{{0, 0.7, 1.0, 2.2}, {0, 1, 1.3, 2}, {0, 0.5}}},
                                           [](int i, int j, int) { return !(i == 1 && j == 1); }),
                    1});
  shapes.push_back({"two holes", voxel_polycube({{{0, 1, 2, 3, 4, 5}, {0, 1, 2, 3}, {0, 0.4, 1}}},
                                                [](int i, int j, int k) { return !(j == 1 && (i == 1 || i == 3) && k >= 0); }),
                    2});
  return shapes;
}

// Total angle of P at each of its vertices.
Eigen::VectorXd angle_sums(const TriMesh& mesh) {
  Eigen::VectorXd angle = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d p = mesh.V.row(mesh.F(f, i));
      const Eigen::Vector3d u = mesh.V.row(mesh.F(f, (i + 1) % 3)).transpose() - p;
      const Eigen::Vector3d v = mesh.V.row(mesh.F(f, (i + 2) % 3)).transpose() - p;
      angle[mesh.F(f, i)] += std::acos(std::clamp(u.normalized().dot(v.normalized()), -1.0, 1.0));
    }
  return angle;
}

std::tuple<double, double, double> key_of(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

// Every property of the grid that holds on any polycube.
// equal_parts: every cell split into equal quads (false for a locally refined grid, whose chords
// have unequal parts).
void expect_valid_grid(const TriMesh& P, const PolycubeGrid& grid, bool equal_parts = true) {
  const QuadMesh& quads = grid.mesh;
  const int nv = quads.num_vertices(), nq = quads.num_quads();
  ASSERT_GT(nq, 0);
  ASSERT_EQ(grid.quad_cell.size(), nq);
  ASSERT_EQ(static_cast<int>(grid.on_polycube.size()), nv);
  ASSERT_EQ(grid.quad_axis.size(), nq);
  const double diagonal = bounding_box(P.V).diagonal();

  // Closed, oriented, connected 2-manifold with P's Euler characteristic.
  const QuadTopology t = quad_topology(quads);
  EXPECT_EQ(t.boundary_edges, 0) << "T-junctions or holes";
  EXPECT_EQ(t.nonmanifold_edges, 0);
  EXPECT_EQ(t.misoriented_edges, 0);
  EXPECT_EQ(t.nonmanifold_vertices, 0);
  EXPECT_EQ(t.unreferenced_vertices, 0);
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.euler, euler_characteristic(P.F, P.num_vertices()));

  // Every quad an axis-aligned rectangle in its plane, with the outward normal of quad_axis.
  int not_rectangle = 0, wrong_normal = 0, degenerate = 0;
  double area = 0;
  for (int q = 0; q < nq; ++q) {
    const int axis = std::abs(grid.quad_axis[q]) - 1;
    Eigen::Vector3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = quads.V.row(quads.Q(q, k));
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d e = p[(k + 1) % 4] - p[k], f = p[(k + 3) % 4] - p[k];
      if (e[axis] != 0 || e.dot(f) != 0 || (e.array() != 0).count() != 1) ++not_rectangle;
      if (e.norm() <= 1e-9 * diagonal) ++degenerate;
    }
    const Eigen::Vector3d n = (p[1] - p[0]).cross(p[3] - p[0]);
    if (n[axis] * grid.quad_axis[q] <= 0) ++wrong_normal;
    area += n.norm();
  }
  EXPECT_EQ(not_rectangle, 0);
  EXPECT_EQ(wrong_normal, 0);
  EXPECT_EQ(degenerate, 0);
  // The quads tile P: same area, and every quad centre on P.
  EXPECT_NEAR(area, surface_area(P), 1e-9 * surface_area(P));
  const SurfaceProjector on_p(P);
  double off = 0;
  for (int q = 0; q < nq; ++q) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) centre += quads.V.row(quads.Q(q, k)).transpose() / 4;
    off = std::max(off, on_p.closest(centre).distance);
  }
  EXPECT_LE(off, 1e-12 * diagonal);

  // Surface points reproduce the vertices.
  double error = 0;
  for (int v = 0; v < nv; ++v) {
    const SurfacePoint& s = grid.on_polycube[v];
    ASSERT_TRUE(s.face >= 0 && s.face < P.num_faces());
    EXPECT_TRUE((s.bary.array() >= 0).all());
    EXPECT_NEAR(s.bary.sum(), 1, 1e-12);
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) x += s.bary[i] * P.V.row(P.F(s.face, i)).transpose();
    error = std::max(error, (x - quads.V.row(v).transpose()).norm());
  }
  EXPECT_LE(error, 1e-12 * diagonal);

  // Valence 4 except at P's vertices whose total angle is not 2π, where valence × 90° = angle.
  const Eigen::VectorXd angle = angle_sums(P);
  std::map<std::tuple<double, double, double>, int> p_vertex;
  for (int v = 0; v < P.num_vertices(); ++v) p_vertex[key_of(P.V.row(v))] = v;
  std::set<int> irregular, expected;
  int wrong_valence = 0;
  for (int v = 0; v < nv; ++v) {
    const auto it = p_vertex.find(key_of(quads.V.row(v)));
    const double total = it == p_vertex.end() ? 2 * kPi : angle[it->second];
    if (std::abs(total - t.valence[v] * kPi / 2) > 1e-6) ++wrong_valence;
    if (t.valence[v] != 4) irregular.insert(v);
    if (std::abs(total - 2 * kPi) > 1e-6) expected.insert(v);
  }
  EXPECT_EQ(wrong_valence, 0);
  EXPECT_EQ(irregular, expected);
  EXPECT_EQ(irregular, std::set<int>(grid.corners.begin(), grid.corners.end()));
  EXPECT_EQ(grid.corners.size(), cone_vertices(P).size());
  ASSERT_EQ(grid.corner_polycube_vertex.size(), grid.corners.size());
  for (size_t c = 0; c < grid.corners.size(); ++c)
    EXPECT_EQ(quads.V.row(grid.corners[c]), P.V.row(grid.corner_polycube_vertex[c]));

  // The layout: a closed manifold of rectangles on P's planes; each cell split into
  // parts x parts equal quads.
  const QuadTopology lt = quad_topology(grid.layout);
  EXPECT_TRUE(lt.closed_manifold());
  EXPECT_EQ(lt.euler, t.euler);
  ASSERT_EQ(grid.cell_parts.rows(), grid.layout.num_quads());
  std::vector<int> per_cell(grid.layout.num_quads(), 0);
  int wrong_size = 0;
  for (int q = 0; q < nq; ++q) {
    const int s = grid.quad_cell[q];
    ASSERT_TRUE(s >= 0 && s < grid.layout.num_quads());
    ++per_cell[s];
    for (int k = 0; k < 4; ++k) {
      const double side = (grid.layout.V.row(grid.layout.Q(s, k % 2 + 1)) - grid.layout.V.row(grid.layout.Q(s, k % 2))).norm();
      const double edge = (quads.V.row(quads.Q(q, (k + 1) % 4)) - quads.V.row(quads.Q(q, k))).norm();
      if (std::abs(edge - side / grid.cell_parts(s, k % 2)) > 1e-12 * diagonal) ++wrong_size;
    }
  }
  if (equal_parts) {
    EXPECT_EQ(wrong_size, 0);
  }
  for (int s = 0; s < grid.layout.num_quads(); ++s) EXPECT_EQ(per_cell[s], grid.cell_parts(s, 0) * grid.cell_parts(s, 1));
  for (int a = 0; a < 3; ++a) EXPECT_TRUE(std::is_sorted(grid.levels[a].begin(), grid.levels[a].end()));
  for (int q = 0; q < nq; ++q) {
    const int axis = std::abs(grid.quad_axis[q]) - 1;
    EXPECT_TRUE(std::binary_search(grid.levels[axis].begin(), grid.levels[axis].end(), quads.V(quads.Q(q, 0), axis)));
  }
}

TEST(QuadGrid, SyntheticPolycubes) {
  for (const Shape& shape : synthetic_shapes()) {
    SCOPED_TRACE(shape.name);
    ASSERT_EQ(genus(shape.mesh.F, shape.mesh.num_vertices()), shape.genus);
    for (int target : {1, 300, 3000}) {
      SCOPED_TRACE("target " + std::to_string(target));
      PolycubeGridOptions options;
      options.target_quads = target;
      const PolycubeGrid grid = build_polycube_grid(shape.mesh, options);
      expect_valid_grid(shape.mesh, grid);
      if (target >= 300) {
        EXPECT_NEAR(grid.mesh.num_quads(), target, 0.1 * target);
      }
      if (target == 1) {
        EXPECT_EQ(grid.mesh.num_quads(), grid.layout.num_quads()) << "one quad per layout cell";
      }
    }
  }
}

double triangle_area(const TriMesh& mesh, int f) {
  const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
  return (b - a).cross(c - a).norm() / 2;
}

int largest_triangle(const TriMesh& mesh) {
  int f = 0;
  for (int g = 1; g < mesh.num_faces(); ++g)
    if (triangle_area(mesh, g) > triangle_area(mesh, f)) f = g;
  return f;
}

// The grid quads on P that contain point x (on the plane of triangle f's face).
std::vector<int> quads_at(const TriMesh& P, const PolycubeGrid& grid, int f, const Eigen::Vector3d& x) {
  const Eigen::Vector3d n = (P.V.row(P.F(f, 1)) - P.V.row(P.F(f, 0))).cross(P.V.row(P.F(f, 2)) - P.V.row(P.F(f, 0))).transpose();
  std::vector<int> out;
  for (int q = 0; q < grid.mesh.num_quads(); ++q) {
    const int axis = std::abs(grid.quad_axis[q]) - 1;
    if (n.cwiseAbs().maxCoeff() != std::abs(n[axis]) || (n[axis] > 0) != (grid.quad_axis[q] > 0)) continue;
    if (std::abs(grid.mesh.V(grid.mesh.Q(q, 0), axis) - x[axis]) > 1e-12) continue;
    Eigen::Vector3d lo = grid.mesh.V.row(grid.mesh.Q(q, 0)), hi = lo;
    for (int k = 1; k < 4; ++k) {
      lo = lo.cwiseMin(grid.mesh.V.row(grid.mesh.Q(q, k)).transpose());
      hi = hi.cwiseMax(grid.mesh.V.row(grid.mesh.Q(q, k)).transpose());
    }
    if (((x - lo).array() < -1e-12).any() || ((hi - x).array() < -1e-12).any()) continue;
    out.push_back(q);
  }
  return out;
}

// The sides of the grid quads on P that contain point x (on the plane of triangle f's face).
std::vector<double> sides_of_quads_at(const TriMesh& P, const PolycubeGrid& grid, int f, const Eigen::Vector3d& x) {
  std::vector<double> sides;
  for (int q : quads_at(P, grid, f, x)) {
    const int axis = std::abs(grid.quad_axis[q]) - 1;
    Eigen::Vector3d lo = grid.mesh.V.row(grid.mesh.Q(q, 0)), hi = lo;
    for (int k = 1; k < 4; ++k) {
      lo = lo.cwiseMin(grid.mesh.V.row(grid.mesh.Q(q, k)).transpose());
      hi = hi.cwiseMax(grid.mesh.V.row(grid.mesh.Q(q, k)).transpose());
    }
    for (int a = 0; a < 3; ++a)
      if (a != axis) sides.push_back(hi[a] - lo[a]);
  }
  return sides;
}

// Local refinement: each round halves the parts of the two chords through a point, so the quads
// there shrink by half per round while the grid stays a valid conforming grid (irregular only
// at P's corners); several points in one part halve it once; the budget stops it.
TEST(QuadGrid, RefinementHalvesThePartsAtAPoint) {
  for (const Shape& shape : synthetic_shapes()) {
    SCOPED_TRACE(shape.name);
    const TriMesh& P = shape.mesh;
    PolycubeGridOptions options;
    options.target_quads = 300;
    const PolycubeGrid base = build_polycube_grid(P, options);
    // A point inside a face, on no dyadic line: in the largest triangle.
    const int f = largest_triangle(P);
    SurfacePoint point;
    point.face = f;
    point.bary = Eigen::Vector3d(0.21, 0.33, 0.46);
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) x += point.bary[i] * P.V.row(P.F(f, i)).transpose();
    const std::vector<double> before = sides_of_quads_at(P, base, f, x);
    ASSERT_FALSE(before.empty());
    const double largest_before = *std::max_element(before.begin(), before.end());

    int previous_quads = base.mesh.num_quads();
    for (int rounds = 1; rounds <= 3; ++rounds) {
      SCOPED_TRACE("rounds " + std::to_string(rounds));
      options.refine_rounds.push_back({GridRefinement{point, 1}});
      const PolycubeGrid refined = build_polycube_grid(P, options);
      expect_valid_grid(P, refined, false);
      EXPECT_EQ(refined.refined_parts, 2 * rounds) << "one part of each of the two chords per round";
      EXPECT_GT(refined.mesh.num_quads(), previous_quads);
      previous_quads = refined.mesh.num_quads();
      const std::vector<double> after = sides_of_quads_at(P, refined, f, x);
      ASSERT_FALSE(after.empty());
      EXPECT_LE(*std::max_element(after.begin(), after.end()), largest_before / (1 << rounds) * (1 + 1e-9));
    }

    // The same point twice in one round: halved once.
    PolycubeGridOptions twice;
    twice.target_quads = 300;
    twice.refine_rounds = {{GridRefinement{point, 1}, GridRefinement{point, 1}}};
    EXPECT_EQ(build_polycube_grid(P, twice).refined_parts, 2);
    // No room in the budget: nothing refined.
    twice.refine_max_quads = base.mesh.num_quads();
    const PolycubeGrid capped = build_polycube_grid(P, twice);
    EXPECT_EQ(capped.refined_parts, 0);
    EXPECT_EQ(capped.mesh.num_quads(), base.mesh.num_quads());
    // A point on no triangle of P is an error.
    // Three halvings at once: as three rounds of one.
    twice.refine_max_quads = 0;
    twice.refine_rounds = {{GridRefinement{point, 3}}};
    const PolycubeGrid deep = build_polycube_grid(P, twice);
    expect_valid_grid(P, deep, false);
    EXPECT_EQ(deep.refined_parts, 6);
    EXPECT_EQ(deep.mesh.num_quads(), previous_quads);
    // A point on no triangle of P, or no halving, is an error.
    twice.refine_rounds = {{GridRefinement{SurfacePoint{P.num_faces(), Eigen::Vector3d(1, 0, 0)}, 1}}};
    EXPECT_THROW(build_polycube_grid(P, twice), std::invalid_argument);
    twice.refine_rounds = {{GridRefinement{point, 0}}};
    EXPECT_THROW(build_polycube_grid(P, twice), std::invalid_argument);
  }
}

// Each quad names the point of the last round whose cut line bounds it (what the quad remesh
// blames a round's flipped quads on): the quads at that point, and only the last round's points.
TEST(QuadGrid, QuadsNameTheLastRoundsPointThatCutThem) {
  for (const Shape& shape : synthetic_shapes()) {
    SCOPED_TRACE(shape.name);
    const TriMesh& P = shape.mesh;
    PolycubeGridOptions options;
    options.target_quads = 300;
    const PolycubeGrid base = build_polycube_grid(P, options);
    ASSERT_EQ(base.quad_refined_by.size(), base.mesh.num_quads());
    EXPECT_EQ(base.quad_refined_by.maxCoeff(), -1);
    // Two points on two faces of different axes, one per round, then both in one round.
    const int f = largest_triangle(P);
    const auto axis_of = [&](int g) {
      const Eigen::Vector3d n = (P.V.row(P.F(g, 1)) - P.V.row(P.F(g, 0))).cross(P.V.row(P.F(g, 2)) - P.V.row(P.F(g, 0)));
      int a = 0;
      n.cwiseAbs().maxCoeff(&a);
      return a;
    };
    int h = -1;
    for (int g = 0; g < P.num_faces(); ++g)
      if (axis_of(g) != axis_of(f) && (h < 0 || triangle_area(P, g) > triangle_area(P, h))) h = g;
    ASSERT_GE(h, 0);
    const SurfacePoint a{f, Eigen::Vector3d(0.21, 0.33, 0.46)}, b{h, Eigen::Vector3d(0.4, 0.35, 0.25)};
    const auto at = [&](const SurfacePoint& p) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (int i = 0; i < 3; ++i) x += p.bary[i] * P.V.row(P.F(p.face, i)).transpose();
      return x;
    };
    options.refine_rounds = {{GridRefinement{a, 1}}, {GridRefinement{b, 1}}};
    const PolycubeGrid two = build_polycube_grid(P, options);
    ASSERT_EQ(two.refined_parts, 4);
    ASSERT_EQ(two.quad_refined_by.size(), two.mesh.num_quads());
    EXPECT_EQ(two.quad_refined_by.minCoeff(), -1) << "quads away from the last round's lines";
    EXPECT_EQ(two.quad_refined_by.maxCoeff(), 0) << "the last round has one point";
    for (int q : quads_at(P, two, h, at(b))) EXPECT_EQ(two.quad_refined_by[q], 0);
    options.refine_rounds = {{GridRefinement{a, 1}, GridRefinement{b, 1}}};
    const PolycubeGrid one = build_polycube_grid(P, options);
    // A quad names the latest of the points whose lines bound it.
    const std::vector<int> at_a = quads_at(P, one, f, at(a)), at_b = quads_at(P, one, h, at(b));
    ASSERT_FALSE(at_a.empty());
    ASSERT_FALSE(at_b.empty());
    for (int q : at_a) EXPECT_GE(one.quad_refined_by[q], 0);
    for (int q : at_b) EXPECT_EQ(one.quad_refined_by[q], 1);
  }
}

TEST(QuadGrid, SaddleWithTwoEdgeDirectionsIsIrregular) {
  const Shape shape = synthetic_shapes()[1];
  const PolycubeGrid grid = build_polycube_grid(shape.mesh, {});
  const QuadTopology t = quad_topology(grid.mesh);
  int valence6 = 0;
  for (int v : grid.corners) valence6 += t.valence[v] == 6;
  EXPECT_GE(valence6, 1);
  // A box has exactly its 8 corners, valence 3.
  const PolycubeGrid box = build_polycube_grid(synthetic_shapes()[0].mesh, {});
  ASSERT_EQ(box.corners.size(), 8u);
  const QuadTopology bt = quad_topology(box.mesh);
  for (int v : box.corners) EXPECT_EQ(bt.valence[v], 3);
}

TEST(QuadGrid, CellSizeGivesNearSquares) {
  const Shape shape = synthetic_shapes()[3];
  for (double h : {0.31, 0.1, 0.037}) {
    SCOPED_TRACE("h " + std::to_string(h));
    PolycubeGridOptions options;
    options.cell_size = h;
    const PolycubeGrid grid = build_polycube_grid(shape.mesh, options);
    EXPECT_EQ(grid.cell_size, h);
    const QuadMesh& layout = grid.layout;
    for (int q = 0; q < grid.mesh.num_quads(); ++q)
      for (int k = 0; k < 2; ++k) {
        const int s = grid.quad_cell[q];
        const double side = (layout.V.row(layout.Q(s, k + 1)) - layout.V.row(layout.Q(s, k))).norm();
        if (side < h / 2) {  // narrower than half a quad: one part, as narrow as P makes it
          EXPECT_EQ(grid.cell_parts(s, k), 1);
          continue;
        }
        const double step = (grid.mesh.V.row(grid.mesh.Q(q, k + 1)) - grid.mesh.V.row(grid.mesh.Q(q, k))).norm();
        EXPECT_GE(step, h / 2 - 1e-12);
        EXPECT_LE(step, 1.5 * h + 1e-12);
      }
  }
}

// Two towers of heights 2 and 3 on a common base: the top of the short one is a level whose line
// around the tall one is needed by nothing, and is removed; without removal it stays.
TEST(QuadGrid, FreeLoopsAreRemoved) {
  const TriMesh towers = voxel_polycube({{{0, 1, 2, 3}, {0, 1}, {0, 1, 2, 3}}}, [](int i, int, int k) {
    return k == 0 || (i == 0 && k == 1) || i == 2;
  });
  PolycubeGridOptions options;
  options.target_quads = 1;
  const PolycubeGrid merged = build_polycube_grid(towers, options);
  options.remove_free_loops = false;
  const PolycubeGrid global = build_polycube_grid(towers, options);
  expect_valid_grid(towers, merged);
  expect_valid_grid(towers, global);
  EXPECT_EQ(merged.free_loops, 1);
  EXPECT_EQ(global.free_loops, 0);
  EXPECT_EQ(global.layout.num_quads(), global.level_cells);
  EXPECT_EQ(merged.layout.num_quads(), global.layout.num_quads() - 4) << "4 cells around the tall tower merge with 4";
  EXPECT_EQ(merged.corners.size(), global.corners.size());
  for (const Shape& shape : synthetic_shapes()) {
    SCOPED_TRACE(shape.name);
    PolycubeGridOptions plain;
    plain.remove_free_loops = false;
    plain.target_quads = 500;
    expect_valid_grid(shape.mesh, build_polycube_grid(shape.mesh, plain));
  }
}

// Sized through a map that stretches x threefold, quads are near-squares on the image (and
// three times as many columns along x), while sized on P they are 3:1 rectangles there.
TEST(QuadGrid, SizedThroughAMap) {
  const TriMesh box = synthetic_shapes()[0].mesh;
  const SurfaceMap stretch = [&box](const SurfacePoint& p) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) x += p.bary[i] * box.V.row(box.F(p.face, i)).transpose();
    x.x() *= 3;
    return x;
  };
  TriMesh stretched = box;
  stretched.V.col(0) *= 3;
  const SurfaceProjector image(stretched);
  PolycubeGridOptions options;
  options.target_quads = 2000;
  QuadQualityOptions no_sampling;
  no_sampling.hausdorff = false;
  const PolycubeGrid on_p = build_polycube_grid(box, options);
  const PolycubeGrid on_m = build_polycube_grid(box, options, stretch);
  expect_valid_grid(box, on_m);
  EXPECT_FALSE(on_p.sized_through_map);
  EXPECT_TRUE(on_m.sized_through_map);
  const QuadQuality a = measure_quads(carry_grid(on_p, stretch), image, on_p.corners, no_sampling);
  const QuadQuality b = measure_quads(carry_grid(on_m, stretch), image, on_m.corners, no_sampling);
  EXPECT_GT(a.aspect_ratio_max, 2.5);
  EXPECT_LT(b.aspect_ratio_max, 1.5);
  EXPECT_LT(b.aspect_ratio_mean, a.aspect_ratio_mean - 0.5);
  EXPECT_NEAR(b.quads, 2000, 200);
  EXPECT_EQ(b.flipped_quads, 0);
}

TEST(QuadGrid, CountGrowsWithTheTarget) {
  const Shape shape = synthetic_shapes()[4];
  int previous = 0;
  for (int target : {10, 100, 400, 1000, 5000, 20000}) {
    PolycubeGridOptions options;
    options.target_quads = target;
    const int count = build_polycube_grid(shape.mesh, options).mesh.num_quads();
    EXPECT_GE(count, previous);
    previous = count;
  }
  EXPECT_NEAR(previous, 20000, 2000);
}

TEST(QuadGrid, ScaleAndTranslationInvariant) {
  const Shape shape = synthetic_shapes()[3];
  const PolycubeGrid reference = build_polycube_grid(shape.mesh, {});
  for (double scale : {1e-8, 1e8}) {
    TriMesh moved = shape.mesh;
    moved.V = (moved.V * scale).rowwise() + Eigen::RowVector3d(3 * scale, -5 * scale, 7 * scale);
    const PolycubeGrid grid = build_polycube_grid(moved, {});
    EXPECT_EQ(grid.mesh.Q, reference.mesh.Q);
    EXPECT_EQ(grid.cell_parts, reference.cell_parts);
    const Eigen::MatrixX3d expected = (reference.mesh.V * scale).rowwise() + Eigen::RowVector3d(3 * scale, -5 * scale, 7 * scale);
    EXPECT_LE((grid.mesh.V - expected).cwiseAbs().maxCoeff(), 1e-12 * scale);
    EXPECT_EQ(grid.corners, reference.corners);
  }
}

// A polycube written turned (as `polycube map` writes P back in the input's frame): gridded in
// its own axes, the same grid turned.
TEST(QuadGrid, TurnedPolycube) {
  const Shape shape = synthetic_shapes()[4];
  const Eigen::Matrix3d turn =
      (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()) * Eigen::AngleAxisd(-1.9, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  TriMesh turned = shape.mesh;
  turned.V = shape.mesh.V * turn.transpose();
  PolycubeGridOptions options;
  options.cell_size = 0.0937;  // no width is near a half-integer multiple: the same parts either way
  const PolycubeGrid reference = build_polycube_grid(shape.mesh, options);
  const PolycubeGrid grid = build_polycube_grid(turned, options);
  EXPECT_TRUE(reference.frame.isIdentity(0));
  EXPECT_LE((grid.frame.transpose() * grid.frame - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
  // The same vertices (in another order: P's axes may come out permuted).
  ASSERT_EQ(grid.mesh.num_quads(), reference.mesh.num_quads());
  ASSERT_EQ(grid.mesh.num_vertices(), reference.mesh.num_vertices());
  EXPECT_EQ(grid.corners.size(), reference.corners.size());
  const Eigen::MatrixX3d back = grid.mesh.V * turn;  // into the unturned frame
  const auto rounded = [](const Eigen::MatrixX3d& V) {
    std::vector<std::tuple<long long, long long, long long>> points;
    for (int v = 0; v < V.rows(); ++v)
      points.emplace_back(std::llround(V(v, 0) * 1e9), std::llround(V(v, 1) * 1e9), std::llround(V(v, 2) * 1e9));
    std::sort(points.begin(), points.end());
    return points;
  };
  EXPECT_EQ(rounded(back), rounded(reference.mesh.V));
  const QuadTopology t = quad_topology(grid.mesh);
  EXPECT_TRUE(t.closed_manifold());
  // Each quad a rectangle on the turned P, its normal along one of P's axes.
  const SurfaceProjector on_p(turned);
  double worst_angle = 0, off = 0;
  for (int q = 0; q < grid.mesh.num_quads(); ++q) {
    Eigen::Vector3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = grid.mesh.V.row(grid.mesh.Q(q, k));
    for (int k = 0; k < 4; ++k)
      worst_angle = std::max(worst_angle, std::abs((p[(k + 1) % 4] - p[k]).normalized().dot((p[(k + 3) % 4] - p[k]).normalized())));
    off = std::max(off, on_p.closest((p[0] + p[1] + p[2] + p[3]) / 4).distance);
  }
  EXPECT_LE(worst_angle, 1e-12);
  EXPECT_LE(off, 1e-12);
}

TEST(QuadGrid, RejectsNonPolycubesAndBadOptions) {
  EXPECT_THROW(build_polycube_grid(test::make_sphere(1), {}), MeshError);
  PolycubeGridOptions options;
  options.cell_size = -1;
  EXPECT_THROW(build_polycube_grid(synthetic_shapes()[0].mesh, options), std::invalid_argument);
  options.cell_size = 1e-5;  // 2 · (1·2 + 2·3 + 1·3) · 1e10 quads
  EXPECT_THROW(build_polycube_grid(synthetic_shapes()[0].mesh, options), AlgorithmError);
}

// P built by the engine from real meshes; P.corners (edges of three directions) are among the
// irregular vertices, and every irregular vertex is a polycube vertex.
TEST(QuadGrid, PolycubesOfTestMeshes) {
  for (const std::string name : {"sphere.off", "eight.off", "torus_quad.off", "anchor.off", "double-torus-example.off"}) {
    SCOPED_TRACE(name);
    const TriMesh model = test::load_test_mesh(name);
    const PolycubeResult built = build_polycube(model, analyse_topology(model));
    const Polycube& P = built.polycube;
    PolycubeGridOptions options;
    options.target_quads = 4000;
    const PolycubeGrid grid = build_polycube_grid(P.mesh, options);
    expect_valid_grid(P.mesh, grid);
    EXPECT_EQ(quad_topology(grid.mesh).genus(), built.genus);
    if (static_cast<long long>(options.target_quads) > 2 * grid.layout.num_quads()) {
      EXPECT_NEAR(grid.mesh.num_quads(), options.target_quads, 0.15 * options.target_quads);
    }

    const std::set<int> at(grid.corner_polycube_vertex.begin(), grid.corner_polycube_vertex.end());
    for (int c : P.corners) EXPECT_TRUE(at.count(c)) << "polycube corner " << c << " regular";
    for (int c : at) EXPECT_TRUE(std::binary_search(P.vertices.begin(), P.vertices.end(), c)) << "vertex " << c;
  }
}

// Template refinement (quad_templates.h) of the grid at marked vertices: still a closed, oriented,
// connected all-quad manifold of P's Euler characteristic tiling P, every quad flat on P with its
// parent's outward normal and positive area; old vertices keep their places; each quad split by
// its marked corners (after the closure: none, one, two along an edge, all four) into 1, 3, 7 or
// 9 quads; the new vertices' surface points reproduce them; a quad at a marked vertex is split
// again by a second round, whose quads are a third of the size.
TEST(QuadGrid, TemplatesRefineOnlyAtTheMarksAndConform) {
  for (const Shape& shape : synthetic_shapes()) {
    SCOPED_TRACE(shape.name);
    const TriMesh& P = shape.mesh;
    PolycubeGridOptions options;
    options.target_quads = 300;
    const PolycubeGrid base = build_polycube_grid(P, options);
    const SurfaceProjector on_p(P);
    const auto locate = [&](const Eigen::Vector3d& x) {
      SurfacePoint point;
      point.face = on_p.closest(x).face;
      point.bary = closest_on_triangle(x, P.V.row(P.F(point.face, 0)), P.V.row(P.F(point.face, 1)), P.V.row(P.F(point.face, 2))).bary;
      return point;
    };
    const double diagonal = bounding_box(P.V).diagonal();
    // Every 7th vertex marked (isolated marks, pairs along edges and closures all occur).
    std::vector<char> marked(base.mesh.num_vertices(), 0);
    for (int v = 0; v < base.mesh.num_vertices(); v += 7) marked[v] = 1;
    const std::vector<char> closed = close_template_marks(base.mesh.Q, marked);
    const PolycubeGrid refined = refine_grid_by_templates(base, marked, locate);

    const QuadTopology t = quad_topology(refined.mesh);
    EXPECT_TRUE(t.closed_manifold());
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.euler, euler_characteristic(P.F, P.num_vertices()));
    EXPECT_EQ(refined.mesh.V.topRows(base.mesh.num_vertices()), base.mesh.V);
    EXPECT_EQ(refined.corners, base.corners);
    ASSERT_EQ(refined.quad_axis.size(), refined.mesh.num_quads());
    int expected_quads = 0, closure_left = 0;
    for (int q = 0; q < base.mesh.num_quads(); ++q) {
      int count = 0;
      for (int k = 0; k < 4; ++k) count += closed[base.mesh.Q(q, k)];
      const bool opposite = count == 2 && closed[base.mesh.Q(q, 0)] == closed[base.mesh.Q(q, 2)];
      if (count == 3 || opposite) ++closure_left;
      expected_quads += count == 0 ? 1 : count == 1 ? 3 : count == 2 ? 7 : 9;
    }
    EXPECT_EQ(closure_left, 0);
    EXPECT_EQ(refined.mesh.num_quads(), expected_quads);
    EXPECT_GT(refined.mesh.num_quads(), base.mesh.num_quads());
    double area = 0;
    int wrong_normal = 0, off_plane = 0;
    for (int q = 0; q < refined.mesh.num_quads(); ++q) {
      const int axis = std::abs(refined.quad_axis[q]) - 1;
      Eigen::Vector3d p[4];
      for (int k = 0; k < 4; ++k) p[k] = refined.mesh.V.row(refined.mesh.Q(q, k));
      // Both triangles of the quad face outwards (so the quad is convex enough to have no fold).
      const Eigen::Vector3d n1 = (p[1] - p[0]).cross(p[2] - p[0]), n2 = (p[2] - p[0]).cross(p[3] - p[0]);
      const Eigen::Vector3d m1 = (p[2] - p[1]).cross(p[3] - p[1]), m2 = (p[3] - p[1]).cross(p[0] - p[1]);
      if (n1[axis] * refined.quad_axis[q] <= 0 || n2[axis] * refined.quad_axis[q] <= 0) ++wrong_normal;
      if (m1[axis] * refined.quad_axis[q] <= 0 || m2[axis] * refined.quad_axis[q] <= 0) ++wrong_normal;
      for (int k = 1; k < 4; ++k)
        if (std::abs(p[k][axis] - p[0][axis]) > 1e-12 * diagonal) ++off_plane;
      area += (n1.norm() + n2.norm()) / 2;
    }
    EXPECT_EQ(wrong_normal, 0);
    EXPECT_EQ(off_plane, 0);
    EXPECT_NEAR(area, surface_area(P), 1e-9 * surface_area(P));
    double error = 0;
    for (int v = base.mesh.num_vertices(); v < refined.mesh.num_vertices(); ++v)
      error = std::max(error, (surface_position(P, refined.on_polycube[v]) - refined.mesh.V.row(v).transpose()).norm());
    EXPECT_LE(error, 1e-9 * diagonal);

    // Again at one marked vertex of the refined grid: the quads round it a third of the size.
    std::vector<char> again(refined.mesh.num_vertices(), 0);
    again[0] = 1;
    const PolycubeGrid twice = refine_grid_by_templates(refined, again, locate);
    EXPECT_TRUE(quad_topology(twice.mesh).closed_manifold());
    EXPECT_GT(twice.mesh.num_quads(), refined.mesh.num_quads());
    const auto shortest_at_0 = [](const QuadMesh& m) {
      double shortest = INFINITY;
      for (int q = 0; q < m.num_quads(); ++q)
        for (int k = 0; k < 4; ++k)
          if (m.Q(q, k) == 0) shortest = std::min(shortest, (m.V.row(m.Q(q, (k + 1) % 4)) - m.V.row(0)).norm());
      return shortest;
    };
    EXPECT_NEAR(shortest_at_0(twice.mesh), shortest_at_0(refined.mesh) / 3, 1e-9 * diagonal);
    EXPECT_THROW(refine_grid_by_templates(refined, marked, locate), std::invalid_argument);
  }
}

// From P written as OBJ and read back (as `quad --map DIR` does), the same grid.
TEST(QuadGrid, SameFromPolycubeReadBackFromDisk) {
  const TriMesh model = test::load_test_mesh("eight.off");
  const PolycubeResult built = build_polycube(model, analyse_topology(model));
  const std::string path = test::temp_dir("quad-grid") + "/polycube.obj";
  write_mesh(path, built.polycube.mesh);
  const PolygonSoup soup = read_polygon_soup(path);
  TriMesh back;
  back.V.resize(soup.points.size(), 3);
  for (size_t v = 0; v < soup.points.size(); ++v) back.V.row(v) = soup.points[v];
  back.F.resize(soup.polygons.size(), 3);
  for (size_t f = 0; f < soup.polygons.size(); ++f) back.F.row(f) << soup.polygons[f][0], soup.polygons[f][1], soup.polygons[f][2];
  const PolycubeGrid a = build_polycube_grid(built.polycube.mesh, {}), b = build_polycube_grid(back, {});
  EXPECT_EQ(a.mesh.V, b.mesh.V);
  EXPECT_EQ(a.mesh.Q, b.mesh.Q);
  EXPECT_EQ(a.corners, b.corners);
}

}  // namespace
}  // namespace polycube
