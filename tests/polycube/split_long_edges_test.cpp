// split_long_edges: every edge ends up short enough, the surface is the same (area, volume, each
// new vertex on an input edge, each new triangle inside an input triangle with its orientation),
// and the topology is kept, on CAD meshes of tests/data and a generated torus.
#include "polycube/split_long_edges.h"

#include "polycube/closest_point.h"
#include "polycube/mesh_topology.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace polycube {
namespace {

double longest_edge(const TriMesh& mesh) {
  double longest = 0;
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int i = 0; i < 3; ++i)
      longest = std::max(longest, (mesh.V.row(mesh.F(f, i)) - mesh.V.row(mesh.F(f, (i + 1) % 3))).norm());
  return longest;
}

// Checks everything split_long_edges promises of `split` made from `mesh` with `max_length`.
void expect_same_surface(const TriMesh& mesh, const SplitLongEdges& split, double max_length) {
  const TriMesh& fine = split.mesh;
  ASSERT_GE(fine.num_vertices(), mesh.num_vertices());
  EXPECT_TRUE(fine.V.topRows(mesh.num_vertices()) == mesh.V) << "the input's vertices come first, unchanged";
  if (!split.capped) {
    EXPECT_LE(longest_edge(fine), max_length * (1 + 1e-12));
  }
  const double scale = bounding_box(mesh.V).diagonal();
  EXPECT_NEAR(surface_area(fine), surface_area(mesh), 1e-9 * surface_area(mesh));
  EXPECT_NEAR(signed_volume(fine), signed_volume(mesh), 1e-9 * scale * scale * scale);
  // Same topology: closed (every edge in two triangles), same Euler characteristic and components.
  const EdgeMap edges = build_edge_map(fine.F);
  for (int e = 0; e < edges.num_edges(); ++e) ASSERT_EQ(edges.face_count[e], 2) << "edge " << e;
  EXPECT_EQ(euler_characteristic(fine.F, fine.num_vertices()), euler_characteristic(mesh.F, mesh.num_vertices()));
  EXPECT_EQ(connected_components(fine.F, fine.num_vertices()), connected_components(mesh.F, mesh.num_vertices()));
  // Every new triangle lies in an input triangle with the same orientation: its centroid is on
  // the input surface and its normal agrees with the normal of the input triangle there (the
  // closest one by brute force; the meshes here are small).
  const Eigen::MatrixX3d normals = face_normals(mesh);
  const Eigen::MatrixX3d fine_normals = face_normals(fine);
  for (int f = 0; f < fine.num_faces(); ++f) {
    const Eigen::Vector3d c = (fine.V.row(fine.F(f, 0)) + fine.V.row(fine.F(f, 1)) + fine.V.row(fine.F(f, 2))).transpose() / 3;
    double best = INFINITY;
    int holder = -1;
    for (int g = 0; g < mesh.num_faces(); ++g) {
      const double d = (closest_on_triangle(c, mesh.V.row(mesh.F(g, 0)), mesh.V.row(mesh.F(g, 1)), mesh.V.row(mesh.F(g, 2))).point - c).norm();
      if (d < best) {
        best = d;
        holder = g;
      }
    }
    ASSERT_LE(best, 1e-12 * scale) << "triangle " << f << " off the surface";
    ASSERT_GT(fine_normals.row(f).dot(normals.row(holder)), 0.999) << "triangle " << f << " turned";
  }
}

TEST(SplitLongEdges, CadMeshesGetShortEdgesOnTheSameSurface) {
  for (const char* name : {"tetrahedron.off", "corner.off", "joint.off"}) {
    SCOPED_TRACE(name);
    const TriMesh mesh = test::load_test_mesh(name);
    const double max_length = longest_edge(mesh) / 5;
    const SplitLongEdges split = split_long_edges(mesh, max_length, 10'000'000);
    EXPECT_FALSE(split.capped);
    EXPECT_GE(split.rounds, 3);  // 5 times shorter: at least log2(5) rounds
    EXPECT_GT(split.mesh.num_faces(), mesh.num_faces());
    expect_same_surface(mesh, split, max_length);
  }
}

TEST(SplitLongEdges, WellShapedTrianglesSplitIntoFour) {
  // The corner tetrahedron's edges (1 and sqrt 2) all stay longer than the limit together until
  // the last round: every round splits every triangle into four (red), never two (green).
  const TriMesh mesh = test::load_test_mesh("tetrahedron.off");
  const SplitLongEdges split = split_long_edges(mesh, longest_edge(mesh) / 7, 10'000'000);
  EXPECT_EQ(split.rounds, 3);
  EXPECT_EQ(split.mesh.num_faces(), mesh.num_faces() * 64);
  expect_same_surface(mesh, split, longest_edge(mesh) / 7);
}

TEST(SplitLongEdges, ShortEdgesAreLeftAlone) {
  const TriMesh torus = test::make_torus(1.0, 0.3, 24, 12);
  const SplitLongEdges split = split_long_edges(torus, 2 * longest_edge(torus), 10'000'000);
  EXPECT_EQ(split.rounds, 0);
  EXPECT_FALSE(split.capped);
  EXPECT_TRUE(split.mesh.V == torus.V);
  EXPECT_TRUE(split.mesh.F == torus.F);
  // Half the longest edge: only the long ones (and the closure's) split, the surface kept.
  const SplitLongEdges half = split_long_edges(torus, longest_edge(torus) / 2, 10'000'000);
  EXPECT_GE(half.rounds, 1);
  expect_same_surface(torus, half, longest_edge(torus) / 2);
}

TEST(SplitLongEdges, StopsBeforePassingTheFaceCap) {
  const TriMesh mesh = test::load_test_mesh("tetrahedron.off");
  const SplitLongEdges split = split_long_edges(mesh, longest_edge(mesh) / 100, 1000);
  EXPECT_TRUE(split.capped);
  EXPECT_LE(split.mesh.num_faces(), 1000);
  EXPECT_GT(split.mesh.num_faces() * 4, 1000) << "one more round would pass the cap";
  expect_same_surface(mesh, split, longest_edge(mesh) / 100);
}

TEST(SplitLongEdges, RejectsBadArguments) {
  const TriMesh mesh = test::load_test_mesh("tetrahedron.off");
  EXPECT_THROW(split_long_edges(mesh, 0, 100), std::invalid_argument);
  EXPECT_THROW(split_long_edges(mesh, -1, 100), std::invalid_argument);
  EXPECT_THROW(split_long_edges(mesh, 1, 0), std::invalid_argument);
}


// The share of the area in slivers: a triangle 100 times as long as high counts at aspect 50, not
// at 200; an equilateral one never; weighted by area; a rod's sides are almost all of it.
TEST(SplitLongEdges, SliverAreaShareWeighsTheLongThinTriangles) {
  TriMesh two;
  two.V.resize(6, 3);
  two.V << 0, 0, 0, 1, 0, 0, 0, 0.01, 0,  // legs 1 and 0.01: longest 1.00005, height 0.0099995
      0, 0, 1, 1, 0, 1, 0.5, std::sqrt(3.0) / 2, 1;  // equilateral, side 1
  two.F.resize(2, 3);
  two.F << 0, 1, 2, 3, 4, 5;
  const double sliver = 0.005, equilateral = std::sqrt(3.0) / 4;
  EXPECT_NEAR(sliver_area_share(two, 50), sliver / (sliver + equilateral), 1e-12);
  EXPECT_EQ(sliver_area_share(two, 200), 0);
  EXPECT_GT(sliver_area_share(test::make_rod(0.001, 1, 24), 50), 0.99);
  EXPECT_EQ(sliver_area_share(test::make_sphere(2), 50), 0);
  EXPECT_THROW(sliver_area_share(two, 0), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
