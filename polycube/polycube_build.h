// Stage 2 of the method (§3.2): the polycube P, built automatically from the model's cutting
// planes with a topology guarantee — P cut by the same planes has pieces matching the model's
// pieces one to one, with the same boundary loops and genus 0, so P has the model's genus and a
// one-to-one map between them exists piece by piece (§3.3–3.4, Appendix).
#pragma once

#include "polycube/contour_sections.h"
#include "polycube/errors.h"
#include "polycube/mesh.h"
#include "polycube/polycube_surface.h"
#include "polycube/slice.h"
#include "polycube/topology.h"

#include <string>
#include <vector>

namespace polycube {

struct PolycubeOptions {
  // Largest normalised area difference area(Q_r Δ R_r) / area(R_r) of every region r of a cross
  // section and its axis-aligned approximation (§3.2's d_a; §3.2's d_z is TopologyOptions::dz).
  double da = 0.3;
  // Deepest quadtree level the d_a refinement goes to (cells of 2^-level of the largest
  // bounding-box side).
  int max_level = 10;
  // Thin parts kept (QuadtreeOptions::feature_distance; fraction of the largest bounding-box
  // side; 0: only d_a decides).
  double feature_distance = 0;
  // Deepest quadtree level topology repairs may subdivide to (at most kQuadGridBits = 20).
  int max_repair_level = 18;
  // About how many vertices P's mesh gets; 0: as many as the model has, at least min_vertices.
  int target_vertices = 0;
  int min_vertices = 0;
  // Per slab, how many times the quadtree cells where a failing slab's regions meet may be
  // subdivided (only when the finely sampled contours pass the slab's check, i.e. subdivision
  // can repair it) before a plane is inserted in the middle of the slab instead. More attempts
  // trade planes for (many) corners.
  int refine_attempts = 1;
  // Most quadtree leaves per plane: subdivisions for the stacking stop there (then planes are
  // inserted instead), and a cross-section needing more for its own topology is an error.
  int max_plane_cells = 40000;
  // Planes the repairs may insert in total before giving up.
  int max_inserted_planes = 400;
  // Check-and-repair rounds before giving up.
  int max_rounds = 80;
  // Most common-grid cells the checks may cover in total (quadtree_raster.h, rasterized_cells:
  // their work, without a clock) before giving up; 0: no limit. A scoring budget for orientations whose sections are
  // costly to check (a box with holes turned off its axes: minutes per candidate).
  double max_rasterized_cells = 0;
  // Thinnest slab, as a fraction of the model's height, that may still get a plane inserted.
  double min_slab = 1e-5;
  // Once every slab passes, simplify the quadtrees wherever d_a, the sections' topology and both
  // slabs' checks allow: merge sibling leaves the repairs split (coarsen_section), then relabel
  // leaves so that each Q_i follows its neighbours where that removes corners (snap_section).
  // No cell is merged into one wider than the widest gap between planes, none relabelled wider
  // than half of it. Fewer, larger steps: fewer corners.
  bool simplify = true;
};

// Everything the stage did.
//   polycube          P in the input's coordinate frame
//   model_sliced      the model cut by the final planes: its pieces M_j (the topology stage's
//                     slicing when no plane was inserted)
//   model_sections    the model's contours on the final planes
//   polycube_sliced   P cut by the same planes: its pieces P_j
//   polycube_piece_contours  per P piece: the model contours of its loops
//   piece_match       per model piece M_j: the index of P_j (into polycube_sliced.pieces)
//   planes_z          the final planes, input frame, ascending (= model_sliced.planes)
//   genus             of the model and of P
//   planes_inserted   planes the repairs inserted between existing ones
//   accuracy_splits   quadtree subdivisions for d_a (§3.2)
//   section_splits    subdivisions repairing the topology of single cross-sections (merged or
//                     vanished contours, holes, diagonal touches)
//   section_relabels  cells relabelled where a cross-section's topology needed cells finer than
//                     max_repair_level (slivers, near-touching contours)
//   stacking_splits   subdivisions repairing slabs (non-manifold touches between extrusions,
//                     pieces whose loops or genus did not match)
//   relabelled_cells  cells grown into or shrunk out of a Q_i to remove non-manifold touches
//   rounds            check-and-repair rounds (1 when nothing needed repair)
//   deepest_level     of any quadtree leaf
//   max_region_error  largest area(Q_r Δ R_r) / area(R_r) over all regions of all planes (the
//                     simplification keeps every region within max(d_a, what the repairs left))
//   coarsening_merges  sibling leaf groups merged into their parent by the simplification
//   snapped_cells     leaves the simplification relabelled to follow a neighbouring plane
//   repairs           one line per repair made
struct PolycubeResult {
  Polycube polycube;
  SlicedMesh model_sliced;
  CrossSections model_sections;
  SlicedMesh polycube_sliced;
  std::vector<std::vector<int>> polycube_piece_contours;
  std::vector<int> piece_match;
  std::vector<double> planes_z;
  int genus = 0;
  int planes_inserted = 0;
  int accuracy_splits = 0;
  int section_splits = 0;
  int section_relabels = 0;
  int stacking_splits = 0;
  int relabelled_cells = 0;
  int rounds = 0;
  int deepest_level = 0;
  double max_region_error = 0;
  int coarsening_merges = 0;
  int snapped_cells = 0;
  std::vector<std::string> repairs;
  double seconds_quadtrees = 0;  // building and repairing the quadtrees
  double seconds_checks = 0;     // slab checks and re-slicing
  double seconds_simplify = 0;   // coarsening and snapping after the checks pass
  double seconds_surface = 0;    // faces, edges and triangulation of P
  double seconds_verify = 0;     // final check of P
  double seconds_total = 0;
  long long rasterized_cells = 0;  // grid cells the checks rasterized (quadtree_raster.h)
};

// Builds the polycube of §3.2 for a model and its topology stage:
//   1. contours of every plane and their nesting (cross_sections);
//   2. per plane a quadtree approximation Q_i on a global dyadic grid, refined for d_a and for
//      the topology of the contours (approximate_section);
//   3. per slab between consecutive planes, a combinatorial check that the stacked extrusions
//      are a 2-manifold and have the model's pieces (check_slab). Failures are repaired locally,
//      in this order: non-manifold touches by growing or shrinking the cells around them so
//      that the two cross-sections nest there (kept only if neither slab of the plane gets
//      worse); then, if the contours sampled finely would pass (sample_section), by subdividing
//      the cells where the slab's regions meet; otherwise by inserting a plane in the middle of
//      the slab and re-slicing the model. Inserted planes whose cross-section cannot be
//      approximated (a neck finer than the deepest cells) are moved within their slab;
//   4. simplification (PolycubeOptions::simplify): leaves merged back and relabelled to follow
//      the neighbouring planes where d_a, the sections' topology and both slabs' checks allow;
//   5. the surface, its faces, edges and corners, triangulated (build_polycube_surface);
//   6. the guarantee checked on the triangle mesh (verify_polycube); should the simplified
//      quadtrees fail it, P is built again from the unsimplified ones and checked again.
//   model     the closed mesh the topology stage ran on (input frame)
//   topology  analyse_topology(model, ...)
// Throws AlgorithmError when the repairs exceed their limits or P fails its final check — an
// invalid polycube is never returned — and std::invalid_argument for inconsistent inputs.
PolycubeResult build_polycube(const TriMesh& model, const TopologyResult& topology, const PolycubeOptions& options = {});

// Whether two builds for the same model and topology gave the same polycube: the same planes,
// P's triangles, vertex positions (exactly), face axes and patches, edges, vertices, corners,
// levels, spacing and section loops, and the same piece matching and contours. Everything later (the map, its refinement and finish) depends on nothing else, so a
// caller may skip a build that repeats an earlier one: finer contours (d_a) often leave a coarse
// CAD model's axis-aligned sections, and so P, as they were.
bool same_polycube(const PolycubeResult& a, const PolycubeResult& b);

// What build_polycube throws when its check-and-repair rounds (PolycubeOptions::max_rounds) run
// out with slabs still failing: a budget that ran out, where more rounds may succeed, rather than a
// cross-section that cannot be approximated within the limits.
class RepairRoundsExhausted : public AlgorithmError {
 public:
  RepairRoundsExhausted(const std::string& message, int failing_slabs) : AlgorithmError(message), failing_slabs(failing_slabs) {}
  int failing_slabs;
};

}  // namespace polycube
