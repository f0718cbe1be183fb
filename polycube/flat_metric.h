// The uniform flat metric of a genus-0 piece with b >= 1 boundary loops (§3.3, eq. 3–5): a
// discrete conformal metric that is flat at every interior vertex and has constant geodesic
// curvature on each boundary loop, total 2π on the outer (longest) loop and −2π on every other
// loop. Laid out in the plane (circle_domain) it is a circle domain: the unit disk minus b − 1
// disks, the multi-hole disk D_{M_i} of Fig. 5.
//
// Method. The paper's Ricci flow du/dt = K̄ − K (eq. 2) is the gradient flow of a convex energy;
// this goes straight to its fixed point: vertex scaling l_ij = e^{(u_i+u_j)/2} l⁰_ij, the energy
// of Springborn–Schröder–Pinkall ("Conformal equivalence of triangle meshes", 2008) minimised
// by Newton's method with a trust region and backtracking line search, the triangulation kept
// intrinsic Delaunay by Ptolemy flips at every evaluated u (Gillespie–Springborn–Crane,
// "Discrete conformal equivalence of polyhedral surfaces", 2021), which keeps the energy C¹ and
// every interior triangle valid for any u. The Hessian (cotangent Laplacian plus the loops' terms, below) is
// factored by sparse LDLᵀ, its pattern analysed once per connectivity.
//
// Constant geodesic curvature. A loop's target turning angles are those of the polygon
// inscribed in a circle with the loop's current edge lengths: half the sum of the central angles
// of the two edges at the vertex. For short edges this is the length share
// k_i = ±2π (l_{i−1,i} + l_{i,i+1}) / (2 L) up to O((l/R)²), but it makes the loops exact circles
// and is invariant under the Möbius maps between circle domains. The targets follow the metric;
// their derivatives are part of the Newton Hessian (a sparse part and one rank-one term per
// loop, by Sherman–Morrison–Woodbury), so convergence is quadratic.
//
// Gauge. Solutions are unique up to scale (u = 0 at a gauge vertex) and the Möbius motions of
// the disk (2 parameters), along which the Hessian is singular at the solution. Those are fixed
// by a constraint solved with the Newton system (KKT): the outer loop's vertices, weighted by
// their share of the input loop length, have their barycentre at the centre of the outer circle
// (Douady–Earle's conformal barycentre), so the outer circle is parametrised as evenly as the
// input loop. A symmetric tube gives concentric circles.
//
// Boundary slivers. An outer-loop edge whose triangle would be pushed past its chord when the
// loop becomes a circle (triangle inequality violated; boundary edges cannot be flipped) is split
// at its midpoint: beforehand where the opposite angle is close to π, during the solve where the
// line search meets it. The metric then lives on the input vertices plus those inserted ones.
#pragma once

#include "polycube/intrinsic_delaunay.h"
#include "polycube/mesh.h"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace polycube {

struct FlatMetricOptions {
  // Converged when every vertex's angle sum is within this many radians of its target (interior
  // 2π, boundary π − target geodesic curvature), i.e. max |curvature error| <= tolerance.
  double tolerance = 1e-10;
  // Newton iterations before giving up with AlgorithmError (typical: 4–20; up to ~80 on small
  // pieces with clusters of tiny boundary edges, where flips keep changing the Hessian).
  int max_iterations = 200;
  // Keep the triangulation intrinsic Delaunay by Ptolemy flips during the solve (recommended:
  // the energy stays convex in the interior and every interior triangle stays valid). false keeps
  // the starting connectivity; then invalid triangles are handled only by the line search.
  bool delaunay_flips = true;
  // First make the input intrinsically Delaunay by metric-preserving (Euclidean) flips, so the
  // conformal class is that of the piecewise-flat input surface rather than of its (possibly
  // sliver-filled) triangulation.
  bool initial_delaunay = true;
  // Edges with cos(alpha) + cos(beta) below -delaunay_tolerance are flipped.
  double delaunay_tolerance = 1e-12;
  // Bound on flips per Delaunay pass, as a multiple of the edge count.
  double max_flips_per_edge = 100;
  // Levenberg–Marquardt damping of the Newton steps: damping * max(residual, 1e-8) / #V is
  // added to the Hessian's diagonal, which is singular along the Möbius motions at the solution;
  // proportional to the residual, so convergence stays quadratic.
  double damping = 1;
  // Reject line-search points with more invalid triangles than the current one.
  bool reject_invalid = true;
  // Outer-loop edges whose opposite angle exceeds pi - boundary_split_safety * theta / 2 (theta
  // = 2 pi l / L, the edge's expected central angle) are split at their midpoint before solving,
  // so that the triangle on them stays valid when the loop becomes a circle; 0 disables.
  double boundary_split_safety = 3;
  // A boundary edge that is too long in a triangle rejected by the line search is split (in the
  // current metric) when the accepted step is shorter than this fraction of the Newton step.
  double split_step = 1.0 / 8;
  // Most vertices inserted by splits, over the whole solve; -1: the number of boundary edges
  // plus 16 (then the solve goes on without splitting, and fails if it stalls).
  int max_inserted_vertices = -1;
  // Initial trust region: the largest change of any u in one Newton step (the step is scaled
  // down to it), against steps into badly modelled regions, e.g. towards crowded outer loops.
  // It doubles (up to 64 times this) while capped steps are accepted in full, and halves back
  // (not below this) when the line search cuts a step.
  double max_step = 1;
  // Halvings of the Newton step in one line search before giving up with AlgorithmError.
  int max_line_search_steps = 60;
  // Fix the Möbius freedom by the constraint FlatMetric::balance = 0, to balance_tolerance.
  // false: only the damping keeps the iteration from drifting along the family of solutions
  // (the layout then depends on rounding at the 1e-6 level, and can end up crowded).
  bool balance = true;
  double balance_tolerance = 1e-10;
  // Line-search points where the balance exceeds max(its current value, balance_slack) are
  // rejected: the energy alone can decrease towards a crowded outer loop.
  double balance_slack = 0.1;
  // Index of the loop to map to the outer circle; -1: the longest loop by input length (§3.3).
  int outer_loop = -1;
  // false: return an unconverged result (converged = false) instead of throwing AlgorithmError.
  bool throw_on_failure = true;
};

// The flat metric and how it was found. Vertex ids below #V(piece) are the piece's; the
// vertices flat_metric inserted follow (inserted_vertices).
//   u                   log scale factors, one per vertex: on an input edge
//                       l_ij = e^{(u_i+u_j)/2} l⁰_ij; u = 0 at the gauge vertex
//   triangulation       the intrinsic Delaunay triangulation the metric lives on (connectivity
//                       changed by flips and splits), lengths of the flat metric in input units;
//                       adjacent = adjacent_edge = -1 across boundary edges
//   curvature           per vertex of the result: Gaussian curvature 2π − Θ at interior
//                       vertices, geodesic curvature π − Θ at loop vertices (Θ = angle sum)
//   target_curvature    0 inside; on loop vertices ± half the central angles of the two adjacent
//                       edges on the loop's circle (+ outer loop, − holes)
//   loops               the loops as given, with inserted vertices in between; outer_loop
//                       indexes the one with total +2π
//   loop_total_curvature per loop: sum of target_curvature (+2π outer, −2π others)
//   loop_radius         per loop: radius of its circle in the flat metric (input units)
//   gauge_vertex        the vertex with u = 0 (first vertex of the outer loop)
//   input_vertices      #V(piece)
//   inserted_vertices   per inserted vertex, the two ends of the boundary edge it split (at the
//                       edge's midpoint in the metric of that moment); the first
//                       presplit_vertices of them were split before solving, in the input
//                       metric, so they are midpoints of input edges
//   residual            max over all vertices of |curvature − target_curvature| (radians)
//   balance             distance of the weighted barycentre of the outer loop's vertices from
//                       the centre of the outer circle, relative to its radius (the gauge)
//   converged           residual <= tolerance and balance <= balance_tolerance
//   iterations          Newton steps; fallback_steps of them used the convex part of the
//                       Hessian because the full one gave no descent direction
//   line_search_halvings  total over all steps
//   initial_flips       metric-preserving flips before solving; flips: Ptolemy flips after
//   invalid_triangles   triangles of the result violating the triangle inequality (0 unless
//                       not converged)
//   non_delaunay_edges  interior edges left non-Delaunay (0 unless a flip bound was hit)
//   energy              final value of the minimised energy (for diagnostics)
struct FlatMetric {
  Eigen::VectorXd u;
  IntrinsicTriangulation triangulation;
  Eigen::VectorXd curvature;
  Eigen::VectorXd target_curvature;
  std::vector<std::vector<int>> loops;
  int outer_loop = 0;
  std::vector<double> loop_total_curvature;
  std::vector<double> loop_radius;
  int gauge_vertex = -1;
  int input_vertices = 0;
  std::vector<std::array<int, 2>> inserted_vertices;
  int presplit_vertices = 0;
  double residual = 0;
  double balance = 0;
  bool converged = false;
  int iterations = 0;
  int fallback_steps = 0;
  int line_search_halvings = 0;
  int initial_flips = 0;
  int flips = 0;
  int invalid_triangles = 0;
  int non_delaunay_edges = 0;
  double energy = 0;
};

// Computes the uniform flat metric of a piece.
//   piece  oriented, edge-manifold triangle mesh of genus 0 with b >= 1 boundary loops, no
//          zero-length edge, every vertex used (e.g. PieceMesh::mesh)
//   loops  its b boundary loops as vertex cycles with the piece on the left (each consecutive
//          pair, and last-first, a boundary edge in face orientation), each boundary edge once
// Throws MeshError if the piece is not of that kind (with the measured Euler characteristic,
// loop count, offending edge), AlgorithmError (with the residual reached) if Newton's method does
// not converge within max_iterations or its line search stalls.
FlatMetric flat_metric(const TriMesh& piece, const std::vector<std::vector<int>>& loops,
                       const FlatMetricOptions& options = {});

}  // namespace polycube
