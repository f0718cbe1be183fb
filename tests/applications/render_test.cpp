// Software renderer: framing, colour sources, shading and input checks.
#include "applications/preview/render.h"

#include "polycube/errors.h"
#include "support/generated_meshes.h"

#include <gtest/gtest.h>

#include <set>

namespace polycube {
namespace {

bool is_background(const Image& image, int x, int y) {
  return image.at(x, y, 0) == 1.0f && image.at(x, y, 1) == 1.0f && image.at(x, y, 2) == 1.0f;
}

TEST(Render, ObjectIsFramedToFillItsTile) {
  const TriMesh sphere = test::make_sphere(3);
  RenderItem item;
  item.mesh = &sphere;
  RenderOptions options;
  options.tile_width = options.tile_height = 100;
  const Image image = render_tiles({item}, options);
  ASSERT_EQ(image.width, 100);
  ASSERT_EQ(image.height, 100);
  ASSERT_EQ(image.channels, 3);
  int x0 = 100, x1 = -1, y0 = 100, y1 = -1;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x)
      if (!is_background(image, x, y)) {
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
  EXPECT_GE(x1 - x0, 85) << "a sphere fills about 92% of the tile";
  EXPECT_LE(x1 - x0, 95);
  EXPECT_NEAR((x0 + x1) / 2.0, 49.5, 2.0) << "centred";
  EXPECT_NEAR((y0 + y1) / 2.0, 49.5, 2.0);
  EXPECT_TRUE(is_background(image, 0, 0));
}

TEST(Render, ShadingVariesAcrossACurvedSurfaceAndFacesAreFlatWhenAsked) {
  const TriMesh sphere = test::make_sphere(3);
  RenderItem item;
  item.mesh = &sphere;
  RenderOptions options;
  options.tile_width = options.tile_height = 64;
  options.supersampling = 1;
  const Image smooth = render_tiles({item}, options);
  std::set<float> greys;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      if (!is_background(smooth, x, y)) greys.insert(smooth.at(x, y, 0));
  EXPECT_GT(greys.size(), 50u) << "smooth shading gives a gradient";

  // A flat-shaded cube shows at most three visible faces, so at most three shades.
  TriMesh cube;
  cube.V.resize(8, 3);
  cube.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  cube.F.resize(12, 3);
  cube.F << 0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7;
  item.mesh = &cube;
  item.smooth = false;
  const Image flat = render_tiles({item}, options);
  std::set<float> shades;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      if (!is_background(flat, x, y)) shades.insert(flat.at(x, y, 0));
  EXPECT_LE(shades.size(), 3u);
  EXPECT_GE(shades.size(), 2u);
}

TEST(Render, CheckerAndFaceColoursShowUp) {
  const TriMesh sphere = test::make_sphere(3);
  const Eigen::MatrixX3d coords = sphere.V;
  RenderItem checker;
  checker.mesh = &sphere;
  checker.checker_coords = &coords;
  checker.checker_size = 0.25;
  Eigen::MatrixX3d blue(sphere.num_faces(), 3);
  blue.rowwise() = Eigen::RowVector3d(0, 0, 1);
  RenderItem coloured;
  coloured.mesh = &sphere;
  coloured.face_rgb = &blue;
  RenderOptions options;
  options.tile_width = options.tile_height = 80;
  const Image image = render_tiles({checker, coloured}, options);
  ASSERT_EQ(image.width, 160);
  int orange = 0, light = 0, bluish = 0;
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 160; ++x) {
      if (is_background(image, x, y)) continue;
      const float r = image.at(x, y, 0), g = image.at(x, y, 1), b = image.at(x, y, 2);
      if (x < 80) {
        orange += r > 1.5f * b && r > g;
        light += std::abs(r - b) < 0.15f * r;
      } else {
        bluish += b > 0 && r == 0 && g == 0;
      }
    }
  EXPECT_GT(orange, 300) << "both checker colours appear";
  EXPECT_GT(light, 300);
  EXPECT_GT(bluish, 1000);
}

TEST(Render, SameScaleDrawsASmallerObjectSmaller) {
  const TriMesh big = test::make_sphere(2);
  TriMesh small = big;
  small.V *= 0.5;
  RenderItem a, b;
  a.mesh = &big;
  b.mesh = &small;
  RenderOptions options;
  options.tile_width = options.tile_height = 100;
  options.same_scale = true;
  const Image image = render_tiles({a, b}, options);
  auto covered = [&](int tile) {
    int count = 0;
    for (int y = 0; y < 100; ++y)
      for (int x = 0; x < 100; ++x) count += !is_background(image, tile * 100 + x, y);
    return count;
  };
  EXPECT_NEAR(covered(1) / static_cast<double>(covered(0)), 0.25, 0.03) << "half the radius, a quarter of the area";
}

TEST(Render, RejectsInconsistentInput) {
  const TriMesh sphere = test::make_sphere(1);
  Eigen::MatrixX3d wrong(3, 3);
  RenderItem item;
  item.mesh = &sphere;
  item.face_rgb = &wrong;
  EXPECT_THROW(render_tiles({item}), AlgorithmError);
  EXPECT_THROW(render_tiles({}), AlgorithmError);
  RenderItem empty;
  EXPECT_THROW(render_tiles({empty}), AlgorithmError);
}

}  // namespace
}  // namespace polycube
