// Catmull–Clark refinement: the counts every level must have, topology preserved, geometry
// shrinking and symmetric on a cube, boundaries interpolated at corners, clean input errors.
#include "applications/tspline/subdivision.h"

#include "polycube/errors.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

namespace polycube {
namespace {

constexpr double kPi = 3.14159265358979323846;

PolyMesh cube() {
  PolyMesh mesh;
  mesh.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) mesh.V.row(i) << (i & 1 ? 1 : -1), (i & 2 ? 1 : -1), (i & 4 ? 1 : -1);
  // Counter-clockwise seen from outside.
  mesh.faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  return mesh;
}

// Quad torus around the z axis, n segments around the axis and m around the tube.
PolyMesh torus(int n, int m) {
  PolyMesh mesh;
  mesh.V.resize(n * m, 3);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i) {
      const double u = 2 * kPi * i / n, v = 2 * kPi * j / m;
      mesh.V.row(i + n * j) << (2 + 0.7 * std::cos(v)) * std::cos(u), (2 + 0.7 * std::cos(v)) * std::sin(u),
          0.7 * std::sin(v);
    }
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i)
      mesh.faces.push_back({i + n * j, (i + 1) % n + n * j, (i + 1) % n + n * ((j + 1) % m), i + n * ((j + 1) % m)});
  return mesh;
}

// Undirected edges with the number of faces on each.
std::map<std::pair<int, int>, int> edge_counts(const PolyMesh& mesh) {
  std::map<std::pair<int, int>, int> edges;
  for (const auto& face : mesh.faces)
    for (size_t k = 0; k < face.size(); ++k) {
      const int a = face[k], b = face[(k + 1) % face.size()];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  return edges;
}

int euler_characteristic(const PolyMesh& mesh) {
  return mesh.num_vertices() - static_cast<int>(edge_counts(mesh).size()) + mesh.num_faces();
}

bool all_quads(const PolyMesh& mesh) {
  return std::all_of(mesh.faces.begin(), mesh.faces.end(), [](const auto& f) { return f.size() == 4; });
}

// Enclosed volume by the divergence theorem over fan triangles: positive if faces point outward.
double signed_volume(const PolyMesh& mesh) {
  double volume = 0;
  for (const auto& face : mesh.faces)
    for (size_t k = 1; k + 1 < face.size(); ++k) {
      const Eigen::Vector3d a = mesh.V.row(face[0]), b = mesh.V.row(face[k]), c = mesh.V.row(face[k + 1]);
      volume += a.dot(b.cross(c)) / 6.0;
    }
  return volume;
}

// Distance from p to the nearest vertex of mesh.
double nearest_vertex_distance(const PolyMesh& mesh, const Eigen::Vector3d& p) {
  return (mesh.V.rowwise() - p.transpose()).rowwise().norm().minCoeff();
}

TEST(Subdivision, CubeCountsPerLevel) {
  const PolyMesh one = subdivide_catmull_clark(cube(), 1);
  EXPECT_EQ(one.num_vertices(), 26);
  EXPECT_EQ(one.num_faces(), 24);
  EXPECT_TRUE(all_quads(one));
  const PolyMesh two = subdivide_catmull_clark(cube(), 2);
  EXPECT_EQ(two.num_vertices(), 98);
  EXPECT_EQ(two.num_faces(), 96);
  EXPECT_TRUE(all_quads(two));
}

TEST(Subdivision, CubeShrinksStaysSymmetricClosedAndOutward) {
  for (int levels = 1; levels <= 3; ++levels) {
    SCOPED_TRACE(levels);
    // Refined points: the face points of level 1 stay on the cube's faces, nothing goes outside.
    EXPECT_LE(subdivide_catmull_clark(cube(), levels).V.cwiseAbs().maxCoeff(), 1.0);
    // The limit surface lies strictly inside.
    const PolyMesh refined = subdivide_catmull_clark(cube(), levels, /*limit_positions=*/true);
    EXPECT_LT(refined.V.cwiseAbs().maxCoeff(), 1.0);
    EXPECT_GT(refined.V.cwiseAbs().maxCoeff(), 0.5);
    // Invariant under mirroring in each coordinate plane and under swapping coordinates.
    for (int v = 0; v < refined.num_vertices(); ++v) {
      const Eigen::Vector3d p = refined.V.row(v);
      for (int d = 0; d < 3; ++d) {
        Eigen::Vector3d mirrored = p;
        mirrored[d] = -mirrored[d];
        EXPECT_LT(nearest_vertex_distance(refined, mirrored), 1e-12);
      }
      EXPECT_LT(nearest_vertex_distance(refined, Eigen::Vector3d(p.y(), p.z(), p.x())), 1e-12);
    }
    EXPECT_EQ(euler_characteristic(refined), 2);
    for (const auto& [edge, count] : edge_counts(refined)) EXPECT_EQ(count, 2);
    EXPECT_GT(signed_volume(refined), 0);
    EXPECT_LT(signed_volume(refined), 8.0);
  }
}

TEST(Subdivision, TorusKeepsEulerCharacteristicZero) {
  const PolyMesh control = torus(8, 6);
  ASSERT_EQ(euler_characteristic(control), 0);
  for (int levels = 1; levels <= 3; ++levels) {
    SCOPED_TRACE(levels);
    const PolyMesh refined = subdivide_catmull_clark(control, levels);
    EXPECT_EQ(refined.num_faces(), control.num_faces() << (2 * levels));
    EXPECT_TRUE(all_quads(refined));
    EXPECT_EQ(euler_characteristic(refined), 0);
    for (const auto& [edge, count] : edge_counts(refined)) EXPECT_EQ(count, 2);
    EXPECT_GT(signed_volume(refined), 0);
  }
}

TEST(Subdivision, TrianglesAndPentagonsBecomeQuads) {
  // Square pyramid: one quad and four triangles.
  PolyMesh pyramid;
  pyramid.V.resize(5, 3);
  pyramid.V << -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0, 0, 0, 1.5;
  pyramid.faces = {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  const PolyMesh refined = subdivide_catmull_clark(pyramid, 1);
  // Each n-gon gives n quads; vertices: 5 + 8 edges + 5 faces.
  EXPECT_EQ(refined.num_faces(), 4 + 4 * 3);
  EXPECT_EQ(refined.num_vertices(), 5 + 8 + 5);
  EXPECT_TRUE(all_quads(refined));
  EXPECT_EQ(euler_characteristic(refined), 2);
}

TEST(Subdivision, BoundaryCornersAreInterpolated) {
  // Open 2x2 grid of quads in the plane z = 0.
  PolyMesh grid;
  grid.V.resize(9, 3);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) grid.V.row(i + 3 * j) << i, j, 0;
  grid.faces = {{0, 1, 4, 3}, {1, 2, 5, 4}, {3, 4, 7, 6}, {4, 5, 8, 7}};
  const PolyMesh refined = subdivide_catmull_clark(grid, 2);
  EXPECT_EQ(refined.num_faces(), 64);
  EXPECT_EQ(euler_characteristic(refined), 1);
  for (const int corner : {0, 2, 6, 8}) EXPECT_LT(nearest_vertex_distance(refined, grid.V.row(corner)), 1e-12);
  EXPECT_LT(refined.V.col(2).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Subdivision, LimitPositionsConvergeWithLevels) {
  // Limit points of a coarser level are limit points of every finer level too: the vertices
  // of level 1 keep their indices at level 3 (vertex-vertices come last in each level, so look
  // them up by position instead).
  const PolyMesh one = subdivide_catmull_clark(torus(8, 6), 1, true);
  const PolyMesh three = subdivide_catmull_clark(torus(8, 6), 3, true);
  for (int v = 0; v < one.num_vertices(); ++v) EXPECT_LT(nearest_vertex_distance(three, one.V.row(v)), 1e-9);
}

TEST(Subdivision, ZeroLevelsReturnsControl) {
  const PolyMesh control = cube();
  const PolyMesh same = subdivide_catmull_clark(control, 0);
  EXPECT_EQ(same.V, control.V);
  EXPECT_EQ(same.faces, control.faces);
}

TEST(Subdivision, InvalidInputIsRejected) {
  PolyMesh bad = cube();
  bad.faces[2] = {0, 1};
  EXPECT_THROW(subdivide_catmull_clark(bad, 1), MeshError);
  bad = cube();
  bad.faces[0][1] = 8;
  EXPECT_THROW(subdivide_catmull_clark(bad, 1), MeshError);
  EXPECT_THROW(subdivide_catmull_clark(PolyMesh{}, 1), MeshError);
  EXPECT_THROW(subdivide_catmull_clark(cube(), -1), std::invalid_argument);
  EXPECT_THROW(subdivide_catmull_clark(cube(), 11), std::invalid_argument);
  EXPECT_THROW(subdivide_catmull_clark(cube(), 0, /*limit_positions=*/true), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
