// The quad relaxation on real polycube maps (shipped meshes, map built in memory as `polycube
// quad` does): it lowers the angle deviation, never adds a flipped quad or an inverted corner,
// untangles quads a tangled map folded, keeps the all-quad manifold, its genus and its irregular
// vertices, and the result stays within the Hausdorff bound.
#include "applications/quad/quad_remesh.h"
#include "applications/quad/quad_smooth.h"

#include "polycube/polycube_build.h"
#include "polycube/polycube_map.h"
#include "polycube/topology.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <stdexcept>
#include <string>

namespace polycube {
namespace {

// A shipped model, its polycube and map (default options, input orientation).
struct Mapped {
  const test::MappedModel& stages;
  const TriMesh& model;
  const PolycubeResult& polycube;
  const PolycubeMap& map;
  std::unique_ptr<SurfaceProjector> projector;
};

const Mapped& mapped(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Mapped>> cache;
  std::unique_ptr<Mapped>& slot = cache[name];
  if (!slot) {
    const test::MappedModel& m = test::mapped_model(name);
    slot.reset(new Mapped{m, m.model, m.polycube, m.map, std::make_unique<SurfaceProjector>(m.model)});
  }
  return *slot;
}

QuadRemeshResult remesh(const Mapped& m, int quads, int sweeps) {
  QuadRemeshOptions options;
  options.grid.target_quads = quads;
  options.smooth.sweeps = sweeps;
  const SurfaceMap to_model = [&m](const SurfacePoint& p) { return surface_position(m.model, m.map.to_model(p)); };
  return remesh_quads(m.polycube.polycube.mesh, to_model, *m.projector, options);
}

// Properties every result must have, smoothed or not.
void expect_valid_layout(const QuadRemeshResult& r, int genus, const std::string& what) {
  const QuadQuality& q = r.quality;
  EXPECT_TRUE(q.topology.closed_manifold()) << what;
  EXPECT_EQ(q.topology.components, 1) << what;
  EXPECT_EQ(q.genus, genus) << what;
  EXPECT_EQ(q.irregular_vertices, q.irregular_at_corners) << what << ": irregular only at the polycube's cones";
  EXPECT_EQ(q.corners_irregular, static_cast<int>(r.grid.corners.size())) << what;
  EXPECT_LE(q.max_distance_to_surface, 1e-9 * q.diagonal) << what << ": vertices stay on the model";
}

TEST(QuadSmooth, LowersTheAngleDeviationOnARealMap) {
  const Mapped& m = mapped("eight.off");
  const QuadRemeshResult before = remesh(m, 4000, 0);
  const QuadRemeshResult after = remesh(m, 4000, 30);
  expect_valid_layout(before, 2, "unsmoothed");
  expect_valid_layout(after, 2, "smoothed");
  EXPECT_EQ(after.mesh.Q, before.mesh.Q);
  EXPECT_GT(after.smoothing.moves, 0);
  EXPECT_LE(after.quality.flipped_quads, before.quality.flipped_quads);
  EXPECT_LE(after.quality.inverted_corners, before.quality.inverted_corners);
  EXPECT_EQ(after.quality.flipped_quads, 0);
  EXPECT_EQ(after.quality.degenerate_quads, 0);
  // Measured 22.1° -> 5.2° mean (Hausdorff 0.46 %); demand a clear gain.
  EXPECT_LT(after.quality.angle_deviation_mean, 0.6 * before.quality.angle_deviation_mean)
      << before.quality.angle_deviation_mean << " -> " << after.quality.angle_deviation_mean;
  EXPECT_LT(after.quality.angle_deviation_p95, before.quality.angle_deviation_p95);
  ASSERT_TRUE(after.quality.hausdorff_measured);
  EXPECT_LE(after.quality.hausdorff_percent, 0.5) << "issue 7's bound on a smooth genus-2 model";
}

TEST(QuadSmooth, UntanglesFoldedQuadsOfATangledMap) {
  // anchor's map folds in places (thin parts): the unsmoothed quads have flips.
  const Mapped& m = mapped("anchor.off");
  const QuadRemeshResult before = remesh(m, 3000, 0);
  const QuadRemeshResult after = remesh(m, 3000, 30);
  const int genus = (2 - (m.model.num_vertices() - 3 * m.model.num_faces() / 2 + m.model.num_faces())) / 2;
  expect_valid_layout(before, genus, "unsmoothed");
  expect_valid_layout(after, genus, "smoothed");
  ASSERT_GT(before.quality.inverted_corners, 0) << "the test needs a tangled map";
  // Measured: 23 flipped quads and 228 inverted corners -> 7 and 32.
  EXPECT_LE(after.quality.flipped_quads, before.quality.flipped_quads);
  EXPECT_LT(after.quality.inverted_corners, before.quality.inverted_corners / 2)
      << before.quality.inverted_corners << " -> " << after.quality.inverted_corners;
  EXPECT_LT(after.quality.angle_deviation_mean, before.quality.angle_deviation_mean);
}

TEST(QuadSmooth, StopsWhenConvergedAndChecksOptions) {
  const Mapped& m = mapped("eight.off");
  const QuadRemeshResult r = remesh(m, 1000, 0);
  QuadSmoothOptions options;
  options.sweeps = 500;
  options.tolerance = 1e-2;
  const QuadSmoothResult smoothed = smooth_quads(r.mesh, *m.projector, options);
  EXPECT_TRUE(smoothed.converged);
  EXPECT_LT(smoothed.sweeps, 500);
  EXPECT_LE(smoothed.largest_move, 1e-2);
  options.average_weight = options.angle_weight = options.cross_weight = 0;
  EXPECT_THROW(smooth_quads(r.mesh, *m.projector, options), std::invalid_argument);
  options.average_weight = 1;
  options.tolerance = -1;
  EXPECT_THROW(smooth_quads(r.mesh, *m.projector, options), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
