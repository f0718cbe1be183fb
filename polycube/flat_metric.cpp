#include "polycube/flat_metric.h"

#include "polycube/errors.h"
#include "polycube/ricci_mesh.h"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace polycube {

namespace {

constexpr double kPi = 3.14159265358979323846;
using ricci::RicciMesh;
using SparseMatrix = Eigen::SparseMatrix<double>;
using Solver = Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>>;
using Permutation = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>;
using Complex = std::complex<double>;

std::string num(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", x);
  return buffer;
}

// A boundary loop: its vertices v_k, the boundary halfedges v_k -> v_{k+1}, and the sign of its
// total geodesic curvature (+1 for the outer circle, -1 for a hole).
struct LoopData {
  std::vector<int> vertices;
  std::vector<int> halfedges;
  double sigma = 1;
};

// Everything computed from the metric at one u.
//   energy   E(u) = sum_T [sum_e (2 alpha_e - pi) x_e + 2 L(alpha_e)] + sum_v Theta0_v u_v
//                   - sum_loops sigma Phi_loop(u)
//            with x_e the log-lengths, L Lobachevsky's function, Theta0 = 2pi inside and pi on
//            the boundary, and per loop Phi = sum_e 2 (phi_e (x_e - rho) + L(phi_e)) + 2 pi rho,
//            stationary in rho (the loop's circumradius), whose u-gradient is the turning angle
//            phi_prev + phi_next of the inscribed polygon. The gradient of E is target - angle
//            sum; its Hessian the cotangent Laplacian plus the loops' terms (NewtonSystem).
//   balance  the gauge constraint: sum_k w_k exp(i theta_k) / sum_k w_k over the outer loop's
//            vertices at their angles theta_k on its circle (theta_0 = 0), weighted by their
//            share w_k of the loop's input length; balance_gradient its u-derivative per vertex
//            of the outer loop.
struct Evaluation {
  bool valid = false;  // every loop's polygon exists
  double energy = 0;
  double energy_scale = 0;  // sum of |terms|, for the rounding tolerance of energy comparisons
  Eigen::VectorXd angle_sum, target, gradient;
  std::vector<double> cot;  // per halfedge: cot of the angle opposite it (0 if degenerate)
  std::vector<std::vector<double>> phi, tan_phi;
  std::vector<double> rho, tan_sum;
  Complex balance = 0;
  std::vector<Complex> balance_gradient;
  int invalid_triangles = 0;
  double residual = std::numeric_limits<double>::infinity();
};

void evaluate(const RicciMesh& m, const Eigen::VectorXd& u, const std::vector<LoopData>& loops, int outer,
              Evaluation& ev) {
  const int nv = m.num_vertices, nf = m.num_faces();
  ev.valid = false;
  ev.angle_sum.setZero(nv);
  ev.cot.assign(m.num_halfedges(), 0.0);
  double energy = 0, scale = 0;
  int invalid = 0;
  for (int f = 0; f < nf; ++f) {
    const int h0 = m.face_halfedge[f], h1 = m.next[h0], h2 = m.next[h1];
    const int hs[3] = {h0, h1, h2};
    double x[3], opposite[3], cot[3];
    for (int i = 0; i < 3; ++i) x[i] = m.log_length(hs[i], u);
    if (!ricci::triangle_angles(x, opposite, cot)) ++invalid;
    for (int i = 0; i < 3; ++i) {
      ev.cot[hs[i]] = cot[i];
      ev.angle_sum[m.vert[hs[(i + 2) % 3]]] += opposite[i];
      const double term = (2 * opposite[i] - kPi) * x[i] + 2 * ricci::lobachevsky(opposite[i]);
      energy += term;
      scale += std::abs(term);
    }
  }
  ev.target.resize(nv);
  for (int v = 0; v < nv; ++v) {
    ev.target[v] = m.boundary_vertex[v] ? kPi : 2 * kPi;
    energy += ev.target[v] * u[v];
    scale += std::abs(ev.target[v] * u[v]);
  }
  const int nl = static_cast<int>(loops.size());
  ev.phi.resize(nl);
  ev.tan_phi.resize(nl);
  ev.rho.assign(nl, 0.0);
  ev.tan_sum.assign(nl, 0.0);
  std::vector<double> x;
  for (int l = 0; l < nl; ++l) {
    const LoopData& loop = loops[l];
    const int n = static_cast<int>(loop.halfedges.size());
    x.resize(n);
    for (int k = 0; k < n; ++k) x[k] = m.log_length(loop.halfedges[k], u);
    std::vector<double>& phi = ev.phi[l];
    if (!ricci::cyclic_polygon(x, ev.rho[l], phi)) return;
    double Phi = 2 * kPi * ev.rho[l];
    std::vector<double>& tp = ev.tan_phi[l];
    tp.resize(n);
    double tan_sum = 0;
    for (int k = 0; k < n; ++k) {
      Phi += 2 * (phi[k] * (x[k] - ev.rho[l]) + ricci::lobachevsky(phi[k]));
      tp[k] = std::tan(phi[k]);
      tan_sum += tp[k];
    }
    ev.tan_sum[l] = tan_sum;
    energy -= loop.sigma * Phi;
    scale += std::abs(Phi);
    for (int k = 0; k < n; ++k) ev.target[loop.vertices[k]] -= loop.sigma * (phi[(k + n - 1) % n] + phi[k]);
  }

  // Balance of the outer loop. theta_k = 2 sum_{e<k} phi_e, so with s_e = sum_{k>e} w_k i
  // exp(i theta_k): dC = (2/W) sum_e s_e dphi_e, dphi = (D - t t^T / T) dx (D = diag t, t = tan
  // phi, T = sum t: the derivative of the inscribed polygon's angles under sum phi = pi), and
  // dx_e = (du_a + du_b) / 2.
  {
    const LoopData& o = loops[outer];
    const int n = static_cast<int>(o.vertices.size());
    const std::vector<double>& phi = ev.phi[outer];
    const std::vector<double>& t = ev.tan_phi[outer];
    std::vector<double> w(n);
    double total = 0;
    for (int k = 0; k < n; ++k) {
      w[k] = 0.5 * (std::exp(m.lambda[o.halfedges[(k + n - 1) % n]]) + std::exp(m.lambda[o.halfedges[k]]));
      total += w[k];
    }
    std::vector<Complex> term(n);
    double theta = 0;
    Complex sum = 0;
    for (int k = 0; k < n; ++k) {
      term[k] = w[k] * std::polar(1.0, theta);
      sum += term[k];
      theta += 2 * phi[k];
    }
    ev.balance = sum / total;
    std::vector<Complex> s(n);
    Complex suffix = 0;
    for (int e = n - 1; e >= 0; --e) {
      s[e] = suffix * Complex(0, 1);
      suffix += term[e];
    }
    Complex st = 0;
    for (int e = 0; e < n; ++e) st += s[e] * t[e];
    const Complex mean = st / ev.tan_sum[outer];
    ev.balance_gradient.assign(n, 0.0);
    for (int e = 0; e < n; ++e) {
      const Complex r = t[e] * (s[e] - mean) / total;
      ev.balance_gradient[e] += r;
      ev.balance_gradient[(e + 1) % n] += r;
    }
  }
  ev.gradient = ev.target - ev.angle_sum;
  ev.residual = nv > 0 ? ev.gradient.cwiseAbs().maxCoeff() : 0.0;
  ev.energy = energy;
  ev.energy_scale = scale;
  ev.invalid_triangles = invalid;
  ev.valid = std::isfinite(energy) && std::isfinite(std::abs(ev.balance));
}

// The Newton matrix on the free vertices (all but the gauge vertex): H + damping I with
// H = S + sum_loops c_l w_l w_l^T, S sparse (cotangent Laplacian with weights
// (cot alpha + cot beta) / 2, plus -sigma/2 sum_e tan(phi_e) (e_a + e_b)(e_a + e_b)^T per loop
// edge) and, per loop, w_l = sum_e tan(phi_e) (e_a + e_b), c_l = sigma / (2 sum_e tan(phi_e)):
// the derivatives of the loops' targets, d(turning angle)/du = (1/2) A (D - t t^T / T) A^T for
// the loop's vertex-edge incidence A. S is factored by LDL^T (its pattern analysed once per
// connectivity), the rank-one terms added by Sherman–Morrison–Woodbury.
class NewtonSystem {
 public:
  // New unknowns: index[v] is the unknown of vertex v, or -1.
  void reset(const std::vector<int>& index, int n) {
    index_ = index;
    n_ = n;
    analysed_version_ = -1;
    ordering_.resize(0);
  }

  // Factors the full Hessian (with_outer) or its convex part (the cotangent Laplacian and the
  // holes' terms, without the outer loop's concave term). Returns false if that fails.
  bool factor(const RicciMesh& m, const Evaluation& ev, const std::vector<LoopData>& loops, bool with_outer,
              double damping) {
    triplets_.clear();
    for (int i = 0; i < n_; ++i) triplets_.emplace_back(i, i, damping);
    for (int h = 0; h < m.num_halfedges(); ++h) {
      const double w = 0.5 * ev.cot[h];
      const int a = m.vert[h], b = m.head(h);
      if (a == b) continue;  // an edge from a vertex to itself: w (u_a - u_a)^2 = 0
      add(a, a, w);
      add(b, b, w);
      add(a, b, -w);
    }
    const int nl = static_cast<int>(loops.size());
    W_.setZero(n_, nl);
    c_.resize(nl);
    int r = 0;
    for (int l = 0; l < nl; ++l) {
      if (!with_outer && loops[l].sigma > 0) continue;
      const LoopData& loop = loops[l];
      const int n = static_cast<int>(loop.vertices.size());
      for (int k = 0; k < n; ++k) {
        const double t = ev.tan_phi[l][k];
        const int a = loop.vertices[k], b = loop.vertices[(k + 1) % n];
        const double c = -0.5 * loop.sigma * t;
        add(a, a, c);
        add(b, b, c);
        add(a, b, c);
        if (index_[a] >= 0) W_(index_[a], r) += t;
        if (index_[b] >= 0) W_(index_[b], r) += t;
      }
      c_[r++] = loop.sigma / (2 * ev.tan_sum[l]);
    }
    W_.conservativeResize(n_, r);
    c_.conservativeResize(r);
    S_.resize(n_, n_);
    S_.setFromTriplets(triplets_.begin(), triplets_.end());
    // Fill-reducing ordering (AMD) once per set of unknowns: flips change the pattern only a
    // little, so the ordering stays good; the symbolic analysis is redone when they happened.
    if (ordering_.size() != n_) {
      Eigen::AMDOrdering<int> amd;
      Permutation inverse;
      amd(S_.selfadjointView<Eigen::Lower>(), inverse);
      ordering_ = inverse.inverse();
    }
    P_.resize(n_, n_);
    P_.selfadjointView<Eigen::Lower>() = S_.selfadjointView<Eigen::Lower>().twistedBy(ordering_);
    if (analysed_version_ != m.connectivity_version) {
      solver_.analyzePattern(P_);
      analysed_version_ = m.connectivity_version;
    }
    solver_.factorize(P_);
    if (solver_.info() != Eigen::Success) return false;
    if (r > 0) {
      Y_ = solve_sparse(W_);
      Eigen::MatrixXd M = W_.transpose() * Y_;
      for (int j = 0; j < r; ++j) M(j, j) += 1 / c_[j];
      capacitance_ = M.fullPivLu();
    }
    return true;
  }

  // H^-1 rhs (several columns); false if not finite or not backward stable (S may be indefinite
  // and its LDL^T does not pivot): every column needs |H x - b| <= 1e-9 (|H| |x| + |b|).
  bool solve(const Eigen::MatrixXd& rhs, Eigen::MatrixXd& x) const {
    x = solve_sparse(rhs);
    if (W_.cols() > 0) x -= Y_ * capacitance_.solve(W_.transpose() * x);
    if (!x.allFinite()) return false;
    Eigen::MatrixXd residual = S_.selfadjointView<Eigen::Lower>() * x - rhs;
    if (W_.cols() > 0) residual += W_ * (c_.asDiagonal() * (W_.transpose() * x));
    double norm = 0;  // max row sum of |S| (an upper bound of |H| up to the rank-one terms)
    Eigen::VectorXd rows = Eigen::VectorXd::Zero(n_);
    for (int k = 0; k < S_.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(S_, k); it; ++it) {
        rows[it.row()] += std::abs(it.value());
        if (it.row() != it.col()) rows[it.col()] += std::abs(it.value());
      }
    if (n_ > 0) norm = rows.maxCoeff();
    for (int j = 0; j < x.cols(); ++j)
      if (!(residual.col(j).norm() <= 1e-9 * (norm * x.col(j).norm() + rhs.col(j).norm()) + 1e-300)) return false;
    return true;
  }

 private:
  // S^-1 rhs through the permuted factorisation.
  Eigen::MatrixXd solve_sparse(const Eigen::MatrixXd& rhs) const {
    return ordering_.transpose() * Eigen::MatrixXd(solver_.solve(ordering_ * rhs));
  }

  void add(int a, int b, double value) {
    const int i = index_[a], j = index_[b];
    if (i >= 0 && j >= 0) triplets_.emplace_back(std::max(i, j), std::min(i, j), value);
  }

  std::vector<int> index_;
  int n_ = 0;
  std::vector<Eigen::Triplet<double>> triplets_;
  SparseMatrix S_, P_;
  Permutation ordering_;  // new position of each unknown
  Solver solver_;
  long long analysed_version_ = -1;
  Eigen::MatrixXd W_, Y_;
  Eigen::VectorXd c_;
  Eigen::FullPivLU<Eigen::MatrixXd> capacitance_;
};

// Checks the loops against the boundary of the halfedge mesh and returns them with their
// boundary halfedges. Throws MeshError on any mismatch.
std::vector<LoopData> match_loops(const RicciMesh& m, const std::vector<std::vector<int>>& loops) {
  std::vector<std::vector<int>> outgoing(m.num_vertices);  // boundary halfedges by tail
  int boundary_halfedges = 0;
  for (int h = 0; h < m.num_halfedges(); ++h)
    if (m.twin[h] < 0) {
      outgoing[m.vert[h]].push_back(h);
      ++boundary_halfedges;
    }
  std::vector<char> used(m.num_halfedges(), 0);
  std::vector<LoopData> out;
  int matched = 0;
  for (size_t l = 0; l < loops.size(); ++l) {
    const std::vector<int>& loop = loops[l];
    const int n = static_cast<int>(loop.size());
    if (n < 3)
      throw MeshError("flat_metric: loop " + std::to_string(l) + " has " + std::to_string(n) +
                      " vertices, expected at least 3");
    LoopData data;
    data.vertices = loop;
    for (int k = 0; k < n; ++k) {
      const int a = loop[k], b = loop[(k + 1) % n];
      if (a < 0 || a >= m.num_vertices || b < 0 || b >= m.num_vertices)
        throw MeshError("flat_metric: loop " + std::to_string(l) + " has a vertex id out of range");
      int found = -1;
      for (int h : outgoing[a])
        if (m.head(h) == b && !used[h]) found = h;
      if (found < 0)
        throw MeshError("flat_metric: loop " + std::to_string(l) + " step (" + std::to_string(a) + ", " +
                        std::to_string(b) + ") is not a boundary edge in face orientation");
      used[found] = 1;
      data.halfedges.push_back(found);
      ++matched;
    }
    out.push_back(std::move(data));
  }
  if (matched != boundary_halfedges)
    throw MeshError("flat_metric: the loops cover " + std::to_string(matched) + " of " +
                    std::to_string(boundary_halfedges) + " boundary edges");
  return out;
}

IntrinsicTriangulation export_triangulation(const RicciMesh& m, const Eigen::VectorXd& u, double log_scale,
                                            const Evaluation& ev) {
  const int nf = m.num_faces();
  IntrinsicTriangulation t;
  t.F.resize(nf, 3);
  t.adjacent.resize(nf, 3);
  t.adjacent_edge.resize(nf, 3);
  t.length.resize(nf, 3);
  std::vector<int> slot(m.num_halfedges());
  for (int f = 0; f < nf; ++f) {
    int h = m.face_halfedge[f];
    for (int i = 0; i < 3; ++i, h = m.next[h]) slot[h] = i;
  }
  t.min_cotan_sum = std::numeric_limits<double>::infinity();
  for (int f = 0; f < nf; ++f) {
    int h = m.face_halfedge[f];
    for (int i = 0; i < 3; ++i, h = m.next[h]) {
      t.F(f, i) = m.vert[h];
      t.length(f, i) = std::exp(m.log_length(h, u) + log_scale);
      const int g = m.twin[h];
      t.adjacent(f, i) = g >= 0 ? m.face[g] : -1;
      t.adjacent_edge(f, i) = g >= 0 ? slot[g] : -1;
      if (g > h) t.min_cotan_sum = std::min(t.min_cotan_sum, ev.cot[h] + ev.cot[g]);
    }
  }
  t.flips = static_cast<int>(m.flips);
  return t;
}

// Boundary halfedges that are the too-long edge of a triangle violating the triangle inequality
// at u_trial but not at u.
std::vector<int> invalid_boundary_edges(const RicciMesh& m, const Eigen::VectorXd& u_trial, const Eigen::VectorXd& u) {
  std::vector<int> out;
  for (int f = 0; f < m.num_faces(); ++f) {
    const int hs[3] = {m.face_halfedge[f], m.next[m.face_halfedge[f]], m.next[m.next[m.face_halfedge[f]]]};
    double x[3], opposite[3], cot[3];
    for (int i = 0; i < 3; ++i) x[i] = m.log_length(hs[i], u_trial);
    if (ricci::triangle_angles(x, opposite, cot)) continue;
    const double longest = std::max({x[0], x[1], x[2]});
    double y[3];
    for (int i = 0; i < 3; ++i) y[i] = m.log_length(hs[i], u);
    if (!ricci::triangle_angles(y, opposite, cot)) continue;
    for (int i = 0; i < 3; ++i)
      if (m.twin[hs[i]] < 0 && x[i] >= longest) out.push_back(hs[i]);
  }
  return out;
}

}  // namespace

FlatMetric flat_metric(const TriMesh& piece, const std::vector<std::vector<int>>& loops_in,
                       const FlatMetricOptions& options) {
  const int nv = piece.num_vertices(), nf = piece.num_faces();
  if (loops_in.empty()) throw MeshError("flat_metric: the piece has no boundary loop (closed surface)");
  if (nf == 0) throw MeshError("flat_metric: the piece has no faces");

  // Work in units of the mean edge length, so that the energy's terms stay of moderate size and
  // the result does not depend on the scale of the input.
  double log_scale = 0;
  for (int f = 0; f < nf; ++f)
    for (int i = 0; i < 3; ++i)
      log_scale += std::log((piece.V.row(piece.F(f, i)) - piece.V.row(piece.F(f, (i + 1) % 3))).norm());
  log_scale /= 3.0 * nf;
  if (!std::isfinite(log_scale)) throw MeshError("flat_metric: the piece has an edge of zero or non-finite length");
  RicciMesh m = ricci::build_ricci_mesh(piece, log_scale);

  std::vector<char> referenced(nv, 0);
  for (int h = 0; h < m.num_halfedges(); ++h) referenced[m.vert[h]] = 1;
  const int unreferenced = static_cast<int>(std::count(referenced.begin(), referenced.end(), 0));
  if (unreferenced > 0)
    throw MeshError("flat_metric: " + std::to_string(unreferenced) + " vertices are used by no face");
  int boundary_halfedges = 0;
  for (int h = 0; h < m.num_halfedges(); ++h) boundary_halfedges += m.twin[h] < 0;
  const int num_edges = (3 * nf + boundary_halfedges) / 2;
  const int b = static_cast<int>(loops_in.size());
  const int euler = nv - num_edges + nf;
  if (euler != 2 - b)
    throw MeshError("flat_metric: the piece must be genus 0 with its " + std::to_string(b) +
                    " loops, got Euler characteristic " + std::to_string(euler) + " (expected " +
                    std::to_string(2 - b) + ")");
  std::vector<LoopData> loops = match_loops(m, loops_in);

  // Outer loop: the longest by input length (§3.3), unless chosen.
  std::vector<double> loop_length(b, 0.0);
  for (int l = 0; l < b; ++l)
    for (int h : loops[l].halfedges) loop_length[l] += std::exp(m.lambda[h]);
  int outer = options.outer_loop;
  if (outer < 0 || outer >= b)
    outer = static_cast<int>(std::max_element(loop_length.begin(), loop_length.end()) - loop_length.begin());
  for (int l = 0; l < b; ++l) loops[l].sigma = l == outer ? 1.0 : -1.0;

  FlatMetric result;
  result.input_vertices = nv;
  const long long max_flips = static_cast<long long>(options.max_flips_per_edge * std::max(1, num_edges));
  Eigen::VectorXd u = Eigen::VectorXd::Zero(nv);
  if (options.initial_delaunay)
    result.initial_flips = static_cast<int>(ricci::make_delaunay(m, u, {true, options.delaunay_tolerance, max_flips}));
  const int max_inserted = options.max_inserted_vertices >= 0 ? options.max_inserted_vertices : boundary_halfedges + 16;

  // Splits the boundary edge of halfedge h at its midpoint in the metric at u and records it.
  auto split_boundary_edge = [&](int h) {
    const int va = m.vert[h], vb = m.head(h);
    const int n1 = ricci::split_edge(m, h, u);
    if (n1 < 0) return false;
    for (LoopData& loop : loops) {
      const auto it = std::find(loop.halfedges.begin(), loop.halfedges.end(), h);
      if (it == loop.halfedges.end()) continue;
      const auto k = it - loop.halfedges.begin();
      loop.halfedges.insert(loop.halfedges.begin() + k + 1, n1);
      loop.vertices.insert(loop.vertices.begin() + k + 1, m.num_vertices - 1);
    }
    result.inserted_vertices.push_back({va, vb});
    return true;
  };

  // Boundary edges of the outer loop must stay edges of a valid triangulation when the loop
  // becomes a circle: the apex c of the triangle on edge ab has to stay inside the chord ab,
  // whose sagitta is about l * theta / 8 for the central angle theta ~ 2 pi l / L. So an edge
  // whose opposite angle exceeds pi - safety * theta / 2 is split beforehand (in the input
  // metric, so the new vertex is the midpoint of the input edge). Edges the solve still pushes
  // out of the valid range are split when that happens (below).
  if (options.boundary_split_safety > 0) {
    for (int pass = 0; pass < 20; ++pass) {
      const LoopData& o = loops[outer];
      double length = 0;
      for (int h : o.halfedges) length += std::exp(m.log_length(h, u));
      std::vector<int> to_split;
      for (int h : o.halfedges) {
        const int h1 = m.next[h], h2 = m.next[h1];
        const double x[3] = {m.log_length(h, u), m.log_length(h1, u), m.log_length(h2, u)};
        double opposite[3], cot[3];
        ricci::triangle_angles(x, opposite, cot);
        const double theta = 2 * kPi * std::exp(x[0]) / length;
        if (opposite[0] > kPi - options.boundary_split_safety * theta / 2) to_split.push_back(h);
      }
      bool any = false;
      for (int h : to_split)
        if (static_cast<int>(result.inserted_vertices.size()) < max_inserted && split_boundary_edge(h)) any = true;
      if (!any) break;
      if (options.initial_delaunay)
        result.initial_flips += static_cast<int>(ricci::make_delaunay(m, u, {true, options.delaunay_tolerance, max_flips}));
    }
  }
  result.presplit_vertices = static_cast<int>(result.inserted_vertices.size());
  const long long flips_before = m.flips;

  // Gauge. The scale: u = 0 at the first vertex of the outer loop. The Möbius motions of the
  // circle domain (2 parameters; the energy is exactly invariant under them, so the Hessian is
  // singular along them at the solution): the constraint balance = 0, solved together with the
  // Newton system (KKT). The steps are also damped by damping * residual / #V.
  result.gauge_vertex = loops[outer].vertices[0];
  std::vector<int> index;
  int n_free = 0;
  NewtonSystem system;
  auto reindex = [&]() {
    index.assign(m.num_vertices, 0);
    index[result.gauge_vertex] = -1;
    n_free = 0;
    for (int v = 0; v < m.num_vertices; ++v)
      if (index[v] == 0) index[v] = n_free++;
    system.reset(index, n_free);
  };
  reindex();

  Evaluation ev, trial;
  evaluate(m, u, loops, outer, ev);
  if (!ev.valid)
    throw MeshError("flat_metric: a boundary loop is degenerate (its longest edge is as long as the rest)");

  const bool balance = options.balance;
  double penalty = 1;
  double radius = options.max_step;  // trust region for the largest change of u in one step
  bool capped = false;
  Eigen::Vector2d multiplier = Eigen::Vector2d::Zero();
  auto merit = [&](const Evaluation& e) {
    const Eigen::Vector2d C(e.balance.real(), e.balance.imag());
    return e.energy + (balance ? multiplier.dot(C) + 0.5 * penalty * C.squaredNorm() : 0.0);
  };
  auto converged = [&](const Evaluation& e) {
    return e.residual <= options.tolerance && (!balance || std::abs(e.balance) <= options.balance_tolerance);
  };
  Eigen::VectorXd delta_full, u_trial;
  struct Outcome {
    std::string failure;     // empty: converged (or split requested)
    std::vector<int> split;  // boundary halfedges to split before going on
  };

  // Damped Newton steps with backtracking line search on the merit function until converged.
  auto newton = [&]() -> Outcome {
    const int nvt = m.num_vertices;
    delta_full.resize(nvt);
    while (true) {
      if (!ev.valid) return {"invalid metric", {}};
      if (converged(ev)) return {};
      if (result.iterations >= options.max_iterations)
        return {"no convergence after " + std::to_string(result.iterations) + " Newton iterations", {}};
      if (n_free == 0) return {"no free vertex to adjust", {}};
      Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n_free, balance ? 3 : 1);
      for (int v = 0; v < nvt; ++v)
        if (index[v] >= 0) rhs(index[v], 0) = -ev.gradient[v];
      Eigen::VectorXd c_re = Eigen::VectorXd::Zero(n_free), c_im = Eigen::VectorXd::Zero(n_free);
      if (balance) {
        const LoopData& o = loops[outer];
        for (size_t k = 0; k < o.vertices.size(); ++k) {
          const int i = index[o.vertices[k]];
          if (i < 0) continue;
          c_re[i] = ev.balance_gradient[k].real();
          c_im[i] = ev.balance_gradient[k].imag();
        }
        rhs.col(1) = c_re;
        rhs.col(2) = c_im;
      }
      // Newton (KKT) direction with the full Hessian; if it fails or gives no descent, with its
      // convex part (the outer loop's term is concave, so H can be indefinite far from the
      // solution); as the last resort steepest descent. Trust region: the step is scaled so that
      // no u changes by more than max_step, so a badly predicted direction cannot jump far.
      // Merit function: the augmented Lagrangian E + nu . C + penalty / 2 |C|^2 of the balance
      // constraint C, with the step's multiplier nu.
      const double damping = options.damping * std::max(ev.residual, 1e-8) / nvt;
      const Eigen::Vector2d C(ev.balance.real(), ev.balance.imag());
      Eigen::VectorXd delta;
      double slope = 0;
      multiplier.setZero();
      for (int attempt = 0; attempt < 3; ++attempt) {
        Eigen::MatrixXd x;
        if (attempt < 2) {
          if (attempt == 1) ++result.fallback_steps;
          if (!system.factor(m, ev, loops, attempt == 0, damping) || !system.solve(rhs, x)) continue;
          delta = x.col(0);
          if (balance) {
            // H delta + C_u^T nu = -g, C_u delta = -C: delta = z - Y nu, (C_u Y) nu = C_u z + C.
            Eigen::Matrix2d CY;
            CY << c_re.dot(x.col(1)), c_re.dot(x.col(2)), c_im.dot(x.col(1)), c_im.dot(x.col(2));
            multiplier = CY.fullPivLu().solve(Eigen::Vector2d(c_re.dot(delta) + C.x(), c_im.dot(delta) + C.y()));
            if (!multiplier.allFinite()) continue;
            delta -= x.col(1) * multiplier[0] + x.col(2) * multiplier[1];
          }
        } else {
          delta = rhs.col(0);
          multiplier.setZero();
        }
        if (!delta.allFinite()) continue;
        const double largest = delta.cwiseAbs().maxCoeff();
        capped = largest > radius;
        if (capped) delta *= radius / largest;
        // Descent needs the Lagrangian part to decrease (H positive on the step); the penalty
        // part then does too, as the step reduces C.
        const double gd = -rhs.col(0).dot(delta);
        const Eigen::Vector2d Cd(c_re.dot(delta), c_im.dot(delta));
        const double lagrangian = gd + (balance ? multiplier.dot(Cd) : 0.0);
        slope = lagrangian + (balance ? penalty * C.dot(Cd) : 0.0);
        // Near the solution (quadratic convergence) the slope is lost in rounding; the line
        // search then accepts a full step that shrinks the residual.
        if ((lagrangian < 0 && slope < 0) || (attempt == 0 && ev.residual < 1e-6)) break;
      }
      for (int v = 0; v < nvt; ++v) delta_full[v] = index[v] >= 0 ? delta[index[v]] : 0.0;

      // Backtracking line search on the merit function (with a tolerance for its rounding
      // error; near the solution a full step that shrinks the residual is accepted as well).
      // Points where more triangles violate the triangle inequality are rejected; the boundary
      // edges that were too long there are remembered, to be split if the step has to shrink a
      // lot.
      const double merit0 = merit(ev);
      double t = 1;
      bool accepted = false;
      std::vector<int> too_long;
      for (int step = 0; step <= options.max_line_search_steps; ++step) {
        u_trial = u + t * delta_full;
        if (options.delaunay_flips) ricci::make_delaunay(m, u_trial, {false, options.delaunay_tolerance, max_flips});
        evaluate(m, u_trial, loops, outer, trial);
        const bool more_invalid = trial.invalid_triangles > ev.invalid_triangles;
        // The balance may not grow beyond max(current, balance_slack): far from the solution
        // the energy can keep decreasing towards a crowded outer loop, which only the
        // constraint stops.
        const bool balanced = !balance || std::abs(trial.balance) <= std::max(std::abs(ev.balance), options.balance_slack);
        if (trial.valid && balanced && !(options.reject_invalid && more_invalid)) {
          const double rounding = 1e-13 * std::max(ev.energy_scale, trial.energy_scale);
          const bool armijo = merit(trial) <= merit0 + 1e-4 * t * slope + rounding;
          const bool near = t == 1 && ev.residual < 1e-6 && trial.residual < 0.5 * ev.residual &&
                            std::abs(trial.balance) <= std::max(std::abs(ev.balance), options.balance_tolerance);
          if (armijo || near) {
            accepted = true;
            break;
          }
        }
        if (trial.valid && more_invalid && too_long.empty()) too_long = invalid_boundary_edges(m, u_trial, u);
        ++result.line_search_halvings;
        t *= 0.5;
      }
      // The trust region grows while capped steps are taken in full and shrinks back when the
      // line search has to cut.
      if (accepted && t == 1 && capped) radius = std::min(2 * radius, 64 * options.max_step);
      if (t < 1) radius = std::max(options.max_step, 0.5 * radius);
      if (accepted) {
        u.swap(u_trial);
        std::swap(ev, trial);
        ++result.iterations;
      } else {
        // Leave the triangulation Delaunay for the last accepted u.
        if (options.delaunay_flips) ricci::make_delaunay(m, u, {false, options.delaunay_tolerance, max_flips});
        evaluate(m, u, loops, outer, ev);
      }
      const std::string stalled =
          accepted ? std::string() : "line search stalled after " + std::to_string(result.iterations) + " Newton iterations";
      if (!too_long.empty() && t < options.split_step) return {stalled, too_long};
      if (!accepted) return {stalled, {}};
    }
  };

  // Newton, splitting boundary edges where the line search asks for it. Ends: each round either
  // inserts a vertex (at most max_inserted), takes a step (at most max_iterations) or fails.
  std::string failure;
  while (true) {
    Outcome outcome = newton();
    failure = outcome.failure;
    if (outcome.split.empty()) break;
    bool any = false;
    for (int h : outcome.split)
      if (static_cast<int>(result.inserted_vertices.size()) < max_inserted && split_boundary_edge(h)) any = true;
    if (any) {
      failure.clear();
      if (options.delaunay_flips) ricci::make_delaunay(m, u, {false, options.delaunay_tolerance, max_flips});
      reindex();
      evaluate(m, u, loops, outer, ev);
    } else if (!failure.empty()) {
      break;
    }
  }
  result.converged = failure.empty();

  const int nvt = m.num_vertices;
  result.residual = ev.residual;
  result.balance = std::abs(ev.balance);
  result.flips = static_cast<int>(m.flips - flips_before);
  result.energy = ev.energy;
  result.invalid_triangles = ev.invalid_triangles;
  result.non_delaunay_edges = ricci::count_non_delaunay(m, u, options.delaunay_tolerance);
  if (!result.converged && options.throw_on_failure)
    throw AlgorithmError("flat_metric: " + failure + ": max curvature error " + num(ev.residual) + " (tolerance " +
                         num(options.tolerance) + "), balance " + num(std::abs(ev.balance)) + ", " +
                         std::to_string(nv) + " vertices, " + std::to_string(b) + " loops, " +
                         std::to_string(ev.invalid_triangles) + " invalid triangles");
  result.u = u;
  result.triangulation = export_triangulation(m, u, log_scale, ev);
  result.triangulation.non_delaunay_edges = result.non_delaunay_edges;
  result.curvature.resize(nvt);
  result.target_curvature.resize(nvt);
  for (int v = 0; v < nvt; ++v) {
    const double base = m.boundary_vertex[v] ? kPi : 2 * kPi;
    result.curvature[v] = base - ev.angle_sum[v];
    result.target_curvature[v] = base - ev.target[v];
  }
  result.loops.resize(b);
  result.outer_loop = outer;
  result.loop_total_curvature.resize(b);
  result.loop_radius.resize(b);
  for (int l = 0; l < b; ++l) {
    result.loops[l] = loops[l].vertices;
    double total = 0;
    for (int v : loops[l].vertices) total += result.target_curvature[v];
    result.loop_total_curvature[l] = total;
    result.loop_radius[l] = std::exp(ev.rho[l] + log_scale);
  }
  return result;
}

}  // namespace polycube
