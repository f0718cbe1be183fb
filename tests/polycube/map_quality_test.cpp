// map_distortion: the paper's angle and area distortion (eq. 9, 10) on maps whose per-triangle
// singular values and areas are known by hand, and against an independent SVD computation.
#include "polycube/map_quality.h"

#include "support/generated_meshes.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace polycube {
namespace {

constexpr double kExact = 1e-12;

// Every distortion field equals value.
void expect_all(const DistortionStats& s, double angle, double area, double tolerance) {
  EXPECT_NEAR(s.eps_angle, angle, tolerance);
  EXPECT_NEAR(s.angle_p50, angle, tolerance);
  EXPECT_NEAR(s.angle_p95, angle, tolerance);
  EXPECT_NEAR(s.angle_max, angle, tolerance);
  EXPECT_NEAR(s.eps_area, area, tolerance);
  EXPECT_NEAR(s.area_p50, area, tolerance);
  EXPECT_NEAR(s.area_p95, area, tolerance);
  EXPECT_NEAR(s.area_max, area, tolerance);
}

// (n+1)^2 vertices in the plane z = 0 on [0, n]^2, moved by a deterministic jitter so that the
// triangles have many shapes; 2n^2 counter-clockwise triangles.
TriMesh jittered_grid(int n) {
  TriMesh mesh;
  mesh.V.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      mesh.V.row(i + (n + 1) * j) << i + 0.3 * std::sin(2.1 * i + 1.3 * j * j), j + 0.3 * std::cos(1.7 * i * j + 0.4 * j), 0;
  mesh.F.resize(2 * n * n, 3);
  int f = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = i + (n + 1) * j, b = a + 1, c = a + n + 2, d = a + n + 1;
      mesh.F.row(f++) << a, b, c;
      mesh.F.row(f++) << a, c, d;
    }
  return mesh;
}

Eigen::MatrixX3d transformed(const Eigen::MatrixX3d& V, const Eigen::Matrix3d& A, const Eigen::Vector3d& t = Eigen::Vector3d::Zero()) {
  return (V * A.transpose()).rowwise() + t.transpose();
}

// A square [-1, 1]^2 fanned from its centre (vertex 0): right, top, left, bottom triangles.
TriMesh fan_square() {
  TriMesh mesh;
  mesh.V.resize(5, 3);
  mesh.V << 0, 0, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0, -1, -1, 0;
  mesh.F.resize(4, 3);
  mesh.F << 0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1;
  return mesh;
}

// Independent reference: per triangle, the 3x2 Jacobian in an orthonormal frame of T, its
// singular values by SVD, and the area-weighted means with both meshes normalised to area 1.
DistortionStats by_singular_values(const TriMesh& domain, const Eigen::MatrixX3d& image) {
  std::vector<double> angle, area, image_area;
  double total = 0, total_image = 0;
  for (int f = 0; f < domain.num_faces(); ++f) {
    const Eigen::Vector3d p0 = domain.V.row(domain.F(f, 0)), p1 = domain.V.row(domain.F(f, 1)),
                          p2 = domain.V.row(domain.F(f, 2));
    const Eigen::Vector3d q0 = image.row(domain.F(f, 0)), q1 = image.row(domain.F(f, 1)), q2 = image.row(domain.F(f, 2));
    const Eigen::Vector3d e1 = (p1 - p0).normalized(), n = (p1 - p0).cross(p2 - p0).normalized(), e2 = n.cross(e1);
    Eigen::Matrix2d P;
    P << (p1 - p0).dot(e1), (p2 - p0).dot(e1), (p1 - p0).dot(e2), (p2 - p0).dot(e2);
    Eigen::Matrix<double, 3, 2> Q;
    Q << q1 - q0, q2 - q0;
    const Eigen::Matrix<double, 3, 2> J = Q * P.inverse();
    const Eigen::Vector2d s = Eigen::JacobiSVD<Eigen::Matrix<double, 3, 2>>(J).singularValues();
    angle.push_back((s[0] * s[0] + s[1] * s[1]) / (2 * s[0] * s[1]));
    area.push_back(0.5 * std::abs(P.determinant()));
    image_area.push_back(0.5 * (q1 - q0).cross(q2 - q0).norm());
    total += area.back();
    total_image += image_area.back();
  }
  DistortionStats s;
  s.eps_angle = s.eps_area = s.angle_max = s.area_max = 0;
  for (size_t f = 0; f < angle.size(); ++f) {
    const double w = image_area[f] / total_image, r = (area[f] / total) / w, area_change = 0.5 * (r + 1 / r);
    s.eps_angle += w * angle[f];
    s.eps_area += w * area_change;
    s.angle_max = std::max(s.angle_max, angle[f]);
    s.area_max = std::max(s.area_max, area_change);
  }
  return s;
}

// A smooth non-linear, orientation-preserving deformation of the unit sphere.
Eigen::MatrixX3d bent(const Eigen::MatrixX3d& V) {
  Eigen::MatrixX3d W(V.rows(), 3);
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const double x = V(v, 0), y = V(v, 1), z = V(v, 2);
    W.row(v) << 1.5 * x + 0.2 * std::sin(3 * y), y + 0.15 * std::cos(2 * z), 0.7 * z + 0.1 * std::sin(x + z);
  }
  return W;
}

TEST(MapQuality, IdentityIsExactlyOne) {
  for (const TriMesh& mesh : {test::make_sphere(3), test::make_torus(3, 1, 32, 16), jittered_grid(8)}) {
    const DistortionStats s = map_distortion(mesh, mesh.V);
    expect_all(s, 1, 1, kExact);
    EXPECT_EQ(s.triangles, mesh.num_faces());
    EXPECT_EQ(s.degenerate_domain, 0);
    EXPECT_EQ(s.degenerate_image, 0);
  }
}

TEST(MapQuality, SimilarityIsOne) {
  const TriMesh torus = test::make_torus(3, 1, 24, 12);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  expect_all(map_distortion(torus, transformed(torus.V, 7.5 * R, Eigen::Vector3d(1, -2, 3))), 1, 1, kExact);
  // Both areas are normalised, so any scale of either mesh is a similarity (scaled by 1e8, 1e-8).
  for (double scale : {1e8, 1e-8}) {
    SCOPED_TRACE(scale);
    expect_all(map_distortion(torus, scale * torus.V), 1, 1, kExact);
    TriMesh scaled = torus;
    scaled.V *= scale;
    expect_all(map_distortion(scaled, torus.V), 1, 1, kExact);
  }
}

TEST(MapQuality, StretchOfAFlatMeshHasKnownSingularValues) {
  // diag(2, 1): σ1 = 2, σ2 = 1 on every triangle, so ε_angle = (4 + 1) / (2·2·1) = 1.25 everywhere;
  // every area doubles, which normalisation removes: ε_area = 1.
  const TriMesh grid = jittered_grid(8);
  expect_all(map_distortion(grid, transformed(grid.V, Eigen::Vector3d(2, 1, 1).asDiagonal())), 1.25, 1, kExact);
  // The same stretch along an oblique direction of the plane, then moved rigidly into 3D.
  const Eigen::Matrix3d in_plane = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d rigid = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, -1, 2).normalized()).toRotationMatrix();
  const Eigen::Matrix3d A = rigid * in_plane * Eigen::Vector3d(2, 1, 1).asDiagonal() * in_plane.transpose();
  expect_all(map_distortion(grid, transformed(grid.V, A, Eigen::Vector3d(5, 0, -2))), 1.25, 1, kExact);
  // The inverse stretch (σ = 1/2, 1) has the same angle distortion.
  TriMesh stretched = grid;
  stretched.V = transformed(grid.V, Eigen::Vector3d(2, 1, 1).asDiagonal());
  expect_all(map_distortion(stretched, grid.V), 1.25, 1, kExact);
}

TEST(MapQuality, MovedCentreHasKnownPerTriangleValues) {
  // Moving the centre of the fanned square to (0.5, 0) keeps the outer vertices: the right
  // triangle is scaled by diag(0.5, 1) (area 1 -> 0.5), the left by diag(1.5, 1) (area 1 -> 1.5),
  // top and bottom are sheared by 0.5 (area 1). Total areas stay 4.
  //   ε_angle: right (0.25 + 1) / 1 = 1.25, left (2.25 + 1) / 3 = 13/12, shears (2 + 0.25) / 2 = 1.125
  //   ε_area:  right ½(2 + ½) = 1.25, left ½(2/3 + 3/2) = 13/12, shears 1
  //   weights A(T')/4: right 1/8, left 3/8, top 1/4, bottom 1/4
  const TriMesh square = fan_square();
  Eigen::MatrixX3d image = square.V;
  image.row(0) << 0.5, 0, 0;
  const DistortionStats s = map_distortion(square, image);
  EXPECT_NEAR(s.eps_angle, 1.25 / 8 + 3.0 / 8 * 13 / 12 + 0.5 * 1.125, kExact);
  EXPECT_NEAR(s.eps_area, 1.25 / 8 + 3.0 / 8 * 13 / 12 + 0.5, kExact);
  EXPECT_NEAR(s.eps_angle, 1.125, kExact);
  EXPECT_NEAR(s.eps_area, 1.0625, kExact);
  // Nearest rank over 4 values: p50 is the 2nd smallest, p95 the largest.
  EXPECT_NEAR(s.angle_p50, 1.125, kExact);
  EXPECT_NEAR(s.angle_p95, 1.25, kExact);
  EXPECT_NEAR(s.angle_max, 1.25, kExact);
  EXPECT_NEAR(s.area_p50, 1, kExact);
  EXPECT_NEAR(s.area_p95, 1.25, kExact);
  EXPECT_NEAR(s.area_max, 1.25, kExact);
  EXPECT_EQ(s.triangles, 4);
}

TEST(MapQuality, AreasAreNormalisedBeforeComparing) {
  // Two separate congruent right triangles; the image doubles the first (conformal, area 1/2 -> 2)
  // and keeps the second. Normalised image areas 0.8 and 0.2 against 0.5 and 0.5:
  //   ε_area = 0.8·½(0.625 + 1.6) + 0.2·½(2.5 + 0.4) = 0.8·1.1125 + 0.2·1.45 = 1.18
  TriMesh two;
  two.V.resize(6, 3);
  two.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 3, 0, 0, 4, 0, 0, 3, 1, 0;
  two.F.resize(2, 3);
  two.F << 0, 1, 2, 3, 4, 5;
  Eigen::MatrixX3d image = two.V;
  image.topRows(3) *= 2;
  for (double scale : {1.0, 10.0, 1e-3}) {
    SCOPED_TRACE(scale);
    const DistortionStats s = map_distortion(two, scale * image);
    EXPECT_NEAR(s.eps_angle, 1, kExact);
    EXPECT_NEAR(s.eps_area, 1.18, kExact);
    EXPECT_NEAR(s.area_p50, 1.1125, kExact);
    EXPECT_NEAR(s.area_max, 1.45, kExact);
  }
}

TEST(MapQuality, CotangentFormAgreesWithSingularValues) {
  const TriMesh sphere = test::make_sphere(2);
  const Eigen::MatrixX3d image = bent(sphere.V);
  const DistortionStats s = map_distortion(sphere, image), reference = by_singular_values(sphere, image);
  EXPECT_GT(s.eps_angle, 1.01) << "the deformation is far from conformal";
  EXPECT_NEAR(s.eps_angle, reference.eps_angle, 1e-10);
  EXPECT_NEAR(s.eps_area, reference.eps_area, 1e-10);
  EXPECT_NEAR(s.angle_max, reference.angle_max, 1e-10);
  EXPECT_NEAR(s.area_max, reference.area_max, 1e-10);
  EXPECT_LE(s.angle_p50, s.angle_p95);
  EXPECT_LE(s.angle_p95, s.angle_max);
  EXPECT_LE(s.area_p50, s.area_p95);
  EXPECT_LE(s.area_p95, s.area_max);
  EXPECT_GE(s.angle_p50, 1);
  EXPECT_GE(s.area_p50, 1);
}

TEST(MapQuality, InvariantUnderScalingEitherMesh) {
  const TriMesh sphere = test::make_sphere(2);
  const Eigen::MatrixX3d image = bent(sphere.V);
  const DistortionStats base = map_distortion(sphere, image);
  TriMesh big = sphere;
  big.V *= 1e8;
  const DistortionStats scaled = map_distortion(big, 1e-8 * image);
  EXPECT_NEAR(scaled.eps_angle, base.eps_angle, 1e-12 * base.eps_angle);
  EXPECT_NEAR(scaled.eps_area, base.eps_area, 1e-12 * base.eps_area);
  EXPECT_NEAR(scaled.angle_max, base.angle_max, 1e-12 * base.angle_max);
  EXPECT_NEAR(scaled.area_p95, base.area_p95, 1e-12 * base.area_p95);
}

TEST(MapQuality, DegenerateTrianglesAreCountedAndSkipped) {
  const TriMesh square = fan_square();
  // Centre moved onto the right edge: the right triangle collapses. The rest: left diag(2, 1)
  // (ε_angle 1.25, normalised area 1/2 against 1/4: ε_area 1.25), top and bottom sheared by 1
  // (ε_angle 1.5, ε_area 1); weights 1/2, 1/4, 1/4.
  Eigen::MatrixX3d image = square.V;
  image.row(0) << 1, 0, 0;
  const DistortionStats s = map_distortion(square, image);
  EXPECT_EQ(s.degenerate_image, 1);
  EXPECT_EQ(s.degenerate_domain, 0);
  EXPECT_EQ(s.triangles, 4);
  EXPECT_NEAR(s.eps_angle, 0.5 * 1.25 + 0.5 * 1.5, kExact);
  EXPECT_NEAR(s.eps_area, 0.5 * 1.25 + 0.5 * 1, kExact);
  EXPECT_NEAR(s.angle_max, 1.5, kExact);
  // Nearly onto the edge: the right triangle keeps an area of 1e-15 (2.5e-16 of the total).
  image(0, 0) = 1 - 1e-15;
  EXPECT_EQ(map_distortion(square, image).degenerate_image, 1);

  // The same with the roles swapped: the collapsed triangle is in the domain.
  TriMesh collapsed = square;
  collapsed.V = image;
  const DistortionStats back = map_distortion(collapsed, square.V);
  EXPECT_EQ(back.degenerate_domain, 1);
  EXPECT_EQ(back.degenerate_image, 0);
  EXPECT_TRUE(std::isfinite(back.eps_angle));

  // A non-finite image vertex makes its triangles degenerate; with nothing left to measure, the
  // distortion is infinite rather than a perfect 1.
  Eigen::MatrixX3d broken = square.V;
  broken(0, 1) = std::numeric_limits<double>::quiet_NaN();
  const DistortionStats nan = map_distortion(square, broken);
  EXPECT_EQ(nan.degenerate_image, 4);
  EXPECT_TRUE(std::isinf(nan.eps_angle));
  EXPECT_TRUE(std::isinf(nan.eps_area));
  EXPECT_TRUE(std::isinf(nan.angle_max));

  const DistortionStats point = map_distortion(square, Eigen::MatrixX3d::Ones(5, 3));
  EXPECT_EQ(point.degenerate_image, 4);
  EXPECT_TRUE(std::isinf(point.eps_angle));
}

TEST(MapQuality, RejectsBadArguments) {
  const TriMesh square = fan_square();
  EXPECT_THROW(map_distortion(square, Eigen::MatrixX3d::Zero(4, 3)), std::invalid_argument);
  EXPECT_THROW(map_distortion(TriMesh{}, Eigen::MatrixX3d::Zero(0, 3)), std::invalid_argument);
  TriMesh bad_index = square;
  bad_index.F(2, 1) = 5;
  EXPECT_THROW(map_distortion(bad_index, square.V), std::invalid_argument);
  TriMesh flat_line = square;
  flat_line.V.col(1).setZero();
  EXPECT_THROW(map_distortion(flat_line, square.V), std::invalid_argument);
  TriMesh nan_domain = square;
  nan_domain.V(3, 2) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(map_distortion(nan_domain, square.V), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
