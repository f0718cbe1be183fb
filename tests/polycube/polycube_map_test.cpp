// build_polycube_map (§3.4): per piece pair both disk maps are embeddings; the glued map and its
// inverse land on the surfaces, undo each other, and agree across the cutting contours; the
// boundary map ψ keeps anchors and orientation.
#include "polycube/polycube_map.h"

#include "polycube/contour_map.h"
#include "polycube/map_audit.h"
#include "polycube/mesh_topology.h"
#include "polycube/piece_disk.h"
#include "polycube/topology.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

namespace polycube {
namespace {

using namespace test;

struct Pipeline {
  TriMesh model;
  PolycubeResult polycube;
  PolycubeMap map;
};

Pipeline run(const TriMesh& model) {
  Pipeline p;
  p.model = model;
  const TopologyResult topology = analyse_topology(model);
  p.polycube = build_polycube(model, topology);
  p.map = build_polycube_map(model, p.polycube);
  return p;
}

// A random point of a random face (area-weighted is not needed here).
SurfacePoint random_point(const TriMesh& mesh, std::mt19937& rng) {
  std::uniform_int_distribution<int> face(0, mesh.num_faces() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double a = unit(rng), b = unit(rng);
  if (a + b > 1) {
    a = 1 - a;
    b = 1 - b;
  }
  SurfacePoint p;
  p.face = face(rng);
  p.bary = Eigen::Vector3d(1 - a - b, a, b);
  return p;
}

class PolycubeMapOnMeshes : public ::testing::TestWithParam<std::string> {};

TEST_P(PolycubeMapOnMeshes, DisksEmbedImagesOnSurfacesRoundTrip) {
  const std::string name = GetParam();
  const TriMesh model = name == "rocker-arm.obj" ? load_mesh_file(example_path(name)) : load_test_mesh(name);
  const Pipeline p = run(model);
  const TriMesh& P = p.polycube.polycube.mesh;
  ASSERT_EQ(p.map.pieces.size(), p.polycube.model_sliced.pieces.size());
  for (const PieceMapStats& s : p.map.pieces) {
    EXPECT_EQ(s.flipped_model_disk, 0) << name << " piece " << s.model_piece;
    EXPECT_EQ(s.flipped_polycube_disk, 0) << name << " piece " << s.model_piece;
    EXPECT_GT(s.min_disk_area, 0) << name << " piece " << s.model_piece;
    EXPECT_EQ(s.slits, s.loops - 1) << name << " piece " << s.model_piece;
  }
  ASSERT_EQ(p.map.polycube_on_model_xyz.rows(), P.num_vertices());
  ASSERT_EQ(p.map.model_on_polycube_xyz.rows(), model.num_vertices());

  // Images lie on the other surface (judged by the independent audit).
  const MapAudit audit = audit_map(model, P, p.map.polycube_on_model_xyz, p.map.model_on_polycube_xyz);
  EXPECT_LT(audit.polycube_to_model.max_distance, 1e-9) << name;
  EXPECT_LT(audit.model_to_polycube.max_distance, 1e-9) << name;
  EXPECT_EQ(audit.polycube_to_model.degenerate + audit.model_to_polycube.degenerate, 0) << name;

  // The audit's verdicts do not depend on the frame: the unsmoothed map's images lie on P's edges
  // and vertices, where faces tie for closest; the same meshes and images turned (an exact axis
  // permutation with a reflection-free sign change, and a generic rotation) audit the same.
  for (const Eigen::Matrix3d& R : {Eigen::Matrix3d((Eigen::Matrix3d() << 0, 1, 0, 0, 0, -1, -1, 0, 0).finished()),
                                   Eigen::Matrix3d(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix())}) {
    TriMesh model_turned = model, P_turned = P;
    model_turned.V = model.V * R.transpose();
    P_turned.V = P.V * R.transpose();
    const MapAudit turned = audit_map(model_turned, P_turned, p.map.polycube_on_model_xyz * R.transpose(),
                                      p.map.model_on_polycube_xyz * R.transpose());
    EXPECT_EQ(turned.polycube_to_model.flipped, audit.polycube_to_model.flipped) << name;
    EXPECT_EQ(turned.model_to_polycube.flipped, audit.model_to_polycube.flipped) << name;
  }

  // φ⁻¹ ∘ φ and φ ∘ φ⁻¹ are the identity at random points.
  const double diagonal = bounding_box(model.V).diagonal();
  std::mt19937 rng(7);
  double worst = 0;
  for (int k = 0; k < 300; ++k) {
    const SurfacePoint x = random_point(P, rng);
    const Eigen::Vector3d back = surface_position(P, p.map.to_polycube(p.map.to_model(x)));
    worst = std::max(worst, (back - surface_position(P, x)).norm());
    const SurfacePoint y = random_point(model, rng);
    const Eigen::Vector3d forth = surface_position(model, p.map.to_model(p.map.to_polycube(y)));
    worst = std::max(worst, (forth - surface_position(model, y)).norm());
  }
  EXPECT_LT(worst / diagonal, 1e-7) << name;

  // Continuous across the contours: the two sides of a plane, 2e-11 of the diagonal apart inside
  // one triangle of P, land next to each other on the model (a seam would leave a gap of the
  // order of the mesh spacing).
  int crossings = 0;
  double jump = 0;
  for (int f = 0; f < P.num_faces() && crossings < 200; ++f) {
    const Eigen::Vector3d a = P.V.row(P.F(f, 0)), b = P.V.row(P.F(f, 1)), c = P.V.row(P.F(f, 2));
    for (double z : p.polycube.planes_z) {
      // Where the plane crosses edge ab (if it does), nudged up and down along the edge.
      if ((a.z() - z) * (b.z() - z) >= 0) continue;
      const double t = (z - a.z()) / (b.z() - a.z());
      const double dt = 1e-11 * diagonal / (b - a).norm();
      SurfacePoint lo, hi;
      lo.face = hi.face = f;
      lo.bary = Eigen::Vector3d(1 - (t - dt), t - dt, 0);
      hi.bary = Eigen::Vector3d(1 - (t + dt), t + dt, 0);
      const Eigen::Vector3d ml = surface_position(model, p.map.to_model(lo)), mh = surface_position(model, p.map.to_model(hi));
      jump = std::max(jump, (ml - mh).norm());
      ++crossings;
      (void)c;
    }
  }
  EXPECT_GT(crossings, 0) << name;
  EXPECT_LT(jump / diagonal, 1e-6) << name;
}

INSTANTIATE_TEST_SUITE_P(Meshes, PolycubeMapOnMeshes,
                         ::testing::Values("sphere.off", "eight.off", "knot.off", "helmet.off", "double-torus-example.off", "rocker-arm.obj"),
                         [](const auto& info) { return test::test_name_of_file(info.param); });

// Surfaces no one tuned for: generated genus 5 and 11. Every disk embeds, φ⁻¹ ∘ φ is the identity
// and the images lie on the surfaces.
TEST(PolycubeMap, GeneratedHighGenusSurfaces) {
  for (int g : {5, 11}) {
    const TriMesh model = make_genus_surface(g, 40);
    const Pipeline p = run(model);
    EXPECT_EQ(p.polycube.genus, g);
    for (const PieceMapStats& s : p.map.pieces) {
      EXPECT_EQ(s.flipped_model_disk + s.flipped_polycube_disk, 0) << "genus " << g << " piece " << s.model_piece;
    }
    const TriMesh& P = p.polycube.polycube.mesh;
    const MapAudit audit = audit_map(model, P, p.map.polycube_on_model_xyz, p.map.model_on_polycube_xyz);
    EXPECT_LT(audit.polycube_to_model.max_distance, 1e-9);
    EXPECT_LT(audit.model_to_polycube.max_distance, 1e-9);
    const double diagonal = bounding_box(model.V).diagonal();
    std::mt19937 rng(11);
    double worst = 0;
    for (int k = 0; k < 200; ++k) {
      const SurfacePoint x = random_point(P, rng);
      worst = std::max(worst, (surface_position(P, p.map.to_polycube(p.map.to_model(x))) - surface_position(P, x)).norm());
    }
    EXPECT_LT(worst / diagonal, 1e-7) << "genus " << g;
  }
}

// On a finely meshed model the image of P covers the model's area (the 2 %).
TEST(PolycubeMap, ImageOfPolycubeCoversTheModel) {
  const TriMesh model = load_mesh_file(example_path("rocker-arm.obj"));
  const Pipeline p = run(model);
  const MapAudit audit = audit_map(model, p.polycube.polycube.mesh, p.map.polycube_on_model_xyz, p.map.model_on_polycube_xyz);
  EXPECT_NEAR(audit.polycube_to_model.area_ratio, 1.0, 0.02);
}

// ψ on a circle and a square around the same centre: both counter-clockwise whatever the input
// orientation, anchors get equal u, u is increasing along both curves, and the rotation found by
// eq. 6 puts the square's corners next to the circle's points at the same angle.
TEST(ContourMap, CircleToSquare) {
  const int n = 96;
  Eigen::MatrixX3d circle(n, 3), square(16, 3);
  std::vector<int> circle_loop, square_loop;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n + 0.3;  // starts at angle 0.3
    circle.row(i) << std::cos(t), std::sin(t), 0.5;
    circle_loop.push_back(n - 1 - i);  // clockwise on input
  }
  for (int i = 0; i < 16; ++i) {
    const int side = i / 4, k = i % 4;
    const double s = -1 + 0.5 * k;
    Eigen::Vector2d q;
    if (side == 0) q = {1, s};
    if (side == 1) q = {-s, 1};
    if (side == 2) q = {-1, -s};
    if (side == 3) q = {s, -1};
    square.row(i) << 0.9 * q.x(), 0.9 * q.y(), 0.5;
    square_loop.push_back(i);
  }
  ContourMap map = start_contour_map(circle_loop, circle, square_loop, square);
  // Counter-clockwise: positive shoelace area.
  auto area = [](const std::vector<int>& loop, const Eigen::MatrixX3d& V) {
    double a = 0;
    for (size_t i = 0; i < loop.size(); ++i) {
      const auto p = V.row(loop[i]), q = V.row(loop[(i + 1) % loop.size()]);
      a += p.x() * q.y() - q.x() * p.y();
    }
    return a;
  };
  EXPECT_GT(area(map.model_vertices, circle), 0);
  EXPECT_GT(area(map.polycube_vertices, square), 0);
  add_anchor(map, 10);
  add_anchor(map, 50);
  add_anchor(map, 10);
  finish_contour_map(map, circle, square);
  ASSERT_EQ(map.anchors.size(), 2u);
  for (const auto& [m, q] : map.anchors) EXPECT_EQ(map.model_u[m], map.polycube_u[q]);
  EXPECT_EQ(anchor_of(map, 10), map.anchors[0].first == 10 ? map.anchors[0].second : map.anchors[1].second);
  // ψ moves points by less than the gap between the curves plus the polygon's corner offset.
  EXPECT_LT(map.rms_distance, 0.3);
  // u increases along both loops (one wrap each).
  auto wraps = [](const std::vector<double>& u) {
    int w = 0;
    for (size_t i = 0; i < u.size(); ++i) w += u[(i + 1) % u.size()] < u[i];
    return w;
  };
  EXPECT_EQ(wraps(map.model_u), 1);
  EXPECT_EQ(wraps(map.polycube_u), 1);
  EXPECT_TRUE(std::is_sorted(map.u.begin(), map.u.end()));
  EXPECT_EQ(map.u.size(), map.model_at.size());
}

// A thin-walled pipe standing on its axis (walls 1.5 % of its diameter apart): each slab's piece
// is a band, and the slits of the bands below and above a contour end next to each other. The
// raw map (no refinement, no smoothing) covers the model once: before the slit ends were pinned
// in order, P's image covered 1.8 times the model's area with 539 / 260 flipped triangles.
TEST(PolycubeMap, ThinWalledPipeStandingOnItsAxis) {
  const TriMesh model = make_pipe(1.0, 0.97, 2.0, 96, 16);
  const Pipeline p = run(model);
  const MapAudit audit = audit_map(model, p.polycube.polycube.mesh, p.map.polycube_on_model_xyz, p.map.model_on_polycube_xyz);
  EXPECT_NEAR(audit.polycube_to_model.area_ratio, 1.0, 0.02);
  EXPECT_EQ(audit.polycube_to_model.flipped, 0);
  EXPECT_LT(audit.model_to_polycube.flipped, 20);  // the raw map's few, which the untangling clears (`map`: 0)
}

// Two slit ends close together on a contour whose polygon has one vertex between them and the
// next a long edge away on either side (a thin-walled pipe's bands: the slits of the pieces below
// and above end 0.13 % of the contour apart): the second end is pinned after the first, not just
// behind it, which would leave the pinned map the whole contour but one edge to squeeze into
// that edge.
TEST(ContourMap, CloseSlitEndsArePinnedInOrder) {
  const int n = 720;
  Eigen::MatrixX3d circle(n, 3), octagon(8, 3);
  std::vector<int> circle_loop, octagon_loop;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n;
    circle.row(i) << std::cos(t), std::sin(t), 0.5;
    circle_loop.push_back(i);
  }
  for (int i = 0; i < 8; ++i) {
    const double t = 2 * M_PI * i / 8 + 0.05;  // a vertex just past both ends
    octagon.row(i) << std::cos(t), std::sin(t), 0.5;
    octagon_loop.push_back(i);
  }
  const int first_end = 2, second_end = 4;  // at angles 0.017 and 0.035
  // Added in model order, the second end is pinned after the first: the circular rule put it
  // just behind the first (arc 0.875). Added the other way round, the first pin goes to the
  // vertex past both ends and the other end to the one before it, by either rule: that case
  // checks that the insertion order does not matter.
  for (const bool reversed : {false, true}) {
    ContourMap map = start_contour_map(circle_loop, circle, octagon_loop, octagon);
    add_anchor(map, reversed ? second_end : first_end);
    add_anchor(map, reversed ? first_end : second_end);
    finish_contour_map(map, circle, octagon);
    const int a = anchor_of(map, first_end), b = anchor_of(map, second_end);
    ASSERT_NE(a, b);
    // Forwards (counter-clockwise) from the first end to the second: one edge of the octagon, not
    // seven.
    double arc = map.polycube_u[b] - map.polycube_u[a];
    arc -= std::floor(arc);
    EXPECT_NEAR(arc, 0.125, 1e-9) << (reversed ? "second end added first" : "first end added first");
    // So the model's contour away from the two ends keeps most of the parameter.
    double model_arc = map.model_u[first_end] - map.model_u[second_end];
    model_arc -= std::floor(model_arc);
    EXPECT_GT(model_arc, 0.8);
  }
}

// A tube cut by one slit is a disk; its embedding has no flipped triangle, and splitting inner
// edges keeps the boundary and the area.
TEST(PieceDisk, TubeCutAndEmbedded) {
  const TriMesh tube = make_tube(1.0, 2.0, 24, 6);
  const std::vector<std::vector<int>> loops = boundary_loops(tube.F);
  ASSERT_EQ(loops.size(), 2u);
  const EdgeLength length = [&](int a, int b) { return (tube.V.row(a) - tube.V.row(b)).norm(); };
  const std::vector<Slit> slits = find_slits(tube, loops, 0, length);
  ASSERT_EQ(slits.size(), 1u);
  const CutDisk cut = cut_open(tube, slits);
  EXPECT_EQ(cut.mesh.num_vertices(), tube.num_vertices() + static_cast<int>(slits[0].path.size()));
  const int nb = static_cast<int>(cut.boundary.size());
  std::vector<double> angle(nb);
  for (int k = 0; k < nb; ++k) angle[k] = 2 * M_PI * k / nb;
  const DiskEmbedding disk = embed_disk(cut, angle, std::vector<std::vector<std::pair<double, double>>>(nb));
  EXPECT_EQ(disk.flipped, 0);
  EXPECT_GT(disk.min_area, 0);

  std::vector<int> parent;
  const TriMesh split = split_inner_edges(tube, parent);
  EXPECT_NEAR(surface_area(split), surface_area(tube), 1e-12);
  EXPECT_EQ(boundary_loops(split.F).size(), 2u);
  EXPECT_EQ(static_cast<int>(parent.size()), split.num_faces());
}

// A square plate with a blind pocket (a square tube one cell wide and 14 cells deep, closed at the
// end), as the one disk of a piece: the harmonic map squeezes the pocket to a point (each ring of
// 4 vertices shrinks it by ~e^-π in area). decrowd_disk spreads it by lowering weights: still no
// flipped triangle, the boundary where it was, the plate away from the pocket nearly unmoved.
TEST(PieceDisk, PocketSqueezedByTheHarmonicMapIsSpread) {
  const int m = 6, side = 2 * m + 2, depth = 14;
  std::vector<Eigen::Vector3d> V;
  std::vector<Eigen::Vector3i> F;
  auto plate = [&](int i, int j) { return j * side + i; };
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) V.emplace_back(i - m - 0.5, j - m - 0.5, 0.0);
  for (int j = 0; j + 1 < side; ++j)
    for (int i = 0; i + 1 < side; ++i) {
      if (i == m && j == m) continue;  // the pocket's mouth
      F.emplace_back(plate(i, j), plate(i + 1, j), plate(i + 1, j + 1));
      F.emplace_back(plate(i, j), plate(i + 1, j + 1), plate(i, j + 1));
    }
  std::vector<int> ring = {plate(m, m), plate(m + 1, m), plate(m + 1, m + 1), plate(m, m + 1)};
  for (int t = 1; t <= depth; ++t) {
    std::vector<int> next;
    for (int k = 0; k < 4; ++k) {
      next.push_back(static_cast<int>(V.size()));
      V.push_back(V[ring[k]] - Eigen::Vector3d(0, 0, 1));
    }
    for (int k = 0; k < 4; ++k) {
      const int a = ring[k], b = ring[(k + 1) % 4], c = next[(k + 1) % 4], d = next[k];
      F.emplace_back(a, b, c);
      F.emplace_back(a, c, d);
    }
    ring = next;
  }
  const int end = static_cast<int>(V.size());
  V.push_back((V[ring[0]] + V[ring[2]]) / 2 - Eigen::Vector3d(0, 0, 0.5));
  for (int k = 0; k < 4; ++k) F.emplace_back(ring[k], ring[(k + 1) % 4], end);
  CutDisk cut;
  cut.mesh.V.resize(V.size(), 3);
  for (size_t v = 0; v < V.size(); ++v) cut.mesh.V.row(v) = V[v];
  cut.mesh.F.resize(F.size(), 3);
  for (size_t f = 0; f < F.size(); ++f) cut.mesh.F.row(f) = F[f];
  cut.vertex_origin.resize(V.size());
  std::iota(cut.vertex_origin.begin(), cut.vertex_origin.end(), 0);
  const std::vector<std::vector<int>> loops = boundary_loops(cut.mesh.F);
  ASSERT_EQ(loops.size(), 1u);
  cut.boundary = loops.front();
  const int nb = static_cast<int>(cut.boundary.size());
  std::vector<double> angle(nb);
  for (int k = 0; k < nb; ++k) angle[k] = 2 * M_PI * k / nb;
  DiskEmbedding disk = embed_disk(cut, angle, std::vector<std::vector<std::pair<double, double>>>(nb));
  ASSERT_EQ(disk.flipped, 0);

  // Crowding by the disk's own measure: a face's share of the disk over its share of the surface.
  const double total = surface_area(disk.mesh);
  const AreaRatio own = [&](const DiskEmbedding& d) {
    std::vector<double> ratio(d.mesh.num_faces());
    for (int f = 0; f < d.mesh.num_faces(); ++f) {
      const Eigen::Vector3d a = d.mesh.V.row(d.mesh.F(f, 0)), b = d.mesh.V.row(d.mesh.F(f, 1)), c = d.mesh.V.row(d.mesh.F(f, 2));
      ratio[f] = (uv_area(d, f) / M_PI) / (0.5 * (b - a).cross(c - a).norm() / total);
    }
    return ratio;
  };
  const std::vector<double> before = own(disk);
  const double worst_before = *std::min_element(before.begin(), before.end());
  ASSERT_LT(worst_before, 1e-12);  // the pocket's end really is squeezed
  const Eigen::MatrixX2d uv_before = disk.uv;

  const DecrowdResult result = decrowd_disk(disk, own);
  EXPECT_GT(result.iterations, 0);
  EXPECT_DOUBLE_EQ(result.min_ratio_before, worst_before);
  const std::vector<double> after = own(disk);
  const double worst_after = *std::min_element(after.begin(), after.end());
  EXPECT_DOUBLE_EQ(result.min_ratio_after, worst_after);
  EXPECT_GT(worst_after, 1e4 * worst_before);
  EXPECT_GT(worst_after, 1e-3);
  EXPECT_EQ(disk.flipped, 0);
  for (int f = 0; f < disk.mesh.num_faces(); ++f) EXPECT_GT(uv_area(disk, f), 0) << f;
  for (int v : cut.boundary) EXPECT_EQ(disk.uv.row(v), uv_before.row(v));
  // Plate vertices more than two cells from the mouth barely move.
  double far_moved = 0;
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i)
      if (std::max(std::abs(i - m - 0.5), std::abs(j - m - 0.5)) > 2.5)
        far_moved = std::max(far_moved, (disk.uv.row(plate(i, j)) - uv_before.row(plate(i, j))).norm());
  EXPECT_LT(far_moved, 0.05);

  // A disk with nothing below the trigger is left as it is.
  DiskEmbedding plain = embed_disk(cut, angle, std::vector<std::vector<std::pair<double, double>>>(nb));
  DecrowdOptions never;
  never.trigger = worst_before / 2;
  const DecrowdResult untouched = decrowd_disk(plain, own, never);
  EXPECT_EQ(untouched.iterations, 0);
  EXPECT_EQ(plain.uv, uv_before);
}

}  // namespace
}  // namespace polycube
