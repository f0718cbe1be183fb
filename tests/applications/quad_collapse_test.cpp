// The diagonal collapse of quads left bad: on the grid of a cube lying on the cube, one quad in
// the middle of a face is made degenerate (two opposite corners on its centre) or flipped (those
// corners moved past each other). The collapse removes it and nothing else, leaves no bad quad, a
// closed genus-0 2-manifold, three more irregular vertices, and the grid, the corners and the
// pinned flags consistent with the quads; a quad it cannot remove leaves everything unchanged.
#include "applications/quad/polycube_grid.h"
#include "applications/quad/quad_collapse.h"
#include "applications/quad/quad_quality.h"
#include "applications/quad/surface_projector.h"

#include "support/generated_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace polycube {
namespace {


struct CubeCase {
  PolycubeGrid grid;
  QuadMesh quads;
  std::vector<char> pinned;
  int target = -1;  // the quad made bad
};

// The grid on the cube (about 600 quads), the quads on the cube itself, every other vertex pinned;
// the quad nearest the centre of the face z = 1 has its corners 0 and 2 put `past` of the way
// beyond its centre (0: both on the centre, degenerate; > 0: moved past each other, flipped).
CubeCase make_setup(double past) {
  CubeCase s;
  PolycubeGridOptions options;
  options.target_quads = 600;
  s.grid = build_polycube_grid(test::make_cube(), options);
  s.quads = s.grid.mesh;
  s.pinned.assign(s.quads.num_vertices(), 0);
  for (int v = 0; v < s.quads.num_vertices(); v += 2) s.pinned[v] = 1;
  double nearest = 1e9;
  for (int q = 0; q < s.quads.num_quads(); ++q) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) centre += s.quads.V.row(s.quads.Q(q, k)).transpose() / 4;
    const double d = (centre - Eigen::Vector3d(0, 0, 1)).norm();
    if (d < nearest) {
      nearest = d;
      s.target = q;
    }
  }
  const int a = s.quads.Q(s.target, 0), c = s.quads.Q(s.target, 2);
  const Eigen::Vector3d pa = s.quads.V.row(a), pc = s.quads.V.row(c), centre = (pa + pc) / 2;
  s.quads.V.row(a) = (centre + past * (pc - pa)).transpose();
  s.quads.V.row(c) = (centre - past * (pc - pa)).transpose();
  return s;
}

int irregular(const QuadMesh& quads) {
  const QuadTopology t = quad_topology(quads);
  return static_cast<int>((t.valence.array() != 4).count());
}

void expect_collapsed(CubeCase s, const char* what) {
  SCOPED_TRACE(what);
  const SurfaceProjector model(test::make_cube());
  ASSERT_EQ(bad_quads(s.quads, model), std::vector<int>{s.target});
  const int nv = s.quads.num_vertices(), nq = s.quads.num_quads(), was_irregular = irregular(s.quads);
  std::vector<Eigen::Vector3d> corner_places;
  for (int c : s.grid.corners) corner_places.push_back(s.quads.V.row(c));
  const int pinned_before = static_cast<int>(std::count(s.pinned.begin(), s.pinned.end(), 1));

  const QuadCollapseResult r = collapse_bad_quads(s.quads, s.grid, s.pinned, model);
  EXPECT_EQ(r.collapsed, 1);
  EXPECT_EQ(r.bad_before, 1);
  EXPECT_EQ(r.bad_after, 0);
  EXPECT_TRUE(bad_quads(s.quads, model).empty());
  EXPECT_EQ(s.quads.num_quads(), nq - 1);
  EXPECT_EQ(s.quads.num_vertices(), nv - 1);
  const QuadTopology t = quad_topology(s.quads);
  EXPECT_TRUE(t.closed_manifold());
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.genus(), 0);
  // A valence-6 vertex where the two corners met, two valence-3 ones beside it.
  EXPECT_EQ(irregular(s.quads), was_irregular + 3);
  EXPECT_EQ(r.irregular_added, 3);
  EXPECT_EQ(t.valence.maxCoeff(), 6);
  // Every vertex on the model.
  for (int v = 0; v < s.quads.num_vertices(); ++v)
    EXPECT_LT(model.closest(s.quads.V.row(v).transpose()).distance, 1e-12) << v;
  // The grid follows: same connectivity, the per-vertex and per-quad arrays resized, the corners
  // still at the cube's corners, in the same order; pinned flags per vertex, one fewer at most.
  EXPECT_EQ(s.grid.mesh.Q, s.quads.Q);
  EXPECT_EQ(s.grid.mesh.num_vertices(), s.quads.num_vertices());
  EXPECT_EQ(static_cast<int>(s.grid.on_polycube.size()), s.quads.num_vertices());
  EXPECT_EQ(s.grid.quad_axis.size(), s.quads.num_quads());
  EXPECT_EQ(s.grid.quad_refined_by.size(), s.quads.num_quads());
  ASSERT_EQ(s.grid.corners.size(), corner_places.size());
  for (size_t i = 0; i < corner_places.size(); ++i)
    EXPECT_EQ(Eigen::Vector3d(s.quads.V.row(s.grid.corners[i])), corner_places[i]);
  ASSERT_EQ(static_cast<int>(s.pinned.size()), s.quads.num_vertices());
  const int pinned_after = static_cast<int>(std::count(s.pinned.begin(), s.pinned.end(), 1));
  EXPECT_GE(pinned_after, pinned_before - 2);
  EXPECT_LE(pinned_after, pinned_before);
}

TEST(QuadCollapse, DegenerateQuadRemoved) { expect_collapsed(make_setup(0), "degenerate"); }

TEST(QuadCollapse, FlippedQuadRemoved) { expect_collapsed(make_setup(0.05), "flipped"); }

TEST(QuadCollapse, NothingBadNothingChanged) {
  const SurfaceProjector model(test::make_cube());
  CubeCase s = make_setup(-0.5);  // corners back at their places: the plain grid
  const QuadMesh before = s.quads;
  const QuadCollapseResult r = collapse_bad_quads(s.quads, s.grid, s.pinned, model);
  EXPECT_EQ(r.collapsed, 0);
  EXPECT_EQ(r.bad_before, 0);
  EXPECT_EQ(s.quads.Q, before.Q);
  EXPECT_EQ(s.quads.V, before.V);
}

TEST(QuadCollapse, QuadAtAPolycubeCornerCollapsesOntoIt) {
  // A quad at a cube corner made degenerate (its corner opposite the cube's put on it): the
  // collapse keeps the cube's corner where it is, with 5 quads round it now, and still a corner.
  const SurfaceProjector model(test::make_cube());
  CubeCase s = make_setup(-0.5);  // the plain grid
  const int corner = s.grid.corners.front();
  const Eigen::Vector3d place = s.quads.V.row(corner);
  int q = 0;
  while (q < s.quads.num_quads() && (s.quads.Q.row(q).array() != corner).all()) ++q;
  ASSERT_LT(q, s.quads.num_quads());
  int k = 0;
  while (s.quads.Q(q, k) != corner) ++k;
  s.quads.V.row(s.quads.Q(q, (k + 2) % 4)) = place.transpose();
  ASSERT_EQ(bad_quads(s.quads, model), std::vector<int>{q});
  const QuadCollapseResult r = collapse_bad_quads(s.quads, s.grid, s.pinned, model);
  EXPECT_EQ(r.collapsed, 1);
  EXPECT_EQ(r.bad_after, 0);
  EXPECT_TRUE(bad_quads(s.quads, model).empty());
  const int now = s.grid.corners.front();
  EXPECT_EQ(Eigen::Vector3d(s.quads.V.row(now)), place);
  const QuadTopology t = quad_topology(s.quads);
  EXPECT_TRUE(t.closed_manifold());
  EXPECT_EQ(t.genus(), 0);
  EXPECT_EQ(t.valence[now], 5);
}

TEST(QuadCollapse, MismatchedGridThrows) {
  const SurfaceProjector model(test::make_cube());
  CubeCase s = make_setup(0);
  s.grid.on_polycube.pop_back();
  EXPECT_THROW(collapse_bad_quads(s.quads, s.grid, s.pinned, model), std::invalid_argument);
  CubeCase t = make_setup(0);
  t.pinned.pop_back();
  EXPECT_THROW(collapse_bad_quads(t.quads, t.grid, t.pinned, model), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
