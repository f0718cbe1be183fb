// The separated copy of a self-intersecting model (separate.h): no face pair intersects, the
// faces are the model's, only vertices round the crossings move, and points go back to the model.
#include "polycube/errors.h"
#include "polycube/separate.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace polycube {
namespace {

TEST(Separate, AModelThatDoesNotIntersectItselfIsLeftAsItIs) {
  const TriMesh model = test::load_test_mesh("knot.off");
  ASSERT_TRUE(self_intersecting_faces(model).empty());
  const Separation s = separate_self_intersections(model);
  EXPECT_EQ(s.pairs_before, 0);
  EXPECT_EQ(s.rounds, 0);
  EXPECT_EQ(s.moved_vertices, 0);
  EXPECT_TRUE(s.mesh.V == model.V);
  EXPECT_TRUE(s.mesh.F == model.F);
}

// CGAL's elk.off passes through itself in a few places (7 face pairs). The copy has none, the same
// faces, outward orientation and no zero-area face; the vertices that moved are few and near the
// crossings, and moved little.
TEST(Separate, ElksSurfaceComesApartWhereItPassesThroughItself) {
  const TriMesh model = test::load_test_mesh("elk.off");
  const std::vector<std::pair<int, int>> pairs = self_intersecting_faces(model);
  ASSERT_FALSE(pairs.empty()) << "elk.off no longer intersects itself: pick another mesh";
  const Separation s = separate_self_intersections(model);
  EXPECT_EQ(s.pairs_before, static_cast<int>(pairs.size()));
  EXPECT_GE(s.rounds, 1);
  EXPECT_TRUE(self_intersecting_faces(s.mesh).empty());
  EXPECT_TRUE(s.mesh.F == model.F);
  EXPECT_GT(signed_volume(s.mesh), 0);
  EXPECT_GT(face_areas(s.mesh).minCoeff(), 0);

  // Moved: only vertices within rings + rounds rings of the crossing faces' vertices.
  std::vector<char> near(model.num_vertices(), 0);
  for (const auto& [a, b] : pairs)
    for (int f : {a, b})
      for (int k = 0; k < 3; ++k) near[model.F(f, k)] = 1;
  for (int ring = 0; ring < SeparationOptions().rings + s.rounds; ++ring) {
    std::vector<char> grown = near;
    for (int f = 0; f < model.num_faces(); ++f)
      if (near[model.F(f, 0)] || near[model.F(f, 1)] || near[model.F(f, 2)])
        for (int k = 0; k < 3; ++k) grown[model.F(f, k)] = 1;
    near.swap(grown);
  }
  const double diagonal = bounding_box(model.V).diagonal();
  int moved = 0;
  double largest = 0;
  for (int v = 0; v < model.num_vertices(); ++v) {
    const double shift = (s.mesh.V.row(v) - model.V.row(v)).norm();
    if (shift == 0) continue;
    ++moved;
    largest = std::max(largest, shift / diagonal);
    EXPECT_TRUE(near[v]) << "vertex " << v << " moved far from every crossing";
  }
  EXPECT_EQ(moved, s.moved_vertices);
  EXPECT_LT(moved, model.num_vertices() / 10);
  EXPECT_DOUBLE_EQ(largest, s.max_shift);
  EXPECT_LT(s.max_shift, 0.02);
}

TEST(Separate, ItSaysSoWhenTheRoundsRunOut) {
  const TriMesh model = test::load_test_mesh("elk.off");
  SeparationOptions options;
  options.max_rounds = 0;
  EXPECT_THROW(separate_self_intersections(model, options), AlgorithmError);
}

// Points of the copy go to the same face and barycentric coordinates of the model: its vertices
// to the model's vertices, its face centroids to the model's.
TEST(Separate, PointsOnTheCopyGoBackToTheSamePlaceOfTheModel) {
  const TriMesh model = test::load_test_mesh("elk.off");
  const Separation s = separate_self_intersections(model);
  ASSERT_GT(s.moved_vertices, 0);
  const double tolerance = 1e-9 * bounding_box(model.V).diagonal();
  const Eigen::MatrixX3d vertices = to_original_surface(s.mesh, model, s.mesh.V);
  EXPECT_LT((vertices - model.V).rowwise().norm().maxCoeff(), tolerance);
  Eigen::MatrixX3d centroids(model.num_faces(), 3), expected(model.num_faces(), 3);
  for (int f = 0; f < model.num_faces(); ++f) {
    centroids.row(f) = (s.mesh.V.row(s.mesh.F(f, 0)) + s.mesh.V.row(s.mesh.F(f, 1)) + s.mesh.V.row(s.mesh.F(f, 2))) / 3;
    expected.row(f) = (model.V.row(model.F(f, 0)) + model.V.row(model.F(f, 1)) + model.V.row(model.F(f, 2))) / 3;
  }
  EXPECT_LT((to_original_surface(s.mesh, model, centroids) - expected).rowwise().norm().maxCoeff(), tolerance);
  TriMesh other = model;
  other.F.row(0) = other.F.row(0).reverse().eval();
  EXPECT_THROW(to_original_surface(s.mesh, other, s.mesh.V), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
