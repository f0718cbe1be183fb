// Tetrahedralization must fill exactly the solid bounded by the surface: same volume, positively
// oriented tets, the surface itself as boundary, and clean errors for inputs TetGen cannot take.
#include "applications/hex/tetrahedralize.h"

#include "polycube/errors.h"
#include "polycube/mesh.h"
#include "support/generated_meshes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <stdexcept>

namespace polycube {
namespace {

using Triangle = std::array<int, 3>;

// Same cyclic order, smallest index first: equal for equally oriented copies of a triangle.
Triangle canonical_rotation(Triangle t) {
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

double tet_volume(const TetMesh& mesh, int t) {
  const Eigen::Vector3d a = mesh.V.row(mesh.T(t, 0)), b = mesh.V.row(mesh.T(t, 1)), c = mesh.V.row(mesh.T(t, 2)),
                        d = mesh.V.row(mesh.T(t, 3));
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

// Faces used by exactly one tet, oriented outward (away from that tet).
std::set<Triangle> boundary_faces(const TetMesh& mesh) {
  std::map<Triangle, std::pair<int, Triangle>> faces;  // sorted key -> (count, oriented face)
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const int a = mesh.T(t, 0), b = mesh.T(t, 1), c = mesh.T(t, 2), d = mesh.T(t, 3);
    for (const Triangle& face : {Triangle{a, c, b}, Triangle{a, b, d}, Triangle{a, d, c}, Triangle{b, c, d}}) {
      Triangle key = face;
      std::sort(key.begin(), key.end());
      auto& entry = faces[key];
      ++entry.first;
      entry.second = face;
    }
  }
  std::set<Triangle> boundary;
  for (const auto& [key, entry] : faces) {
    EXPECT_LE(entry.first, 2) << "face shared by more than two tets";
    if (entry.first == 1) boundary.insert(canonical_rotation(entry.second));
  }
  return boundary;
}

void expect_fills_surface(const TriMesh& surface, const TetMesh& tets) {
  ASSERT_GE(tets.num_vertices(), surface.num_vertices());
  ASSERT_GT(tets.num_tets(), 0);
  EXPECT_EQ(tets.V.topRows(surface.num_vertices()), surface.V);
  EXPECT_GE(tets.T.minCoeff(), 0);
  EXPECT_LT(tets.T.maxCoeff(), tets.num_vertices());

  double total = 0, smallest = 1e300;
  for (int t = 0; t < tets.num_tets(); ++t) {
    const double v = tet_volume(tets, t);
    total += v;
    smallest = std::min(smallest, v);
  }
  EXPECT_GT(smallest, 0);
  const double expected = signed_volume(surface);
  EXPECT_NEAR(total, expected, 1e-9 * std::abs(expected));

  std::set<Triangle> input;
  for (int f = 0; f < surface.num_faces(); ++f)
    input.insert(canonical_rotation({surface.F(f, 0), surface.F(f, 1), surface.F(f, 2)}));
  EXPECT_TRUE(boundary_faces(tets) == input) << "boundary of the tet mesh differs from the input surface";
}

TEST(Tetrahedralize, SphereIsFilledExactly) {
  const TriMesh sphere = test::make_sphere(2);
  expect_fills_surface(sphere, tetrahedralize(sphere));
}

TEST(Tetrahedralize, TorusIsFilledExactly) {
  const TriMesh torus = test::make_torus(2.0, 0.7, 32, 16);
  expect_fills_surface(torus, tetrahedralize(torus));
}

TEST(Tetrahedralize, GenusTwoSurfaceIsFilledExactly) {
  const TriMesh surface = test::make_genus_surface(2, 24);
  expect_fills_surface(surface, tetrahedralize(surface));
}

TEST(Tetrahedralize, VolumeBoundRefinesInterior) {
  const TriMesh sphere = test::make_sphere(2);
  const TetMesh coarse = tetrahedralize(sphere);
  TetrahedralizeOptions options;
  options.max_volume = 0.002;
  const TetMesh fine = tetrahedralize(sphere, options);
  expect_fills_surface(sphere, fine);
  EXPECT_GT(fine.num_tets(), coarse.num_tets());
  // The surface is never split, so tets with a surface vertex may exceed the bound; all others
  // must meet it, and the largest tet shrinks.
  double largest_fine = 0, largest_coarse = 0;
  for (int t = 0; t < fine.num_tets(); ++t) {
    largest_fine = std::max(largest_fine, tet_volume(fine, t));
    if ((fine.T.row(t).array() >= sphere.num_vertices()).all()) {
      EXPECT_LE(tet_volume(fine, t), options.max_volume * (1 + 1e-9));
    }
  }
  for (int t = 0; t < coarse.num_tets(); ++t) largest_coarse = std::max(largest_coarse, tet_volume(coarse, t));
  EXPECT_LT(largest_fine, 0.5 * largest_coarse);
}

TEST(Tetrahedralize, WithoutQualityRefinementStillFillsSurface) {
  const TriMesh torus = test::make_torus(2.0, 0.7, 24, 12);
  TetrahedralizeOptions options;
  options.min_ratio = 0;
  expect_fills_surface(torus, tetrahedralize(torus, options));
}

TEST(Tetrahedralize, SurvivesExtremeScales) {
  for (const double scale : {1e-6, 1e6}) {
    SCOPED_TRACE(scale);
    TriMesh sphere = test::make_sphere(1);
    sphere.V *= scale;
    expect_fills_surface(sphere, tetrahedralize(sphere));
  }
}

TEST(Tetrahedralize, SelfIntersectingSurfaceIsAlgorithmError) {
  // Two closed tetrahedra that pierce each other.
  TriMesh mesh = test::two_tetrahedra();
  mesh.V.bottomRows(4) = mesh.V.topRows(4).rowwise() + Eigen::RowVector3d(0.2, 0.15, 0.1);
  try {
    tetrahedralize(mesh);
    ADD_FAILURE() << "self-intersecting input was accepted";
  } catch (const AlgorithmError& e) {
    EXPECT_NE(std::string(e.what()).find("intersect"), std::string::npos) << e.what();
  }
}

TEST(Tetrahedralize, OpenOrBrokenSurfaceIsMeshError) {
  EXPECT_THROW(tetrahedralize(test::open_cylinder()), MeshError);
  EXPECT_THROW(tetrahedralize(test::nonmanifold_edge()), MeshError);
  EXPECT_THROW(tetrahedralize(TriMesh{}), MeshError);
  TriMesh bad_index = test::make_sphere(0);
  bad_index.F(0, 0) = 99;
  EXPECT_THROW(tetrahedralize(bad_index), MeshError);
}

TEST(Tetrahedralize, DegenerateFaceAndDuplicateVertexAreMeshErrors) {
  TriMesh flat = test::make_sphere(1);
  flat.V.row(flat.F(0, 2)) = 0.5 * (flat.V.row(flat.F(0, 0)) + flat.V.row(flat.F(0, 1)));
  EXPECT_THROW(tetrahedralize(flat), MeshError);
  TriMesh doubled = test::make_sphere(1);
  doubled.V.row(5) = doubled.V.row(17);
  EXPECT_THROW(tetrahedralize(doubled), MeshError);
}

TEST(Tetrahedralize, BadOptionsAreRejected) {
  TetrahedralizeOptions options;
  options.min_ratio = 0.5;
  EXPECT_THROW(tetrahedralize(test::make_sphere(1), options), std::invalid_argument);
  options = {};
  options.max_volume = -1;
  EXPECT_THROW(tetrahedralize(test::make_sphere(1), options), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
