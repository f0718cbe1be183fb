// Auto-orientation (the paper's limitation 1: its polycube depends on how the model is turned).
// Candidates are the input frame, the model's principal axes (when its variances differ; otherwise
// only when no other candidate passes four times the scoring budget) and the frame its surface normals
// align with best (normal_axes; when they align markedly, as a CAD part's do; otherwise only when
// no other candidate passes the scoring budget; never when it is one of the other two), each with
// each of its three axes as the sweep direction z (a rotation already a candidate is not one
// again: principal axes snapped to the coordinate axes can repeat the input frame's). Each gets
// its polycube (under a small repair budget); the few with the fewest corners also get their
// map, and the map with the fewest flipped image triangles (then the least ε_angle, then the
// fewest corners) wins. When no candidate passes the budget, they are tried again with four
// times the budget, then in order with the caller's full budget, and the first that builds wins
// (an invalid polycube is never returned: build_polycube throws instead).
#pragma once

#include "polycube/mesh.h"
#include "polycube/polycube_build.h"
#include "polycube/polycube_map.h"
#include "polycube/topology.h"

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace polycube {

// One orientation tried: x_aligned = rotation * x_input (a proper rotation).
//   corners  of the polycube built in it (-1 if the stages failed there, see error)
//   flipped, eps_angle, eps_area  of its map before smoothing, both directions (-1 if not mapped)
//   fallback_budget  its polycube was built with more than the scoring budget: by the fallback (no
//            candidate passed the scoring budget: four times that budget, or the caller's full
//            one), or as a near miss given a second chance (four times the budget)
//   failing_slabs  when its last polycube build ran out of repair rounds (RepairRoundsExhausted):
//            the slabs still failing; 0 otherwise
//   error    why its stages failed ("not built: the search was stopped" when AlignmentOptions::
//            stop ended the search first)
//   rasterized_cells  grid cells its last polycube build's checks rasterized, passed or not
struct AlignmentCandidate {
  std::string name;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  int corners = -1;
  int flipped = -1;
  double eps_angle = -1;
  double eps_area = -1;
  bool fallback_budget = false;
  int failing_slabs = 0;
  long long rasterized_cells = 0;  // the work of its last polycube build's checks (quadtree_raster.h)
  double seconds = 0;
  std::string error;
};

//   chosen     index of the winner, -1 if every candidate failed (within the scoring budget, and
//              with the full budget when full_budget_fallback is on)
//   topology, polycube, map  the winner's stages (built on the turned model), so they need not be
//              redone (map is null when the winner was not mapped, or was scored on the proxy)
//   proxy_faces  faces of the simplified copy the candidates were scored on (0: the model itself)
//   stopped    AlignmentOptions::stop ended the search: nothing is chosen
//   alternatives  other mapped candidates with their stages, next best first (see
//              AlignmentOptions::alternatives), for a caller whose later stages (refinement,
//              smoothing) may end with flips on the winner and who then tries the next
struct AlignedStages {
  int candidate = -1;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  std::shared_ptr<TopologyResult> topology;
  std::shared_ptr<PolycubeResult> polycube;
  std::shared_ptr<PolycubeMap> map;
};
// Whether b's stages repeat a's: both polycubes built, the same rotation and the same polycube
// (same_polycube). On the same model, with the same options after the polycube, the map and all
// that follows are then the same (map and quad skip such an attempt of a later search).
bool same_stages(const AlignedStages& a, const AlignedStages& b);
struct Alignment {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  int chosen = -1;
  std::vector<AlignmentCandidate> candidates;
  std::shared_ptr<TopologyResult> topology;
  std::shared_ptr<PolycubeResult> polycube;
  std::shared_ptr<PolycubeMap> map;
  int proxy_faces = 0;
  bool stopped = false;
  std::vector<AlignedStages> alternatives;
  // The other candidates built (neither the winner nor an alternative), best by the score first
  // (mapped ones before the rest), with their topology and polycube; map null (it is rebuilt,
  // the same, if asked for: holding every candidate's map would hold memory few callers use).
  // For a caller whose winner and alternatives all finish short of what it needs. Never on the
  // proxy.
  std::vector<AlignedStages> reserve;
  // The winner's stages, then the alternatives'. With no winner (nothing chosen, or no search
  // run): one entry with the identity and nothing built, for the caller to build in the input
  // frame.
  std::vector<AlignedStages> stages_in_order() const;
};

// Principal axes of the surface (area-weighted covariance of the triangles), as the rows of a
// proper rotation, largest variance first.
// spread (optional): the largest variance divided by the smallest (1 for a sphere or a cube,
// whose principal axes are any axes: rounding picks them).
Eigen::Matrix3d principal_axes(const TriMesh& mesh, double* spread = nullptr);

// A long model's scaled copy (map and quad --equalise-axes): the model turned to its principal
// axes (the rows of principal_axes), each scaled so that the surface's standard deviations along
// them come within max_ratio of each other (those beyond the geometric mean's band,
// sqrt(max_ratio) either way, are brought to its edge; the scales' product is 1). It is a linear
// image of the model, and scaling along the axes keeps a polycube built in the copy's frame
// axis-aligned: the copy's P, scaled back, is a polycube of the model. Made when the largest
// principal standard deviation exceeds the next long_ratio times. Defaults measured (bench/map.md, thirty-fourth
// session): CAD rods 1000 and 3 333 times as long as wide (ratios 411 and 1 369) need it (the
// latter's own map did not finish in 26 minutes, the former's quads took 404 s); below 100 the
// model's own maps and quads were as good or better: a 100 : 1 rod (41) ε_angle 1.032 against
// 1.043 through the copy, quads 1.8° against 5.3°; a 40:2:3 needle (11.6) 1.034 against 1.021; the
// 20 shipped meshes reach 3.2 (femur). Flat models (the two largest deviations alike) are never
// long: plates, a washer and a sheet had less conformal maps through a copy.
//   copy        rotated(model, scales.asDiagonal() * axes)
//   axes        principal_axes(model)
//   scales      the copy's x, y, z are the model's along axes times these
//   deviations  the model's standard deviations along axes
struct EqualisedCopy {
  TriMesh copy;
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d scales = Eigen::Vector3d::Ones(), deviations = Eigen::Vector3d::Zero();
  // For a candidate turning the copy by `rotation` (a permutation of its axes: input_frame_only):
  // the scales of the turned copy's x, y, z, and the rotation turning the model into that frame
  // unscaled (turned copy = turned model times turned_scales).
  Eigen::Vector3d turned_scales(const Eigen::Matrix3d& rotation) const { return rotation.cwiseAbs() * scales; }
  Eigen::Matrix3d turned_axes(const Eigen::Matrix3d& rotation) const { return rotation * axes; }
};
struct EqualisedCopyOptions {
  double long_ratio = 100;
  double max_ratio = 4;
};
std::optional<EqualisedCopy> equalised_copy(const TriMesh& model, const EqualisedCopyOptions& options = {});

// P built on a scaled copy turned by a permutation of its axes (its x, y, z the model's turned
// frame's times scales), its coordinates divided by the scales: an axis-aligned scaling keeps its
// faces axis-aligned and its structure (faces' coordinates and areas, sections, levels and
// spacing follow).
Polycube unscaled_polycube(const Polycube& P, const Eigen::Vector3d& scales);

// φ sampled at the vertices of both meshes, taken back the same way: the surface points are
// barycentric, so they stay; the positions are divided. Without the copy's map data (disks and
// locators are the copy's): what finishes a map (smoothing, the second refinement, the audit)
// needs only the samples.
PolycubeMap unscaled_samples(const PolycubeMap& map, const Eigen::Vector3d& scales);

// The frame whose axes the surface normals align with best, as the rows of a proper rotation: the
// minimiser of Σ_f area_f (x²y² + y²z² + z²x²) over the faces' unit normals (x, y, z) in that
// frame, which is 0 exactly when every face is perpendicular to an axis (a CAD part in its own
// frame). Found by evaluating a fixed set of 1000 rotations, then refining the best few by
// rotations about the axes (to about 0.01°), on at most max_faces faces (every k-th). Axes
// within 5° of the coordinate axes are the coordinate axes, as for principal_axes. Defined only
// up to the cube's 24 rotations; which of them is returned is fixed (the axis most aligned with
// the input's z becomes z, ...). misalignment (optional): the minimum divided by the total area
// (0: every face perpendicular to an axis; 0.2 for normals spread evenly over the sphere).
Eigen::Matrix3d normal_axes(const TriMesh& mesh, int max_faces = 20000, double* misalignment = nullptr);

// Whether two frames differ only by one of the cube's rotations (axes permuted and flipped),
// within `degrees`.
bool same_axes(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b, double degrees = 1);

// The mesh turned by `rotation` about the origin (V * rotation^T).
TriMesh rotated(const TriMesh& mesh, const Eigen::Matrix3d& rotation);

// The scoring budget: each candidate's polycube is built with the caller's options capped by these,
// so that an orientation needing heavy repairs fails in a fraction of a second instead of being
// scored (it would give many corners anyway).
struct AlignmentOptions {
  int threads = 0;  // candidates in parallel; 0: all cores
  int max_rounds = 12;
  int max_inserted_planes = 30;
  int max_plane_cells = 4000;
  int max_repair_level = 12;
  // Most grid cells a candidate's checks may rasterize (PolycubeOptions::max_rasterized_cells);
  // 0: no limit. Measured (bench/map.md): every candidate that passes the scoring budget on the
  // 63 shipped and unseen meshes rasterized at most 3.2e7 cells, every one that passes four times
  // the budget at most 8.0e7 (at d_a 0.1, on cow, femur, 3torus, bull, mpi, camel, dino: 5.0e7 and
  // 1.9e8); the checks filled 1–2e7 of them a second when they ran on the grid (on the leaves
  // since the thirty-seventh session: the same count, no slower, far faster where the grid is huge);
  // cheese turned off its axes spent 229–1 445 s per input-frame candidate.
  double max_rasterized_cells = 5e8;
  // The same for the builds with four times the scoring budget (full_budget_fallback,
  // near_miss_slabs): their rounds, planes and cells are four times the scoring's, their
  // rasterized cells are not. Those that passed needed at most 1.9e8 (above); cow's separated
  // copy turned to its least-spread principal axis spent 108 s on 2.0e9 cells and failed all the
  // same (bench/map.md, thirty-first session). 0: no limit.
  double max_fallback_rasterized_cells = 5e8;
  // Only the input frame's three axes are candidates, in the fallbacks too (a copy whose own frame
  // must be kept: one scaled along its axes, equalised_copy).
  bool input_frame_only = false;
  // The mesh is a copy whose x, y, z are a model's times these (with input_frame_only): each
  // candidate's girth rule measures on the model (TopologyOptions::length_scales).
  Eigen::Vector3d axis_scales = Eigen::Vector3d::Ones();
  // The input frame is the model's principal axes (an equalised copy's): its candidates are named
  // as the principal axes' ("principal axes, longest axis up").
  bool input_frame_is_principal = false;
  // How many candidates (fewest corners first) get their map built and audited first; if all of
  // those still have flipped triangles, the rest are mapped too. 0: corners only.
  int mapped_candidates = 2;
  // The normals' frame is a candidate when its misalignment (normal_axes) is below this.
  double normal_axes_misalignment = 0.12;
  // The principal axes are a candidate when the largest variance exceeds the smallest by this
  // factor (principal_axes' spread); below it they are noise (a cube turned by rounding: cheese,
  // genus 133, spread 1.19, had 116 459 corners there against 2 516 in its own frame; its three
  // principal candidates took 625, 892 and 387 s, the alignment 1 028 s of a 1 730 s run), and
  // are tried only when no other candidate passes four times the scoring budget (cheese's own
  // frame passes only that).
  double principal_axes_spread = 1.25;
  // Models with more faces than proxy_above are scored on a copy simplified to about proxy_faces
  // faces (simplify.h); the winner's topology and polycube are then built on the model itself
  // (next best when that fails), without its map. 0: never.
  int proxy_above = 150000;
  int proxy_faces = 50000;
  // When no candidate passes the scoring budget, build them all again with four times that budget
  // (the fewest corners win) and, if none passes, with the caller's full budget, in order, until
  // one succeeds (chosen is then that one, with its topology and polycube but no map).
  bool full_budget_fallback = true;
  // When every mapped candidate has flips, a candidate whose repair rounds ran out with at most
  // this many slabs still failing (AlignmentCandidate::failing_slabs) is built again with four
  // times the scoring budget and mapped, and competes with the others. 0: never.
  int near_miss_slabs = 2;
  // A model with fewer vertices than coarse_below (and no target_vertices asked for) also tries
  // its mapped candidates with P triangulated by at least fine_polycube_vertices vertices; the
  // map with the fewest flips still wins. 0: never.
  int coarse_below = 5000;
  int fine_polycube_vertices = 20000;
  // How many other mapped candidates come back in Alignment::alternatives: first the best of the
  // other P density (the winner's twin kind: finer P when the winner is not, and the other way
  // round), then the next best by the score. The unsmoothed flips the score counts are a weak
  // proxy for the finished map's (a winner by 28 to 32 flips ended 1 / 1, the runner-up 0 / 1).
  // Never on the proxy (the alternatives would be stages of the copy).
  int alternatives = 2;
  // Asked before each candidate's next step (its topology and polycube, its map, its stages on
  // the model itself; steps under way finish) and between the search's phases: once it returns
  // true, no step starts and the search returns with nothing chosen and `stopped` set (a caller's
  // time limit, for a search whose result it can do without). Called from several threads.
  std::function<bool()> stop;
};

// Scores the candidates (input frame / principal axes / normal axes × which axis is z); see the
// top.
Alignment choose_alignment(const TriMesh& mesh, const TopologyOptions& topology, const PolycubeOptions& polycube,
                           const AlignmentOptions& options = {});

}  // namespace polycube
