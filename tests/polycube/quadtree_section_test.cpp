// approximate_section and sample_section: the quadtree approximation of a cross-section meets
// d_a (or stops at max_level), keeps the topology of the contours (every face has one connected
// cell set, faces no contour separates never touch, no diagonal touches), and honours edits.
// coarsen_section undoes subdivisions beyond the d_a refinement and snap_section makes a section
// follow its neighbour, where their checks allow.
#include "polycube/quadtree_section.h"

#include "polycube/quadtree_raster.h"
#include "polycube/quadtree_sampled.h"
#include "polycube/quadtree_simplify.h"
#include "polycube/quadtree_topology.h"
#include "polycube/slice.h"
#include "support/generated_meshes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
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

// A prism over a polygon star-shaped from `centre` (counter-clockwise), from z = 0 to 1.
TriMesh prism(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& centre) {
  const int n = static_cast<int>(polygon.size());
  TriMesh mesh;
  mesh.V.resize(2 * n + 2, 3);
  for (int i = 0; i < n; ++i) {
    mesh.V.row(i) << polygon[i].x(), polygon[i].y(), 0;
    mesh.V.row(n + i) << polygon[i].x(), polygon[i].y(), 1;
  }
  mesh.V.row(2 * n) << centre.x(), centre.y(), 0;
  mesh.V.row(2 * n + 1) << centre.x(), centre.y(), 1;
  mesh.F.resize(4 * n, 3);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    mesh.F.row(4 * i) << 2 * n, j, i;
    mesh.F.row(4 * i + 1) << 2 * n + 1, n + i, n + j;
    mesh.F.row(4 * i + 2) << i, j, n + j;
    mesh.F.row(4 * i + 3) << i, n + j, n + i;
  }
  return mesh;
}

// A square with a thin arm (a tail: 2 % of the section's area) cut across: d_a alone drops the
// arm, the region's area error being small; with feature_distance the arm keeps cells of its own
// along most of its length, and the topology still holds.
TEST(QuadtreeSection, FeatureDistanceKeepsAThinArm) {
  const std::vector<Eigen::Vector2d> polygon = {{0, 0},         {1, 0},        {1, 0.485}, {1.8, 0.485},
                                                {1.8, 0.515},   {1, 0.515},    {1, 1},     {0, 1}};
  const CrossSections sections = sections_of(prism(polygon, {0.995, 0.5}), {0.5});
  ASSERT_EQ(sections.planes[0].num_faces(), 2);
  // The arm in unit-square units (the frame's scale is the 1.8 wide side).
  const double x0 = 1.05 / 1.8, x1 = 1.8 / 1.8, y0 = 0.485 / 1.8, y1 = 0.515 / 1.8;
  const auto arm_covered = [&](const QuadtreeSection& q) {
    double covered = 0;
    for (const QuadLeaf& leaf : q.leaves) {
      if (leaf.face != 1) continue;
      const double s = std::ldexp(1.0, -leaf.cell.level);
      const double w = std::min(x1, (leaf.cell.ix + 1) * s) - std::max(x0, leaf.cell.ix * s);
      const double h = std::min(y1, (leaf.cell.iy + 1) * s) - std::max(y0, leaf.cell.iy * s);
      if (w > 0 && h > 0) covered += w * h;
    }
    return covered / ((x1 - x0) * (y1 - y0));
  };
  QuadtreeOptions options;
  options.da = 0.3;
  const QuadtreeSection plain = approximate_section(sections, 0, {}, options);
  ASSERT_TRUE(plain.valid) << plain.problem;
  EXPECT_LT(arm_covered(plain), 0.2);
  EXPECT_EQ(plain.feature_splits, 0);
  options.feature_distance = 0.02;
  const QuadtreeSection kept = approximate_section(sections, 0, {}, options);
  ASSERT_TRUE(kept.valid) << kept.problem;
  expect_partition(kept.leaves);
  std::vector<char> mark;
  EXPECT_EQ(check_section_topology(sections.planes[0], kept.leaves, mark), "");
  EXPECT_GT(kept.feature_splits, 0);
  EXPECT_GT(arm_covered(kept), 0.5);
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

TEST(QuadtreeSection, LeafLocatorTilesTheSquareWithFillers) {
  // Leaves over part of the square: the lower left quarter, and three of the four cells of the
  // lower right quarter's quarters. Fillers (face 0) take the rest.
  std::vector<QuadLeaf> leaves(4);
  leaves[0].cell = {1, 0, 0};
  leaves[0].face = 2;
  leaves[1].cell = {2, 2, 0};
  leaves[2].cell = {2, 3, 0};
  leaves[3].cell = {2, 2, 1};
  for (int l = 1; l < 4; ++l) leaves[l].face = 1;
  const LeafLocator tiles(leaves);
  ASSERT_EQ(tiles.leaves(), 4);
  ASSERT_EQ(tiles.size(), 7);  // fillers: one cell of level 2, two of level 1
  std::set<QuadCell> fillers;
  double area = 0;
  for (int t = 0; t < tiles.size(); ++t) {
    area += std::ldexp(1.0, -2 * tiles.cell(t).level);
    if (t >= tiles.leaves()) {
      fillers.insert(tiles.cell(t));
      EXPECT_EQ(tiles.face(t), 0);
    }
  }
  EXPECT_DOUBLE_EQ(area, 1.0);
  EXPECT_EQ(fillers, (std::set<QuadCell>{{2, 3, 1}, {1, 0, 1}, {1, 1, 1}}));
  EXPECT_EQ(tiles.face(0), 2);

  const int half = kQuadGridSize / 2, quarter = kQuadGridSize / 4;
  EXPECT_EQ(tiles.at(0, 0), 0);
  EXPECT_EQ(tiles.at(half - 1, half - 1), 0);
  EXPECT_EQ(tiles.at(-1, 0), -1);
  EXPECT_EQ(tiles.at(0, kQuadGridSize), -1);
  EXPECT_EQ(tiles.beside(half, half, -1, -1), 0);
  EXPECT_EQ(tiles.beside(half, half, 1, -1), 3);
  EXPECT_EQ(tiles.cell(tiles.beside(half, half, 1, 1)), (QuadCell{1, 1, 1}));
  EXPECT_EQ(tiles.cell(tiles.beside(half, half, -1, 1)), (QuadCell{1, 0, 1}));
  EXPECT_EQ(tiles.cell(tiles.at(half + quarter, quarter)), (QuadCell{2, 3, 1}));
  EXPECT_EQ(tiles.find({2, 3, 0}), 2);
  EXPECT_EQ(tiles.find({1, 1, 0}), LeafLocator::kSubdivided);
  EXPECT_EQ(tiles.find({3, 0, 0}), LeafLocator::kInside);

  // Every tile corner once, in raster order, with the tiles around it.
  const std::vector<TileCorner> corners = tile_corners(tiles);
  std::set<std::pair<int, int>> distinct;
  for (size_t c = 0; c < corners.size(); ++c) {
    distinct.insert({corners[c].y, corners[c].x});
    if (c > 0) {
      EXPECT_LT(std::make_pair(corners[c - 1].y, corners[c - 1].x), std::make_pair(corners[c].y, corners[c].x));
    }
  }
  EXPECT_EQ(distinct.size(), corners.size());
  EXPECT_EQ(corners.size(), 14u);  // the 3 x 3 points of level 1 and 5 more of level 2
  const auto centre = std::find_if(corners.begin(), corners.end(),
                                   [&](const TileCorner& c) { return c.x == half && c.y == half; });
  ASSERT_NE(centre, corners.end());
  EXPECT_EQ(centre->around[0], 0);
  EXPECT_EQ(centre->around[1], 3);
  const auto corner = std::find_if(corners.begin(), corners.end(), [](const TileCorner& c) { return c.x == 0 && c.y == 0; });
  ASSERT_NE(corner, corners.end());
  EXPECT_EQ(corner->around, (std::array<int, 4>{-1, -1, 0, -1}));
}

// The annulus of a torus section, approximated for d_a, then every mixed cell subdivided three
// more times as the stacking repairs would.
struct OverRefined {
  CrossSections sections;
  QuadtreeSection plain, refined;
};

OverRefined over_refined_annulus() {
  OverRefined r;
  r.sections = sections_of(test::make_torus(1.0, 0.3, 96, 48), {0.05});
  r.plain = approximate_section(r.sections, 0);
  QuadtreeEdits edits;
  r.refined = r.plain;
  for (int round = 0; round < 3; ++round) {
    for (const QuadLeaf& leaf : r.refined.leaves)
      if (leaf.mixed) edits.splits.push_back(leaf.cell);
    r.refined = approximate_section(r.sections, 0, edits);
  }
  return r;
}

std::map<QuadCell, int> labels_of(const std::vector<QuadLeaf>& leaves) {
  std::map<QuadCell, int> labels;
  for (const QuadLeaf& leaf : leaves) labels[leaf.cell] = leaf.face;
  return labels;
}

TEST(QuadtreeCoarsening, UndoesTheSubdivisionsBeyondTheAccuracyRefinement) {
  const OverRefined r = over_refined_annulus();
  ASSERT_TRUE(r.plain.valid && r.refined.valid);
  ASSERT_GT(r.refined.leaves.size(), 4 * r.plain.leaves.size());
  for (const QuadLeaf& leaf : r.refined.leaves) EXPECT_LE(leaf.accuracy_level, r.plain.deepest_level);
  const auto accept = [](const std::vector<QuadLeaf>&, std::vector<char>&) { return true; };
  const CoarsenedSection coarsened = coarsen_section(r.sections.planes[0], r.refined.leaves, 0.3, 0, accept);
  expect_partition(coarsened.leaves);
  std::vector<char> mark;
  EXPECT_EQ(check_section_topology(r.sections.planes[0], coarsened.leaves, mark), "");
  EXPECT_GT(coarsened.merges, 0);
  // A merged parent takes the face covering most of it, as the d_a refinement labelled it.
  EXPECT_EQ(labels_of(coarsened.leaves), labels_of(r.plain.leaves));
  // The coarsest level bounds the merges: a leaf coarser than it was there before.
  const int coarsest = r.plain.deepest_level + 1;
  const std::map<QuadCell, int> refined = labels_of(r.refined.leaves);
  const CoarsenedSection bounded = coarsen_section(r.sections.planes[0], r.refined.leaves, 0.3, coarsest, accept);
  for (const QuadLeaf& leaf : bounded.leaves)
    EXPECT_TRUE(leaf.cell.level >= coarsest || refined.count(leaf.cell)) << leaf.cell.level;
  EXPECT_LT(bounded.leaves.size(), r.refined.leaves.size());
  EXPECT_GT(bounded.leaves.size(), coarsened.leaves.size());
}

// Whether two leaf sets label every point with x in [x0, x1) (grid units) alike; when `blame` is
// given, it gets the leaves of `a` that do not.
bool same_labels(const std::vector<QuadLeaf>& a, const std::vector<QuadLeaf>& b, int x0, int x1,
                 std::vector<char>* blame = nullptr) {
  const QuadRaster raster = rasterize({&a, &b});
  bool same = true;
  for (int cy = 0; cy < raster.ny(); ++cy)
    for (int cx = 0; cx < raster.nx(); ++cx) {
      if (raster.xs[cx] < x0 || raster.xs[cx + 1] > x1) continue;
      const int la = raster.leaf_at(0, cx, cy), lb = raster.leaf_at(1, cx, cy);
      if (a[la].face == b[lb].face) continue;
      same = false;
      if (blame) (*blame)[la] = 1;
    }
  return same;
}

TEST(QuadtreeCoarsening, KeepsWhatItsCheckRejects) {
  const OverRefined r = over_refined_annulus();
  const PlaneSection& section = r.sections.planes[0];
  // Nothing accepted: only merges of siblings labelled alike, which change no label.
  const auto reject = [](const std::vector<QuadLeaf>&, std::vector<char>&) { return false; };
  const CoarsenedSection none = coarsen_section(section, r.refined.leaves, 0.3, 0, reject);
  EXPECT_GT(none.undone, 0);
  EXPECT_LT(none.leaves.size(), r.refined.leaves.size());
  EXPECT_TRUE(same_labels(none.leaves, r.refined.leaves, 0, kQuadGridSize));
  // Label changes in the left half are blamed: only the right half takes the labels of the d_a
  // refinement again.
  const int half = kQuadGridSize / 2;
  const auto right_only = [&](const std::vector<QuadLeaf>& leaves, std::vector<char>& implicated) {
    return same_labels(leaves, r.refined.leaves, 0, half, &implicated);
  };
  const CoarsenedSection right = coarsen_section(section, r.refined.leaves, 0.3, 0, right_only);
  EXPECT_GT(right.merges, 0);
  EXPECT_TRUE(same_labels(right.leaves, r.refined.leaves, 0, half));
  EXPECT_TRUE(same_labels(right.leaves, r.plain.leaves, half, kQuadGridSize));
  EXPECT_FALSE(same_labels(r.refined.leaves, r.plain.leaves, half, kQuadGridSize));
}

// Area of the cells solid in one of two leaf sets and not in the other.
double solid_difference(const PlaneSection& a_section, const std::vector<QuadLeaf>& a, const PlaneSection& b_section,
                        const std::vector<QuadLeaf>& b) {
  const QuadRaster raster = rasterize({&a, &b});
  double area = 0;
  for (int cy = 0; cy < raster.ny(); ++cy)
    for (int cx = 0; cx < raster.nx(); ++cx) {
      const bool in_a = a_section.face_solid[a[raster.leaf_at(0, cx, cy)].face];
      const bool in_b = b_section.face_solid[b[raster.leaf_at(1, cx, cy)].face];
      if (in_a != in_b)
        area += double(raster.xs[cx + 1] - raster.xs[cx]) * (raster.ys[cy + 1] - raster.ys[cy]) /
                (double(kQuadGridSize) * kQuadGridSize);
    }
  return area;
}

TEST(QuadtreeSnapping, FollowsTheNeighbourWithinDa) {
  // Two sections of a tilted torus: the annulus moves sideways from one plane to the next.
  TriMesh mesh = test::make_torus(1.0, 0.3, 96, 48);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  mesh.V = (mesh.V * R.transpose()).eval();
  const CrossSections sections = sections_of(mesh, {0.0, 0.06});
  const PlaneSection &lower = sections.planes[0], &upper = sections.planes[1];
  QuadtreeOptions options;
  options.max_level = 6;
  const QuadtreeSection a = approximate_section(sections, 0, {}, options);
  const QuadtreeSection b = approximate_section(sections, 1, {}, options);
  ASSERT_TRUE(a.valid && b.valid);
  const auto accept = [](const std::vector<QuadLeaf>&, std::vector<char>&) { return true; };
  const CoarsenedSection snapped =
      snap_section(upper, b.leaves, 0.3, 0, SnapNeighbour{&lower, &a.leaves}, SnapNeighbour{}, true, accept);
  EXPECT_GT(snapped.merges, 0);
  expect_partition(snapped.leaves);
  std::vector<char> mark;
  EXPECT_EQ(check_section_topology(upper, snapped.leaves, mark), "");
  EXPECT_LT(solid_difference(lower, a.leaves, upper, snapped.leaves),
            solid_difference(lower, a.leaves, upper, b.leaves));
  // Every region stays within d_a (or what it had), measured like approximate_section does.
  const std::vector<double> before = region_errors(upper, b.leaves), after = region_errors(upper, snapped.leaves);
  for (int f = 0; f < upper.num_faces(); ++f) {
    EXPECT_NEAR(before[f], b.region_error[f], 1e-12) << "face " << f;
    EXPECT_LE(after[f], std::max(0.3, before[f]) + 1e-9) << "face " << f;
  }
  // Nothing the check rejects is kept.
  const auto reject = [](const std::vector<QuadLeaf>&, std::vector<char>&) { return false; };
  const CoarsenedSection none =
      snap_section(upper, b.leaves, 0.3, 0, SnapNeighbour{&lower, &a.leaves}, SnapNeighbour{}, true, reject);
  EXPECT_EQ(none.merges, 0);
  EXPECT_EQ(labels_of(none.leaves), labels_of(b.leaves));
}

}  // namespace
}  // namespace polycube
