// max_min_affine: the point where the smallest of a few affine functions of the plane is largest.
#include "polycube/max_min_affine.h"

#include <gtest/gtest.h>

#include <cmath>

namespace polycube {
namespace {

// Twice the signed areas of the triangles (q, p_k, p_k+1) round a regular hexagon whose centre is
// at c: largest, and all equal, at q = c.
TEST(MaxMinAffine, FindsTheCentreOfARegularFan) {
  const Eigen::Vector2d c(0.3, -0.2);
  std::vector<double> a;
  std::vector<Eigen::Vector2d> g;
  for (int k = 0; k < 6; ++k) {
    const Eigen::Vector2d u = c + Eigen::Vector2d(std::cos(k * M_PI / 3), std::sin(k * M_PI / 3));
    const Eigen::Vector2d w = c + Eigen::Vector2d(std::cos((k + 1) * M_PI / 3), std::sin((k + 1) * M_PI / 3));
    a.push_back(u.x() * w.y() - u.y() * w.x());
    g.emplace_back(u.y() - w.y(), w.x() - u.x());
  }
  const MaxMinPoint best = max_min_affine(a, g);
  EXPECT_NEAR((best.q - c).norm(), 0, 1e-12);
  EXPECT_NEAR(best.value, std::sin(M_PI / 3), 1e-12);  // twice the area of one unit triangle
  // Bounded by a square that does not reach the centre: the best point lies on its boundary,
  // as close to the centre as the square allows along the binding functions.
  const MaxMinPoint bounded = max_min_affine(a, g, 0.1);
  EXPECT_LE(bounded.q.cwiseAbs().maxCoeff(), 0.1 + 1e-12);
  EXPECT_GT(bounded.value, max_min_affine(a, g, 0.05).value);
  EXPECT_LT(bounded.value, best.value);
}

// One increasing function alone: unbounded in the plane (no vertex: q = 0 is returned), at the
// square's far corner when bounded.
TEST(MaxMinAffine, ASingleFunctionGoesToTheSquaresCorner) {
  const MaxMinPoint best = max_min_affine({1.0}, {Eigen::Vector2d(1, 2)}, 0.5);
  EXPECT_EQ(best.q, Eigen::Vector2d(0.5, 0.5));
  EXPECT_DOUBLE_EQ(best.value, 2.5);
  EXPECT_EQ(max_min_affine({1.0}, {Eigen::Vector2d(1, 2)}).q, Eigen::Vector2d::Zero());
}

}  // namespace
}  // namespace polycube
