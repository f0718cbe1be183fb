// prepare_mesh / require_mappable: the engine's entry gate, on real meshes and on fixtures built
// here for each defect class.
#include "polycube/validate.h"

#include "formats/mesh_io.h"
#include "polycube/errors.h"
#include "polycube/mesh_topology.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <map>

namespace polycube {
namespace {

PolygonSoup soup_of(const std::vector<Eigen::Vector3d>& points, const std::vector<std::vector<int>>& polygons) {
  return PolygonSoup{points, polygons};
}

// Unit cube as 6 quads, outward.
PolygonSoup cube_quads() {
  return soup_of({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},
                 {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}});
}

// Tetrahedron, outward, shifted by (dx, 0, 0).
PolygonSoup tetrahedron(double dx = 0) {
  return soup_of({{dx, 0, 0}, {dx + 1, 0, 0}, {dx, 1, 0}, {dx, 0, 1}}, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
}

PolygonSoup merge(PolygonSoup a, const PolygonSoup& b) {
  const int offset = static_cast<int>(a.points.size());
  a.points.insert(a.points.end(), b.points.begin(), b.points.end());
  for (auto polygon : b.polygons) {
    for (int& v : polygon) v += offset;
    a.polygons.push_back(polygon);
  }
  return a;
}

TEST(Validate, GenusAndEulerOfEveryClosedTestMesh) {
  for (const auto& [name, expected_genus] : test::closed_test_meshes()) {
    SCOPED_TRACE(name);
    const PreparedMesh prepared = prepare_mesh(read_polygon_soup(test::data_path(name)));
    const MeshDiagnosis& d = prepared.diagnosis;
    EXPECT_TRUE(d.valid()) << (d.problems.empty() ? "" : d.problems.front());
    ASSERT_TRUE(d.genus.has_value());
    EXPECT_EQ(*d.genus, expected_genus);
    EXPECT_EQ(d.euler, 2 - 2 * expected_genus);
    EXPECT_EQ(d.components, 1);
    EXPECT_EQ(d.boundary_loops, 0);
    EXPECT_GT(signed_volume(prepared.mesh), 0) << "prepared meshes face outward";
    EXPECT_GE(d.self_intersections, 0) << "checked on manifold meshes";
  }
}

PolygonSoup soup_of(const TriMesh& mesh) {
  PolygonSoup soup;
  for (int v = 0; v < mesh.num_vertices(); ++v) soup.points.push_back(mesh.V.row(v).transpose());
  for (int f = 0; f < mesh.num_faces(); ++f) soup.polygons.push_back({mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)});
  return soup;
}

TEST(Validate, GenusOfGeneratedSurfaces) {
  for (int g = 0; g <= 3; ++g) {
    SCOPED_TRACE(g);
    const PreparedMesh prepared = prepare_mesh(soup_of(test::make_genus_surface(g, 32)));
    EXPECT_TRUE(prepared.diagnosis.valid());
    EXPECT_EQ(prepared.diagnosis.genus, g);
    EXPECT_EQ(prepared.diagnosis.euler, 2 - 2 * g);
  }
  const PreparedMesh torus = prepare_mesh(soup_of(test::make_torus(2.0, 0.5, 24, 12)));
  EXPECT_TRUE(torus.diagnosis.valid());
  EXPECT_EQ(torus.diagnosis.genus, 1);
}

TEST(Validate, GeneratedFixturesCarryTheirDefect) {
  EXPECT_EQ(prepare_mesh(soup_of(test::open_cylinder())).diagnosis.boundary_loops, 2);
  EXPECT_EQ(prepare_mesh(soup_of(test::two_tetrahedra())).diagnosis.components, 2);
  EXPECT_GT(prepare_mesh(soup_of(test::nonmanifold_edge())).diagnosis.nonmanifold_edges, 0);
  EXPECT_EQ(prepare_mesh(soup_of(test::nonmanifold_vertex())).diagnosis.nonmanifold_vertices, 1);
  const PreparedMesh flipped = prepare_mesh(soup_of(test::flipped_face_tetrahedron()));
  EXPECT_TRUE(flipped.diagnosis.valid());
  EXPECT_GT(signed_volume(flipped.mesh), 0);
}

TEST(Validate, QuadCubeIsTriangulatedAndValid) {
  const PreparedMesh prepared = prepare_mesh(cube_quads());
  EXPECT_EQ(prepared.mesh.num_faces(), 12);
  EXPECT_TRUE(prepared.diagnosis.valid());
  EXPECT_EQ(prepared.diagnosis.genus, 0);
  EXPECT_NEAR(signed_volume(prepared.mesh), 1.0, 1e-12);
  EXPECT_NEAR(surface_area(prepared.mesh), 6.0, 1e-12);
}

TEST(Validate, NonConvexPolygonIsTriangulatedWithoutOverlap) {
  // An L-shaped prism: the two L faces are non-convex hexagons, where a fan would overlap.
  std::vector<Eigen::Vector3d> points;
  const double L[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  for (int z = 0; z < 2; ++z)
    for (const auto& p : L) points.emplace_back(p[0], p[1], z);
  std::vector<std::vector<int>> polygons = {{5, 4, 3, 2, 1, 0}, {6, 7, 8, 9, 10, 11}};
  for (int i = 0; i < 6; ++i) polygons.push_back({i, (i + 1) % 6, 6 + (i + 1) % 6, 6 + i});
  const PreparedMesh prepared = prepare_mesh(soup_of(points, polygons));
  EXPECT_TRUE(prepared.diagnosis.valid());
  EXPECT_NEAR(signed_volume(prepared.mesh), 3.0, 1e-12);
  EXPECT_NEAR(surface_area(prepared.mesh), 2 * 3.0 + 8.0, 1e-12);
}

TEST(Validate, InconsistentAndInwardOrientationIsRepaired) {
  PolygonSoup soup = tetrahedron();
  std::swap(soup.polygons[1][0], soup.polygons[1][1]);  // one face flipped
  PreparedMesh prepared = prepare_mesh(soup);
  EXPECT_TRUE(prepared.diagnosis.valid());
  EXPECT_FALSE(prepared.repairs.empty());
  EXPECT_GT(signed_volume(prepared.mesh), 0);

  PolygonSoup inward = tetrahedron();
  for (auto& polygon : inward.polygons) std::swap(polygon[0], polygon[1]);
  prepared = prepare_mesh(inward);
  EXPECT_TRUE(prepared.diagnosis.valid());
  EXPECT_GT(signed_volume(prepared.mesh), 0);
}

TEST(Validate, RepeatedCornerDuplicateFacesAndUnreferencedVerticesAreRemoved) {
  PolygonSoup soup = tetrahedron();
  soup.polygons.push_back({0, 0, 1});         // repeated corner
  soup.polygons.push_back(soup.polygons[0]);  // duplicate
  soup.points.emplace_back(5, 5, 5);          // unreferenced
  const PreparedMesh prepared = prepare_mesh(soup);
  EXPECT_TRUE(prepared.diagnosis.valid());
  EXPECT_EQ(prepared.mesh.num_faces(), 4);
  EXPECT_EQ(prepared.mesh.num_vertices(), 4);
  EXPECT_EQ(prepared.repairs.size(), 3u);
}

TEST(Validate, OpenSurfaceReportsLoopsAndFillHolesClosesIt) {
  PolygonSoup open = cube_quads();
  open.polygons.pop_back();
  open.polygons.erase(open.polygons.begin());  // bottom and one side removed: one loop
  PreparedMesh prepared = prepare_mesh(open);
  EXPECT_FALSE(prepared.diagnosis.valid());
  EXPECT_EQ(prepared.diagnosis.boundary_loops, 1);
  EXPECT_EQ(prepared.diagnosis.boundary_edges, 6);
  EXPECT_EQ(prepared.diagnosis.genus, 0);
  EXPECT_THROW(require_mappable(prepared.diagnosis), MeshError);

  PrepareOptions fill;
  fill.fill_holes = true;
  prepared = prepare_mesh(open, fill);
  EXPECT_TRUE(prepared.diagnosis.valid()) << prepared.diagnosis.problems.front();
  EXPECT_EQ(prepared.diagnosis.genus, 0);
  EXPECT_GT(signed_volume(prepared.mesh), 0.5);
}

TEST(Validate, SeveralComponentsAndLargestComponent) {
  PolygonSoup two = merge(merge(cube_quads(), tetrahedron(3)), tetrahedron(6));
  PreparedMesh prepared = prepare_mesh(two);
  EXPECT_EQ(prepared.diagnosis.components, 3);
  EXPECT_FALSE(prepared.diagnosis.valid());
  try {
    require_mappable(prepared.diagnosis);
    FAIL() << "expected MeshError";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("3 connected components"), std::string::npos) << e.what();
  }
  PrepareOptions largest;
  largest.largest_component = true;
  prepared = prepare_mesh(two, largest);
  EXPECT_TRUE(prepared.diagnosis.valid());
  EXPECT_EQ(prepared.mesh.num_faces(), 12);  // the cube
}

TEST(Validate, NonManifoldEdgeAndVertex) {
  // Three triangles on one edge.
  PolygonSoup fin = soup_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}}, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  PreparedMesh prepared = prepare_mesh(fin);
  EXPECT_EQ(prepared.diagnosis.nonmanifold_edges, 1);
  EXPECT_FALSE(prepared.diagnosis.genus.has_value());
  EXPECT_FALSE(prepared.diagnosis.valid());
  // Open too: --fill-holes cannot fill a non-manifold mesh, and the problem says so instead of
  // suggesting it.
  PrepareOptions fill;
  fill.fill_holes = true;
  const PreparedMesh unfilled = prepare_mesh(fin, fill);
  EXPECT_GT(unfilled.diagnosis.boundary_edges, 0);
  const auto says = [](const MeshDiagnosis& d, const std::string& text) {
    return std::any_of(d.problems.begin(), d.problems.end(), [&](const std::string& p) { return p.find(text) != std::string::npos; });
  };
  EXPECT_TRUE(says(unfilled.diagnosis, "--fill-holes needs a manifold, oriented mesh"));
  EXPECT_FALSE(says(unfilled.diagnosis, "--fill-holes closes them"));
  EXPECT_TRUE(says(prepared.diagnosis, "--fill-holes closes them"));

  // Two tetrahedra sharing one vertex (the apex of the second is vertex 0 of the first).
  PolygonSoup bowtie = tetrahedron();
  bowtie.points.push_back({-1, 0, 0});
  bowtie.points.push_back({0, -1, 0});
  bowtie.points.push_back({0, 0, -1});
  for (const auto& face : std::vector<std::vector<int>>{{0, 4, 5}, {0, 5, 6}, {0, 6, 4}, {4, 6, 5}})
    bowtie.polygons.push_back(face);
  prepared = prepare_mesh(bowtie);
  EXPECT_EQ(prepared.diagnosis.nonmanifold_vertices, 1);
  EXPECT_EQ(prepared.diagnosis.nonmanifold_edges, 0);
  EXPECT_FALSE(prepared.diagnosis.valid());
}

TEST(Validate, SelfIntersectionsAreCountedAndOnlyWarned) {
  // Two overlapping closed tetrahedra: each is valid alone, together they intersect.
  PreparedMesh prepared = prepare_mesh(merge(tetrahedron(0), tetrahedron(0.25)));
  EXPECT_GT(prepared.diagnosis.self_intersections, 0);
  EXPECT_EQ(prepared.diagnosis.warnings.size(), 1u);
  EXPECT_EQ(prepared.diagnosis.problems.size(), 1u) << "only the two components are a problem";

  PrepareOptions skip;
  skip.check_self_intersections = false;
  prepared = prepare_mesh(tetrahedron(), skip);
  EXPECT_EQ(prepared.diagnosis.self_intersections, -1);
  EXPECT_TRUE(prepared.diagnosis.valid());
}

TEST(Validate, ZeroAreaFaceIsRemovedWhenTheMeshStaysValid) {
  // A cube whose top edge 4-5 carries an extra vertex 8 at its middle: the top is triangulated
  // through 8, the front keeps the long edge 4-5, and a zero-area "cap" triangle 4-5-8 closes
  // the gap between them. The mesh is closed and manifold but has one collinear face.
  PolygonSoup soup = cube_quads();
  soup.points.push_back({0.5, 0, 1});
  soup.polygons[1] = {4, 8, 7};
  soup.polygons.push_back({8, 5, 6});
  soup.polygons.push_back({8, 6, 7});
  soup.polygons.push_back({4, 5, 8});
  const PreparedMesh prepared = prepare_mesh(soup);
  EXPECT_TRUE(prepared.diagnosis.valid()) << (prepared.diagnosis.problems.empty() ? "" : prepared.diagnosis.problems[0]);
  EXPECT_EQ(prepared.diagnosis.degenerate_faces, 0);
  EXPECT_FALSE(prepared.repairs.empty());
  EXPECT_NEAR(signed_volume(prepared.mesh), 1.0, 1e-12);
  EXPECT_NEAR(surface_area(prepared.mesh), 6.0, 1e-12);
}

// Faces that are not exactly collinear but whose smallest altitude is rounding noise (at most
// kZeroAltitude of the diagonal) count as zero-area too: the same cube with vertex 8 a hair off
// the edge 4-5 (a cap) or a hair from vertex 4 (a needle besides). OpenSCAD's issue945e.stl had
// 9 such faces: they passed validation and every map through them flipped (the disk maps' own
// triangles too). A thin face well above that altitude is kept as it is.
TEST(Validate, FacesOfRoundingNoiseAltitudeAreZeroAreaToo) {
  const auto cube_with_cap = [](const Eigen::Vector3d& extra) {
    PolygonSoup soup = cube_quads();
    soup.points.push_back(extra);
    soup.polygons[1] = {4, 8, 7};
    soup.polygons.push_back({8, 5, 6});
    soup.polygons.push_back({8, 6, 7});
    soup.polygons.push_back({4, 5, 8});
    return soup;
  };
  // The smallest altitude of the mesh's faces (twice the area over the longest edge).
  const auto smallest_altitude = [](const TriMesh& mesh) {
    double smallest = std::numeric_limits<double>::infinity();
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
      const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
      smallest = std::min(smallest, (b - a).cross(c - a).norm() / longest);
    }
    return smallest;
  };
  for (const Eigen::Vector3d& extra : {Eigen::Vector3d(0.5, 1e-14, 1), Eigen::Vector3d(1e-13, 1e-14, 1)}) {
    const PolygonSoup soup = cube_with_cap(extra);
    const PreparedMesh prepared = prepare_mesh(soup);
    EXPECT_TRUE(prepared.diagnosis.valid()) << (prepared.diagnosis.problems.empty() ? "" : prepared.diagnosis.problems[0]);
    EXPECT_EQ(prepared.diagnosis.degenerate_faces, 0);
    ASSERT_FALSE(prepared.repairs.empty());
    EXPECT_NE(prepared.repairs.back().find("zero-area"), std::string::npos) << prepared.repairs.back();
    // The cap's long edge is flipped (vertex 8 stays, on the cube's edge), the needle's short
    // edge collapsed (vertex 8 merged into 4).
    EXPECT_EQ(prepared.mesh.num_vertices(), extra.x() == 0.5 ? 9 : 8) << extra.transpose();
    EXPECT_GT(smallest_altitude(prepared.mesh), 0.1) << extra.transpose();
    EXPECT_EQ(prepared.diagnosis.genus, 0);
    EXPECT_NEAR(signed_volume(prepared.mesh), 1.0, 1e-12);
    EXPECT_NEAR(surface_area(prepared.mesh), 6.0, 1e-12);
  }
  const PreparedMesh thin = prepare_mesh(cube_with_cap(Eigen::Vector3d(0.5, 1e-9, 1)));
  EXPECT_TRUE(thin.diagnosis.valid());
  EXPECT_EQ(thin.mesh.num_vertices(), 9);
  EXPECT_LT(smallest_altitude(thin.mesh), 1e-8);
  for (const std::string& repair : thin.repairs) EXPECT_EQ(repair.find("zero-area"), std::string::npos) << repair;
}

TEST(Validate, NonFiniteCoordinatesAndBadIndicesThrowInputError) {
  PolygonSoup nan = tetrahedron();
  nan.points[2].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(prepare_mesh(nan), InputError);
  PolygonSoup bad_index = tetrahedron();
  bad_index.polygons[0][1] = 17;
  EXPECT_THROW(prepare_mesh(bad_index), InputError);
}

// Faces that all have zero area are all removed: nothing is left to map (before, the empty mesh
// passed as valid and the topology stage failed on it).
TEST(Validate, OnlyZeroAreaFacesIsNotMappable) {
  PolygonSoup one_point = tetrahedron();
  for (Eigen::Vector3d& p : one_point.points) p = Eigen::Vector3d(0.5, 0.25, 2);
  PolygonSoup on_a_line = tetrahedron();
  for (int i = 0; i < 4; ++i) on_a_line.points[i] = Eigen::Vector3d(i, 2.0 * i, 0);
  for (const PolygonSoup& soup : {one_point, on_a_line}) {
    const PreparedMesh prepared = prepare_mesh(soup);
    EXPECT_FALSE(prepared.diagnosis.valid());
    EXPECT_THROW(require_mappable(prepared.diagnosis), MeshError);
  }
}

// A closed surface whose sides lie on each other (a tetrahedron pressed flat: four faces of
// non-zero area, closed, manifold, genus 0) encloses no volume and is refused by name; a thin
// plate still encloses one and is valid.
TEST(Validate, AClosedSurfaceEnclosingNoVolumeIsNotMappable) {
  PolygonSoup flat = tetrahedron();
  flat.points[3] = Eigen::Vector3d(0.25, 0.25, 0);
  const PreparedMesh pressed = prepare_mesh(flat);
  EXPECT_TRUE(pressed.diagnosis.closed());
  EXPECT_EQ(pressed.diagnosis.genus, 0);
  ASSERT_FALSE(pressed.diagnosis.valid());
  EXPECT_NE(pressed.diagnosis.problems.back().find("encloses no volume"), std::string::npos) << pressed.diagnosis.problems.back();
  EXPECT_THROW(require_mappable(pressed.diagnosis), MeshError);

  PolygonSoup plate = cube_quads();
  for (Eigen::Vector3d& p : plate.points) p.z() *= 1e-3;
  const PreparedMesh thin = prepare_mesh(plate);
  EXPECT_TRUE(thin.diagnosis.valid()) << (thin.diagnosis.problems.empty() ? "" : thin.diagnosis.problems.front());
}

// A model so large or so small that its squared areas leave the doubles is refused with its size;
// within the range it is valid.
TEST(Validate, ModelsBeyondTheDoublesRangeAreNotMappable) {
  const auto scaled = [](double scale, double dx = 0) {
    PolygonSoup soup = tetrahedron(dx);
    for (Eigen::Vector3d& p : soup.points) p *= scale;
    return prepare_mesh(soup).diagnosis;
  };
  for (double scale : {1e300, 1e-60}) {
    const MeshDiagnosis d = scaled(scale);
    ASSERT_FALSE(d.valid()) << scale;
    EXPECT_NE(d.problems.back().find("bounding-box diagonal"), std::string::npos) << d.problems.back();
  }
  PolygonSoup one_far = tetrahedron();
  one_far.points[3].z() = 1e300;
  EXPECT_FALSE(prepare_mesh(one_far).diagnosis.valid());
  for (double scale : {1e-40, 1e-3, 1e3, 1e40}) EXPECT_TRUE(scaled(scale).valid()) << scale;
}

// A model far from the origin (beyond centre_beyond_diagonals of its size) is moved there, exactly,
// with the offset recorded and the diagnosis' box the input's; one nearer stays where it is.
TEST(Validate, AModelFarFromTheOriginIsMovedThere) {
  const Eigen::Vector3d far(1e7, -3e6, 5e6);
  PolygonSoup soup = tetrahedron();
  for (Eigen::Vector3d& p : soup.points) p += far;
  const PreparedMesh moved = prepare_mesh(soup);
  ASSERT_TRUE(moved.diagnosis.valid());
  const Eigen::Vector3d centre = far + Eigen::Vector3d(0.5, 0.5, 0.5);
  EXPECT_EQ(moved.offset, centre);
  EXPECT_EQ(moved.repairs.back().find("moved the model to the origin"), 0u) << moved.repairs.back();
  const PreparedMesh near = prepare_mesh(tetrahedron());
  ASSERT_EQ(near.mesh.num_vertices(), moved.mesh.num_vertices());
  for (int v = 0; v < near.mesh.num_vertices(); ++v)
    EXPECT_EQ((near.mesh.V.row(v).transpose() - Eigen::Vector3d(0.5, 0.5, 0.5)).eval(), moved.mesh.V.row(v).transpose()) << v;
  EXPECT_EQ(near.mesh.F, moved.mesh.F) << "the same faces, oriented the same way";
  EXPECT_EQ(moved.diagnosis.bbox.min, far);
  EXPECT_EQ(moved.diagnosis.bbox.max, (far + Eigen::Vector3d::Ones()).eval());
  EXPECT_TRUE(near.offset.isZero(0));
  PolygonSoup at_100 = tetrahedron(100);
  EXPECT_TRUE(prepare_mesh(at_100).offset.isZero(0)) << "100 diagonals away is not far";
  PrepareOptions never;
  never.centre_beyond_diagonals = 0;
  EXPECT_TRUE(prepare_mesh(soup, never).offset.isZero(0));
}

// Every triangle with its own copies of its corners (a soup, as some exporters write PLY and OFF):
// the boundary vertices at one position are merged, and the mesh is the one the soup was made of.
TEST(Validate, ASoupOfSeparateTrianglesIsWelded) {
  const TriMesh sphere = test::load_mesh_file(test::data_path("sphere.off"));
  PolygonSoup soup;
  for (int f = 0; f < sphere.num_faces(); ++f) {
    std::vector<int> polygon;
    for (int k = 0; k < 3; ++k) {
      polygon.push_back(static_cast<int>(soup.points.size()));
      soup.points.push_back(sphere.V.row(sphere.F(f, k)).transpose());
    }
    soup.polygons.push_back(polygon);
  }
  // One face written twice, with its own corners again: a duplicate once welded, removed after.
  soup.points.insert(soup.points.end(), soup.points.begin(), soup.points.begin() + 3);
  soup.polygons.push_back({static_cast<int>(soup.points.size()) - 3, static_cast<int>(soup.points.size()) - 2,
                           static_cast<int>(soup.points.size()) - 1});
  const PreparedMesh prepared = prepare_mesh(soup);
  EXPECT_TRUE(prepared.diagnosis.valid()) << (prepared.diagnosis.problems.empty() ? "" : prepared.diagnosis.problems[0]);
  EXPECT_EQ(prepared.diagnosis.vertices, sphere.num_vertices());
  EXPECT_EQ(prepared.diagnosis.faces, sphere.num_faces());
  EXPECT_EQ(prepared.diagnosis.genus, 0);
  EXPECT_NEAR(surface_area(prepared.mesh), surface_area(sphere), 1e-12);
  ASSERT_FALSE(prepared.repairs.empty());
  EXPECT_NE(prepared.repairs.front().find("merged " + std::to_string(3 * sphere.num_faces() + 3 - sphere.num_vertices()) +
                                          " boundary vertices"),
            std::string::npos)
      << prepared.repairs.front();
  EXPECT_NE(std::find(prepared.repairs.begin(), prepared.repairs.end(), "removed 1 duplicate face"), prepared.repairs.end());

  // A closed mesh is never welded: two tetrahedra touching at one point stay two components.
  PolygonSoup touching = merge(tetrahedron(0), tetrahedron(1));  // (1, 0, 0) twice
  const PreparedMesh apart = prepare_mesh(touching);
  EXPECT_EQ(apart.diagnosis.components, 2);
  EXPECT_EQ(apart.diagnosis.nonmanifold_vertices, 0);
}

// A cube whose top is two rectangles: their shared side ends at the middles of two top edges,
// which the front and back faces do not have (T-junctions, as polyhedra written with a vertex
// inside an edge are). Those faces are split there, and the cube is closed; a vertex off the edge
// by more than the tolerance is not a T-junction, and the surface stays open.
TEST(Validate, TJunctionsAreSplit) {
  const auto split_top = [](double off) {
    PolygonSoup soup = cube_quads();
    soup.points.push_back({0.5, -off, 1});  // 8: inside edge 4-5
    soup.points.push_back({0.5, 1, 1});     // 9: inside edge 6-7
    soup.polygons[1] = {4, 8, 9, 7};
    soup.polygons.push_back({8, 5, 6, 9});
    return prepare_mesh(soup);
  };
  const PreparedMesh split = split_top(1e-7);  // within kTJunctionTolerance × √3
  EXPECT_TRUE(split.diagnosis.valid()) << (split.diagnosis.problems.empty() ? "" : split.diagnosis.problems[0]);
  EXPECT_EQ(split.diagnosis.genus, 0);
  EXPECT_NEAR(signed_volume(split.mesh), 1.0, 1e-6);
  EXPECT_NE(std::find(split.repairs.begin(), split.repairs.end(),
                      "split 2 faces at T-junctions (a boundary vertex inside another face's edge)"),
            split.repairs.end());

  const PreparedMesh open = split_top(1e-3);
  EXPECT_FALSE(open.diagnosis.valid());
  EXPECT_EQ(open.diagnosis.boundary_loops, 1);  // 6-7 is split at 9; 4-5 and 4-8-5 stay open
  EXPECT_EQ(open.diagnosis.boundary_edges, 3);
}

TEST(Validate, EmptySoupIsNotMappable) {
  const PreparedMesh prepared = prepare_mesh(PolygonSoup{});
  EXPECT_FALSE(prepared.diagnosis.valid());
  EXPECT_THROW(require_mappable(prepared.diagnosis), MeshError);
}

}  // namespace
}  // namespace polycube
