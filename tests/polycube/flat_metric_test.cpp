// flat_metric: the uniform flat metric of §3.3 (eq. 3–5). Checked from the exported intrinsic
// triangulation alone (angles recomputed from its edge lengths): flat at every interior vertex,
// constant geodesic curvature on each loop in the discrete sense (the loop's polygon inscribed in
// a circle), totals +2π on the longest loop and −2π on the others, Gauss–Bonnet, valid Delaunay
// triangles. On every piece of sliced test meshes, on generated surfaces, on slivers, under
// scaling; plus the numerical building blocks and the error paths.
#include "polycube/flat_metric.h"

#include "polycube/errors.h"
#include "polycube/mesh_topology.h"
#include "polycube/piece_mesh.h"
#include "polycube/ricci_mesh.h"  // internal: Lobachevsky function, cyclic polygons, angles
#include "polycube/slice.h"
#include "polycube/topology.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace polycube {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Angle opposite a in the triangle (a, b, c); NaN if the lengths are not a triangle.
double angle_opposite(double a, double b, double c) {
  if (!(a < b + c && b < a + c && c < a + b)) return std::nan("");
  return std::acos(std::clamp((b * b + c * c - a * a) / (2 * b * c), -1.0, 1.0));
}

// Everything flat_metric promises, checked from its triangulation's lengths.
void expect_uniform_flat_metric(const TriMesh& piece, const std::vector<std::vector<int>>& loops,
                                const FlatMetric& fm, double tolerance = 1e-9, bool delaunay = true) {
  ASSERT_TRUE(fm.converged);
  EXPECT_LE(fm.residual, tolerance);
  const int nvt = static_cast<int>(fm.u.size());
  ASSERT_EQ(fm.input_vertices, piece.num_vertices());
  ASSERT_EQ(nvt, piece.num_vertices() + static_cast<int>(fm.inserted_vertices.size()));
  ASSERT_EQ(fm.loops.size(), loops.size());
  EXPECT_EQ(fm.u[fm.gauge_vertex], 0.0);
  EXPECT_EQ(fm.invalid_triangles, 0);
  if (delaunay) {
    EXPECT_EQ(fm.non_delaunay_edges, 0);
    EXPECT_GE(fm.triangulation.min_cotan_sum, -1e-9);
  }

  // The output loops are the input loops with inserted vertices in between.
  std::vector<char> on_loop(nvt, 0);
  for (size_t l = 0; l < loops.size(); ++l) {
    std::vector<int> kept;
    for (int v : fm.loops[l]) {
      on_loop[v] = 1;
      if (v < piece.num_vertices()) kept.push_back(v);
    }
    EXPECT_EQ(kept, loops[l]) << "loop " << l;
  }

  // Angle sums from the triangulation's lengths; adjacency consistent; Delaunay.
  const IntrinsicTriangulation& T = fm.triangulation;
  std::vector<double> angle_sum(nvt, 0.0);
  int boundary_edges = 0;
  for (int f = 0; f < T.F.rows(); ++f)
    for (int i = 0; i < 3; ++i) {
      const double a = T.length(f, (i + 1) % 3), b = T.length(f, i), c = T.length(f, (i + 2) % 3);
      const double alpha = angle_opposite(a, b, c);  // at corner i
      ASSERT_TRUE(std::isfinite(alpha)) << "face " << f << " is not a triangle";
      angle_sum[T.F(f, i)] += alpha;
      const int g = T.adjacent(f, i);
      if (g < 0) {
        ++boundary_edges;
        EXPECT_TRUE(on_loop[T.F(f, i)] && on_loop[T.F(f, (i + 1) % 3)]);
        continue;
      }
      const int j = T.adjacent_edge(f, i);
      EXPECT_EQ(T.adjacent(g, j), f);
      EXPECT_EQ(T.F(g, j), T.F(f, (i + 1) % 3));
      EXPECT_EQ(T.length(g, j), T.length(f, i));
    }
  int loop_edges = 0;
  for (const auto& loop : fm.loops) loop_edges += static_cast<int>(loop.size());
  EXPECT_EQ(boundary_edges, loop_edges);

  // Targets: 0 inside; on a loop the turning angles of the polygon inscribed in a circle with
  // the loop's edge lengths (half the central angles of the two edges at the vertex).
  double total = 0;
  for (int v = 0; v < nvt; ++v) {
    const double curvature = (on_loop[v] ? kPi : 2 * kPi) - angle_sum[v];
    EXPECT_NEAR(curvature, fm.target_curvature[v], tolerance) << "vertex " << v;
    EXPECT_NEAR(curvature, fm.curvature[v], 1e-11) << "vertex " << v;
    if (!on_loop[v]) {
      EXPECT_EQ(fm.target_curvature[v], 0.0);
    }
    total += curvature;
  }
  const int b = static_cast<int>(loops.size());
  EXPECT_NEAR(total, 2 * kPi * (2 - b), 1e-9) << "Gauss–Bonnet";  // eq. (5) with g = 0
  std::vector<double> input_length(b, 0.0);
  for (int l = 0; l < b; ++l)
    for (size_t k = 0; k < loops[l].size(); ++k)
      input_length[l] += (piece.V.row(loops[l][k]) - piece.V.row(loops[l][(k + 1) % loops[l].size()])).norm();
  EXPECT_GE(input_length[fm.outer_loop], (1 - 1e-12) * *std::max_element(input_length.begin(), input_length.end()));
  for (int l = 0; l < b; ++l) {
    EXPECT_NEAR(fm.loop_total_curvature[l], l == fm.outer_loop ? 2 * kPi : -2 * kPi, 1e-9);
    // Inscribed: the turning angle at each vertex is phi1 + phi2, the half central angles of its
    // edges on the loop's circle of radius R: phi = asin(l / 2R), or pi - asin(l / 2R) for the
    // one edge whose arc exceeds a half circle when the centre lies outside the polygon.
    const auto& loop = fm.loops[l];
    const int n = static_cast<int>(loop.size());
    std::vector<double> len(n, 0.0);
    for (int f = 0; f < T.F.rows(); ++f)
      for (int i = 0; i < 3; ++i)
        if (T.adjacent(f, i) < 0)
          for (int k = 0; k < n; ++k)
            if (T.F(f, i) == loop[k] && T.F(f, (i + 1) % 3) == loop[(k + 1) % n]) len[k] = T.length(f, i);
    const double R = fm.loop_radius[l];
    std::vector<double> phi(n);
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += phi[k] = std::asin(std::min(1.0, len[k] / (2 * R)));
    if (sum < kPi - 1e-6) {
      const int longest = static_cast<int>(std::max_element(len.begin(), len.end()) - len.begin());
      phi[longest] = kPi - phi[longest];
    }
    const double sign = l == fm.outer_loop ? 1 : -1;
    for (int k = 0; k < n; ++k)
      EXPECT_NEAR(fm.target_curvature[loop[k]], sign * (phi[(k + n - 1) % n] + phi[k]), 1e-8)
          << "loop " << l << " vertex " << k;
  }
}

// ---- building blocks ------------------------------------------------------------------------------

TEST(FlatMetric, LobachevskyFunction) {
  const double catalan = 0.915965594177219015054603514932;
  EXPECT_NEAR(ricci::lobachevsky(kPi / 4), catalan / 2, 1e-15);
  EXPECT_NEAR(ricci::lobachevsky(kPi / 6), 1.5 * ricci::lobachevsky(kPi / 3), 1e-15);
  EXPECT_NEAR(ricci::lobachevsky(kPi / 3), 1.0149416064096536250 / 3, 1e-15);
  for (double x : {0.0, kPi / 2, kPi, -kPi})
    EXPECT_NEAR(ricci::lobachevsky(x), 0.0, 1e-15) << x;
  // Odd, pi-periodic, and the integral of -log|2 sin t| (Simpson on [0.3, x]).
  for (double x : {0.1, 0.7, 1.3, 2.0, 2.9}) {
    EXPECT_NEAR(ricci::lobachevsky(-x), -ricci::lobachevsky(x), 1e-15);
    EXPECT_NEAR(ricci::lobachevsky(x + kPi), ricci::lobachevsky(x), 1e-14);
    const int n = 2000;
    const double a = 0.3, h = (x - a) / n;
    double integral = 0;
    for (int k = 0; k <= n; ++k) {
      const double w = (k == 0 || k == n) ? 1 : (k % 2 ? 4 : 2);
      integral += w * -std::log(std::abs(2 * std::sin(a + k * h)));
    }
    integral *= h / 3;
    EXPECT_NEAR(ricci::lobachevsky(x) - ricci::lobachevsky(a), integral, 1e-10) << x;
  }
}

TEST(FlatMetric, TriangleAnglesFromLogLengths) {
  const double x[3] = {std::log(3.0), std::log(4.0), std::log(5.0)};
  double opposite[3], cot[3];
  ASSERT_TRUE(ricci::triangle_angles(x, opposite, cot));
  EXPECT_NEAR(opposite[0], std::atan2(3.0, 4.0), 1e-15);
  EXPECT_NEAR(opposite[1], std::atan2(4.0, 3.0), 1e-15);
  EXPECT_NEAR(opposite[2], kPi / 2, 1e-15);
  EXPECT_NEAR(cot[0], 4.0 / 3.0, 1e-14);
  EXPECT_NEAR(cot[2], 0.0, 1e-15);
  // Violating the triangle inequality: extended by (pi, 0, 0), zero cotangents.
  const double y[3] = {std::log(1.0), std::log(3.0), std::log(1.5)};
  EXPECT_FALSE(ricci::triangle_angles(y, opposite, cot));
  EXPECT_EQ(opposite[1], kPi);
  EXPECT_EQ(opposite[0] + opposite[2], 0.0);
}

TEST(FlatMetric, CyclicPolygonRecoversTheCircle) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    // Points on a circle of radius R at random angles; sometimes all within a half circle, so
    // the centre is outside the polygon (one edge longer than a "diameter chord").
    const int n = 3 + trial % 7;
    const double R = std::exp(4 * unit(rng) - 2);
    const double spread = trial % 3 == 0 ? kPi * (0.3 + 0.6 * unit(rng)) : 2 * kPi;
    std::vector<double> angle(n);
    for (double& a : angle) a = spread * unit(rng);
    std::sort(angle.begin(), angle.end());
    std::vector<double> x(n);
    double longest = 0;
    for (int k = 0; k < n; ++k) {
      double central = k + 1 < n ? angle[k + 1] - angle[k] : 2 * kPi - angle[n - 1] + angle[0];
      x[k] = std::log(2 * R * std::sin(central / 2));
      longest = std::max(longest, central);
    }
    double rho;
    std::vector<double> phi;
    ASSERT_TRUE(ricci::cyclic_polygon(x, rho, phi));
    EXPECT_NEAR(std::exp(rho), R, 1e-9 * R) << "trial " << trial;
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      const double central = k + 1 < n ? angle[k + 1] - angle[k] : 2 * kPi - angle[n - 1] + angle[0];
      EXPECT_NEAR(phi[k], central / 2, 1e-9) << "trial " << trial;
      sum += phi[k];
    }
    EXPECT_NEAR(sum, kPi, 1e-12);
    EXPECT_EQ(longest > kPi, *std::max_element(phi.begin(), phi.end()) > kPi / 2);
  }
  // No polygon: the longest edge is as long as the others together.
  double rho;
  std::vector<double> phi;
  EXPECT_FALSE(ricci::cyclic_polygon({std::log(2.0), 0.0, 0.0}, rho, phi));
}

// ---- pieces ----------------------------------------------------------------------------------------

TEST(FlatMetric, EveryPieceOfSlicedTestMeshes) {
  for (const std::string name : {"sphere.off", "torus_quad.off", "double-torus-example.off", "eight.off", "joint.off",
                                 "helmet.off", "rotor.off", "anchor.off", "elk.off", "knot.off"}) {
    SCOPED_TRACE(name);
    const TopologyResult topo = analyse_topology(test::load_test_mesh(name));
    for (int p = 0; p < static_cast<int>(topo.sliced.pieces.size()); ++p) {
      SCOPED_TRACE("piece " + std::to_string(p));
      const PieceMesh piece = extract_piece(topo.sliced, p);
      const FlatMetric fm = flat_metric(piece.mesh, piece.loops);
      expect_uniform_flat_metric(piece.mesh, piece.loops, fm);
      EXPECT_LE(fm.iterations, 30);
    }
  }
}

TEST(FlatMetric, PiecesOfGeneratedSurfaces) {
  for (int g : {0, 3}) {
    SCOPED_TRACE("genus " + std::to_string(g));
    const TopologyResult topo = analyse_topology(test::make_genus_surface(g, 32));
    for (int p = 0; p < static_cast<int>(topo.sliced.pieces.size()); ++p) {
      SCOPED_TRACE("piece " + std::to_string(p));
      const PieceMesh piece = extract_piece(topo.sliced, p);
      const FlatMetric fm = flat_metric(piece.mesh, piece.loops);
      expect_uniform_flat_metric(piece.mesh, piece.loops, fm);
      EXPECT_LE(fm.iterations, 20);
    }
  }
}

TEST(FlatMetric, QuadraticConvergenceOnATube) {
  const TriMesh m = test::make_tube(1, 1, 48, 16);
  const auto loops = boundary_loops(m.F);
  FlatMetricOptions options;
  options.tolerance = 1e-12;
  const FlatMetric fm = flat_metric(m, loops, options);
  expect_uniform_flat_metric(m, loops, fm, 1e-12);
  EXPECT_LE(fm.iterations, 10);
  EXPECT_EQ(fm.fallback_steps, 0);
  EXPECT_TRUE(fm.inserted_vertices.empty());
}

// A tube whose second and second-to-last rings sit 1e-4 from the loops: needles of aspect ratio
// ~1000 along both loops; with the rings turned by half a step, slivers whose apex lies over the
// middle of a loop edge (angle ~pi there), which the outer loop's circle would push past the
// chord unless the edge is split.
TriMesh tube_with_slivers(bool apex_over_edge_middle) {
  TriMesh m = test::make_tube(1, 1, 40, 10);
  for (int j : {1, 9})
    for (int i = 0; i < 40; ++i) {
      const double angle = 2 * kPi * (i + (apex_over_edge_middle ? 0.5 : 0.0)) / 40;
      m.V.row(j * 40 + i) << std::cos(angle), std::sin(angle), j == 1 ? 1e-4 : 1 - 1e-4;
    }
  return m;
}

TEST(FlatMetric, SliversAlongTheBoundary) {
  for (bool middle : {false, true}) {
    const TriMesh m = tube_with_slivers(middle);
    const auto loops = boundary_loops(m.F);
    const FlatMetric fm = flat_metric(m, loops);
    expect_uniform_flat_metric(m, loops, fm);
    // The outer loop's 40 edges each had a sliver with its apex over the middle: all split
    // beforehand; needles over a vertex need nothing.
    EXPECT_EQ(fm.presplit_vertices, middle ? 40 : 0);
    EXPECT_EQ(static_cast<int>(fm.inserted_vertices.size()), fm.presplit_vertices);
    for (const auto& e : fm.inserted_vertices) {
      const auto& outer = loops[fm.outer_loop];
      const auto k = std::find(outer.begin(), outer.end(), e[0]) - outer.begin();
      EXPECT_EQ(outer[(k + 1) % outer.size()], e[1]) << "splits an outer-loop edge";
    }
  }
  // A plane-sliced sphere with the slicer's thin triangles.

  const TriMesh sphere = test::make_sphere(3);
  const SlicedMesh sliced = slice_mesh(sphere, {-0.999, -0.3, 0.31, 0.9999});
  for (int p = 0; p < static_cast<int>(sliced.pieces.size()); ++p) {
    const PieceMesh piece = extract_piece(sliced, p);
    expect_uniform_flat_metric(piece.mesh, piece.loops, flat_metric(piece.mesh, piece.loops));
  }
}

TEST(FlatMetric, UnchangedUnderScaling) {
  const TopologyResult topo = analyse_topology(test::load_test_mesh("eight.off"));
  const PieceMesh piece = extract_piece(topo.sliced, 3);
  const FlatMetric reference = flat_metric(piece.mesh, piece.loops);
  for (double s : {1e8, 1e-8}) {
    TriMesh scaled = piece.mesh;
    scaled.V *= s;
    const FlatMetric fm = flat_metric(scaled, piece.loops);
    ASSERT_EQ(fm.u.size(), reference.u.size());
    EXPECT_LE((fm.u - reference.u).cwiseAbs().maxCoeff(), 1e-9) << s;
    EXPECT_EQ(fm.iterations, reference.iterations);
    for (size_t l = 0; l < fm.loop_radius.size(); ++l)
      EXPECT_NEAR(fm.loop_radius[l], s * reference.loop_radius[l], 1e-9 * s * reference.loop_radius[l]);
    EXPECT_NEAR(fm.triangulation.length(0, 0), s * reference.triangulation.length(0, 0),
                1e-9 * s * reference.triangulation.length(0, 0));
  }
}

TEST(FlatMetric, WithoutFlipsOrBalanceOnAGoodMesh) {
  const TriMesh m = test::make_tube(1, 1.5, 32, 8);
  const auto loops = boundary_loops(m.F);
  FlatMetricOptions options;
  options.delaunay_flips = false;
  options.initial_delaunay = false;
  const FlatMetric fixed = flat_metric(m, loops, options);
  expect_uniform_flat_metric(m, loops, fixed, 1e-9, /*delaunay=*/false);
  EXPECT_EQ(fixed.flips + fixed.initial_flips, 0);
  options = {};
  options.balance = false;
  const FlatMetric free = flat_metric(m, loops, options);
  ASSERT_TRUE(free.converged);
  EXPECT_LE(free.residual, 1e-10);
}

TEST(FlatMetric, OuterLoopCanBeChosen) {
  const TriMesh m = test::make_tube(1, 0.5, 32, 8);
  const auto loops = boundary_loops(m.F);
  for (int outer : {0, 1}) {
    FlatMetricOptions options;
    options.outer_loop = outer;
    const FlatMetric fm = flat_metric(m, loops, options);
    EXPECT_EQ(fm.outer_loop, outer);
    EXPECT_NEAR(fm.loop_total_curvature[outer], 2 * kPi, 1e-9);
    EXPECT_NEAR(fm.loop_total_curvature[1 - outer], -2 * kPi, 1e-9);
  }
}

// ---- errors ----------------------------------------------------------------------------------------

TEST(FlatMetric, RejectsWhatIsNotAGenusZeroPieceWithItsLoops) {
  const TriMesh closed = test::make_sphere(1);
  EXPECT_THROW(flat_metric(closed, {}), MeshError);
  const TriMesh m = test::make_tube(1, 1, 12, 3);
  auto loops = boundary_loops(m.F);
  EXPECT_THROW(flat_metric(m, {loops[0]}), MeshError);  // a loop missing
  auto reversed = loops;
  std::reverse(reversed[0].begin(), reversed[0].end());
  EXPECT_THROW(flat_metric(m, reversed), MeshError);  // against the face orientation
  // A torus with a hole: one loop, but genus 1.
  TriMesh torus = test::make_torus(2, 0.7, 12, 8);
  TriMesh holed = torus;
  holed.F = torus.F.bottomRows(torus.F.rows() - 1);
  try {
    flat_metric(holed, boundary_loops(holed.F));
    FAIL() << "expected MeshError";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("Euler characteristic -1"), std::string::npos) << e.what();
  }
}

TEST(FlatMetric, IterationCapThrowsWithTheResidual) {
  const TriMesh m = test::make_tube(1, 2, 24, 12);
  const auto loops = boundary_loops(m.F);
  FlatMetricOptions options;
  options.max_iterations = 1;
  try {
    flat_metric(m, loops, options);
    FAIL() << "expected AlgorithmError";
  } catch (const AlgorithmError& e) {
    EXPECT_NE(std::string(e.what()).find("max curvature error"), std::string::npos) << e.what();
  }
  options.throw_on_failure = false;
  const FlatMetric fm = flat_metric(m, loops, options);
  EXPECT_FALSE(fm.converged);
  EXPECT_EQ(fm.iterations, 1);
  EXPECT_GT(fm.residual, options.tolerance);
}

}  // namespace
}  // namespace polycube
