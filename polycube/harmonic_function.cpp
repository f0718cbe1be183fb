#include "polycube/harmonic_function.h"

#include "polycube/triangle_geometry.h"

#include "polycube/errors.h"
#include "polycube/mesh_topology.h"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
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

// Throws MeshError unless the mesh has faces, every vertex used and one component.
void require_solvable(const TriMesh& mesh) {
  const int nv = mesh.num_vertices();
  if (nv < 3 || mesh.num_faces() == 0) throw MeshError("harmonic_function: empty mesh");
  if (const int unused = count_unreferenced_vertices(mesh.F, nv); unused > 0)
    throw MeshError("harmonic_function: " + std::to_string(unused) + " vertices are used by no face");
  if (const int components = connected_components(mesh.F, nv); components != 1)
    throw MeshError("harmonic_function: mesh must be connected, got " + std::to_string(components) + " components");
}

// The triangulation the Laplacian is built on, lengths of the mesh scaled to the unit cube (only
// lengths matter, so scaling is enough): intrinsic Delaunay, or the mesh's own.
IntrinsicTriangulation unit_intrinsic_triangulation(const TriMesh& mesh, const HarmonicOptions& options) {
  const double extent = bounding_box(mesh.V).extent().maxCoeff();
  if (!(extent > 0)) throw MeshError("harmonic_function: mesh has no extent");
  const TriMesh unit{mesh.V / extent, mesh.F};
  IntrinsicDelaunayOptions idt;
  if (!options.intrinsic_delaunay) idt.max_flips_per_edge = 0;
  return intrinsic_delaunay(unit, idt);
}

// The cotangent weights, each edge once: each face adds half the cotangent of its angle opposite
// the edge. negative: below -1e-10 times the mean (beyond rounding of cocircular quads). With
// intrinsic Delaunay, weights below min_weight times the mean are raised to it (raised): zero
// weights (cocircular quads) and the rare negative ones of edges the flips could not make
// Delaunay (next to spike vertices); with all weights > 0 every free vertex lies strictly
// between its lowest and highest neighbour (strict maximum principle).
struct EdgeWeights {
  std::vector<std::pair<int, int>> edges;
  std::vector<double> weight;
  int negative = 0;
  int raised = 0;
};

EdgeWeights laplacian_weights(const IntrinsicTriangulation& T, const HarmonicOptions& options) {
  Eigen::MatrixX3d half_weight(T.F.rows(), 3);
  for (int f = 0; f < T.F.rows(); ++f)
    for (int i = 0; i < 3; ++i)
      half_weight(f, i) = half_cotan_opposite(T.length(f, i), T.length(f, (i + 1) % 3), T.length(f, (i + 2) % 3));
  const double mean_weight = half_weight.sum() / (1.5 * T.F.rows());
  const double weight_floor = options.intrinsic_delaunay ? options.min_weight * mean_weight
                                                         : -std::numeric_limits<double>::infinity();
  EdgeWeights out;
  for (int f = 0; f < T.F.rows(); ++f)
    for (int i = 0; i < 3; ++i) {
      const int g = T.adjacent(f, i), j = T.adjacent_edge(f, i);
      if (g < f || (g == f && j < i)) continue;  // each edge once
      double w = half_weight(f, i) + half_weight(g, j);
      if (w < -1e-10 * mean_weight) ++out.negative;
      if (w < weight_floor) {
        w = weight_floor;
        ++out.raised;
      }
      out.edges.emplace_back(T.F(f, i), T.F(f, (i + 1) % 3));
      out.weight.push_back(w);
    }
  return out;
}

// A Cholesky factorisation of a symmetric positive definite matrix given by its lower triangle:
// Eigen's SimplicialLDLT (AMD ordering) below `supernodal_min` unknowns, CHOLMOD's supernodal
// LLᵀ (METIS ordering, which fills a mesh Laplacian's factor less than AMD: 37.7 M against 63.2 M
// nonzeros at 773 409 unknowns) from there on.
class LaplacianFactor {
 public:
  using Matrix = Eigen::SparseMatrix<double>;

  // Returns false when the factorisation fails.
  bool compute(const Matrix& lower, int supernodal_min) {
    if (lower.rows() >= supernodal_min) {
      supernodal_ = std::make_unique<Eigen::CholmodSupernodalLLT<Matrix, Eigen::Lower>>();
      cholmod_common& common = supernodal_->cholmod();
      common.print = 0;  // failures are reported by info(), never printed
      common.nmethods = 1;
      common.method[0].ordering = CHOLMOD_METIS;
      // Eigen's wrapper factorises whatever the analysis left: when that failed (out of memory)
      // there is no factor, so the status is checked between the two.
      supernodal_->analyzePattern(lower);
      if (common.status < CHOLMOD_OK) return false;
      supernodal_->factorize(lower);
      return common.status >= CHOLMOD_OK && supernodal_->info() == Eigen::Success;
    }
    simplicial_ = std::make_unique<Eigen::SimplicialLDLT<Matrix, Eigen::Lower, Eigen::AMDOrdering<int>>>(lower);
    return simplicial_->info() == Eigen::Success;
  }

  Eigen::VectorXd solve(const Eigen::VectorXd& b) const {
    return supernodal_ ? Eigen::VectorXd(supernodal_->solve(b)) : Eigen::VectorXd(simplicial_->solve(b));
  }

  bool supernodal() const { return supernodal_ != nullptr; }

 private:
  std::unique_ptr<Eigen::SimplicialLDLT<Matrix, Eigen::Lower, Eigen::AMDOrdering<int>>> simplicial_;
  std::unique_ptr<Eigen::CholmodSupernodalLLT<Matrix, Eigen::Lower>> supernodal_;
};

}  // namespace

HarmonicFunction harmonic_function(const TriMesh& mesh, const HarmonicOptions& options) {
  require_solvable(mesh);
  const int nv = mesh.num_vertices();
  HarmonicFunction result;
  extreme_vertices(mesh.V, result.source, result.sink);
  if (!(mesh.V(result.sink, 2) > mesh.V(result.source, 2)))
    throw MeshError("harmonic_function: mesh has no height (all z equal)");
  result.intrinsic = unit_intrinsic_triangulation(mesh, options);
  result.intrinsic_flips = result.intrinsic.flips;
  const EdgeWeights weights = laplacian_weights(result.intrinsic, options);
  result.negative_weights = weights.negative;
  result.raised_weights = weights.raised;

  // Free vertices are numbered 0..nv-3; source and sink are fixed.
  std::vector<int> unknown(nv, -1);
  int n = 0;
  for (int v = 0; v < nv; ++v)
    if (v != result.source && v != result.sink) unknown[v] = n++;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(weights.edges.size() + nv);
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(n), rhs = Eigen::VectorXd::Zero(n);
  for (size_t e = 0; e < weights.edges.size(); ++e) {
    const auto [a, b] = weights.edges[e];
    const double w = weights.weight[e];
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
    LaplacianFactor solver;
    const bool factored = solver.compute(L, options.supernodal_min_unknowns);
    result.supernodal = solver.supernodal();
    if (!factored)
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

struct HarmonicSolver::Impl {
  Eigen::MatrixX3i F;
  int nv = 0;
  IntrinsicTriangulation intrinsic;
  int negative_weights = 0;
  int raised_weights = 0;
  int refinement_steps = 0;
  // Each edge once: its ends and weight (raised as harmonic_function raises it).
  std::vector<std::pair<int, int>> edges;
  std::vector<double> weights;
  // The Laplacian without row and column `ground` (vertex v > ground is unknown v − 1), lower
  // triangle, and its factorisation.
  int ground = 0;
  Eigen::SparseMatrix<double> L;
  LaplacianFactor solver;
  mutable std::mutex mutex;
};

HarmonicSolver::HarmonicSolver(const TriMesh& mesh, const HarmonicOptions& options) : impl_(std::make_unique<Impl>()) {
  require_solvable(mesh);
  const int nv = mesh.num_vertices();
  Impl& m = *impl_;
  m.F = mesh.F;
  m.nv = nv;
  m.refinement_steps = options.refinement_steps;
  m.intrinsic = unit_intrinsic_triangulation(mesh, options);
  EdgeWeights weights = laplacian_weights(m.intrinsic, options);
  m.negative_weights = weights.negative;
  m.raised_weights = weights.raised;
  m.edges = std::move(weights.edges);
  m.weights = std::move(weights.weight);
  const int n = nv - 1;
  auto unknown = [&m](int v) { return v < m.ground ? v : v == m.ground ? -1 : v - 1; };
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(m.edges.size() + n);
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(n);
  for (size_t e = 0; e < m.edges.size(); ++e) {
    const int ua = unknown(m.edges[e].first), ub = unknown(m.edges[e].second);
    const double w = m.weights[e];
    if (ua >= 0) diagonal[ua] += w;
    if (ub >= 0) diagonal[ub] += w;
    if (ua >= 0 && ub >= 0 && ua != ub) triplets.emplace_back(std::max(ua, ub), std::min(ua, ub), -w);
  }
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, i, diagonal[i]);
  m.L.resize(n, n);
  m.L.setFromTriplets(triplets.begin(), triplets.end());
  if (!m.solver.compute(m.L, options.supernodal_min_unknowns))
    throw AlgorithmError("harmonic_function: Cholesky factorisation of the grounded " + std::to_string(n) + " x " +
                         std::to_string(n) + " Laplacian failed");
}

HarmonicSolver::~HarmonicSolver() = default;

HarmonicFunction HarmonicSolver::solve(const TriMesh& moved) const {
  const Impl& m = *impl_;
  if (moved.num_vertices() != m.nv || moved.F.rows() != m.F.rows() || moved.F != m.F)
    throw std::invalid_argument("HarmonicSolver::solve: the mesh's faces or vertex count differ from the solver's");
  HarmonicFunction result;
  extreme_vertices(moved.V, result.source, result.sink);
  if (!(moved.V(result.sink, 2) > moved.V(result.source, 2)))
    throw MeshError("harmonic_function: mesh has no height (all z equal)");
  const int n = m.nv - 1;
  auto unknown = [&m](int v) { return v < m.ground ? v : v == m.ground ? -1 : v - 1; };
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  if (unknown(result.sink) >= 0) rhs[unknown(result.sink)] += 1;
  if (unknown(result.source) >= 0) rhs[unknown(result.source)] -= 1;
  Eigen::VectorXd x;
  {
    const std::lock_guard<std::mutex> lock(m.mutex);
    x = m.solver.solve(rhs);
    const auto full = m.L.selfadjointView<Eigen::Lower>();
    for (int step = 0; step < m.refinement_steps; ++step) {
      const Eigen::VectorXd r = rhs - full * x;
      x += m.solver.solve(r);
    }
  }
  if (!x.allFinite()) throw AlgorithmError("harmonic_function: the Laplace solve produced non-finite values");
  Eigen::VectorXd u(m.nv);
  for (int v = 0; v < m.nv; ++v) u[v] = unknown(v) >= 0 ? x[unknown(v)] : 0.0;
  const double low = u[result.source], span = u[result.sink] - low;
  if (!(span > 0)) throw AlgorithmError("harmonic_function: the dipole solve gave no rise from source to sink");
  result.f = (u.array() - low) / span;
  result.f[result.source] = 0;
  result.f[result.sink] = 1;
  // The Dirichlet problem's residual at the free vertices, relative to its right-hand side (the
  // weights into the sink), as harmonic_function reports it.
  Eigen::VectorXd Lf = Eigen::VectorXd::Zero(m.nv), into_sink = Eigen::VectorXd::Zero(m.nv);
  for (size_t e = 0; e < m.edges.size(); ++e) {
    const auto [a, b] = m.edges[e];
    const double w = m.weights[e], d = w * (result.f[a] - result.f[b]);
    Lf[a] += d;
    Lf[b] -= d;
    if (b == result.sink) into_sink[a] += w;
    if (a == result.sink) into_sink[b] += w;
  }
  double worst = 0, scale = 0;
  for (int v = 0; v < m.nv; ++v) {
    if (v == result.source || v == result.sink) continue;
    worst = std::max(worst, std::abs(Lf[v]));
    scale = std::max(scale, into_sink[v]);
  }
  result.residual = worst / std::max(scale, 1e-300);
  result.intrinsic = m.intrinsic;
  result.intrinsic_flips = m.intrinsic.flips;
  result.negative_weights = m.negative_weights;
  result.raised_weights = m.raised_weights;
  result.supernodal = m.solver.supernodal();
  return result;
}

}  // namespace polycube
