// The generated test meshes are what other tests build on: check that the clean ones are closed,
// manifold, consistently outward-oriented, of the requested genus and well shaped, and that each
// broken fixture carries exactly its defect.
#include "support/generated_meshes.h"

#include "polycube/mesh.h"
#include "polycube/mesh_topology.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

namespace polycube::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Counts directed edges used by more than one face: zero iff adjacent faces agree in orientation
// (given an edge-manifold mesh).
int count_repeated_directed_edges(const Eigen::MatrixX3i& F) {
  std::set<std::pair<int, int>> seen;
  int repeated = 0;
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      if (!seen.emplace(F(f, c), F(f, (c + 1) % 3)).second) ++repeated;
  return repeated;
}

int count_nonmanifold_edges(const Eigen::MatrixX3i& F) {
  const EdgeMap map = build_edge_map(F);
  return static_cast<int>((map.face_count.array() > 2).count());
}

double min_angle_degrees(const TriMesh& mesh) {
  double smallest = 180;
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d p = mesh.V.row(mesh.F(f, c));
      const Eigen::Vector3d u = Eigen::Vector3d(mesh.V.row(mesh.F(f, (c + 1) % 3))) - p;
      const Eigen::Vector3d v = Eigen::Vector3d(mesh.V.row(mesh.F(f, (c + 2) % 3))) - p;
      smallest = std::min(smallest, std::atan2(u.cross(v).norm(), u.dot(v)) * 180 / kPi);
    }
  return smallest;
}

// Largest angle between the normals of two faces sharing an edge (a fold-over shows as ~180).
double max_dihedral_turn_degrees(const TriMesh& mesh) {
  const EdgeMap map = build_edge_map(mesh.F);
  const Eigen::MatrixX3d N = face_normals(mesh);
  double largest = 0;
  for (int e = 0; e < map.num_edges(); ++e) {
    if (map.EF(e, 1) < 0) continue;
    const double c = std::clamp(N.row(map.EF(e, 0)).dot(N.row(map.EF(e, 1))), -1.0, 1.0);
    largest = std::max(largest, std::acos(c) * 180 / kPi);
  }
  return largest;
}

// Everything a clean closed surface of the given genus must satisfy.
void expect_clean_closed_surface(const TriMesh& mesh, int expected_genus) {
  ASSERT_GT(mesh.num_faces(), 0);
  EXPECT_TRUE(boundary_loops(mesh.F).empty());
  EXPECT_EQ(count_nonmanifold_edges(mesh.F), 0);
  EXPECT_EQ(count_nonmanifold_vertices(mesh.F, mesh.num_vertices()), 0);
  EXPECT_EQ(count_unreferenced_vertices(mesh.F, mesh.num_vertices()), 0);
  EXPECT_EQ(count_repeated_directed_edges(mesh.F), 0);
  EXPECT_EQ(connected_components(mesh.F, mesh.num_vertices()), 1);
  EXPECT_EQ(genus(mesh.F, mesh.num_vertices()), expected_genus);
  EXPECT_EQ(euler_characteristic(mesh.F, mesh.num_vertices()), 2 - 2 * expected_genus);
  EXPECT_GT(signed_volume(mesh), 0);
  const Eigen::VectorXd areas = face_areas(mesh);
  EXPECT_GT(areas.minCoeff() / areas.mean(), 1e-4);
  EXPECT_GT(min_angle_degrees(mesh), 1.0);
  EXPECT_TRUE(mesh.V.allFinite());
}

TEST(GeneratedMeshes, TorusIsCleanGenusOneWithExpectedVolume) {
  const TriMesh torus = make_torus(2.0, 0.5, 48, 24);
  EXPECT_EQ(torus.num_vertices(), 48 * 24);
  EXPECT_EQ(torus.num_faces(), 2 * 48 * 24);
  expect_clean_closed_surface(torus, 1);
  const double exact = 2 * kPi * kPi * 2.0 * 0.5 * 0.5;
  EXPECT_NEAR(signed_volume(torus), exact, 0.02 * exact);
}

TEST(GeneratedMeshes, TorusRejectsBadParameters) {
  EXPECT_THROW(make_torus(1.0, 1.0, 8, 8), std::invalid_argument);
  EXPECT_THROW(make_torus(2.0, 0.5, 2, 8), std::invalid_argument);
}

TEST(GeneratedMeshes, SphereHasIcosphereCountsAndUnitRadius) {
  for (int s = 0; s <= 3; ++s) {
    const TriMesh sphere = make_sphere(s);
    const int scale = 1 << (2 * s);
    EXPECT_EQ(sphere.num_vertices(), 10 * scale + 2);
    EXPECT_EQ(sphere.num_faces(), 20 * scale);
    expect_clean_closed_surface(sphere, 0);
    EXPECT_NEAR(sphere.V.rowwise().norm().minCoeff(), 1.0, 1e-12);
    EXPECT_NEAR(sphere.V.rowwise().norm().maxCoeff(), 1.0, 1e-12);
  }
  EXPECT_NEAR(signed_volume(make_sphere(4)), 4.0 / 3.0 * kPi, 0.01 * 4.0 / 3.0 * kPi);
}

class GenusSurface : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(GenusSurface, IsCleanClosedSurfaceOfRequestedGenus) {
  const auto [g, resolution] = GetParam();
  const TriMesh mesh = make_genus_surface(g, resolution);
  expect_clean_closed_surface(mesh, g);
  // Smooth surface, no fold-overs: neighbouring normals turn by well under 90 degrees.
  EXPECT_LT(max_dihedral_turn_degrees(mesh), 90.0);
  const Eigen::VectorXd areas = face_areas(mesh);
  std::cout << "genus " << g << " resolution " << resolution << ": " << mesh.num_vertices() << " vertices, "
            << mesh.num_faces() << " faces, min angle " << min_angle_degrees(mesh) << " deg, min/mean area "
            << areas.minCoeff() / areas.mean() << ", max normal turn " << max_dihedral_turn_degrees(mesh)
            << " deg\n";
}

INSTANTIATE_TEST_SUITE_P(GenusAndResolution, GenusSurface,
                         ::testing::Values(std::pair{0, 24}, std::pair{1, 24}, std::pair{2, 24}, std::pair{3, 24},
                                           std::pair{4, 24}, std::pair{5, 24}, std::pair{6, 24}, std::pair{0, 48},
                                           std::pair{1, 48}, std::pair{2, 48}, std::pair{3, 48}, std::pair{4, 48},
                                           std::pair{5, 48}, std::pair{6, 48}, std::pair{8, 64},
                                           std::pair{1, 96}),
                         [](const auto& info) {
                           return "genus" + std::to_string(info.param.first) + "_res" +
                                  std::to_string(info.param.second);
                         });

TEST(GeneratedMeshes, GenusSurfaceIsDeterministic) {
  const TriMesh a = make_genus_surface(2, 32), b = make_genus_surface(2, 32);
  EXPECT_EQ(a.F, b.F);
  EXPECT_EQ(a.V, b.V);
}

TEST(GeneratedMeshes, GenusSurfaceRejectsBadParameters) {
  EXPECT_THROW(make_genus_surface(-1), std::invalid_argument);
  EXPECT_THROW(make_genus_surface(1, 4), std::invalid_argument);
}

TEST(GeneratedMeshes, OpenCylinderHasTwoBoundaryLoops) {
  const TriMesh mesh = open_cylinder();
  const auto loops = boundary_loops(mesh.F);
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_EQ(loops[0].size(), 8u);
  EXPECT_EQ(loops[1].size(), 8u);
  EXPECT_EQ(count_nonmanifold_edges(mesh.F), 0);
  EXPECT_EQ(count_nonmanifold_vertices(mesh.F, mesh.num_vertices()), 0);
  EXPECT_EQ(count_repeated_directed_edges(mesh.F), 0);
  EXPECT_EQ(connected_components(mesh.F, mesh.num_vertices()), 1);
  EXPECT_EQ(genus(mesh.F, mesh.num_vertices()), 0);
}

TEST(GeneratedMeshes, TwoTetrahedraAreTwoClosedComponents) {
  const TriMesh mesh = two_tetrahedra();
  EXPECT_EQ(connected_components(mesh.F, mesh.num_vertices()), 2);
  EXPECT_TRUE(boundary_loops(mesh.F).empty());
  EXPECT_EQ(count_nonmanifold_edges(mesh.F), 0);
  EXPECT_EQ(count_nonmanifold_vertices(mesh.F, mesh.num_vertices()), 0);
  EXPECT_EQ(count_repeated_directed_edges(mesh.F), 0);
  EXPECT_NEAR(signed_volume(mesh), 2.0 / 6.0, 1e-12);
}

TEST(GeneratedMeshes, NonmanifoldEdgeHasThreeFacesOnMembraneEdgesAndNoBoundary) {
  const TriMesh mesh = nonmanifold_edge();
  const EdgeMap map = build_edge_map(mesh.F);
  EXPECT_EQ((map.face_count.array() == 3).count(), 3);
  EXPECT_EQ((map.face_count.array() == 1).count(), 0);
  EXPECT_EQ((map.face_count.array() == 2).count(), map.num_edges() - 3);
  EXPECT_EQ(connected_components(mesh.F, mesh.num_vertices()), 1);
}

TEST(GeneratedMeshes, NonmanifoldVertexIsEdgeManifoldWithOneBadVertex) {
  const TriMesh mesh = nonmanifold_vertex();
  EXPECT_EQ(mesh.num_vertices(), 7);
  EXPECT_EQ(count_nonmanifold_edges(mesh.F), 0);
  EXPECT_TRUE(boundary_loops(mesh.F).empty());
  EXPECT_EQ(count_nonmanifold_vertices(mesh.F, mesh.num_vertices()), 1);
  EXPECT_EQ(count_repeated_directed_edges(mesh.F), 0);
  EXPECT_EQ(connected_components(mesh.F, mesh.num_vertices()), 1);
  EXPECT_NEAR(signed_volume(mesh), 2.0 / 6.0, 1e-12);
}

TEST(GeneratedMeshes, FlippedFaceTetrahedronIsClosedButInconsistentlyOriented) {
  const TriMesh mesh = flipped_face_tetrahedron();
  EXPECT_EQ(count_nonmanifold_edges(mesh.F), 0);
  EXPECT_EQ(count_nonmanifold_vertices(mesh.F, mesh.num_vertices()), 0);
  EXPECT_EQ(build_edge_map(mesh.F).num_edges(), 6);
  EXPECT_EQ(count_repeated_directed_edges(mesh.F), 3);
  EXPECT_EQ(connected_components(mesh.F, mesh.num_vertices()), 1);
}

}  // namespace
}  // namespace polycube::test
