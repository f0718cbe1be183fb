// cutting_planes (§3.2): a plane between every two critical levels, no gap wider than dz, no
// plane at a vertex height, all in normalised units so scale and position do not matter.
#include "polycube/cutting_planes.h"

#include "formats/mesh_io.h"
#include "polycube/errors.h"
#include "polycube/harmonic_function.h"
#include "polycube/validate.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace polycube {
namespace {

CriticalPoints harmonic_critical_points(const TriMesh& mesh) {
  const HarmonicFunction h = harmonic_function(mesh);
  CriticalPointOptions options;
  options.cancel_extra_extrema = true;
  options.keep_minimum = h.source;
  options.keep_maximum = h.sink;
  return critical_points(h.intrinsic, h.f, options);
}

std::vector<double> critical_heights(const TriMesh& mesh, const CriticalPoints& c) {
  std::vector<double> z;
  for (const auto* list : {&c.minima, &c.saddles, &c.maxima})
    for (int v : *list) z.push_back(mesh.V(v, 2));
  std::sort(z.begin(), z.end());
  return z;
}

void expect_valid_planes(const TriMesh& mesh, const CriticalPoints& c, const CuttingPlanes& planes,
                         const CuttingPlaneOptions& options) {
  const BoundingBox box = bounding_box(mesh.V);
  const double extent = box.extent().maxCoeff(), height = box.extent().z();
  ASSERT_EQ(planes.z.size(), planes.z_normalised.size());
  ASSERT_FALSE(planes.z.empty());
  for (size_t k = 0; k < planes.z.size(); ++k) {
    EXPECT_GT(planes.z[k], box.min.z());
    EXPECT_LT(planes.z[k], box.max.z());
    if (k > 0) {
      EXPECT_GT(planes.z[k], planes.z[k - 1]);
    }
    EXPECT_NEAR(planes.z_normalised[k], (planes.z[k] - box.min.z()) / extent, 1e-12);
    for (int v = 0; v < mesh.num_vertices(); ++v) ASSERT_NE(mesh.V(v, 2), planes.z[k]) << "plane through vertex " << v;
  }
  // No gap wider than dz, ends included.
  std::vector<double> bounds = {box.min.z()};
  bounds.insert(bounds.end(), planes.z.begin(), planes.z.end());
  bounds.push_back(box.max.z());
  for (size_t k = 0; k + 1 < bounds.size(); ++k) EXPECT_LE(bounds[k + 1] - bounds[k], options.dz * extent * (1 + 1e-12));
  // Every two consecutive critical heights farther apart than the level tolerance have a plane
  // between them.
  const std::vector<double> z = critical_heights(mesh, c);
  for (size_t k = 0; k + 1 < z.size(); ++k) {
    if (z[k + 1] - z[k] <= options.level_merge * height) continue;
    const bool separated = std::any_of(planes.z.begin(), planes.z.end(), [&](double p) { return p > z[k] && p < z[k + 1]; });
    EXPECT_TRUE(separated) << "no plane between critical heights " << z[k] << " and " << z[k + 1];
  }
  EXPECT_EQ(static_cast<int>(planes.z.size()), planes.level_planes + planes.spacing_planes + planes.girth_planes);
}

TEST(CuttingPlanes, SeparateCriticalLevelsAndRespectDz) {
  for (const std::string name : {"sphere.off", "rotor.off", "joint.off", "helmet.off", "anchor.off", "couplingdown.off"}) {
    SCOPED_TRACE(name);
    const TriMesh mesh = test::load_test_mesh(name);
    const CriticalPoints c = harmonic_critical_points(mesh);
    for (double dz : {0.08, 0.03, 0.5}) {
      CuttingPlaneOptions options;
      options.dz = dz;
      expect_valid_planes(mesh, c, cutting_planes(mesh, c, options), options);
    }
  }
}

TEST(CuttingPlanes, SphereGetsOneLevelPlaneAndSmallerDzGivesMorePlanes) {
  const TriMesh sphere = test::make_sphere(3);
  const CriticalPoints c = harmonic_critical_points(sphere);
  const CuttingPlanes coarse = cutting_planes(sphere, c);
  EXPECT_EQ(coarse.levels, 2);
  EXPECT_EQ(coarse.level_planes, 1);
  CuttingPlaneOptions fine;
  fine.dz = 0.02;
  EXPECT_GT(cutting_planes(sphere, c, fine).z.size(), coarse.z.size());
  CuttingPlaneOptions paper;  // §3.2 as written: only gaps between planes are subdivided
  paper.split_end_gaps = false;
  paper.dz = 10;
  EXPECT_EQ(cutting_planes(sphere, c, paper).z.size(), 1u);
}

TEST(CuttingPlanes, CloseCriticalPointsShareALevel) {
  // Two saddles of an upright torus, and a level tolerance wider than their distance.
  // Axis along y: the top and bottom of the hole (z = +-0.2 of a height 3.6) are the saddles.
  TriMesh torus = test::make_torus(1.0, 0.8, 32, 16);
  const Eigen::VectorXd y = torus.V.col(1);
  torus.V.col(1) = -torus.V.col(2);
  torus.V.col(2) = y;
  const CriticalPoints c = harmonic_critical_points(torus);
  ASSERT_EQ(c.saddle_count(), 2);
  CuttingPlaneOptions separate;
  separate.dz = 10;
  separate.split_end_gaps = false;
  EXPECT_EQ(cutting_planes(torus, c, separate).levels, 4);
  CuttingPlaneOptions merged = separate;
  merged.level_merge = 0.2;  // the saddles are 0.11 of the height apart, the extrema 0.44 away
  const CuttingPlanes planes = cutting_planes(torus, c, merged);
  EXPECT_EQ(planes.levels, 3);
  EXPECT_EQ(planes.level_planes, 2);
}

TEST(CuttingPlanes, NormalisedPlanesUnchangedUnderScalingAndTranslation) {
  const TriMesh mesh = test::load_test_mesh("anchor.off");
  const CriticalPoints c = harmonic_critical_points(mesh);
  const CuttingPlanes reference = cutting_planes(mesh, c);
  for (double scale : {1e-6, 1e6}) {
    TriMesh moved = mesh;
    moved.V = (mesh.V * scale).rowwise() + Eigen::RowVector3d(5, -7, 11) * scale;
    const CuttingPlanes planes = cutting_planes(moved, c);
    ASSERT_EQ(planes.z.size(), reference.z.size());
    for (size_t k = 0; k < planes.z.size(); ++k)
      EXPECT_NEAR(planes.z_normalised[k], reference.z_normalised[k], 1e-9);
  }
}

// The contour of a tube's level set is the polygon of its rings (the crossings lie on the chords
// between ring vertices); a plane beside the mesh meets nothing.
TEST(CuttingPlanes, LongestContourOfATubeIsItsPolygon) {
  const int n = 32;
  const TriMesh tube = test::make_tube(0.5, 2, n, 8);
  const double perimeter = 2 * n * 0.5 * std::sin(M_PI / n);
  const std::vector<double> lengths = longest_contours(tube, {-1, 0.3, 1.1, 3});
  ASSERT_EQ(lengths.size(), 4u);
  EXPECT_EQ(lengths[0], 0);
  EXPECT_NEAR(lengths[1], perimeter, 1e-12);
  EXPECT_NEAR(lengths[2], perimeter, 1e-12);
  EXPECT_EQ(lengths[3], 0);
  // Two tubes side by side: the longer contour counts.
  TriMesh both = tube;
  const TriMesh thin = test::make_tube(0.1, 2, n, 8);
  both.V.resize(tube.V.rows() + thin.V.rows(), 3);
  both.V << tube.V, thin.V.rowwise() + Eigen::RowVector3d(3, 0, 0);
  both.F.resize(tube.F.rows() + thin.F.rows(), 3);
  both.F << tube.F, thin.F.array() + static_cast<int>(tube.V.rows());
  EXPECT_NEAR(longest_contours(both, {0.7})[0], perimeter, 1e-12);
}

// A rod 1000 times as long as it is wide gets planes along its length until no gap is longer
// than girth_ratio times the section's contour; a thick one, or the rule turned off, gets none.
TEST(CuttingPlanes, AThinRodGetsPlanesAlongItsLength) {
  const TriMesh rod = test::make_rod(0.001, 1, 24);
  const CriticalPoints c = harmonic_critical_points(rod);
  const CuttingPlaneOptions options;
  const CuttingPlanes planes = cutting_planes(rod, c, options);
  EXPECT_GT(planes.girth_planes, 100);
  EXPECT_EQ(static_cast<int>(planes.z.size()), planes.level_planes + planes.spacing_planes + planes.girth_planes);
  const std::vector<double> lengths = longest_contours(rod, planes.z);
  std::vector<double> bounds = {0};
  bounds.insert(bounds.end(), planes.z.begin(), planes.z.end());
  bounds.push_back(1);
  for (size_t k = 0; k + 1 < bounds.size(); ++k) {
    const double girth = std::max(k > 0 ? lengths[k - 1] : 0.0, k < planes.z.size() ? lengths[k] : 0.0);
    EXPECT_LE(bounds[k + 1] - bounds[k], options.girth_ratio * girth) << "gap " << k;
  }
  for (int v = 0; v < rod.num_vertices(); ++v)
    for (double z : planes.z) ASSERT_NE(rod.V(v, 2), z);

  CuttingPlaneOptions off;
  off.girth_ratio = 0;
  const CuttingPlanes without = cutting_planes(rod, c, off);
  EXPECT_EQ(without.girth_planes, 0);
  EXPECT_EQ(without.z.size(), static_cast<size_t>(without.level_planes + without.spacing_planes));
  EXPECT_LT(without.z.size(), 20u);

  const TriMesh thick = test::make_rod(0.2, 1, 24);
  EXPECT_EQ(cutting_planes(thick, harmonic_critical_points(thick), options).girth_planes, 0);

  // A rod of a hair's width asks for more planes than an int holds: capped, all distinct.
  CuttingPlaneOptions capped;
  capped.girth_max_planes = 50;
  const TriMesh hair = test::make_rod(1e-200, 1, 8);
  const CuttingPlanes few = cutting_planes(hair, CriticalPoints{}, capped);
  EXPECT_GT(few.girth_planes, 0);
  EXPECT_LE(few.girth_planes, 50);
  EXPECT_EQ(static_cast<int>(few.z.size()), few.level_planes + few.spacing_planes + few.girth_planes);
}

// A copy of that rod scaled towards equal spreads (map --equalise-axes): measured on the copy its
// slabs are short against their sections and the rule adds nothing; told the copy's scales, it
// measures on the rod and places the rod's planes, scaled.
TEST(CuttingPlanes, AScaledCopyGetsTheGirthPlanesOfItsModel) {
  const TriMesh rod = test::make_rod(0.001, 1, 24);
  const Eigen::Vector3d scales(10, 10, 0.01);
  TriMesh copy = rod;
  copy.V = rod.V * scales.asDiagonal();
  const CriticalPoints c = harmonic_critical_points(rod);
  // (d_z, a fraction of the largest side, is left out: the copy's largest side is its diameter.)
  CuttingPlaneOptions options;
  options.dz = 1;
  const CuttingPlanes planes = cutting_planes(rod, c, options);
  ASSERT_GT(planes.girth_planes, 100);
  EXPECT_EQ(cutting_planes(copy, c, options).girth_planes, 0);
  CuttingPlaneOptions measured_on_rod = options;
  measured_on_rod.length_scales = scales;
  const CuttingPlanes on_copy = cutting_planes(copy, c, measured_on_rod);
  EXPECT_EQ(on_copy.girth_planes, planes.girth_planes);
  ASSERT_EQ(on_copy.z.size(), planes.z.size());
  for (size_t k = 0; k < planes.z.size(); ++k) EXPECT_NEAR(on_copy.z[k], planes.z[k] * scales(2), 1e-12) << "plane " << k;
}

TEST(CuttingPlanes, RejectsBadOptions) {
  const TriMesh sphere = test::make_sphere(1);
  const CriticalPoints c = harmonic_critical_points(sphere);
  CuttingPlaneOptions options;
  options.dz = 0;
  EXPECT_THROW(cutting_planes(sphere, c, options), std::invalid_argument);
  options.dz = 0.08;
  options.level_merge = -1;
  EXPECT_THROW(cutting_planes(sphere, c, options), std::invalid_argument);
  options.level_merge = 0.01;
  options.girth_ratio = -1;
  EXPECT_THROW(cutting_planes(sphere, c, options), std::invalid_argument);
  options.girth_ratio = 4;
  options.girth_spacing = 0;
  EXPECT_THROW(cutting_planes(sphere, c, options), std::invalid_argument);
  options.girth_spacing = 1;
  options.length_scales = Eigen::Vector3d(1, 0, 1);
  EXPECT_THROW(cutting_planes(sphere, c, options), std::invalid_argument);
  TriMesh flat = sphere;
  flat.V.col(2).setZero();
  EXPECT_THROW(cutting_planes(flat, c), MeshError);
}

}  // namespace
}  // namespace polycube
