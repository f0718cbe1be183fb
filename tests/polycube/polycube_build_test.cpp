// build_polycube: the polycube P is a closed, oriented, connected 2-manifold of the model's genus,
// every triangle flat on an axis-aligned face with its normal exactly along the face's axis, and
// P cut by the model's planes has pieces matching the model's one to one (same loops, genus 0) —
// on generated surfaces of genus 0..4 and on the small test meshes. Smaller d_z / d_a give more
// corners and a closer shape (generated and real meshes); the simplification removes corners
// without losing any of this.
#include "polycube/polycube_build.h"

#include "polycube/errors.h"
#include "polycube/mesh_topology.h"
#include "polycube/polycube_distance.h"
#include "polycube/topology.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace polycube {
namespace {

// Every property the issue lists, checked directly on the result.
void expect_valid_polycube(const TopologyResult& topology, const PolycubeResult& result) {
  const Polycube& P = result.polycube;
  const TriMesh& mesh = P.mesh;
  const int nv = mesh.num_vertices(), nf = mesh.num_faces();
  ASSERT_GT(nf, 0);
  ASSERT_EQ(P.face_axis.size(), nf);
  ASSERT_EQ(P.face_patch.size(), nf);

  // Closed (no T-junctions: they would leave edges with one triangle), 2-manifold, oriented.
  const EdgeDefects defects = edge_defects(mesh.F, build_edge_map(mesh.F));
  EXPECT_EQ(defects.boundary, 0) << "edges with one triangle";
  EXPECT_EQ(defects.nonmanifold, 0) << "edges with more than two triangles";
  EXPECT_EQ(defects.misoriented, 0);
  EXPECT_EQ(count_nonmanifold_vertices(mesh.F, nv), 0);
  EXPECT_EQ(count_unreferenced_vertices(mesh.F, nv), 0);
  EXPECT_EQ(connected_components(mesh.F, nv), 1);
  EXPECT_EQ(genus(mesh.F, nv), topology.genus);
  EXPECT_EQ(result.genus, topology.genus);
  EXPECT_GT(signed_volume(mesh), 0) << "outward";

  // Every triangle: positive area, normal exactly along its face's axis, with the face's sign;
  // and in the plane of its polycube face.
  int tilted = 0, degenerate = 0, off_face = 0;
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const int axis = std::abs(P.face_axis[f]) - 1;
    ASSERT_TRUE(axis >= 0 && axis < 3);
    if (n[axis] == 0) ++degenerate;
    if (n[(axis + 1) % 3] != 0 || n[(axis + 2) % 3] != 0 || (n[axis] > 0) != (P.face_axis[f] > 0)) ++tilted;
    const PolycubeFace& face = P.faces[P.face_patch[f]];
    if (face.axis != axis || a[axis] != face.coordinate || b[axis] != face.coordinate || c[axis] != face.coordinate)
      ++off_face;
  }
  EXPECT_EQ(degenerate, 0);
  EXPECT_EQ(tilted, 0);
  EXPECT_EQ(off_face, 0);

  // No vertex on a cutting plane (so slicing P leaves the planes where they are).
  const std::set<double> planes(result.planes_z.begin(), result.planes_z.end());
  for (int v = 0; v < nv; ++v) EXPECT_EQ(planes.count(mesh.V(v, 2)), 0u);

  // Corners: polycube vertices where edges of all three directions meet; edges are straight.
  std::map<int, std::array<int, 3>> directions;
  for (const PolycubeEdge& edge : P.edges) {
    ASSERT_GE(edge.vertices.size(), 2u);
    for (size_t k = 0; k + 1 < edge.vertices.size(); ++k) {
      const Eigen::Vector3d d = mesh.V.row(edge.vertices[k + 1]) - mesh.V.row(edge.vertices[k]);
      EXPECT_EQ(d[(edge.axis + 1) % 3], 0);
      EXPECT_EQ(d[(edge.axis + 2) % 3], 0);
      EXPECT_NE(d[edge.axis], 0);
    }
    EXPECT_NE(edge.faces[0], edge.faces[1]);
    directions[edge.vertices.front()][edge.axis] = 1;
    directions[edge.vertices.back()][edge.axis] = 1;
  }
  int three = 0;
  for (const auto& [v, d] : directions) three += d[0] && d[1] && d[2];
  EXPECT_EQ(three, static_cast<int>(P.corners.size()));
  for (int v : P.corners) EXPECT_TRUE(directions.count(v) && directions[v][0] && directions[v][1] && directions[v][2]);
  EXPECT_GE(P.corners.size(), 8u);
  EXPECT_TRUE(std::includes(P.vertices.begin(), P.vertices.end(), P.corners.begin(), P.corners.end()));

  // Every contour of the model has exactly one loop of Q on its plane.
  const CrossSections& sections = result.model_sections;
  std::vector<int> loops(sections.contours.size(), 0);
  ASSERT_EQ(P.sections.size(), sections.planes.size());
  for (size_t i = 0; i < P.sections.size(); ++i)
    for (const SectionPolygon& polygon : P.sections[i]) {
      ASSERT_GE(polygon.contour, 0);
      EXPECT_EQ(sections.contours[polygon.contour].plane, static_cast<int>(i));
      ++loops[polygon.contour];
    }
  for (size_t c = 0; c < loops.size(); ++c) EXPECT_EQ(loops[c], 1) << "contour " << c;

  // Pieces: one to one, same loops, genus 0.
  const auto& model_pieces = result.model_sliced.pieces;
  ASSERT_EQ(result.piece_match.size(), model_pieces.size());
  EXPECT_EQ(result.polycube_sliced.pieces.size(), model_pieces.size());
  EXPECT_EQ(result.polycube_sliced.planes, result.model_sliced.planes);
  std::set<int> used;
  for (size_t m = 0; m < model_pieces.size(); ++m) {
    const int p = result.piece_match[m];
    ASSERT_GE(p, 0) << "model piece " << m;
    EXPECT_TRUE(used.insert(p).second);
    EXPECT_EQ(result.polycube_sliced.pieces[p].genus, 0);
    EXPECT_EQ(model_pieces[m].genus, 0);
    std::vector<int> a = sections.piece_contours[m], b = result.polycube_piece_contours[p];
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b) << "loops of model piece " << m;
    EXPECT_EQ(result.polycube_sliced.pieces[p].plane_below, model_pieces[m].plane_below);
  }
}

PolycubeResult build(const TriMesh& mesh, const TopologyResult& topology, const PolycubeOptions& options = {}) {
  return build_polycube(mesh, topology, options);
}

TEST(Polycube, GeneratedSurfacesOfGenus0To4) {
  for (int g = 0; g <= 4; ++g) {
    SCOPED_TRACE("genus " + std::to_string(g));
    const TriMesh mesh = test::make_genus_surface(g, 24);
    const TopologyResult topology = analyse_topology(mesh);
    ASSERT_EQ(topology.genus, g);
    const PolycubeResult result = build(mesh, topology);
    expect_valid_polycube(topology, result);
  }
}

TEST(Polycube, SmallTestMeshes) {
  for (const auto& [name, g] : test::closed_test_meshes()) {
    SCOPED_TRACE(name);
    const TriMesh mesh = test::load_test_mesh(name);
    const TopologyResult topology = analyse_topology(mesh);
    const PolycubeResult result = build(mesh, topology);
    EXPECT_EQ(result.genus, g);
    expect_valid_polycube(topology, result);
  }
}

// A thin torus tilted off the axes, and its topology with coarse planes: its cross-sections move
// sideways from plane to plane, so extrusions of neighbouring planes touch or miss each other
// unless the repairs step in.
TriMesh tilted_thin_torus() {
  TriMesh mesh = test::make_torus(1.0, 0.1, 96, 16);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.2, Eigen::Vector3d(1, 0.3, 0).normalized()).toRotationMatrix();
  mesh.V = (mesh.V * R.transpose()).eval();
  return mesh;
}
TopologyOptions coarse_planes() {
  TopologyOptions coarse;
  coarse.dz = 0.25;
  return coarse;
}

TEST(Polycube, TiltedThinTorusNeedsAndGetsRepairs) {
  const TriMesh mesh = tilted_thin_torus();
  const TopologyResult topology = analyse_topology(mesh, coarse_planes());
  const PolycubeResult result = build(mesh, topology);
  expect_valid_polycube(topology, result);
  EXPECT_FALSE(result.repairs.empty());
  EXPECT_GT(result.rounds, 1);
  EXPECT_GT(result.planes_inserted + result.relabelled_cells + result.stacking_splits, 0);
}

// The checks' work is counted (grid cells rasterized, the same on every run) and budgeted: the
// tilted torus with half the work it needs fails with the budget named; with the work it needs,
// or no limit, it builds the same polycube.
TEST(Polycube, ChecksWorkIsCountedAndBudgeted) {
  const TriMesh mesh = tilted_thin_torus();
  const TopologyResult topology = analyse_topology(mesh, coarse_planes());
  const PolycubeResult free = build_polycube(mesh, topology);
  ASSERT_GT(free.rasterized_cells, 0);
  const PolycubeResult again = build_polycube(mesh, topology);
  EXPECT_EQ(again.rasterized_cells, free.rasterized_cells);
  PolycubeOptions budget;
  budget.max_rasterized_cells = static_cast<double>(free.rasterized_cells);
  const PolycubeResult enough = build_polycube(mesh, topology, budget);
  EXPECT_EQ(enough.polycube.corners.size(), free.polycube.corners.size());
  budget.max_rasterized_cells = 0.5 * static_cast<double>(free.rasterized_cells);
  try {
    build_polycube(mesh, topology, budget);
    ADD_FAILURE() << "built within half the work it needs";
  } catch (const AlgorithmError& e) {
    EXPECT_NE(std::string(e.what()).find("rasterized"), std::string::npos) << e.what();
  }
}

TEST(Polycube, ReslicesTheTopologyStagesSurfaceWhenItWasChanged) {
  // When the topology stage split degenerate saddles, its sliced mesh is not the input: inserted
  // planes must cut the surface it sliced, recovered from its refined mesh. Pretend so on a mesh
  // that needs inserted planes; the result must be the same as from the input.
  const TriMesh mesh = tilted_thin_torus();
  TopologyResult topology = analyse_topology(mesh, coarse_planes());
  const PolycubeResult direct = build(mesh, topology);
  ASSERT_GT(direct.planes_inserted, 0);
  topology.split_saddles = 1;
  const PolycubeResult recovered = build(mesh, topology);
  expect_valid_polycube(topology, recovered);
  EXPECT_EQ(recovered.planes_z, direct.planes_z);
  EXPECT_EQ(recovered.polycube.corners.size(), direct.polycube.corners.size());
  EXPECT_EQ(recovered.model_sliced.mesh.V, direct.model_sliced.mesh.V);
  EXPECT_EQ(recovered.model_sliced.pieces.size(), direct.model_sliced.pieces.size());
}

// The unit cube with each side split into n x n quads (two triangles each), outward-oriented.
TriMesh gridded_unit_cube(int n) {
  TriMesh cube;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
  std::map<std::array<int, 3>, int> index;
  auto vertex = [&](std::array<int, 3> p) {
    auto it = index.find(p);
    if (it != index.end()) return it->second;
    points.emplace_back(p[0] / double(n), p[1] / double(n), p[2] / double(n));
    return index[p] = static_cast<int>(points.size()) - 1;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          std::array<int, 3> q[4];
          const int u = (axis + 1) % 3, v = (axis + 2) % 3;
          const int corners[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
          for (int k = 0; k < 4; ++k) {
            q[k][axis] = side * n;
            q[k][u] = corners[k][0];
            q[k][v] = corners[k][1];
          }
          int a = vertex(q[0]), b = vertex(q[1]), c = vertex(q[2]), d = vertex(q[3]);
          if (side == 0) std::swap(b, d);
          triangles.push_back({a, b, c});
          triangles.push_back({a, c, d});
        }
  cube.V.resize(points.size(), 3);
  for (size_t k = 0; k < points.size(); ++k) cube.V.row(k) = points[k].transpose();
  cube.F.resize(triangles.size(), 3);
  for (size_t k = 0; k < triangles.size(); ++k) cube.F.row(k) << triangles[k][0], triangles[k][1], triangles[k][2];
  return cube;
}

TEST(Polycube, BoxModelGivesTheBox) {
  // A unit cube with each side split into 6 x 6 quads: every cross-section is the whole unit
  // square, so P is the cube itself: 8 corners, 6 faces, 12 edges.
  const TriMesh cube = gridded_unit_cube(6);
  ASSERT_GT(signed_volume(cube), 0);

  const TopologyResult topology = analyse_topology(cube);
  const PolycubeResult result = build(cube, topology);
  expect_valid_polycube(topology, result);
  EXPECT_EQ(result.polycube.corners.size(), 8u);
  EXPECT_EQ(result.polycube.faces.size(), 6u);
  EXPECT_EQ(result.polycube.edges.size(), 12u);
  EXPECT_NEAR(signed_volume(result.polycube.mesh), 1.0, 1e-12);
  EXPECT_LT(hausdorff_distance(cube, result.polycube.mesh).hausdorff, 1e-9);
}

// A thin plate swept through its thickness is sliced by a single plane: the piece below and the
// piece above then have the same loops (every contour of that plane) and are told apart by
// their slab (a Cura printer plate, 230 x 230 x 3, failed the final check here).
TEST(Polycube, APlateSlicedOnceGivesTheSlab) {
  TriMesh plate = gridded_unit_cube(6);
  plate.V.col(2) *= 0.02;
  const TopologyResult topology = analyse_topology(plate);
  ASSERT_EQ(topology.planes_z.size(), 1u) << "the plate is sliced once (else the test tests nothing)";
  ASSERT_EQ(topology.sliced.pieces.size(), 2u);
  const PolycubeResult result = build(plate, topology);
  expect_valid_polycube(topology, result);
  EXPECT_EQ(result.planes_z.size(), 1u);
  EXPECT_EQ(result.polycube.corners.size(), 8u);
  ASSERT_EQ(result.piece_match.size(), 2u);
  EXPECT_NE(result.piece_match[0], result.piece_match[1]);
}

// Corners and Hausdorff distance (a fraction of the diagonal) of P for d_z and d_a; P must be valid.
struct Measured {
  size_t corners = 0;
  double distance = 0;
};

Measured measure(const TriMesh& mesh, double dz, double da) {
  SCOPED_TRACE("dz " + std::to_string(dz) + ", da " + std::to_string(da));
  TopologyOptions topology_options;
  topology_options.dz = dz;
  const TopologyResult topology = analyse_topology(mesh, topology_options);
  PolycubeOptions options;
  options.da = da;
  const PolycubeResult result = build(mesh, topology, options);
  expect_valid_polycube(topology, result);
  return {result.polycube.corners.size(),
          hausdorff_distance(mesh, result.polycube.mesh).hausdorff / bounding_box(mesh.V).diagonal()};
}

TEST(Polycube, SmallerDzAndDaGiveMoreCornersAndACloserShape) {
  const TriMesh mesh = test::make_genus_surface(1, 32);
  const std::pair<double, double> settings[] = {{0.3, 0.6}, {0.08, 0.3}, {0.03, 0.1}};
  Measured previous;
  for (const auto& [dz, da] : settings) {
    const Measured run = measure(mesh, dz, da);
    if (previous.corners > 0) {
      EXPECT_GT(run.corners, previous.corners) << "dz " << dz;
      EXPECT_LT(run.distance, previous.distance) << "dz " << dz;
    }
    previous = run;
  }
}

// The property on real meshes: halving d_z and lowering d_a gives more corners and a
// closer shape. Measured (corners; Hausdorff distance in % of the diagonal) at (0.16, 0.5),
// (0.08, 0.3), (0.04, 0.15): eight 121, 230, 870; 9.6, 4.8, 3.0 — double-torus-example 159, 426,
// 1582; 8.1, 5.6, 3.1 — rotor 68, 254, 889; 23.2, 16.5, 5.5. Moving d_z and d_a by 5-10 %, the
// coarser setting finer and the finer one coarser, the worst ratios between neighbouring settings
// were 1.5 for corners and 0.85 for the distance (double-torus-example), so the bounds below
// (1.25 and 0.9) hold with room, not by luck.
TEST(Polycube, SmallerDzAndDaGiveMoreCornersAndACloserShapeOnTestMeshes) {
  for (const std::string name : {"eight.off", "double-torus-example.off", "rotor.off"}) {
    SCOPED_TRACE(name);
    const TriMesh mesh = test::load_test_mesh(name);
    const std::pair<double, double> settings[] = {{0.16, 0.5}, {0.08, 0.3}, {0.04, 0.15}};
    Measured previous;
    for (const auto& [dz, da] : settings) {
      const Measured run = measure(mesh, dz, da);
      if (previous.corners > 0) {
        EXPECT_GT(run.corners, 1.25 * previous.corners) << "dz " << dz;
        EXPECT_LT(run.distance, 0.9 * previous.distance) << "dz " << dz;
      }
      previous = run;
    }
  }
}

// The stacking repairs subdivide cells along whole contours and neighbouring planes' staircases
// differ; the simplification merges back what the checks do not need and lets each Q_i follow its
// neighbours: fewer corners, still valid, same planes.
TEST(Polycube, SimplificationRemovesCornersAndKeepsTheGuarantee) {
  const TriMesh mesh = test::load_test_mesh("elk.off");
  const TopologyResult topology = analyse_topology(mesh);
  PolycubeOptions options;
  options.simplify = false;
  const PolycubeResult refined = build(mesh, topology, options);
  const PolycubeResult simplified = build(mesh, topology);
  expect_valid_polycube(topology, refined);
  expect_valid_polycube(topology, simplified);
  ASSERT_GT(refined.stacking_splits, 0);
  EXPECT_EQ(refined.coarsening_merges + refined.snapped_cells, 0);
  EXPECT_GT(simplified.coarsening_merges, 0);
  EXPECT_GT(simplified.snapped_cells, 0);
  EXPECT_EQ(simplified.planes_z, refined.planes_z);
  EXPECT_LT(simplified.polycube.corners.size(), refined.polycube.corners.size());
}

TEST(Polycube, SmallerDaAloneGivesACloserShape) {
  const TriMesh mesh = test::make_genus_surface(0, 32);
  const TopologyResult topology = analyse_topology(mesh);
  double previous = 1e300;
  size_t previous_corners = 0;
  for (double da : {0.5, 0.2, 0.05}) {
    PolycubeOptions options;
    options.da = da;
    const PolycubeResult result = build(mesh, topology, options);
    EXPECT_LE(result.max_region_error, da + 1e-12);
    const double distance = hausdorff_distance(mesh, result.polycube.mesh).hausdorff;
    EXPECT_LT(distance, previous) << "da " << da;
    EXPECT_GT(result.polycube.corners.size(), previous_corners) << "da " << da;
    previous = distance;
    previous_corners = result.polycube.corners.size();
  }
}

// same_polycube tells a build that repeats another (map: a finer-contours attempt not mapped
// again) from one that does not: a box's square sections are the same at any d_a, a sphere's
// round ones are not, and another triangulation of the same P is another P.
TEST(Polycube, SamePolycubeIsTheSameBuildOnly) {
  const TriMesh box = gridded_unit_cube(6);
  const TopologyResult box_topology = analyse_topology(box);
  PolycubeOptions coarse, fine, denser;
  fine.da = coarse.da / 3;
  denser.min_vertices = 4 * box.num_vertices();
  const PolycubeResult box_coarse = build(box, box_topology, coarse);
  EXPECT_TRUE(same_polycube(box_coarse, build(box, box_topology, coarse)));
  EXPECT_TRUE(same_polycube(box_coarse, build(box, box_topology, fine)));
  const PolycubeResult box_denser = build(box, box_topology, denser);
  ASSERT_EQ(box_denser.polycube.corners.size(), box_coarse.polycube.corners.size());
  EXPECT_FALSE(same_polycube(box_coarse, box_denser));
  const TriMesh sphere = test::make_genus_surface(0, 32);
  const TopologyResult sphere_topology = analyse_topology(sphere);
  const PolycubeResult sphere_coarse = build(sphere, sphere_topology, coarse);
  const PolycubeResult sphere_fine = build(sphere, sphere_topology, fine);
  ASSERT_NE(sphere_fine.polycube.corners.size(), sphere_coarse.polycube.corners.size());
  EXPECT_FALSE(same_polycube(sphere_coarse, sphere_fine));
  EXPECT_FALSE(same_polycube(sphere_fine, sphere_coarse));
}

TEST(Polycube, TargetVertexCountSetsTheResolution) {
  const TriMesh mesh = test::make_sphere(3);
  const TopologyResult topology = analyse_topology(mesh);
  const PolycubeResult like_model = build(mesh, topology);
  EXPECT_GT(like_model.polycube.mesh.num_vertices(), mesh.num_vertices() / 2);
  EXPECT_LT(like_model.polycube.mesh.num_vertices(), mesh.num_vertices() * 2);
  for (int target : {500, 4000, 20000}) {
    PolycubeOptions options;
    options.target_vertices = target;
    const PolycubeResult result = build(mesh, topology, options);
    expect_valid_polycube(topology, result);
    EXPECT_GT(result.polycube.mesh.num_vertices(), target / 2) << target;
    EXPECT_LT(result.polycube.mesh.num_vertices(), target * 2) << target;
  }
}

TEST(Polycube, ResultDoesNotDependOnScaleOrPosition) {
  const TriMesh mesh = test::make_genus_surface(2, 24);
  const PolycubeResult reference = build(mesh, analyse_topology(mesh));
  for (double scale : {1e-4, 1e4}) {
    TriMesh moved = mesh;
    moved.V = ((mesh.V * scale).rowwise() + Eigen::RowVector3d(3, -7, 11) * scale).eval();
    const TopologyResult topology = analyse_topology(moved);
    const PolycubeResult result = build(moved, topology);
    expect_valid_polycube(topology, result);
    EXPECT_EQ(result.polycube.corners.size(), reference.polycube.corners.size()) << scale;
    EXPECT_EQ(result.polycube.faces.size(), reference.polycube.faces.size()) << scale;
  }
}

TEST(Polycube, RejectsBadOptions) {
  const TriMesh mesh = test::make_sphere(2);
  const TopologyResult topology = analyse_topology(mesh);
  PolycubeOptions options;
  options.da = 0;
  EXPECT_THROW(build(mesh, topology, options), std::invalid_argument);
  TopologyResult empty;
  EXPECT_THROW(build(mesh, empty), std::invalid_argument);
}

TEST(Polycube, GivesUpWithAClearErrorWithinItsLimits) {
  // The tilted thin torus needs repairs; with a single round allowed the stage must fail with
  // AlgorithmError rather than return an invalid polycube.
  const TriMesh mesh = tilted_thin_torus();
  const TopologyResult topology = analyse_topology(mesh, coarse_planes());
  PolycubeOptions options;
  options.max_rounds = 1;
  try {
    build(mesh, topology, options);
    ADD_FAILURE() << "expected AlgorithmError";
  } catch (const AlgorithmError& e) {
    EXPECT_NE(std::string(e.what()).find("build_polycube"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("slab"), std::string::npos) << e.what();
  }
  options.max_rounds = 80;
  options.max_inserted_planes = 0;
  options.refine_attempts = 0;
  options.max_plane_cells = 1;  // no subdivision either: only relabelling may help
  try {
    const PolycubeResult result = build(mesh, topology, options);
    expect_valid_polycube(topology, result);
    EXPECT_EQ(result.planes_inserted, 0);
  } catch (const AlgorithmError& e) {
    EXPECT_NE(std::string(e.what()).find("build_polycube"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace polycube
