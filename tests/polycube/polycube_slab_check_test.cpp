// check_slab and octants_manifold: the combinatorial check of one slab of the stacked polycube
// finds non-manifold touches between the extrusions, the pieces with their loops, and their
// genus.
#include "polycube/polycube_slab_check.h"

#include "polycube/quadtree_section.h"
#include "polycube/slice.h"
#include "support/generated_meshes.h"

#include <gtest/gtest.h>

#include <array>
#include <vector>

namespace polycube {
namespace {

// A sphere cut at two planes: one contour (face 1) on each, one band piece between them.
struct TwoPlanes {
  SlicedMesh sliced;
  CrossSections sections;
  std::vector<std::vector<int>> band;  // the model pieces of the middle slab
  TwoPlanes() {
    const TriMesh mesh = test::make_sphere(4);
    sliced = slice_mesh(mesh, {-0.1, 0.1});
    NormalisedFrame frame;
    frame.origin = bounding_box(mesh.V).min;
    frame.scale = 2;
    sections = cross_sections(sliced, frame);
    for (size_t p = 0; p < sliced.pieces.size(); ++p)
      if (sliced.pieces[p].plane_below == 0) band.push_back(sections.piece_contours[p]);
  }
};

// Leaves of a uniform grid of 2^level cells per side; face 1 where `inside` says so.
template <typename Inside>
std::vector<QuadLeaf> grid(int level, Inside inside) {
  std::vector<QuadLeaf> leaves;
  for (int iy = 0; iy < (1 << level); ++iy)
    for (int ix = 0; ix < (1 << level); ++ix) {
      QuadLeaf leaf;
      leaf.cell = {level, ix, iy};
      leaf.face = inside(ix, iy) ? 1 : 0;
      leaves.push_back(leaf);
    }
  return leaves;
}

TEST(PolycubeSlabCheck, OctantConfigurations) {
  EXPECT_TRUE(octants_manifold(0));
  EXPECT_TRUE(octants_manifold(255));
  EXPECT_TRUE(octants_manifold(1));            // a box corner
  EXPECT_TRUE(octants_manifold(1 | 2));        // two boxes sharing a face
  EXPECT_TRUE(octants_manifold(255 & ~1));     // a box corner from inside
  EXPECT_FALSE(octants_manifold(1 | 8));       // sharing an edge only (z axis)
  EXPECT_FALSE(octants_manifold(1 | 32));      // sharing an edge only (y axis)
  EXPECT_FALSE(octants_manifold(1 | 128));     // sharing a vertex only
  EXPECT_FALSE(octants_manifold(255 & ~(1 | 128)));
  // Nested cross-sections: where a manifold 2x2 configuration lies inside another manifold one,
  // stacking them is manifold (the relabelling repairs rely on this).
  auto manifold_2d = [](int m) { return m != (1 | 8) && m != (2 | 4); };
  for (int a = 0; a < 16; ++a)
    for (int b = 0; b < 16; ++b) {
      if (!manifold_2d(a) || !manifold_2d(b) || (a & b) != a) continue;
      EXPECT_TRUE(octants_manifold(a | (b << 4))) << a << " below " << b;
      EXPECT_TRUE(octants_manifold(b | (a << 4))) << b << " below " << a;
    }
}

TEST(PolycubeSlabCheck, EqualSectionsMakeACylinder) {
  const TwoPlanes t;
  ASSERT_EQ(t.band.size(), 1u);
  const auto square = grid(2, [](int x, int y) { return x >= 1 && x <= 2 && y >= 1 && y <= 2; });
  const SlabCheck check = check_slab(t.sections, {0, &square}, {1, &square}, t.band);
  EXPECT_TRUE(check.ok()) << check.problem;
  EXPECT_EQ(check.nonmanifold_vertices, 0);
  ASSERT_EQ(check.pieces.size(), 1u);
  EXPECT_EQ(check.pieces[0].size(), 2u);
  EXPECT_EQ(check.piece_genus[0], 0);
  EXPECT_EQ(check.model_match[0], 0);
  // The caps below and above: a disk each.
  std::vector<std::vector<int>> cap = {{t.sections.planes[0].contours[0]}};
  EXPECT_TRUE(check_slab(t.sections, {}, {0, &square}, cap).ok());
}

TEST(PolycubeSlabCheck, ExtrusionsTouchingAlongAnEdgeAreNotManifold) {
  const TwoPlanes t;
  const auto left = grid(1, [](int x, int) { return x == 0; });
  const auto right = grid(1, [](int x, int) { return x == 1; });
  const SlabCheck check = check_slab(t.sections, {0, &left}, {1, &right}, t.band);
  EXPECT_FALSE(check.ok());
  EXPECT_EQ(check.nonmanifold_vertices, 3);  // along x = 1/2
  EXPECT_EQ(check.nonmanifold.size(), 3u);
  // Overlapping by a column instead: fine.
  const auto wider = grid(2, [](int x, int) { return x <= 2; });
  const auto shifted = grid(2, [](int x, int) { return x >= 2; });
  EXPECT_TRUE(check_slab(t.sections, {0, &wider}, {1, &shifted}, t.band).ok());
}

TEST(PolycubeSlabCheck, NonManifoldVerticesAreCountedOnTheCommonGrid) {
  // As above, but the lower side's lower left corner is finer: its lines x, y = 1/8, 1/4 cross
  // the edge x = 1/2 where no cell has a corner. The vertices on it are those of the common grid
  // of both sides: y = 0, 1/8, 1/4, 1/2, 3/4, 1.
  const TwoPlanes t;
  std::vector<QuadLeaf> left;
  for (const QuadLeaf& leaf : grid(2, [](int x, int) { return x <= 1; })) {
    if (leaf.cell.ix != 0 || leaf.cell.iy != 0) {
      left.push_back(leaf);
      continue;
    }
    for (int q = 0; q < 4; ++q) {
      QuadLeaf child = leaf;
      child.cell = {3, q & 1, q >> 1};
      left.push_back(child);
    }
  }
  const auto right = grid(1, [](int x, int) { return x == 1; });
  const SlabCheck check = check_slab(t.sections, {0, &left}, {1, &right}, t.band);
  EXPECT_EQ(check.nonmanifold_vertices, 6);
  ASSERT_EQ(check.nonmanifold.size(), 6u);
  // At y = 1/8: the leaves on either side of the edge, the lower side's first (SW, SE, NW, NE).
  const std::array<int, 8> expected = {4, 5, 4, 5, 0, 1, 0, 1};
  EXPECT_EQ(check.nonmanifold[1], expected);
}

TEST(PolycubeSlabCheck, DisjointExtrusionsSplitThePiece) {
  const TwoPlanes t;
  const auto a = grid(2, [](int x, int y) { return x == 0 && y == 0; });
  const auto b = grid(2, [](int x, int y) { return x == 3 && y == 3; });
  const SlabCheck check = check_slab(t.sections, {0, &a}, {1, &b}, t.band);
  EXPECT_FALSE(check.ok());
  EXPECT_EQ(check.pieces.size(), 2u);
  EXPECT_EQ(check.model_match[0], -1);
}

TEST(PolycubeSlabCheck, ClosingARingMakesAHandle) {
  // Below a C, above a bar over its open side overlapping both ends: the union is a ring, the
  // piece between has the two loops but genus 1, which no model piece has.
  const TwoPlanes t;
  const auto c_shape = grid(3, [](int x, int y) {
    const bool frame = x >= 1 && x <= 6 && y >= 1 && y <= 6 && !(x >= 2 && x <= 5 && y >= 2 && y <= 5);
    return frame && !(x == 6 && y >= 3 && y <= 4);
  });
  const auto bar = grid(3, [](int x, int y) { return x == 6 && y >= 2 && y <= 5; });
  const SlabCheck check = check_slab(t.sections, {0, &c_shape}, {1, &bar}, t.band);
  EXPECT_EQ(check.nonmanifold_vertices, 0);
  ASSERT_EQ(check.pieces.size(), 1u);
  EXPECT_EQ(check.pieces[0].size(), 2u);
  EXPECT_EQ(check.piece_genus[0], 1);
  EXPECT_EQ(check.model_match[0], -1);
  EXPECT_FALSE(check.ok());
}

}  // namespace
}  // namespace polycube
