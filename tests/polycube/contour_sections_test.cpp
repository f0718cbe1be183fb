// cross_sections: contours of a sliced model with the inside on their left, their nesting
// (outer contours and holes), the arrangement faces, and the loops of every piece.
#include "polycube/contour_sections.h"

#include "polycube/slice.h"
#include "support/generated_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

namespace polycube {
namespace {

constexpr double kPi = 3.14159265358979323846;

NormalisedFrame frame_of(const TriMesh& mesh) {
  const BoundingBox box = bounding_box(mesh.V);
  NormalisedFrame frame;
  frame.origin = box.min;
  frame.scale = box.extent().maxCoeff();
  return frame;
}

TEST(ContourSections, TorusMiddleIsAnAnnulus) {
  // Torus around the z axis, R = 1, r = 0.3: at z = 0.05 an annulus between radii
  // 1 +- sqrt(r^2 - z^2).
  const TriMesh mesh = test::make_torus(1.0, 0.3, 96, 48);
  const SlicedMesh sliced = slice_mesh(mesh, {0.05});
  const NormalisedFrame frame = frame_of(mesh);
  const CrossSections sections = cross_sections(sliced, frame);
  ASSERT_EQ(sections.planes.size(), 1u);
  const PlaneSection& plane = sections.planes[0];
  ASSERT_EQ(plane.contours.size(), 2u);
  const SectionContour& a = sections.contours[plane.contours[0]];
  const SectionContour& b = sections.contours[plane.contours[1]];
  const SectionContour& outer = a.area > 0 ? a : b;
  const SectionContour& hole = a.area > 0 ? b : a;
  EXPECT_GT(outer.area, 0);
  EXPECT_LT(hole.area, 0);
  EXPECT_EQ(outer.depth, 0);
  EXPECT_EQ(outer.parent, -1);
  EXPECT_EQ(hole.depth, 1);
  EXPECT_EQ(hole.parent, outer.local);
  const double w = std::sqrt(0.3 * 0.3 - 0.05 * 0.05);
  const double s2 = frame.scale * frame.scale;
  EXPECT_NEAR(outer.area * s2, kPi * (1 + w) * (1 + w), 0.01);
  EXPECT_NEAR(-hole.area * s2, kPi * (1 - w) * (1 - w), 0.01);

  // Faces: outside, the region (inside the outer contour), the hole.
  ASSERT_EQ(plane.num_faces(), 3);
  EXPECT_FALSE(plane.face_solid[0]);
  EXPECT_TRUE(plane.face_solid[outer.local + 1]);
  EXPECT_FALSE(plane.face_solid[hole.local + 1]);
  EXPECT_EQ(plane.contour_between(0, outer.local + 1), outer.local);
  EXPECT_EQ(plane.contour_between(outer.local + 1, hole.local + 1), hole.local);
  EXPECT_EQ(plane.contour_between(0, hole.local + 1), -1);
  EXPECT_NEAR(plane.face_area[outer.local + 1], outer.area + hole.area, 1e-12);

  // Every plane vertex is on one contour; each contour bounds one piece below and one above.
  for (int v = 0; v < sliced.mesh.num_vertices(); ++v)
    EXPECT_EQ(sections.vertex_contour[v] >= 0, v >= sliced.input_vertices);
  std::map<int, int> below, above;
  for (size_t p = 0; p < sliced.pieces.size(); ++p)
    for (size_t l = 0; l < sliced.pieces[p].boundary_loops.size(); ++l)
      (sliced.pieces[p].loop_plane[l] == sliced.pieces[p].plane_above ? below : above)[sections.piece_contours[p][l]]++;
  for (int c : plane.contours) {
    EXPECT_EQ(below[c], 1);
    EXPECT_EQ(above[c], 1);
  }
}

TEST(ContourSections, NestedIslandsInAHole) {
  // Three nested tori at one height: their annuli nest, so contours reach depth 5.
  TriMesh mesh;
  const double radii[3] = {3.0, 2.0, 1.0};
  for (double R : radii) {
    const TriMesh t = test::make_torus(R, 0.3, 96, 32);
    const int offset = mesh.num_vertices();
    mesh.V.conservativeResize(offset + t.num_vertices(), 3);
    mesh.V.bottomRows(t.num_vertices()) = t.V;
    const int faces = mesh.num_faces();
    mesh.F.conservativeResize(faces + t.num_faces(), 3);
    mesh.F.bottomRows(t.num_faces()) = t.F.array() + offset;
  }
  const SlicedMesh sliced = slice_mesh(mesh, {0.02});
  const CrossSections sections = cross_sections(sliced, frame_of(mesh));
  const PlaneSection& plane = sections.planes[0];
  ASSERT_EQ(plane.contours.size(), 6u);
  std::map<int, int> depths;
  for (int c : plane.contours) {
    const SectionContour& contour = sections.contours[c];
    depths[contour.depth]++;
    EXPECT_EQ(contour.area > 0, contour.depth % 2 == 0);
    if (contour.depth > 0) {
      EXPECT_EQ(sections.contours[plane.contours[contour.parent]].depth, contour.depth - 1);
    }
  }
  for (int d = 0; d < 6; ++d) EXPECT_EQ(depths[d], 1) << "depth " << d;
}

TEST(ContourSections, PlaneOrderDoesNotDependOnOtherPlanes) {
  // Contours are numbered by their smallest point, so adding planes keeps a plane's numbering.
  const TriMesh mesh = test::make_genus_surface(2, 24);
  const NormalisedFrame frame = frame_of(mesh);
  const CrossSections one = cross_sections(slice_mesh(mesh, {0.01}), frame);
  const CrossSections three = cross_sections(slice_mesh(mesh, {-0.2, 0.01, 0.15}), frame);
  ASSERT_EQ(one.planes[0].contours.size(), three.planes[1].contours.size());
  for (size_t k = 0; k < one.planes[0].contours.size(); ++k) {
    const SectionContour& a = one.contours[one.planes[0].contours[k]];
    const SectionContour& b = three.contours[three.planes[1].contours[k]];
    EXPECT_EQ(a.points, b.points);
    EXPECT_EQ(a.parent, b.parent);
  }
}

// Contours crossing each other or themselves (a self-intersecting surface cut where it meets
// itself) are counted, pair by pair of segments; disjoint, nested and touching-at-a-shared-corner
// segments of one contour are not.
TEST(ContourSections, CrossingContoursAreCounted) {
  auto square = [](double x0, double y0, double side) {
    return std::vector<Eigen::Vector2d>{{x0, y0}, {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}};
  };
  auto sections_of = [](const std::vector<std::vector<Eigen::Vector2d>>& contours) {
    CrossSections sections;
    sections.planes.resize(1);
    for (const auto& points : contours) {
      sections.planes[0].contours.push_back(static_cast<int>(sections.contours.size()));
      SectionContour c;
      c.points = points;
      sections.contours.push_back(c);
    }
    return sections;
  };
  EXPECT_EQ(count_contour_crossings(sections_of({square(0, 0, 1), square(2, 0, 1)}), 0), 0);
  EXPECT_EQ(count_contour_crossings(sections_of({square(0, 0, 3), square(1, 1, 1)}), 0), 0);
  // Two squares overlapping at a corner: two crossing pairs, at (1, 0.5) and (0.5, 1).
  Eigen::Vector2d at;
  EXPECT_EQ(count_contour_crossings(sections_of({square(0, 0, 1), square(0.5, 0.5, 1)}), 0, &at), 2);
  EXPECT_TRUE((at - Eigen::Vector2d(1, 0.5)).norm() < 1e-12 || (at - Eigen::Vector2d(0.5, 1)).norm() < 1e-12) << at.transpose();
  // A bow tie crosses itself once.
  EXPECT_EQ(count_contour_crossings(sections_of({{{0, 0}, {1, 1}, {1, 0}, {0, 1}}}), 0), 1);
  // Many segments (the grid path): a fine circle and a shifted copy cross twice.
  std::vector<Eigen::Vector2d> circle, shifted;
  for (int k = 0; k < 400; ++k) {
    const double t = 2 * kPi * (k + 0.5) / 400;
    circle.emplace_back(std::cos(t), std::sin(t));
    shifted.emplace_back(std::cos(t) + 0.5, std::sin(t));
  }
  EXPECT_EQ(count_contour_crossings(sections_of({circle}), 0), 0);
  EXPECT_EQ(count_contour_crossings(sections_of({circle, shifted}), 0), 2);
}

}  // namespace
}  // namespace polycube
