// harmonic_function (§3.1, eq. 1): boundary values, the discrete maximum principle, the Laplace
// residual, and independence of scale and position.
#include "polycube/harmonic_function.h"

#include "formats/mesh_io.h"
#include "polycube/errors.h"
#include "polycube/validate.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace polycube {
namespace {

const std::vector<std::string> kMeshes = {"sphere.off", "rotor.off",  "elk.off",    "knot.off",
                                          "joint.off",  "eight.off",  "helmet.off", "anchor.off",
                                          "couplingdown.off"};

// Lowest and highest neighbour value of every vertex in the triangulation f was solved on.
void neighbour_range(const IntrinsicTriangulation& T, const Eigen::VectorXd& f, std::vector<double>& low,
                     std::vector<double>& high) {
  low.assign(f.size(), std::numeric_limits<double>::infinity());
  high.assign(f.size(), -std::numeric_limits<double>::infinity());
  for (int k = 0; k < T.F.rows(); ++k)
    for (int i = 0; i < 3; ++i) {
      const int a = T.F(k, i), b = T.F(k, (i + 1) % 3);
      low[a] = std::min(low[a], f[b]);
      high[a] = std::max(high[a], f[b]);
      low[b] = std::min(low[b], f[a]);
      high[b] = std::max(high[b], f[a]);
    }
}

void expect_harmonic(const TriMesh& mesh, const HarmonicFunction& h) {
  ASSERT_EQ(h.f.size(), mesh.num_vertices());
  // Boundary conditions at the lowest and highest vertex (smallest index among equal z).
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    EXPECT_TRUE(mesh.V(v, 2) > mesh.V(h.source, 2) || (mesh.V(v, 2) == mesh.V(h.source, 2) && v >= h.source));
    EXPECT_TRUE(mesh.V(v, 2) < mesh.V(h.sink, 2) || (mesh.V(v, 2) == mesh.V(h.sink, 2) && v >= h.sink));
  }
  EXPECT_EQ(h.f[h.source], 0.0);
  EXPECT_EQ(h.f[h.sink], 1.0);
  EXPECT_LT(h.residual, 1e-10);
  // Maximum principle: every free vertex lies within its neighbours' range (no interior
  // extrema); with all weights positive even strictly inside it, up to rounding.
  std::vector<double> low, high;
  neighbour_range(h.intrinsic, h.f, low, high);
  int violations = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    if (v == h.source || v == h.sink) continue;
    violations += !(h.f[v] >= low[v] - 1e-13 && h.f[v] <= high[v] + 1e-13);
  }
  EXPECT_EQ(violations, 0);
  EXPECT_GE(h.f.minCoeff(), 0.0);
  EXPECT_LE(h.f.maxCoeff(), 1.0);
}

TEST(HarmonicFunction, BoundaryValuesMaximumPrincipleAndResidualOnTestMeshes) {
  for (const auto& name : kMeshes) {
    SCOPED_TRACE(name);
    const TriMesh mesh = test::load_test_mesh(name);
    const HarmonicFunction h = harmonic_function(mesh);
    expect_harmonic(mesh, h);
    EXPECT_EQ(h.negative_weights, h.intrinsic.non_delaunay_edges);
  }
}

TEST(HarmonicFunction, GeneratedSurfaces) {
  for (int g = 0; g <= 4; ++g) {
    SCOPED_TRACE("genus " + std::to_string(g));
    const TriMesh mesh = test::make_genus_surface(g, 32);
    expect_harmonic(mesh, harmonic_function(mesh));
  }
  // Cocircular quads everywhere: zero weights raised, nothing negative.
  const TriMesh torus = test::make_torus(2.0, 0.7, 24, 12);
  const HarmonicFunction h = harmonic_function(torus);
  expect_harmonic(torus, h);
  EXPECT_EQ(h.negative_weights, 0);
}

TEST(HarmonicFunction, IntrinsicDelaunayRemovesNegativeWeights) {
  // The CAD part has obtuse triangles: its own cotangent weights go negative.
  const TriMesh mesh = test::load_test_mesh("couplingdown.off");
  HarmonicOptions plain;
  plain.intrinsic_delaunay = false;
  EXPECT_GT(harmonic_function(mesh, plain).negative_weights, 0);
  const HarmonicFunction h = harmonic_function(mesh);
  EXPECT_EQ(h.negative_weights, 0);
  EXPECT_GT(h.intrinsic_flips, 0);
}

TEST(HarmonicFunction, UnchangedUnderScalingAndTranslation) {
  const TriMesh mesh = test::load_test_mesh("helmet.off");
  const HarmonicFunction reference = harmonic_function(mesh);
  for (double scale : {1e-6, 1e6}) {
    for (double shift : {0.0, 1000.0}) {
      TriMesh moved = mesh;
      moved.V = (mesh.V * scale).rowwise() + Eigen::RowVector3d(shift, -2 * shift, 3 * shift) * scale;
      const HarmonicFunction h = harmonic_function(moved);
      EXPECT_EQ(h.source, reference.source);
      EXPECT_EQ(h.sink, reference.sink);
      EXPECT_EQ(h.intrinsic_flips, reference.intrinsic_flips);
      EXPECT_LT((h.f - reference.f).cwiseAbs().maxCoeff(), 1e-9) << "scale " << scale << " shift " << shift;
    }
  }
}

TEST(HarmonicSolver, SameAsHarmonicFunctionOnTurnedCopies) {
  // One factorisation for every orientation: each turned copy's f, from the grounded dipole,
  // is harmonic_function's on that copy (same extremes, same values to rounding) and satisfies
  // the same boundary values, residual and maximum principle.
  const Eigen::Matrix3d turns[3] = {Eigen::Matrix3d::Identity(),
                                    (Eigen::Matrix3d() << 0, 1, 0, 0, 0, 1, 1, 0, 0).finished(),
                                    Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix()};
  for (const auto& name : kMeshes) {
    SCOPED_TRACE(name);
    const TriMesh mesh = test::load_test_mesh(name);
    const HarmonicSolver solver(mesh);
    for (const Eigen::Matrix3d& turn : turns) {
      TriMesh turned = mesh;
      turned.V = mesh.V * turn.transpose();
      const HarmonicFunction shared = solver.solve(turned);
      expect_harmonic(turned, shared);
      const HarmonicFunction own = harmonic_function(turned);
      EXPECT_EQ(shared.source, own.source);
      EXPECT_EQ(shared.sink, own.sink);
      EXPECT_EQ(shared.negative_weights, own.negative_weights);
      EXPECT_LT((shared.f - own.f).cwiseAbs().maxCoeff(), 1e-9);
    }
  }
  // The grounded vertex (0) as the source, then as the sink.
  const TriMesh sphere = test::make_sphere(2);
  const HarmonicSolver solver(sphere);
  for (const double end : {-1.0, 1.0}) {
    TriMesh turned = sphere;
    const Eigen::Vector3d to = Eigen::Vector3d(0, 0, end);
    turned.V = sphere.V * Eigen::Quaterniond::FromTwoVectors(sphere.V.row(0).transpose().normalized(), to).toRotationMatrix().transpose();
    const HarmonicFunction shared = solver.solve(turned);
    EXPECT_EQ(end < 0 ? shared.source : shared.sink, 0);
    expect_harmonic(turned, shared);
    EXPECT_LT((shared.f - harmonic_function(turned).f).cwiseAbs().maxCoeff(), 1e-9);
  }
  TriMesh other = test::make_sphere(3);
  EXPECT_THROW(solver.solve(other), std::invalid_argument);
  TriMesh flat = sphere;
  flat.V.col(2).setZero();
  EXPECT_THROW(solver.solve(flat), MeshError);
}

TEST(HarmonicFunction, SupernodalFactorisationGivesTheSameFunction) {
  // Large Laplacians go to CHOLMOD's supernodal Cholesky; here every size does, and the function,
  // its boundary values, residual and maximum principle must be the simplicial solve's, for both
  // harmonic_function and the orientation search's HarmonicSolver.
  HarmonicOptions supernodal;
  supernodal.supernodal_min_unknowns = 0;
  for (const std::string name : {"elk.off", "knot.off", "couplingdown.off"}) {
    SCOPED_TRACE(name);
    const TriMesh mesh = test::load_test_mesh(name);
    const HarmonicFunction simplicial = harmonic_function(mesh);
    EXPECT_FALSE(simplicial.supernodal);
    const HarmonicFunction h = harmonic_function(mesh, supernodal);
    EXPECT_TRUE(h.supernodal);
    expect_harmonic(mesh, h);
    EXPECT_EQ(h.source, simplicial.source);
    EXPECT_EQ(h.sink, simplicial.sink);
    EXPECT_LT((h.f - simplicial.f).cwiseAbs().maxCoeff(), 1e-9);
    TriMesh turned = mesh;
    turned.V = mesh.V * Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix().transpose();
    const HarmonicFunction shared = HarmonicSolver(mesh, supernodal).solve(turned);
    EXPECT_TRUE(shared.supernodal);
    expect_harmonic(turned, shared);
    EXPECT_LT((shared.f - harmonic_function(turned).f).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(HarmonicFunction, RejectsMeshesItCannotSolveOn) {
  EXPECT_THROW(harmonic_function(test::two_tetrahedra()), MeshError);
  EXPECT_THROW(harmonic_function(test::open_cylinder()), MeshError);
  TriMesh unused = test::make_sphere(1);
  unused.V.conservativeResize(unused.V.rows() + 1, 3);
  unused.V.bottomRows(1).setZero();
  EXPECT_THROW(harmonic_function(unused), MeshError);
}

}  // namespace
}  // namespace polycube
