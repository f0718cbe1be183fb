// smooth_map (§3.5): on the test meshes, smoothing never flips more image triangles in either
// direction than the input map (judged by the independent audit), keeps every image on the other
// surface, lowers the angle distortion, and does not depend on the number of threads.
#include "polycube/map_smoothing.h"

#include "polycube/map_audit.h"
#include "polycube/polycube_build.h"
#include "polycube/polycube_map.h"
#include "polycube/topology.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <stdexcept>
#include <string>

namespace polycube {
namespace {

using namespace test;

using Pipeline = MappedModel;
const Pipeline& pipeline(const std::string& name) { return mapped_model(name); }

int bad(const MapDirectionAudit& a) { return a.flipped + a.degenerate; }

class MapSmoothingOnMeshes : public ::testing::TestWithParam<std::string> {};

TEST_P(MapSmoothingOnMeshes, NoNewFlipsImagesOnSurfacesLowerAngleDistortion) {
  const std::string name = GetParam();
  const Pipeline& p = pipeline(name);
  const TriMesh& P = p.polycube.polycube.mesh;
  const MapSmoothingResult r = smooth_map(p.model, p.polycube.polycube, p.map);

  ASSERT_EQ(r.polycube_on_model.size(), static_cast<size_t>(P.num_vertices()));
  ASSERT_EQ(r.model_on_polycube.size(), static_cast<size_t>(p.model.num_vertices()));
  ASSERT_EQ(r.polycube_on_model_xyz.rows(), P.num_vertices());
  ASSERT_EQ(r.model_on_polycube_xyz.rows(), p.model.num_vertices());
  // The surface points and the positions say the same.
  for (int v = 0; v < P.num_vertices(); ++v) {
    ASSERT_GE(r.polycube_on_model[v].face, 0);
    ASSERT_LT(r.polycube_on_model[v].face, p.model.num_faces());
    EXPECT_NEAR(r.polycube_on_model[v].bary.sum(), 1.0, 1e-12);
    EXPECT_GE(r.polycube_on_model[v].bary.minCoeff(), 0.0);
    EXPECT_LT((surface_position(p.model, r.polycube_on_model[v]).transpose() - r.polycube_on_model_xyz.row(v)).norm(), 1e-12);
  }
  for (int w = 0; w < p.model.num_vertices(); ++w) {
    ASSERT_GE(r.model_on_polycube[w].face, 0);
    ASSERT_LT(r.model_on_polycube[w].face, P.num_faces());
    EXPECT_NEAR(r.model_on_polycube[w].bary.sum(), 1.0, 1e-12);
    EXPECT_GE(r.model_on_polycube[w].bary.minCoeff(), 0.0);
  }

  const MapAudit before = audit_map(p.model, P, p.map.polycube_on_model_xyz, p.map.model_on_polycube_xyz);
  const MapAudit after = audit_map(p.model, P, r.polycube_on_model_xyz, r.model_on_polycube_xyz);
  // Never more flipped (or degenerate) image triangles than the input, in either direction.
  EXPECT_LE(bad(after.polycube_to_model), bad(before.polycube_to_model)) << name;
  EXPECT_LE(bad(after.model_to_polycube), bad(before.model_to_polycube)) << name;
  // The result reports the audit's counts.
  EXPECT_EQ(r.flipped_before[0], bad(before.polycube_to_model)) << name;
  EXPECT_EQ(r.flipped_before[1], bad(before.model_to_polycube)) << name;
  EXPECT_EQ(r.flipped_after[0], bad(after.polycube_to_model)) << name;
  EXPECT_EQ(r.flipped_after[1], bad(after.model_to_polycube)) << name;
  // Images on the other surface, to rounding.
  EXPECT_LT(after.polycube_to_model.max_distance, 1e-9) << name;
  EXPECT_LT(after.model_to_polycube.max_distance, 1e-9) << name;
  // Smoother: lower angle distortion.
  EXPECT_LT(after.distortion.eps_angle, before.distortion.eps_angle) << name;
  EXPECT_GE(after.distortion.eps_angle, 1.0) << name;
  EXPECT_GT(r.moves, 0) << name;
  EXPECT_GE(r.rounds, 1) << name;
  EXPECT_GT(r.seconds, 0) << name;
}

INSTANTIATE_TEST_SUITE_P(Meshes, MapSmoothingOnMeshes,
                         ::testing::Values("sphere.off", "eight.off", "knot.off", "helmet.off", "double-torus-example.off", "rocker-arm.obj",
                                           "generated-genus-5"),
                         [](const auto& info) { return test::test_name_of_file(info.param); });

// Every closed mesh of tests/data, the coarse and tangled ones included (where the guard may keep
// much of the input): no direction gets worse, images stay on the surfaces, the angle distortion
// does not grow.
TEST(MapSmoothing, NeverWorseOnAnyClosedTestMesh) {
  for (const auto& [name, genus] : closed_test_meshes()) {
    const Pipeline& p = pipeline(name);
    const TriMesh& P = p.polycube.polycube.mesh;
    const MapSmoothingResult r = smooth_map(p.model, p.polycube.polycube, p.map);
    const MapAudit before = audit_map(p.model, P, p.map.polycube_on_model_xyz, p.map.model_on_polycube_xyz);
    const MapAudit after = audit_map(p.model, P, r.polycube_on_model_xyz, r.model_on_polycube_xyz);
    EXPECT_LE(bad(after.polycube_to_model), bad(before.polycube_to_model)) << name;
    EXPECT_LE(bad(after.model_to_polycube), bad(before.model_to_polycube)) << name;
    EXPECT_LT(after.polycube_to_model.max_distance, 1e-9) << name;
    EXPECT_LT(after.model_to_polycube.max_distance, 1e-9) << name;
    EXPECT_LE(after.distortion.eps_angle, before.distortion.eps_angle) << name;
    (void)genus;
  }
}

// Vertices of one colour move in parallel but never see each other's moves: one thread or two,
// the same map.
TEST(MapSmoothing, SameResultOnAnyNumberOfThreads) {
  const Pipeline& p = pipeline("knot.off");
  MapSmoothingOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const MapSmoothingResult a = smooth_map(p.model, p.polycube.polycube, p.map, one);
  const MapSmoothingResult b = smooth_map(p.model, p.polycube.polycube, p.map, two);
  EXPECT_EQ(a.moves, b.moves);
  EXPECT_EQ(a.polycube_on_model_xyz, b.polycube_on_model_xyz);
  EXPECT_EQ(a.model_on_polycube_xyz, b.model_on_polycube_xyz);
}

// No sweeps: nothing moves, and the input map comes back as it was.
TEST(MapSmoothing, NoSweepsReturnsTheInput) {
  const Pipeline& p = pipeline("sphere.off");
  MapSmoothingOptions options;
  options.sweeps = 0;
  const MapSmoothingResult r = smooth_map(p.model, p.polycube.polycube, p.map, options);
  EXPECT_EQ(r.moves, 0);
  EXPECT_EQ(r.relocated, 0);
  EXPECT_EQ(r.polycube_on_model_xyz, p.map.polycube_on_model_xyz);
  EXPECT_EQ(r.model_on_polycube_xyz, p.map.model_on_polycube_xyz);
  EXPECT_EQ(r.flipped_after, r.flipped_before);
}

// A map that is already conformal is returned as it is: CGAL's corner.off (an L-shaped block) has a
// polycube that is the block itself and an unsmoothed map of ε_angle 1.0001, which relaxation
// would pull off the block's corners. The sphere's map is smoothed and kept.
TEST(MapSmoothing, KeptOnlyWhenItRemovesFlipsOrLowersTheAngleDistortion) {
  const Pipeline& corner = pipeline("corner.off");
  const MapSmoothingResult r = smooth_map(corner.model, corner.polycube.polycube, corner.map);
  EXPECT_FALSE(r.kept);
  EXPECT_LT(r.distortion_before.eps_angle, 1.001);
  EXPECT_GE(r.distortion_after.eps_angle, r.distortion_before.eps_angle);
  EXPECT_GT(r.moves, 0);  // it did move, and was not kept
  EXPECT_EQ(r.polycube_on_model_xyz, corner.map.polycube_on_model_xyz);
  EXPECT_EQ(r.model_on_polycube_xyz, corner.map.model_on_polycube_xyz);
  EXPECT_EQ(r.flipped_after, r.flipped_before);

  const Pipeline& sphere = pipeline("sphere.off");
  const MapSmoothingResult s = smooth_map(sphere.model, sphere.polycube.polycube, sphere.map);
  EXPECT_TRUE(s.kept);
  EXPECT_LT(s.distortion_after.eps_angle, s.distortion_before.eps_angle);
  EXPECT_NE(s.polycube_on_model_xyz, sphere.map.polycube_on_model_xyz);
}

// More sweeps, smoother: the angle distortion keeps falling while the flips stay within bounds.
TEST(MapSmoothing, MoreSweepsLowerAngleDistortionFurther) {
  const Pipeline& p = pipeline("rocker-arm.obj");
  const TriMesh& P = p.polycube.polycube.mesh;
  double previous = audit_map(p.model, P, p.map.polycube_on_model_xyz, p.map.model_on_polycube_xyz).distortion.eps_angle;
  for (int sweeps : {2, 10, 30}) {
    MapSmoothingOptions options;
    options.sweeps = sweeps;
    const MapSmoothingResult r = smooth_map(p.model, p.polycube.polycube, p.map, options);
    const MapAudit audit = audit_map(p.model, P, r.polycube_on_model_xyz, r.model_on_polycube_xyz);
    EXPECT_LT(audit.distortion.eps_angle, previous) << sweeps << " sweeps";
    EXPECT_LE(r.flipped_after[0], r.flipped_before[0]);
    EXPECT_LE(r.flipped_after[1], r.flipped_before[1]);
    previous = audit.distortion.eps_angle;
  }
}

// The untangling phases (M's vertices moved on P near the M → P flips the smoothing proper leaves,
// P's vertices relocated over them, then P's near the P → M flips): on the coarse test meshes
// that keep flips after the sweeps over P's vertices, neither direction ends worse than without
// them, and in all they remove M → P flips.
TEST(MapSmoothing, UntanglingRemovesModelToPolycubeFlipsAndNeverAddsAny) {
  int without_m = 0, with_m = 0, phases = 0;
  for (const std::string name : {"joint.off", "helmet.off", "couplingdown.off"}) {
    const Pipeline& p = pipeline(name);
    const TriMesh& P = p.polycube.polycube.mesh;
    MapSmoothingOptions plain;
    plain.untangle_rings = 0;
    const MapSmoothingResult a = smooth_map(p.model, p.polycube.polycube, p.map, plain);
    const MapSmoothingResult b = smooth_map(p.model, p.polycube.polycube, p.map);
    EXPECT_EQ(a.untangle_phases, 0) << name;
    EXPECT_EQ(a.untangle_moves, 0) << name;
    const MapAudit audit_a = audit_map(p.model, P, a.polycube_on_model_xyz, a.model_on_polycube_xyz);
    const MapAudit audit_b = audit_map(p.model, P, b.polycube_on_model_xyz, b.model_on_polycube_xyz);
    EXPECT_EQ(b.flipped_after[0], bad(audit_b.polycube_to_model)) << name;
    EXPECT_EQ(b.flipped_after[1], bad(audit_b.model_to_polycube)) << name;
    EXPECT_LE(bad(audit_b.polycube_to_model), bad(audit_a.polycube_to_model)) << name;
    EXPECT_LE(bad(audit_b.model_to_polycube), bad(audit_a.model_to_polycube)) << name;
    EXPECT_LT(audit_b.polycube_to_model.max_distance, 1e-9) << name;
    EXPECT_LT(audit_b.model_to_polycube.max_distance, 1e-9) << name;
    // A kept phase lowered the flips in all.
    if (b.untangle_phases > 0) EXPECT_LT(b.flipped_after[0] + b.flipped_after[1], a.flipped_after[0] + a.flipped_after[1]) << name;
    else EXPECT_EQ(b.model_on_polycube_xyz, a.model_on_polycube_xyz) << name;
    without_m += bad(audit_a.model_to_polycube);
    with_m += bad(audit_b.model_to_polycube);
    phases += b.untangle_phases;
  }
  EXPECT_GT(phases, 0);
  EXPECT_LT(with_m, without_m);
}

TEST(MapSmoothing, RejectsMismatchedInput) {
  const Pipeline& p = pipeline("sphere.off");
  PolycubeMap truncated = p.map;
  truncated.polycube_on_model.pop_back();
  EXPECT_THROW(smooth_map(p.model, p.polycube.polycube, truncated), std::invalid_argument);
  PolycubeMap bad_face = p.map;
  bad_face.model_on_polycube[0].face = p.polycube.polycube.mesh.num_faces();
  EXPECT_THROW(smooth_map(p.model, p.polycube.polycube, bad_face), std::invalid_argument);
  MapSmoothingOptions options;
  options.rounds = 0;
  EXPECT_THROW(smooth_map(p.model, p.polycube.polycube, p.map, options), std::invalid_argument);
  options.rounds = 1;
  options.sweeps = -1;
  EXPECT_THROW(smooth_map(p.model, p.polycube.polycube, p.map, options), std::invalid_argument);
  options.sweeps = 10;
  options.untangle_rings = -1;
  EXPECT_THROW(smooth_map(p.model, p.polycube.polycube, p.map, options), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
