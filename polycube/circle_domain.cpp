#include "polycube/circle_domain.h"

#include "polycube/ricci_layout.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace polycube {

namespace {

double signed_area(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
}

}  // namespace

CircleDomain circle_domain(const TriMesh& piece, const FlatMetric& metric) {
  const IntrinsicTriangulation& T = metric.triangulation;
  const int nv = piece.num_vertices();
  const int nvt = static_cast<int>(metric.u.size());
  const int nf = static_cast<int>(T.F.rows());
  if (metric.input_vertices != nv || nvt != nv + static_cast<int>(metric.inserted_vertices.size()) || nf == 0)
    throw std::invalid_argument("circle_domain: the flat metric (" + std::to_string(metric.input_vertices) +
                                " input vertices) does not belong to this piece (" + std::to_string(nv) +
                                " vertices)");

  std::vector<Eigen::Vector2d> position = ricci::unfold(T, nvt);

  // Circles, then the similarity taking the outer one to the unit circle.
  CircleDomain out;
  const int nl = static_cast<int>(metric.loops.size());
  out.outer_loop = metric.outer_loop;
  out.centres.resize(nl);
  out.radii.resize(nl);
  auto fit_loop = [&](int l) {
    std::vector<Eigen::Vector2d> points;
    for (int v : metric.loops[l]) points.push_back(position[v]);
    ricci::fit_circle(points, out.centres[l], out.radii[l]);
  };
  fit_loop(out.outer_loop);
  const Eigen::Vector2d c0 = out.centres[out.outer_loop];
  const double scale = 1 / out.radii[out.outer_loop];
  const Eigen::Vector2d first = position[metric.loops[out.outer_loop][0]] - c0;
  const double angle = std::atan2(first.y(), first.x());
  const Eigen::Matrix2d rotation = Eigen::Rotation2Dd(-angle).toRotationMatrix();
  for (auto& p : position) p = scale * (rotation * (p - c0));
  for (int l = 0; l < nl; ++l) fit_loop(l);
  out.centres[out.outer_loop].setZero();
  out.radii[out.outer_loop] = 1;

  for (int l = 0; l < nl; ++l)
    for (int v : metric.loops[l])
      out.max_roundness_error = std::max(out.max_roundness_error,
                                         std::abs((position[v] - out.centres[l]).norm() - out.radii[l]) / out.radii[l]);
  out.min_circle_gap = std::numeric_limits<double>::infinity();
  for (int l = 0; l < nl; ++l) {
    if (l == out.outer_loop) continue;
    out.min_circle_gap = std::min(out.min_circle_gap, 1 - out.centres[l].norm() - out.radii[l]);
    for (int k = l + 1; k < nl; ++k)
      if (k != out.outer_loop)
        out.min_circle_gap = std::min(out.min_circle_gap,
                                      (out.centres[l] - out.centres[k]).norm() - out.radii[l] - out.radii[k]);
  }
  if (nl == 1) out.min_circle_gap = 1;
  out.min_radius = *std::min_element(out.radii.begin(), out.radii.end());

  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector2d& a = position[T.F(f, 0)];
    const Eigen::Vector2d& b = position[T.F(f, 1)];
    const Eigen::Vector2d& c = position[T.F(f, 2)];
    if (!(signed_area(a, b, c) > 0)) ++out.flipped_triangles;
    for (int i = 0; i < 3; ++i) {
      const double laid = (position[T.F(f, (i + 1) % 3)] - position[T.F(f, i)]).norm();
      out.layout_error = std::max(out.layout_error, std::abs(laid - scale * T.length(f, i)));
    }
  }
  for (int f = 0; f < piece.num_faces(); ++f)
    if (!(signed_area(position[piece.F(f, 0)], position[piece.F(f, 1)], position[piece.F(f, 2)]) > 0))
      ++out.flipped_input_triangles;

  out.uv.resize(nv, 2);
  for (int v = 0; v < nv; ++v) out.uv.row(v) = position[v].transpose();
  out.inserted_uv.resize(nvt - nv, 2);
  for (int v = nv; v < nvt; ++v) out.inserted_uv.row(v - nv) = position[v].transpose();
  return out;
}

}  // namespace polycube
