// approximate_section and sample_section: the quadtree approximation of a cross-section meets
// d_a (or stops at max_level), keeps the topology of the contours (every face has one connected
// cell set, faces no contour separates never touch, no diagonal touches), and honours edits.
#include "polycube/quadtree_section.h"

#include "polycube/quadtree_raster.h"
#include "polycube/quadtree_sampled.h"
#include "polycube/quadtree_topology.h"
#include "polycube/slice.h"
#include "support/generated_meshes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <set>

namespace polycube {
namespace {

CrossSections sections_of(const TriMesh& mesh, const std::vector<double>& planes) {
  const BoundingBox box = bounding_box(mesh.V);
  NormalisedFrame frame;
  frame.origin = box.min;
  frame.scale = box.extent().maxCoeff();
  return cross_sections(slice_mesh(mesh, planes), frame);
}

// Leaves cover the unit square exactly once.
void expect_partition(const std::vector<QuadLeaf>& leaves) {
  double area = 0;
  for (const QuadLeaf& leaf : leaves) area += std::ldexp(1.0, -2 * leaf.cell.level);
  EXPECT_DOUBLE_EQ(area, 1.0);
  const QuadRaster raster = rasterize({&leaves});
  for (int l : raster.leaf[0]) EXPECT_GE(l, 0);
}

TEST(QuadtreeSection, AnnulusKeepsItsHoleAndMeetsDa) {
  const TriMesh mesh = test::make_torus(1.0, 0.3, 96, 48);
  const CrossSections sections = sections_of(mesh, {0.05});
  for (double da : {0.5, 0.3, 0.1, 0.03}) {
    QuadtreeOptions options;
    options.da = da;
    const QuadtreeSection q = approximate_section(sections, 0, {}, options);
    ASSERT_TRUE(q.valid) << q.problem;
    expect_partition(q.leaves);
    std::vector<char> mark;
    EXPECT_EQ(check_section_topology(sections.planes[0], q.leaves, mark), "");
    std::set<int> faces;
    for (const QuadLeaf& leaf : q.leaves) faces.insert(leaf.face);
    EXPECT_EQ(faces.size(), 3u) << "outside, region and hole all have cells";
    for (int f = 0; f < sections.planes[0].num_faces(); ++f) EXPECT_LE(q.region_error[f], da) << "face " << f;
    EXPECT_LE(q.deepest_level, options.max_level);
  }
}

TEST(QuadtreeSection, SmallerDaGivesMoreCellsAndLessError) {
  const TriMesh mesh = test::make_genus_surface(3, 32);
  const CrossSections sections = sections_of(mesh, {0.01});
  size_t previous_leaves = 0;
  double previous_error = 1e9;
  for (double da : {0.4, 0.2, 0.1, 0.05}) {
    QuadtreeOptions options;
    options.da = da;
    const QuadtreeSection q = approximate_section(sections, 0, {}, options);
    ASSERT_TRUE(q.valid) << q.problem;
    const double error = *std::max_element(q.region_error.begin(), q.region_error.end());
    EXPECT_GT(q.leaves.size(), previous_leaves);
    EXPECT_LT(error, previous_error);
    previous_leaves = q.leaves.size();
    previous_error = error;
  }
}

TEST(QuadtreeSection, MaxLevelBoundsTheAccuracyRefinement) {
  const TriMesh mesh = test::make_sphere(4);
  const CrossSections sections = sections_of(mesh, {0.1});
  QuadtreeOptions options;
  options.da = 1e-6;  // unreachable
  options.max_level = 5;
  const QuadtreeSection q = approximate_section(sections, 0, {}, options);
  EXPECT_TRUE(q.valid);
  EXPECT_EQ(q.deepest_level, 5);
  EXPECT_GT(q.region_error[1], options.da);
}

TEST(QuadtreeSection, CloseRegionsAreSeparatedAndThinOnesKept) {
  // Two tori side by side, almost touching: their cross-sections at the middle are two annuli
  // 0.023 apart. Coarse cells would merge them; topology repairs separate them, and no two
  // regions touch, not even at a corner.
  TriMesh mesh;
  for (double x : {-1.31, 1.31}) {
    TriMesh t = test::make_torus(1.0, 0.3, 96, 32);
    t.V.col(0).array() += x;
    const int offset = mesh.num_vertices();
    mesh.V.conservativeResize(offset + t.num_vertices(), 3);
    mesh.V.bottomRows(t.num_vertices()) = t.V;
    mesh.F.conservativeResize(mesh.num_faces() + t.num_faces(), 3);
    mesh.F.bottomRows(t.num_faces()) = t.F.array() + offset;
  }
  const CrossSections sections = sections_of(mesh, {0.03});
  ASSERT_EQ(sections.planes[0].contours.size(), 4u);
  const QuadtreeSection q = approximate_section(sections, 0);
  ASSERT_TRUE(q.valid) << q.problem;
  EXPECT_GT(q.topology_splits, 0);
  std::set<int> faces;
  for (const QuadLeaf& leaf : q.leaves) faces.insert(leaf.face);
  EXPECT_EQ(faces.size(), 5u);  // the outside, and per torus its region and its hole
  std::vector<char> mark;
  EXPECT_EQ(check_section_topology(sections.planes[0], q.leaves, mark), "");
}

TEST(QuadtreeSection, EditsSplitAndRelabel) {
  const TriMesh mesh = test::make_sphere(4);
  const CrossSections sections = sections_of(mesh, {0.1});
  const QuadtreeSection plain = approximate_section(sections, 0);
  // A split request deeper than anything there.
  QuadtreeEdits edits;
  const QuadCell deep{9, 256, 256};
  edits.splits.push_back(deep);
  const QuadtreeSection split = approximate_section(sections, 0, edits);
  EXPECT_GT(split.leaves.size(), plain.leaves.size());
  EXPECT_TRUE(std::any_of(split.leaves.begin(), split.leaves.end(), [&](const QuadLeaf& l) {
    return l.cell.level == 10 && (l.cell.ix >> 1) == deep.ix && (l.cell.iy >> 1) == deep.iy;
  }));
  // Relabel a boundary cell of the disk as outside: the leaf takes the face given.
  const auto boundary = std::find_if(plain.leaves.begin(), plain.leaves.end(),
                                     [](const QuadLeaf& l) { return l.mixed && l.face == 1; });
  ASSERT_NE(boundary, plain.leaves.end());
  QuadtreeEdits relabel;
  relabel.labels.push_back({boundary->cell, 0});
  const QuadtreeSection relabelled = approximate_section(sections, 0, relabel);
  if (relabelled.valid) {
    const auto it = std::find_if(relabelled.leaves.begin(), relabelled.leaves.end(),
                                 [&](const QuadLeaf& l) { return l.cell == boundary->cell; });
    ASSERT_NE(it, relabelled.leaves.end());
    EXPECT_EQ(it->face, 0);
  }
}

TEST(QuadtreeSection, SampledSectionFollowsTheContours) {
  const TriMesh mesh = test::make_torus(1.0, 0.3, 96, 48);
  const CrossSections sections = sections_of(mesh, {0.05});
  const std::vector<QuadLeaf> sampled = sample_section(sections, 0, 256);
  double solid = 0;
  for (const QuadLeaf& leaf : sampled)
    if (sections.planes[0].face_solid[leaf.face]) solid += std::ldexp(1.0, -2 * leaf.cell.level);
  const int region = sections.contours[sections.planes[0].contours[0]].area > 0 ? 1 : 2;
  EXPECT_NEAR(solid, sections.planes[0].face_area[region], 0.01 * sections.planes[0].face_area[region]);
  std::vector<char> mark;
  EXPECT_EQ(check_section_topology(sections.planes[0], sampled, mark), "");
}

}  // namespace
}  // namespace polycube
