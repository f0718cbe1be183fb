// untangle_image: the last correction of a map's files, on images whose folds are known by
// construction (a flat grid with a vertex dragged across its neighbours, a sliver reversed on a
// flat face), judged by the independent audit.
#include "polycube/image_untangle.h"

#include "polycube/map_audit.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <utility>
#include <vector>

namespace polycube {
namespace {

// An n × n grid of unit squares in the plane z = 0, each split into two triangles facing +z.
TriMesh flat_grid(int n) {
  TriMesh grid;
  grid.V.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) grid.V.row(j * (n + 1) + i) << i, j, 0;
  grid.F.resize(2 * n * n, 3);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      grid.F.row(2 * (j * n + i)) << a, b, c;
      grid.F.row(2 * (j * n + i) + 1) << a, c, d;
    }
  return grid;
}

int vertex(int n, int i, int j) { return j * (n + 1) + i; }

// The grid's own positions with vertex (i, j) of the n × n grid moved to (x, y, 0).
Eigen::MatrixX3d moved_vertex(const TriMesh& grid, int n, int i, int j, double x, double y) {
  Eigen::MatrixX3d image = grid.V;
  image.row(vertex(n, i, j)) << x, y, 0;
  return image;
}

// Options whose room is max_shift of the diagonal alone (no share of the shortest edge).
ImageUntangleOptions room_of(double max_shift) {
  ImageUntangleOptions options;
  options.max_shift = max_shift;
  options.max_edge_share = 0;
  return options;
}

TEST(ImageUntangle, UnfoldsAVertexDraggedAcrossItsNeighbours) {
  const int n = 10;
  const TriMesh grid = flat_grid(n);
  // The vertex (5, 5) dragged past its right neighbour: its fan folds over.
  const Eigen::MatrixX3d image = moved_vertex(grid, n, 5, 5, 6.3, 5.2);
  const MapDirectionAudit folded = audit_map_direction(grid, image, grid);
  ASSERT_GT(folded.flipped, 0);

  const ImageUntangleOptions options = room_of(0.2);  // the drag was 1.3 / 14.1 of the diagonal
  const ImageUntangleResult result = untangle_image(grid, image, grid, options);
  EXPECT_EQ(result.bad_before, folded.flipped + folded.degenerate);
  EXPECT_EQ(result.bad_after, 0);
  const MapDirectionAudit audit = audit_map_direction(grid, result.image, grid);
  EXPECT_EQ(audit.flipped, 0);
  EXPECT_EQ(audit.degenerate, 0);
  EXPECT_LT(audit.max_distance, 1e-12);  // the images stay on the target
  EXPECT_GT(result.moved, 0);
  EXPECT_LE(result.max_shift, options.max_shift + 1e-12);
  // Only images near the fold moved: every vertex farther than three rings is where it was.
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      if (std::max(std::abs(i - 5), std::abs(j - 5)) > 3) {
        EXPECT_EQ(result.image.row(vertex(n, i, j)), image.row(vertex(n, i, j))) << i << " " << j;
      }
}

// A sliver whose apex lies a hair's breadth across the line through its other corners (a coarse
// model's triangle whose three exact images land on one face of P) is unfolded by a move of
// about that breadth.
TEST(ImageUntangle, UnfoldsAReversedSliverByASmallMove) {
  const int n = 8;
  const TriMesh grid = flat_grid(n);
  // A fan round (4, 4): squeeze the vertex (5, 4) towards the diagonal (4, 4)–(5, 5) so that the
  // triangle (4, 4), (5, 4), (5, 5) becomes a sliver, then just across.
  const Eigen::MatrixX3d image = moved_vertex(grid, n, 5, 4, 4.5 - 0.01, 4.5 + 0.01);
  ASSERT_EQ(audit_map_direction(grid, image, grid).flipped, 1);
  const ImageUntangleResult result = untangle_image(grid, image, grid);
  EXPECT_EQ(result.bad_before, 1);
  EXPECT_EQ(result.bad_after, 0);
  EXPECT_EQ(audit_map_direction(grid, result.image, grid).flipped, 0);
  EXPECT_LE(result.max_shift, ImageUntangleOptions().max_shift);
}

TEST(ImageUntangle, MovesNothingWithoutRoomOrFolds) {
  const int n = 6;
  const TriMesh grid = flat_grid(n);
  // No fold: the input is returned, and no run is reported.
  ImageUntangleOptions counted;
  int reports = 0;
  counted.after_run = [&reports](double, int) { ++reports; };
  const ImageUntangleResult clean = untangle_image(grid, grid.V, grid, counted);
  EXPECT_EQ(reports, 0);
  EXPECT_EQ(clean.bad_before, 0);
  EXPECT_EQ(clean.moved, 0);
  EXPECT_EQ(clean.image, grid.V);
  // A fold but no room to move: left as it is, and counted.
  const Eigen::MatrixX3d image = moved_vertex(grid, n, 3, 3, 4.3, 3.2);
  const ImageUntangleResult stuck = untangle_image(grid, image, grid, room_of(0));
  EXPECT_GT(stuck.bad_before, 0);
  EXPECT_EQ(stuck.bad_after, stuck.bad_before);
  EXPECT_EQ(stuck.moved, 0);
}

// The wider runs (ImageUntangleOptions::wider_shifts) start again from the input images: the
// fold of a vertex dragged past two neighbours is stuck with a 2 % room, half undone with 5 %,
// undone with 10 %, and that run is exactly the run made with 10 % from the start (the set-up
// shared by the runs is reset with the images). They go on only while each does better.
TEST(ImageUntangle, AWiderShiftRunsAgainFromTheInput) {
  const int n = 10;
  const TriMesh grid = flat_grid(n);
  const Eigen::MatrixX3d image = moved_vertex(grid, n, 5, 5, 7.8, 5.2);
  const ImageUntangleOptions narrow = room_of(0.02);
  const ImageUntangleResult stuck = untangle_image(grid, image, grid, narrow);
  ASSERT_GT(stuck.bad_after, 0);
  ASSERT_EQ(stuck.bad_after, stuck.bad_before);
  const int middle_left = untangle_image(grid, image, grid, room_of(0.05)).bad_after;
  ASSERT_GT(middle_left, 0);
  ASSERT_LT(middle_left, stuck.bad_before);

  ImageUntangleOptions wider = narrow;
  wider.wider_shifts = {0.05, 0.1, 0.2};
  std::vector<std::pair<double, int>> runs;  // after_run's reports, one per run made
  wider.after_run = [&runs](double shift, int bad_left) { runs.emplace_back(shift, bad_left); };
  const ImageUntangleResult result = untangle_image(grid, image, grid, wider);
  const std::vector<std::pair<double, int>> expected_runs = {{0.02, stuck.bad_after}, {0.05, middle_left}, {0.1, 0}};
  EXPECT_EQ(runs, expected_runs);
  EXPECT_EQ(result.bad_before, stuck.bad_before);
  EXPECT_EQ(result.bad_after, 0);
  EXPECT_EQ(result.shift_allowed, 0.1);  // the first that leaves none; 0.2 is not run
  EXPECT_LE(result.max_shift, 0.1 + 1e-12);
  const ImageUntangleResult once = untangle_image(grid, image, grid, room_of(0.1));
  EXPECT_EQ(result.image, once.image);
  EXPECT_EQ(result.moved, once.moved);
  // Without wider shifts the first run is the result.
  EXPECT_EQ(stuck.shift_allowed, 0.02);
  // A wider run that leaves as many as the best before it ends the search: 3 % leaves the 2 of
  // 2 %, so 10 % is not run.
  ImageUntangleOptions fruitless = narrow;
  fruitless.wider_shifts = {0.03, 0.1};
  const ImageUntangleResult stopped = untangle_image(grid, image, grid, fruitless);
  EXPECT_EQ(stopped.bad_after, stuck.bad_after);
  EXPECT_EQ(stopped.shift_allowed, 0.02);
  EXPECT_EQ(stopped.image, stuck.image);
}

TEST(ImageUntangle, RejectsBadArguments) {
  const TriMesh grid = flat_grid(3);
  EXPECT_THROW(untangle_image(grid, Eigen::MatrixX3d::Zero(3, 3), grid), std::invalid_argument);
  Eigen::MatrixX3d image = grid.V;
  image(0, 0) = std::nan("");
  EXPECT_THROW(untangle_image(grid, image, grid), std::invalid_argument);
  ImageUntangleOptions options;
  options.max_shift = -1;
  EXPECT_THROW(untangle_image(grid, grid.V, grid, options), std::invalid_argument);
  options.max_shift = 0.01;
  options.max_edge_share = -1;
  EXPECT_THROW(untangle_image(grid, grid.V, grid, options), std::invalid_argument);
  options.max_edge_share = 0.25;
  options.wider_shifts = {0.05, -0.1};
  EXPECT_THROW(untangle_image(grid, grid.V, grid, options), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
