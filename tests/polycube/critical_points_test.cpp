// critical_points (§3.1): PL Morse theory on vertex links. The Euler relation must hold exactly
// for any function; the harmonic function must have one minimum, one maximum and 2g saddles.
#include "polycube/critical_points.h"

#include "formats/mesh_io.h"
#include "polycube/errors.h"
#include "polycube/harmonic_function.h"
#include "polycube/intrinsic_delaunay.h"
#include "polycube/mesh_topology.h"
#include "polycube/validate.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace polycube {
namespace {

const std::vector<std::string> kMeshes = {"sphere.off", "rotor.off",  "elk.off",    "knot.off",
                                          "joint.off",  "eight.off",  "helmet.off", "anchor.off",
                                          "couplingdown.off"};

// Connectivity of the mesh's own triangulation.
IntrinsicTriangulation input_triangulation(const TriMesh& mesh) {
  IntrinsicDelaunayOptions options;
  options.max_flips_per_edge = 0;
  return intrinsic_delaunay(mesh, options);
}

CriticalPoints on_mesh(const TriMesh& mesh, const Eigen::VectorXd& f, const CriticalPointOptions& options = {}) {
  const IntrinsicTriangulation T = input_triangulation(mesh);
  return critical_points(T, f, options);
}

int euler(const TriMesh& mesh) { return euler_characteristic(mesh.F, mesh.num_vertices()); }

TEST(CriticalPoints, LinearFunctionOnConvexSurfaceHasOnlyTwoExtrema) {
  const TriMesh sphere = test::make_sphere(3);
  // Axis directions give many equal values (ties); the others are generic.
  for (const Eigen::Vector3d& direction : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0),
                                          Eigen::Vector3d(0.3, -0.5, 0.8), Eigen::Vector3d(1, 1, 1)}) {
    const Eigen::VectorXd f = sphere.V * direction;
    const CriticalPoints c = on_mesh(sphere, f);
    EXPECT_EQ(c.minima.size(), 1u);
    EXPECT_EQ(c.maxima.size(), 1u);
    EXPECT_EQ(c.saddle_count(), 0);
    ASSERT_EQ(c.minima.size(), 1u);
    EXPECT_NEAR(f[c.minima[0]], f.minCoeff(), 0);
    EXPECT_NEAR(f[c.maxima[0]], f.maxCoeff(), 0);
  }
}

TEST(CriticalPoints, EulerRelationHoldsForRandomFunctionsAndCancellationLeavesTwoGSaddles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::vector<TriMesh> meshes;
  for (const auto& name : kMeshes) meshes.push_back(test::load_test_mesh(name));
  meshes.push_back(test::make_torus(2.0, 0.5, 16, 8));
  for (const TriMesh& mesh : meshes) {
    const int chi = euler(mesh), g = (2 - chi) / 2;
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::VectorXd f(mesh.num_vertices());
      for (int v = 0; v < f.size(); ++v) f[v] = trial == 2 ? std::floor(4 * uniform(rng)) : uniform(rng);  // ties
      const CriticalPoints raw = on_mesh(mesh, f);
      EXPECT_GT(raw.raw_minima, 1);
      EXPECT_EQ(raw.raw_minima - raw.raw_saddle_count + raw.raw_maxima, chi);
      EXPECT_EQ(static_cast<int>(raw.minima.size()) - raw.saddle_count() + static_cast<int>(raw.maxima.size()), chi);
      CriticalPointOptions options;
      options.cancel_extra_extrema = true;
      const CriticalPoints c = on_mesh(mesh, f, options);
      EXPECT_EQ(c.minima.size(), 1u);
      EXPECT_EQ(c.maxima.size(), 1u);
      EXPECT_EQ(c.saddle_count(), 2 * g);
      EXPECT_EQ(c.cancelled_pairs, raw.raw_minima - 1 + raw.raw_maxima - 1);
      EXPECT_EQ(c.unmatched_cancellations, 0);
      EXPECT_EQ(c.saddles.size(), c.saddle_multiplicity.size());
      for (int m : c.saddle_multiplicity) EXPECT_GE(m, 1);
    }
  }
}

TEST(CriticalPoints, CancellationKeepsTheRequestedExtrema) {
  const TriMesh mesh = test::load_test_mesh("eight.off");
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(0, 1);
  Eigen::VectorXd f(mesh.num_vertices());
  for (int v = 0; v < f.size(); ++v) f[v] = uniform(rng);
  const CriticalPoints raw = on_mesh(mesh, f);
  ASSERT_GE(raw.minima.size(), 2u);
  ASSERT_GE(raw.maxima.size(), 2u);
  CriticalPointOptions options;
  options.cancel_extra_extrema = true;
  options.keep_minimum = raw.minima.back();
  options.keep_maximum = raw.maxima.front();
  const CriticalPoints c = on_mesh(mesh, f, options);
  EXPECT_EQ(c.minima, std::vector<int>{raw.minima.back()});
  EXPECT_EQ(c.maxima, std::vector<int>{raw.maxima.front()});
  EXPECT_EQ(c.saddle_count(), 4);
}

TEST(CriticalPoints, MonkeySaddleCountsTwice) {
  const TriMesh sphere = test::make_sphere(2);
  const IntrinsicTriangulation T = input_triangulation(sphere);
  // A vertex of degree 6 and its link in cyclic order.
  int v = -1;
  std::vector<int> degree(sphere.num_vertices(), 0);
  for (int f = 0; f < sphere.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) ++degree[sphere.F(f, i)];
  for (int u = 0; u < sphere.num_vertices() && v < 0; ++u)
    if (degree[u] == 6) v = u;
  ASSERT_GE(v, 0);
  std::vector<int> link;
  int f0 = -1, c0 = -1;
  for (int f = 0; f < sphere.num_faces() && f0 < 0; ++f)
    for (int i = 0; i < 3; ++i)
      if (sphere.F(f, i) == v) f0 = f, c0 = i;
  for (int f = f0, c = c0;;) {
    link.push_back(sphere.F(f, (c + 1) % 3));
    const int g = T.adjacent(f, (c + 2) % 3);
    c = T.adjacent_edge(f, (c + 2) % 3);
    f = g;
    if (f == f0) break;
  }
  ASSERT_EQ(link.size(), 6u);
  // Height everywhere, but around v alternately 0.1 above and below it.
  Eigen::VectorXd f = sphere.V.col(2);
  f[v] = 0.25;
  for (int k = 0; k < 6; ++k) f[link[k]] = 0.25 + (k % 2 ? 0.1 : -0.1);
  const CriticalPoints c = on_mesh(sphere, f);
  const auto it = std::find(c.saddles.begin(), c.saddles.end(), v);
  ASSERT_NE(it, c.saddles.end());
  EXPECT_EQ(c.saddle_multiplicity[it - c.saddles.begin()], 2);
  EXPECT_EQ(c.raw_minima - c.raw_saddle_count + c.raw_maxima, 2);
}

TEST(CriticalPoints, HarmonicFunctionHasOneMinimumOneMaximumAndTwoGSaddles) {
  // On the intrinsic Delaunay links, with no cancellation needed: the maximum principle leaves
  // no interior extrema.
  std::vector<std::pair<std::string, TriMesh>> meshes;
  for (const auto& name : kMeshes) meshes.push_back({name, test::load_test_mesh(name)});
  for (int g = 1; g <= 4; ++g) meshes.push_back({"generated genus " + std::to_string(g), test::make_genus_surface(g, 32)});
  for (const auto& [name, mesh] : meshes) {
    SCOPED_TRACE(name);
    const int g = (2 - euler(mesh)) / 2;
    const HarmonicFunction h = harmonic_function(mesh);
    const IntrinsicTriangulation& T = h.intrinsic;
    const CriticalPoints c = critical_points(T, h.f);
    EXPECT_EQ(c.minima, std::vector<int>{h.source});
    EXPECT_EQ(c.maxima, std::vector<int>{h.sink});
    EXPECT_EQ(c.saddle_count(), 2 * g);
  }
}

TEST(CriticalPoints, TieBreakDecidesEqualValues) {
  // A constant function ordered by height has the critical points of the height.
  const TriMesh mesh = test::load_test_mesh("joint.off");
  const Eigen::VectorXd z = mesh.V.col(2);
  CriticalPointOptions options;
  options.tie_break = &z;
  const CriticalPoints by_tie = on_mesh(mesh, Eigen::VectorXd::Zero(mesh.num_vertices()), options);
  const CriticalPoints by_z = on_mesh(mesh, z);
  EXPECT_EQ(by_tie.minima, by_z.minima);
  EXPECT_EQ(by_tie.maxima, by_z.maxima);
  EXPECT_EQ(by_tie.saddles, by_z.saddles);
  EXPECT_EQ(by_tie.saddle_multiplicity, by_z.saddle_multiplicity);
}

TEST(CriticalPoints, RejectsNonFiniteValues) {
  const TriMesh mesh = test::make_sphere(1);
  Eigen::VectorXd f = mesh.V.col(2);
  f[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(on_mesh(mesh, f), AlgorithmError);
}

}  // namespace
}  // namespace polycube
