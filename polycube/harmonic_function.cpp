#include "polycube/harmonic_function.h"

#include "polycube/triangle_geometry.h"

#include "polycube/errors.h"
#include "polycube/mesh_topology.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace polycube {

namespace {

// Half the cotangent of the angle opposite edge a (the triangle's share of the edge weight).
double half_cotan_opposite(double a, double b, double c) { return 0.5 * cotan_opposite(a, b, c); }

// Lowest and highest vertex by z; ties go to the smallest index.
void extreme_vertices(const Eigen::MatrixX3d& V, int& lowest, int& highest) {
  lowest = highest = 0;
  for (int v = 1; v < V.rows(); ++v) {
    if (V(v, 2) < V(lowest, 2)) lowest = v;
    if (V(v, 2) > V(highest, 2)) highest = v;
  }
}

}  // namespace

HarmonicFunction harmonic_function(const TriMesh& mesh, const HarmonicOptions& options) {
  const int nv = mesh.num_vertices();
  if (nv == 0 || mesh.num_faces() == 0) throw MeshError("harmonic_function: empty mesh");
  if (const int unused = count_unreferenced_vertices(mesh.F, nv); unused > 0)
    throw MeshError("harmonic_function: " + std::to_string(unused) + " vertices are used by no face");
  if (const int components = connected_components(mesh.F, nv); components != 1)
    throw MeshError("harmonic_function: mesh must be connected, got " + std::to_string(components) + " components");

  HarmonicFunction result;
  extreme_vertices(mesh.V, result.source, result.sink);
  if (!(mesh.V(result.sink, 2) > mesh.V(result.source, 2)))
    throw MeshError("harmonic_function: mesh has no height (all z equal)");

  // Unit-cube normalisation: only lengths matter, so scaling is enough.
  const double extent = bounding_box(mesh.V).extent().maxCoeff();
  const TriMesh unit{mesh.V / extent, mesh.F};
  IntrinsicDelaunayOptions idt;
  if (!options.intrinsic_delaunay) idt.max_flips_per_edge = 0;
  result.intrinsic = intrinsic_delaunay(unit, idt);
  result.intrinsic_flips = result.intrinsic.flips;
  const IntrinsicTriangulation& T = result.intrinsic;

  // Edge weights: each face adds half the cotangent of its angle opposite the edge.
  // Free vertices are numbered 0..nv-3; source and sink are fixed.
  std::vector<int> unknown(nv, -1);
  int n = 0;
  for (int v = 0; v < nv; ++v)
    if (v != result.source && v != result.sink) unknown[v] = n++;

  Eigen::MatrixX3d half_weight(T.F.rows(), 3);
  for (int f = 0; f < T.F.rows(); ++f)
    for (int i = 0; i < 3; ++i)
      half_weight(f, i) = half_cotan_opposite(T.length(f, i), T.length(f, (i + 1) % 3), T.length(f, (i + 2) % 3));
  // Weight floor: a fraction of the mean edge weight.
  const double mean_weight = half_weight.sum() / (1.5 * T.F.rows());
  const double weight_floor = options.intrinsic_delaunay ? options.min_weight * mean_weight
                                                         : -std::numeric_limits<double>::infinity();

  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(4 * 3 * T.F.rows() / 2 + nv);
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(n), rhs = Eigen::VectorXd::Zero(n);
  for (int f = 0; f < T.F.rows(); ++f)
    for (int i = 0; i < 3; ++i) {
      const int g = T.adjacent(f, i), j = T.adjacent_edge(f, i);
      if (g < f || (g == f && j < i)) continue;  // each edge once
      double w = half_weight(f, i) + half_weight(g, j);
      if (w < -1e-10 * mean_weight) ++result.negative_weights;  // beyond rounding of cocircular quads
      if (w < weight_floor) {
        // Zero weights (cocircular quads) and the rare negative weights of edges the flips could
        // not make Delaunay (next to spike vertices) are raised to a small positive value: with
        // all weights > 0 every free vertex lies strictly between its lowest and highest
        // neighbour (strict maximum principle), instead of possibly equal to one of them.
        w = weight_floor;
        ++result.raised_weights;
      }
      const int a = T.F(f, i), b = T.F(f, (i + 1) % 3);
      const int ua = unknown[a], ub = unknown[b];
      // Row of a: w (f_a - f_b) = 0, moving fixed values to the right-hand side.
      if (ua >= 0) diagonal[ua] += w;
      if (ub >= 0) diagonal[ub] += w;
      if (ua >= 0 && ub >= 0) {
        triplets.emplace_back(std::max(ua, ub), std::min(ua, ub), -w);
      } else if (ua >= 0 && b == result.sink) {
        rhs[ua] += w;
      } else if (ub >= 0 && a == result.sink) {
        rhs[ub] += w;
      }
    }
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, i, diagonal[i]);
  Eigen::SparseMatrix<double> L(n, n);
  L.setFromTriplets(triplets.begin(), triplets.end());  // lower triangle only

  result.f = Eigen::VectorXd::Zero(nv);
  result.f[result.sink] = 1;
  if (n > 0) {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> solver(L);
    if (solver.info() != Eigen::Success)
      throw AlgorithmError("harmonic_function: Cholesky factorisation of the " + std::to_string(n) + " x " +
                           std::to_string(n) + " Laplacian failed");
    Eigen::VectorXd x = solver.solve(rhs);
    const auto full = L.selfadjointView<Eigen::Lower>();
    for (int step = 0; step < options.refinement_steps; ++step) {
      const Eigen::VectorXd r = rhs - full * x;
      x += solver.solve(r);
    }
    const Eigen::VectorXd r = rhs - full * x;
    result.residual = r.lpNorm<Eigen::Infinity>() / std::max(rhs.lpNorm<Eigen::Infinity>(), 1e-300);
    if (!x.allFinite())
      throw AlgorithmError("harmonic_function: the Laplace solve produced non-finite values");
    for (int v = 0; v < nv; ++v)
      if (unknown[v] >= 0) result.f[v] = x[unknown[v]];
  }
  return result;
}

}  // namespace polycube
