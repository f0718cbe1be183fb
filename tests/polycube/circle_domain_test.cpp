// circle_domain: the uniform flat metric laid out in the plane is a circle domain (Fig. 5): the
// outer loop on the unit circle, the others on circles inside it, the intrinsic triangulation
// embedded (no flipped triangle). A tube of height h and circumference c becomes an annulus of
// conformal modulus ln(R/r) = 2πh/c; a disk-like piece a disk; scaling changes nothing.
#include "polycube/circle_domain.h"

#include "polycube/errors.h"
#include "polycube/flat_metric.h"
#include "polycube/mesh_topology.h"
#include "polycube/piece_mesh.h"
#include "polycube/ricci_pieces.h"
#include "polycube/slice.h"
#include "polycube/topology.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace polycube {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Conformal modulus ln(R/r) of the annulus between the unit circle and an inner circle of radius
// r centred at distance d (Möbius-invariant: the concentric annulus it is equivalent to).
double annulus_modulus(double r, double d) { return std::acosh((1 + r * r - d * d) / (2 * r)); }

void expect_circle_domain(const TriMesh& piece, const FlatMetric& fm, const CircleDomain& cd) {
  ASSERT_EQ(cd.uv.rows(), piece.num_vertices());
  ASSERT_EQ(cd.inserted_uv.rows(), static_cast<int>(fm.inserted_vertices.size()));
  EXPECT_EQ(cd.flipped_triangles, 0);
  // Round to 1e-8 relative, or to 1e-13 absolute (units of the outer radius) on tiny holes.
  EXPECT_LE(cd.max_roundness_error, std::max(1e-8, 1e-13 / cd.min_radius));
  EXPECT_LE(cd.layout_error, 1e-9);
  EXPECT_EQ(cd.outer_loop, fm.outer_loop);
  const int nl = static_cast<int>(fm.loops.size());
  ASSERT_EQ(static_cast<int>(cd.centres.size()), nl);
  EXPECT_EQ(cd.centres[cd.outer_loop], Eigen::Vector2d::Zero());
  EXPECT_EQ(cd.radii[cd.outer_loop], 1.0);
  // The outer loop's first (input) vertex on the positive x axis.
  const int first = fm.loops[cd.outer_loop][0];
  EXPECT_NEAR(cd.uv(first, 0), 1.0, 1e-9);
  EXPECT_NEAR(cd.uv(first, 1), 0.0, 1e-9);
  // Every vertex on its circle; the holes inside the unit disk; all vertices in the unit disk.
  auto position = [&](int v) -> Eigen::Vector2d {
    return v < piece.num_vertices() ? Eigen::Vector2d(cd.uv.row(v)) : Eigen::Vector2d(cd.inserted_uv.row(v - piece.num_vertices()));
  };
  // The region is the outer polygon minus the inner polygons, all inscribed in their circles:
  // an inner circle may bulge past the outer circle by the outer polygon's largest sagitta.
  double sagitta = 0;
  const auto& outer_loop = fm.loops[cd.outer_loop];
  for (size_t k = 0; k < outer_loop.size(); ++k) {
    const double chord = (position(outer_loop[k]) - position(outer_loop[(k + 1) % outer_loop.size()])).norm();
    sagitta = std::max(sagitta, 1 - std::sqrt(std::max(0.0, 1 - chord * chord / 4)));
  }
  for (int l = 0; l < nl; ++l) {
    if (l != cd.outer_loop) {
      EXPECT_LT(cd.centres[l].norm() + cd.radii[l], 1 + sagitta + 1e-9);
    }
    for (int v : fm.loops[l])
      EXPECT_NEAR((position(v) - cd.centres[l]).norm(), cd.radii[l], 1e-8 * cd.radii[l] + 1e-13);
  }
  for (int v = 0; v < piece.num_vertices(); ++v) EXPECT_LE(cd.uv.row(v).norm(), 1 + 1e-9);
  // Flipped input triangles, counted independently.
  int flipped = 0;
  for (int f = 0; f < piece.num_faces(); ++f) {
    const Eigen::Vector2d a = cd.uv.row(piece.F(f, 0)), b = cd.uv.row(piece.F(f, 1)), c = cd.uv.row(piece.F(f, 2));
    if (!((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x() > 0)) ++flipped;
  }
  EXPECT_EQ(flipped, cd.flipped_input_triangles);
}

TEST(CircleDomain, TubeGivesAnAnnulusOfTheRightModulus) {
  for (double h : {0.25, 1.0}) {
    SCOPED_TRACE("height " + std::to_string(h));
    const int n = 96;
    const TriMesh m = test::make_tube(1, h, n, static_cast<int>(std::round(h * n / (2 * kPi))) + 1);
    const FlatMetric fm = flat_metric(m, boundary_loops(m.F));
    const CircleDomain cd = circle_domain(m, fm);
    expect_circle_domain(m, fm, cd);
    EXPECT_EQ(cd.flipped_input_triangles, 0);
    const int inner = 1 - cd.outer_loop;
    const double circumference = 2 * n * std::sin(kPi / n);  // of the polygon
    const double modulus = annulus_modulus(cd.radii[inner], cd.centres[inner].norm());
    EXPECT_NEAR(modulus, 2 * kPi * h / circumference, 2e-3 * 2 * kPi * h / circumference);
    // Symmetric input, balanced outer loop: concentric circles.
    EXPECT_LT(cd.centres[inner].norm(), 1e-9 * cd.radii[inner]);
    EXPECT_EQ(cd.min_radius, cd.radii[inner]);
  }
}

TEST(CircleDomain, SliversStayEmbeddedInTheIntrinsicTriangulation) {
  // Slivers along both loops of a tube (apex over the middle of the loop edges, 1e-4 away):
  // drawn with straight edges some input triangles of the outer loop fall outside their chord,
  // the intrinsic triangulation (with the split outer edges) stays embedded.
  TriMesh m = test::make_tube(1, 1, 40, 10);
  for (int j : {1, 9})
    for (int i = 0; i < 40; ++i) {
      const double angle = 2 * kPi * (i + 0.5) / 40;
      m.V.row(j * 40 + i) << std::cos(angle), std::sin(angle), j == 1 ? 1e-4 : 1 - 1e-4;
    }
  const FlatMetric fm = flat_metric(m, boundary_loops(m.F));
  const CircleDomain cd = circle_domain(m, fm);
  expect_circle_domain(m, fm, cd);
  EXPECT_GT(cd.flipped_input_triangles, 0);
  EXPECT_LE(cd.flipped_input_triangles, 40);
}

TEST(CircleDomain, DiskGivesADisk) {
  const SlicedMesh sliced = slice_mesh(test::make_sphere(3), {0.45});
  for (int p = 0; p < static_cast<int>(sliced.pieces.size()); ++p) {
    const PieceMesh piece = extract_piece(sliced, p);
    ASSERT_EQ(piece.loops.size(), 1u);
    const FlatMetric fm = flat_metric(piece.mesh, piece.loops);
    const CircleDomain cd = circle_domain(piece.mesh, fm);
    expect_circle_domain(piece.mesh, fm, cd);
    EXPECT_EQ(cd.min_circle_gap, 1.0);
  }
}

TEST(CircleDomain, EveryPieceOfSlicedTestMeshes) {
  for (const std::string name : {"torus_quad.off", "double-torus-example.off", "eight.off", "joint.off", "helmet.off",
                                 "rotor.off", "anchor.off", "couplingdown.off"}) {
    SCOPED_TRACE(name);
    const TopologyResult topo = analyse_topology(test::load_test_mesh(name));
    for (int p = 0; p < static_cast<int>(topo.sliced.pieces.size()); ++p) {
      SCOPED_TRACE("piece " + std::to_string(p));
      const PieceMesh piece = extract_piece(topo.sliced, p);
      const FlatMetric fm = flat_metric(piece.mesh, piece.loops);
      expect_circle_domain(piece.mesh, fm, circle_domain(piece.mesh, fm));
    }
  }
}

TEST(CircleDomain, UnchangedUnderScaling) {
  const TopologyResult topo = analyse_topology(test::load_test_mesh("double-torus-example.off"));
  for (int p = 0; p < static_cast<int>(topo.sliced.pieces.size()); ++p) {
    const PieceMesh piece = extract_piece(topo.sliced, p);
    const CircleDomain reference = circle_domain(piece.mesh, flat_metric(piece.mesh, piece.loops));
    for (double s : {1e8, 1e-8}) {
      TriMesh scaled = piece.mesh;
      scaled.V *= s;
      const CircleDomain cd = circle_domain(scaled, flat_metric(scaled, piece.loops));
      EXPECT_LE((cd.uv - reference.uv).cwiseAbs().maxCoeff(), 1e-9) << "piece " << p << " scale " << s;
      for (size_t l = 0; l < cd.radii.size(); ++l) EXPECT_NEAR(cd.radii[l], reference.radii[l], 1e-9);
    }
  }
}

TEST(CircleDomain, AllPiecesOfASlicedMeshOnThreads) {
  const TopologyResult topo = analyse_topology(test::load_test_mesh("eight.off"));
  RicciPiecesOptions options;
  options.threads = 1;
  const RicciPieces serial = ricci_pieces(topo.sliced, options);
  options.threads = 2;
  const RicciPieces parallel = ricci_pieces(topo.sliced, options);
  EXPECT_EQ(parallel.threads, 2);
  ASSERT_EQ(serial.pieces.size(), topo.sliced.pieces.size());
  ASSERT_EQ(parallel.pieces.size(), topo.sliced.pieces.size());
  for (size_t p = 0; p < serial.pieces.size(); ++p) {
    const PieceDomain& a = serial.pieces[p];
    const PieceDomain& b = parallel.pieces[p];
    EXPECT_EQ(a.piece.vertex_to_global, extract_piece(topo.sliced, static_cast<int>(p)).vertex_to_global);
    EXPECT_EQ(a.metric.u, b.metric.u) << "piece " << p;  // each piece on its own: same result
    EXPECT_EQ(a.domain.uv, b.domain.uv) << "piece " << p;
    expect_circle_domain(a.piece.mesh, a.metric, a.domain);
  }
  // A failing piece is reported by number, with its own exception type.
  SlicedMesh broken = topo.sliced;
  std::reverse(broken.pieces[2].boundary_loops[0].begin(), broken.pieces[2].boundary_loops[0].end());
  try {
    ricci_pieces(broken, options);
    FAIL() << "expected MeshError";
  } catch (const MeshError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("piece 2: flat_metric:", 0), 0u) << e.what();
  }
}

TEST(CircleDomain, RejectsAMetricOfAnotherPiece) {
  const TriMesh a = test::make_tube(1, 1, 12, 3), b = test::make_tube(1, 1, 16, 3);
  EXPECT_THROW(circle_domain(b, flat_metric(a, boundary_loops(a.F))), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
