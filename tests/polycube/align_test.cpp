// Auto-orientation: principal axes of a known box, snapping of aligned models, and the candidate
// scoring keeps a valid winner.
#include "polycube/align.h"

#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace polycube {
namespace {

using namespace test;

// A box 4 x 2 x 1 as a closed triangle mesh (6 faces, 12 triangles), centred at c.
TriMesh box(const Eigen::Vector3d& c) {
  TriMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) m.V.row(i) = c.transpose() + Eigen::RowVector3d((i & 1 ? 2 : -2), (i & 2 ? 1 : -1), (i & 4 ? 0.5 : -0.5));
  m.F.resize(12, 3);
  m.F << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5;
  return m;
}

TEST(Align, PrincipalAxesOfATurnedBoxAreItsEdges) {
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const TriMesh turned = rotated(box(Eigen::Vector3d(3, -1, 2)), turn);
  const Eigen::Matrix3d axes = principal_axes(turned);
  EXPECT_NEAR(axes.determinant(), 1.0, 1e-12);
  // Longest spread first: the box's x edge (length 4), then y, then z, up to sign.
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(std::abs(axes.row(i).dot(turn.col(i))), 1.0, 1e-9) << "axis " << i;
}

TEST(Align, AlignedModelsAreNotTilted) {
  // A box turned by 2 degrees snaps back to the coordinate axes; by 20 degrees it does not.
  const Eigen::Matrix3d small = Eigen::AngleAxisd(2 * M_PI / 180, Eigen::Vector3d(0, 0, 1)).toRotationMatrix();
  const Eigen::Matrix3d axes = principal_axes(rotated(box(Eigen::Vector3d::Zero()), small));
  EXPECT_EQ((axes.cwiseAbs() - Eigen::Matrix3d::Identity()).norm(), 0.0);
  const Eigen::Matrix3d large = Eigen::AngleAxisd(20 * M_PI / 180, Eigen::Vector3d(0, 0, 1)).toRotationMatrix();
  EXPECT_GT((principal_axes(rotated(box(Eigen::Vector3d::Zero()), large)).cwiseAbs() - Eigen::Matrix3d::Identity()).norm(), 0.1);
}

TEST(Align, ChoosesTheCandidateWithFewestCorners) {
  const TriMesh model = load_test_mesh("knot.off");
  const Alignment a = choose_alignment(model, TopologyOptions{}, PolycubeOptions{});
  ASSERT_EQ(a.candidates.size(), 6u);
  ASSERT_GE(a.chosen, 0);
  for (const AlignmentCandidate& c : a.candidates) {
    EXPECT_NEAR(c.rotation.determinant(), 1.0, 1e-9) << c.name;
    if (c.corners >= 0) {
      EXPECT_GE(c.corners, a.candidates[a.chosen].corners) << c.name;
    }
  }
  ASSERT_TRUE(a.polycube);
  EXPECT_EQ(static_cast<int>(a.polycube->polycube.corners.size()), a.candidates[a.chosen].corners);
  EXPECT_EQ(a.polycube->genus, 1);
  EXPECT_EQ(a.rotation, a.candidates[a.chosen].rotation);
}

}  // namespace
}  // namespace polycube
