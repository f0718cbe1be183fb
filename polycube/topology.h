// Stage 1 of the method (§3.1–3.2 and the Appendix): the topological structure of the mesh and
// the horizontal planes that cut it into genus-0 pieces.
#pragma once

#include "polycube/critical_points.h"
#include "polycube/cutting_planes.h"
#include "polycube/harmonic_function.h"
#include "polycube/mesh.h"
#include "polycube/slice.h"

#include <vector>

namespace polycube {

struct TopologyOptions {
  // Largest distance between adjacent planes in unit-cube units (§3.2's d_z).
  double dz = 0.08;
  // Critical points within this fraction of the model height are one level (§3.2: 0.01).
  double level_merge = 0.01;
  // Subdivide the gaps between the ends of the model and the first/last plane too.
  bool split_end_gaps = true;
  // Most planes in total (from §3.2 and added for genus) before giving up with AlgorithmError.
  int max_planes = 2000;
  // CuttingPlaneOptions::length_scales (a scaled copy's girth rule measured on its model).
  Eigen::Vector3d length_scales = Eigen::Vector3d::Ones();
  HarmonicOptions harmonic;
};

// Everything the stage computed, with counts and times for reporting.
//   harmonic       f of eq. (1) on the intrinsic Delaunay triangulation
//   critical       its critical points (spurious extrema cancelled: 1 min, 1 max, 2g saddles)
//   initial_planes the planes of §3.2 before genus refinement
//   planes_z       the planes sliced along, input coordinates, ascending (= sliced.planes)
//   planes_normalised  the same as (z - z_min) / (largest bounding-box side)
//   sliced         the refined mesh and its pieces, every piece genus 0. Its vertices are the
//                  input's (same ids), then split_saddles vertices added by saddle splits, then
//                  the vertices created on planes; face_origin refers to the input faces, except
//                  for the 2 faces each split adds (ids >= #F of the input)
//   planes_added_for_genus  planes added because a piece still had a handle
//   split_saddles  degenerate (monkey) saddles of z split because a piece's handle sat in one;
//                  each split moves the surface within the star of one vertex (usually 0)
//   refinement_rounds       slicing passes after the first one
//   euler, genus   of the input mesh
struct TopologyResult {
  HarmonicFunction harmonic;
  CriticalPoints critical;
  CuttingPlanes initial_planes;
  std::vector<double> planes_z;
  std::vector<double> planes_normalised;
  SlicedMesh sliced;
  int planes_added_for_genus = 0;
  int split_saddles = 0;
  int refinement_rounds = 0;
  int euler = 0;
  int genus = 0;
  double seconds_harmonic = 0;
  double seconds_critical = 0;
  double seconds_planes = 0;   // §3.2 planes and genus refinement (without slicing)
  double seconds_slicing = 0;  // all slicing passes
  double seconds_total = 0;
};

// Runs the topology stage on a closed mesh:
//   1. f of eq. (1) and its critical points on the intrinsic Delaunay triangulation (§3.1);
//   2. cutting planes between critical levels and at most dz apart (§3.2);
//   3. exact slicing into pieces;
//   4. while a piece has genus > 0 (its handle fell between two planes: two saddles on one
//      level, or a bent branch), one more plane inside that piece's slab, between two heights
//      of its critical points of z, chosen to leave the least genus in the two halves (then
//      the widest critical-free gap). A slab without critical heights of z is a union of
//      cylinders, so this ends with every piece of genus 0 (Appendix) — except where a handle
//      sits in a single degenerate (monkey) saddle of the PL height function, which no
//      horizontal plane can cut: that saddle is split into two at different heights by a local
//      vertex split first (see split_saddles).
// Throws MeshError unless the mesh is closed, connected, 2-manifold, consistently oriented, with
// finite coordinates and a positive height; AlgorithmError when a piece of positive genus has all
// its critical points of z at one height (no horizontal plane can separate them), when more than
// max_planes planes would be needed, or when the pieces fail their own consistency checks.
// harmonic (optional): a solver built on this mesh's faces with options.harmonic, for step 1 (the
// orientation search builds one for all its candidates, turned copies of one mesh).
TopologyResult analyse_topology(const TriMesh& mesh, const TopologyOptions& options = {}, const HarmonicSolver* harmonic = nullptr);

}  // namespace polycube
