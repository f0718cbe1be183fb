// The harmonic function of §3.1 (eq. 1): Δf = 0 on the surface with f = 0 at the bottom-most and
// f = 1 at the top-most vertex. Its critical points reveal the topology (handles) of the mesh.
#pragma once

#include "polycube/intrinsic_delaunay.h"
#include "polycube/mesh.h"

#include <Eigen/Core>

#include <memory>

namespace polycube {

struct HarmonicOptions {
  // Build the Laplacian on the intrinsic Delaunay triangulation (all cotangent weights >= 0, so
  // f obeys the discrete maximum principle). false: the input triangulation, whose obtuse
  // triangles can give negative weights and spurious extrema.
  bool intrinsic_delaunay = true;
  // Steps of iterative refinement after the Cholesky solve (each one a residual and two
  // triangular solves); they bring f to nearly full double precision where it is flat.
  int refinement_steps = 2;
  // With intrinsic Delaunay: edge weights below this fraction of the mean edge weight are
  // raised to it (see HarmonicFunction::raised_weights).
  double min_weight = 1e-6;
  // Laplacians with at least this many unknowns are factorised by CHOLMOD's supernodal Cholesky
  // (SuiteSparse, METIS ordering); smaller ones by Eigen's SimplicialLDLT (AMD ordering). Both
  // solve the same system; the supernodal one is the faster from about 10^5 unknowns (gargoyle
  // subdivided twice, 773 409 unknowns: 47 s → 12 s; gargoyle, 48 339: 0.37 s → 0.50 s;
  // bench/quad.md, twenty-eighth session).
  int supernodal_min_unknowns = 100000;
};

// f and what it was computed on.
//   f          #V values in [0,1]; f(source) = 0, f(sink) = 1
//   source     lowest vertex by z (smallest index among equal z)
//   sink       highest vertex by z (smallest index among equal z)
//   intrinsic  the triangulation the Laplacian was built on (the input's own triangulation with
//              Euclidean lengths when options.intrinsic_delaunay is false); critical points of f
//              are taken on its vertex links
//   negative_weights  edges whose cotangent weight is below -1e-10 times the mean: only edges
//              the flips could not make Delaunay (IntrinsicTriangulation::non_delaunay_edges),
//              or with intrinsic_delaunay off any edge opposite two angles summing to over π
//   raised_weights    with intrinsic Delaunay: edges whose weight was below min_weight times the
//              mean weight (zero for cocircular quads, negative as above) and was raised to it,
//              so that all weights are positive and f obeys the strict maximum principle: every
//              free vertex lies strictly between its lowest and highest neighbour
//   residual   max-norm of the Laplace equation's residual at the free vertices, relative to
//              the right-hand side
//   supernodal the Laplacian was factorised by CHOLMOD (HarmonicOptions::supernodal_min_unknowns)
struct HarmonicFunction {
  Eigen::VectorXd f;
  int source = -1;
  int sink = -1;
  IntrinsicTriangulation intrinsic;
  int intrinsic_flips = 0;
  int negative_weights = 0;
  int raised_weights = 0;
  double residual = 0;
  bool supernodal = false;
};

// Solves the Dirichlet problem of eq. (1) with the cotangent Laplacian (sparse Cholesky: Eigen's
// or CHOLMOD's, see HarmonicOptions::supernodal_min_unknowns).
// Lengths are taken after scaling the model to the unit cube (largest bounding-box side 1), so
// f does not depend on the scale or position of the input.
//   mesh  closed, connected, edge-manifold, consistently oriented mesh; every vertex used
// Throws MeshError if the mesh is not of that kind or has no height (all z equal), and
// AlgorithmError if the factorisation fails.
HarmonicFunction harmonic_function(const TriMesh& mesh, const HarmonicOptions& options = {});

// The part of harmonic_function that does not depend on which vertices are lowest and highest:
// the intrinsic Delaunay triangulation and the cotangent Laplacian, factorised once, grounded at
// one vertex. solve() then gives harmonic_function of any rigid motion or scaling of the mesh
// (the orientation search's candidates) by one pair of triangular solves: u = L_g⁻¹(e_sink −
// e_source) is harmonic at every vertex but those two (the grounded equation holds because the
// others do and L's rows sum to zero), and f = (u − u_source) / (u_sink − u_source) is the
// Dirichlet solution of eq. (1), the same as harmonic_function's up to rounding. The
// triangulation's lengths are in the units of the mesh given here scaled to the unit cube.
// Thread-safe: solves run one at a time.
class HarmonicSolver {
 public:
  // Throws as harmonic_function does (but needs no height: that is the moved mesh's).
  explicit HarmonicSolver(const TriMesh& mesh, const HarmonicOptions& options = {});
  ~HarmonicSolver();
  HarmonicSolver(const HarmonicSolver&) = delete;
  HarmonicSolver& operator=(const HarmonicSolver&) = delete;

  // f for `moved`: the mesh's faces, its vertices moved rigidly (and scaled). Throws
  // std::invalid_argument for other faces or vertex counts, MeshError for no height.
  HarmonicFunction solve(const TriMesh& moved) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace polycube
