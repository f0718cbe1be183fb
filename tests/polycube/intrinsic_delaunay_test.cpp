// intrinsic_delaunay: flips change the triangulation, never the metric. Checked through what a
// flip must preserve (angle sum at every vertex, total area, face count) and what it must
// achieve (every edge Delaunay), on generated and real meshes.
#include "polycube/intrinsic_delaunay.h"

#include "formats/mesh_io.h"
#include "polycube/errors.h"
#include "polycube/validate.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace polycube {
namespace {

// Angle of a triangle with edge lengths a, b, c at the corner opposite a.
double angle_opposite(double a, double b, double c) {
  return std::acos(std::clamp((b * b + c * c - a * a) / (2 * b * c), -1.0, 1.0));
}

double heron(double a, double b, double c) {
  const double s = 0.5 * (a + b + c);
  return std::sqrt(std::max(0.0, s * (s - a) * (s - b) * (s - c)));
}

// Sum of the corner angles at each vertex.
std::vector<double> angle_sums(const Eigen::MatrixX3i& F, const Eigen::MatrixX3d& L, int nv) {
  std::vector<double> sums(nv, 0.0);
  for (int f = 0; f < F.rows(); ++f)
    for (int i = 0; i < 3; ++i)
      // Corner at F(f,i) lies between edges i and i+2, opposite edge i+1.
      sums[F(f, i)] += angle_opposite(L(f, (i + 1) % 3), L(f, i), L(f, (i + 2) % 3));
  return sums;
}

Eigen::MatrixX3d euclidean_lengths(const TriMesh& mesh) {
  Eigen::MatrixX3d L(mesh.num_faces(), 3);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) L(f, i) = (mesh.V.row(mesh.F(f, i)) - mesh.V.row(mesh.F(f, (i + 1) % 3))).norm();
  return L;
}

double total_area(const Eigen::MatrixX3d& L) {
  double area = 0;
  for (int f = 0; f < L.rows(); ++f) area += heron(L(f, 0), L(f, 1), L(f, 2));
  return area;
}

// cot(alpha) + cot(beta) of edge i of face f.
double cotan_sum(const IntrinsicTriangulation& T, int f, int i) {
  auto cot = [](double a, double b, double c) {
    return (b * b + c * c - a * a) / (4 * heron(a, b, c));
  };
  const int g = T.adjacent(f, i), j = T.adjacent_edge(f, i);
  return cot(T.length(f, i), T.length(f, (i + 1) % 3), T.length(f, (i + 2) % 3)) +
         cot(T.length(g, j), T.length(g, (j + 1) % 3), T.length(g, (j + 2) % 3));
}

void expect_valid_delaunay(const TriMesh& mesh, const IntrinsicTriangulation& T) {
  ASSERT_EQ(T.F.rows(), mesh.num_faces());
  // Adjacency is symmetric and names the same edge from both sides.
  for (int f = 0; f < T.F.rows(); ++f)
    for (int i = 0; i < 3; ++i) {
      const int g = T.adjacent(f, i), j = T.adjacent_edge(f, i);
      ASSERT_GE(g, 0);
      EXPECT_EQ(T.adjacent(g, j), f);
      EXPECT_EQ(T.adjacent_edge(g, j), i);
      EXPECT_EQ(T.F(g, j), T.F(f, (i + 1) % 3));
      EXPECT_EQ(T.F(g, (j + 1) % 3), T.F(f, i));
      EXPECT_DOUBLE_EQ(T.length(g, j), T.length(f, i));
      EXPECT_NE(T.F(f, i), T.F(f, (i + 1) % 3)) << "loop edge";
    }
  // The metric is unchanged: same cone angle at every vertex, same area.
  const std::vector<double> before = angle_sums(mesh.F, euclidean_lengths(mesh), mesh.num_vertices());
  const std::vector<double> after = angle_sums(T.F, T.length, mesh.num_vertices());
  for (int v = 0; v < mesh.num_vertices(); ++v) EXPECT_NEAR(after[v], before[v], 1e-8) << "vertex " << v;
  EXPECT_NEAR(total_area(T.length), total_area(euclidean_lengths(mesh)), 1e-9 * total_area(T.length));
  // Delaunay everywhere but the reported edges.
  int bad = 0;
  for (int f = 0; f < T.F.rows(); ++f)
    for (int i = 0; i < 3; ++i)
      if (f < T.adjacent(f, i) || (f == T.adjacent(f, i) && i < T.adjacent_edge(f, i)))
        bad += cotan_sum(T, f, i) < -1e-8;
  EXPECT_EQ(bad, T.non_delaunay_edges);
  if (T.non_delaunay_edges == 0) {
    EXPECT_GE(T.min_cotan_sum, -1e-8);
  }
}

TEST(IntrinsicDelaunay, PreservesMetricAndMakesEveryEdgeDelaunay) {
  for (const std::string name : {"rotor.off", "joint.off", "helmet.off", "anchor.off", "couplingdown.off", "elk.off"}) {
    SCOPED_TRACE(name);
    const TriMesh mesh = test::load_test_mesh(name);
    const IntrinsicTriangulation T = intrinsic_delaunay(mesh);
    expect_valid_delaunay(mesh, T);
    EXPECT_EQ(T.non_delaunay_edges, 0);
  }
}

TEST(IntrinsicDelaunay, FlipsObtuseTriangulationsAndLeavesDelaunayOnesAlone) {
  // couplingdown (a CAD part) has long thin triangles: many flips. The icosphere is Delaunay.
  EXPECT_GT(intrinsic_delaunay(test::load_test_mesh("couplingdown.off")).flips, 100);
  const TriMesh sphere = test::make_sphere(3);
  const IntrinsicTriangulation T = intrinsic_delaunay(sphere);
  EXPECT_EQ(T.flips, 0);
  EXPECT_EQ(T.F, sphere.F);
}

TEST(IntrinsicDelaunay, ScaleInvariant) {
  TriMesh mesh = test::load_test_mesh("helmet.off");
  const IntrinsicTriangulation T = intrinsic_delaunay(mesh);
  for (double scale : {1e-6, 1e6}) {
    TriMesh scaled = mesh;
    scaled.V *= scale;
    const IntrinsicTriangulation S = intrinsic_delaunay(scaled);
    EXPECT_EQ(S.flips, T.flips);
    EXPECT_EQ(S.F, T.F);
    EXPECT_LT((S.length / scale - T.length).cwiseAbs().maxCoeff(), 1e-9 * T.length.maxCoeff());
  }
}

TEST(IntrinsicDelaunay, WithoutFlipsDescribesTheInput) {
  const TriMesh mesh = test::load_test_mesh("eight.off");
  IntrinsicDelaunayOptions options;
  options.max_flips_per_edge = 0;
  const IntrinsicTriangulation T = intrinsic_delaunay(mesh, options);
  EXPECT_EQ(T.flips, 0);
  EXPECT_EQ(T.F, mesh.F);
  EXPECT_LT((T.length - euclidean_lengths(mesh)).cwiseAbs().maxCoeff(), 1e-14 * T.length.maxCoeff());
}

TEST(IntrinsicDelaunay, RejectsOpenAndMisorientedMeshes) {
  EXPECT_THROW(intrinsic_delaunay(test::open_cylinder()), MeshError);
  EXPECT_THROW(intrinsic_delaunay(test::flipped_face_tetrahedron()), MeshError);
  EXPECT_THROW(intrinsic_delaunay(test::nonmanifold_edge()), MeshError);
}

}  // namespace
}  // namespace polycube
