// `polycube map FILE -o DIR`: the pipeline, stage by stage, with a report of each.
#include "cli/commands.h"
#include "cli/mesh_input.h"
#include "cli/stage_json.h"

#include "applications/preview/render.h"
#include "formats/atomic_file.h"
#include "formats/image_io.h"
#include "formats/mesh_io.h"
#include "polycube/align.h"
#include "polycube/errors.h"
#include "polycube/image_untangle.h"
#include "polycube/polycube_build.h"
#include "polycube/map_audit.h"
#include "polycube/map_overlay.h"
#include "polycube/map_quality.h"
#include "polycube/map_refinement.h"
#include "polycube/map_smoothing.h"
#include "polycube/parallel.h"
#include "polycube/polycube_map.h"
#include "polycube/topology.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <future>
#include <iomanip>
#include <memory>
#include <optional>
#include <sstream>
#include <tuple>

namespace polycube::cli {

namespace {

// The stages `map` can stop after, in pipeline order. The default is the last one built.
const std::vector<std::string> kStages = {"topology", "polycube", "map"};

// The copy's map is kept without a pass on the model itself when it meets the contract with
// ε_angle at most this; otherwise the model's pass runs too and the better map by rank is kept.
// The copy's map is finished on the model, but P's faces and the model's surface turn apart under
// the scaling where they are not parallel: 3 333 : 1 rod 1.088 (the model's own pass did not
// finish in 26 minutes), 1000 : 1 rod 1.019 (1.049); plate 1 x 1 x 0.01 1.428 (1.001), when flat
// models were tried through a copy (equalised_copy now takes long ones only).
constexpr double kEqualiseKeepAngle = 1.1;

bool runs(const std::string& stop_after, const std::string& stage) {
  const auto at = [](const std::string& s) { return std::find(kStages.begin(), kStages.end(), s) - kStages.begin(); };
  return at(stage) <= at(stop_after);
}

struct MapOptions {
  MeshInput input;
  std::string output_dir;
  std::string stage = kStages.back();
  std::string align = "auto";
  std::string separate = "always";
  // auto: a model much longer than wide is mapped first on a copy with its principal axes scaled
  // towards equal spreads (equalised_copy); never: on the model as it is.
  std::string equalise_axes = "auto";
  int smooth_sweeps = 10;
  bool refine = true;
  // The last untangling's largest move of an image, × the target's diagonal; 0: none.
  double untangle_shift = ImageUntangleOptions().max_shift;
  // Where moves within untangle_shift leave a bad triangle: the untangling again from the map's
  // images with 2, 5 and 10 times that shift, at most this much, while each run leaves fewer.
  double untangle_shift_max = 0.1;
  // When no finished map of the orientation search meets the contract, the search and its maps
  // run once more with d_a divided by this (finer contours); 1: never.
  double finer_contours = 3;
  // When no finished map meets the contract after the finer contours and the exact samplings,
  // more of the first search's orientations are finished (best by its score first; each sampled
  // exactly too when it misses), each started while those before took less than this many times
  // the run's time before them (the first always); 0: none.
  double more_orientations = 1;
  // When no finished map (every orientation, finer contours included) meets the contract, the
  // exact sampling of their unsmoothed maps (map_overlay.h), best-ranked first, kept where it
  // ranks better.
  bool exact = true;
  TimeLimit time_limit;
  TopologyOptions topology;
  PolycubeOptions polycube;
};

Eigen::MatrixX3d piece_colours(const SlicedMesh& sliced) {
  Eigen::MatrixX3d rgb(sliced.mesh.num_faces(), 3);
  for (int f = 0; f < sliced.mesh.num_faces(); ++f) rgb.row(f) = distinct_colour(sliced.face_piece[f]);
  return rgb;
}

// The sliced model with each face coloured by its piece, for viewing in MeshLab or Blender.
void write_pieces(const std::string& path, const SlicedMesh& sliced) {
  MeshColors colours;
  colours.face_rgb = piece_colours(sliced);
  std::vector<std::vector<int>> faces(sliced.mesh.num_faces());
  for (int f = 0; f < sliced.mesh.num_faces(); ++f) faces[f] = {sliced.mesh.F(f, 0), sliced.mesh.F(f, 1), sliced.mesh.F(f, 2)};
  write_polygon_mesh(path, sliced.mesh.V, faces, &colours);
}

// A picture of the pieces: the model from a 3/4 view in front and from behind.
void write_pieces_preview(const std::string& path, const SlicedMesh& sliced) {
  const Eigen::MatrixX3d rgb = piece_colours(sliced);
  RenderItem item;
  item.mesh = &sliced.mesh;
  item.face_rgb = &rgb;
  RenderItem back = item;
  back.view_direction = {-item.view_direction.x(), -item.view_direction.y(), item.view_direction.z()};
  write_image(path, render_tiles({item, back}));
}

// The model and the polycube side by side, each piece of P in the colour of its model piece.
void write_polycube_preview(const std::string& path, const PolycubeResult& result) {
  const Eigen::MatrixX3d model_rgb = piece_colours(result.model_sliced);
  std::vector<int> model_piece_of(result.polycube_sliced.pieces.size(), 0);
  for (size_t m = 0; m < result.piece_match.size(); ++m) model_piece_of[result.piece_match[m]] = static_cast<int>(m);
  const TriMesh& cube = result.polycube_sliced.mesh;
  Eigen::MatrixX3d cube_rgb(cube.num_faces(), 3);
  for (int f = 0; f < cube.num_faces(); ++f) cube_rgb.row(f) = distinct_colour(model_piece_of[result.polycube_sliced.face_piece[f]]);
  RenderItem model, polycube;
  model.mesh = &result.model_sliced.mesh;
  model.face_rgb = &model_rgb;
  polycube.mesh = &cube;
  polycube.face_rgb = &cube_rgb;
  polycube.smooth = false;
  RenderOptions options;
  options.same_scale = true;
  write_image(path, render_tiles({model, polycube}, options));
}

// The map at a glance: the model with a checkerboard carried from P through φ⁻¹ beside P with the
// same checkers, both shaded, from the same 3/4 view and at the same scale. Checkers are cubes of
// 1/24 of P's diagonal, shifted off P's faces so that no face lies on a cell boundary.
void write_map_preview(const std::string& path, const TriMesh& model, const Polycube& polycube, const Eigen::MatrixX3d& model_on_polycube) {
  const double cell = bounding_box(polycube.mesh.V).diagonal() / 24;
  const Eigen::RowVector3d shift = Eigen::RowVector3d::Constant(0.3819660112501051 * cell);
  const Eigen::MatrixX3d model_coords = model_on_polycube.rowwise() + shift;
  const Eigen::MatrixX3d polycube_coords = polycube.mesh.V.rowwise() + shift;
  RenderItem m, p;
  m.mesh = &model;
  m.checker_coords = &model_coords;
  m.checker_size = cell;
  p.mesh = &polycube.mesh;
  p.checker_coords = &polycube_coords;
  p.checker_size = cell;
  p.smooth = false;
  RenderOptions options;
  options.same_scale = true;
  write_image(path, render_tiles({m, p}, options));
}

// The end of the map stage on one P: the smoothing, the second refinement, the audit.
struct Finished {
  const Polycube* polycube = nullptr;
  std::unique_ptr<Polycube> overlay_polycube;  // P triangulated by the overlay (exact_map), when that is P
  nlohmann::json overlay = nullptr;
  std::unique_ptr<MapRefinementResult> resampling;
  Eigen::MatrixX3d on_model_xyz, on_polycube_xyz;
  nlohmann::json smoothing = nullptr, resampling_report = nullptr, untangling = nullptr;
  double smooth_seconds = 0, resample_seconds = 0, untangle_seconds = 0;
  MapAudit audit;
  int bad_p() const { return audit.polycube_to_model.flipped + audit.polycube_to_model.degenerate; }
  int bad_m() const { return audit.model_to_polycube.flipped + audit.model_to_polycube.degenerate; }
  // What `map` promises (issue 5): no flipped or degenerate image triangle either way, images on
  // the surfaces, P's image covering the model's area to the audit's 2 %. (The model's image on P
  // is not held to an area: on a coarse model its triangles are chords across P's edges.)
  bool meets_contract() const {
    return bad_p() == 0 && bad_m() == 0 && audit.polycube_to_model.ok &&
           audit.model_to_polycube.max_distance <= MapAuditOptions().surface_tolerance;
  }
  // How far P's image area is outside the audit's tolerance (0 within it).
  double area_miss() const {
    return std::max(0.0, std::abs(audit.polycube_to_model.area_ratio - 1) - MapAuditOptions().area_tolerance);
  }
  // Finished maps compare by flipped + degenerate triangles both ways, then whether they meet
  // the contract, then how far the image area is off, then ε_angle.
  std::tuple<int, int, double, double> rank() const {
    return {bad_p() + bad_m(), meets_contract() ? 0 : 1, area_miss(), audit.distortion.eps_angle};
  }
  // What of the contract the map misses, "; "-separated (empty when it meets it).
  std::string shortfall() const {
    std::ostringstream miss;
    const char* separator = "";
    if (bad_p() + bad_m() > 0) {
      miss << bad_p() << " / " << bad_m() << " flipped or degenerate image triangles (P to M / M to P)";
      separator = "; ";
    }
    if (area_miss() > 0) {
      miss << separator << "P's image covers " << std::fixed << std::setprecision(4) << audit.polycube_to_model.area_ratio
           << " of the model's area";
      separator = "; ";
    }
    const double off = std::max(audit.polycube_to_model.max_distance, audit.model_to_polycube.max_distance);
    if (off > MapAuditOptions().surface_tolerance)
      miss << separator << "images up to " << std::setprecision(4) << off << " of the diagonal off the surface";
    return miss.str();
  }
};

// One orientation's stages (those the orientation search built come with it; candidate -1 with
// --align none), then its finished map. Heap-held: finished points into refinement or polycube.
struct Attempt : AlignedStages {
  TriMesh model;  // turned by rotation
  // An attempt on the scaled copy (--equalise-axes): its topology, polycube, map and first
  // refinement are built on the copy turned by rotation, whose x, y, z are the model's turned by
  // `unscaled` times `scales`. Its map is then taken back to the model turned by `unscaled` (P
  // divided by the scales: still a polycube) and finished there; rotation and model are then
  // those, and real_polycubes hold the P's taken back (unrefined, refined).
  Eigen::Vector3d scales = Eigen::Vector3d::Ones();
  Eigen::Matrix3d unscaled = Eigen::Matrix3d::Identity();
  const TriMesh* unscaled_source = nullptr;
  std::unique_ptr<Polycube> real_polycubes[2];
  std::unique_ptr<PolycubeMap> real_maps[2];
  bool scaled() const { return unscaled_source != nullptr; }
  std::unique_ptr<MapRefinementResult> refinement;  // P's sampling refined before the smoothing
  std::unique_ptr<Finished> finished;               // after it: the P and sampling written
  // A separated model's map as it will be written: P's images moved from the copy to the model
  // (turned by rotation), audited and untangled there. Null without separation.
  std::unique_ptr<Finished> on_model;
  // What the attempt is judged by (rank, contract): the map as it will be written.
  const Finished& judged() const { return on_model ? *on_model : *finished; }
  nlohmann::json refinement_report = nullptr;
  double refine_seconds = 0, smooth_unrefined_seconds = 0, seconds = 0;
  std::string name;  // orientation (and finer contours)
  double da = 0;     // the d_a its polycube was built with
  // Not run: its polycube is an earlier finished attempt's (same_polycube, same rotation and
  // scales), whose map it would repeat bit for bit. That attempt's name.
  std::string same_as;
};

// An earlier finished attempt whose stages `a` would repeat, or null.
const Attempt* repeated_attempt(const std::vector<std::unique_ptr<Attempt>>& attempts, const Attempt& a) {
  for (const std::unique_ptr<Attempt>& b : attempts) {
    if (b.get() == &a) break;
    if (b->finished && b->scales == a.scales && b->unscaled == a.unscaled && b->scaled() == a.scaled() && same_stages(*b, a))
      return b.get();
  }
  return nullptr;
}

nlohmann::json polycube_json(const PolycubeResult& result) {
  const Polycube& p = result.polycube;
  return {{"vertices", p.mesh.num_vertices()},
          {"triangles", p.mesh.num_faces()},
          {"faces", p.faces.size()},
          {"edges", p.edges.size()},
          {"corners", p.corners.size()},
          {"genus", result.genus},
          {"planes", result.planes_z},
          {"pieces", result.polycube_sliced.pieces.size()},
          {"planes_inserted", result.planes_inserted},
          {"quadtree_splits", {{"accuracy", result.accuracy_splits},
                               {"section_topology", result.section_splits},
                               {"stacking", result.stacking_splits}}},
          {"relabelled_cells", result.relabelled_cells},
          {"simplification", {{"merged_cells", result.coarsening_merges}, {"snapped_cells", result.snapped_cells}}},
          {"rounds", result.rounds},
          {"rasterized_cells", result.rasterized_cells},
          {"deepest_level", result.deepest_level},
          {"max_region_area_error", result.max_region_error},
          {"repairs", result.repairs},
          {"seconds", {{"quadtrees", result.seconds_quadtrees},
                       {"checks", result.seconds_checks},
                       {"simplify", result.seconds_simplify},
                       {"surface", result.seconds_surface},
                       {"verify", result.seconds_verify},
                       {"total", result.seconds_total}}}};
}

nlohmann::json direction_json(const MapDirectionAudit& a) {
  return nlohmann::json{{"triangles", a.triangles}, {"flipped", a.flipped}, {"degenerate", a.degenerate},
                        {"max_distance", a.max_distance}, {"area_ratio", a.area_ratio}, {"ok", a.ok}};
}

nlohmann::json refinement_json(const MapRefinementResult& r) {
  auto side = [](const MapDirectionAudit& a) {
    return nlohmann::json{{"flipped", a.flipped}, {"degenerate", a.degenerate}, {"area_ratio", a.area_ratio}};
  };
  return nlohmann::json{{"refined", r.refined},       {"converged", r.converged},
                        {"rounds", r.rounds},         {"bisections", r.bisections},
                        {"vertices_before", r.vertices_before}, {"vertices_after", r.vertices_after},
                        {"triangles_before", r.triangles_before}, {"triangles_after", r.triangles_after},
                        {"before", side(r.before)},   {"after", side(r.after)},
                        {"model_to_polycube_before", side(r.model_to_polycube_before)},
                        {"model_to_polycube_after", side(r.model_to_polycube_after)},
                        {"model_to_polycube_rejected", r.model_to_polycube_rejected},
                        {"frozen_faces", r.frozen_faces},
                        {"seconds", r.seconds}};
}

std::string refinement_line(const MapRefinementResult& r) {
  std::ostringstream line;
  line << r.vertices_before << " -> " << r.vertices_after << " vertices in " << r.rounds << " rounds; P to M flipped "
       << r.before.flipped + r.before.degenerate << " -> " << r.after.flipped + r.after.degenerate << ", image area "
       << std::fixed << std::setprecision(4) << r.before.area_ratio << " -> " << r.after.area_ratio;
  return line.str();
}

// The last correction of the files (image_untangle.h): where an image triangle of either
// direction is still flipped or degenerate, single vertex images move on the target surface until
// the audit passes there; then that direction's audit again. When moves within max_shift leave a
// bad triangle, the untangling runs again from the map's images with 2, 5 and 10 times that
// shift, up to shift_cap (ImageUntangleOptions::wider_shifts), while each run leaves fewer bad
// triangles than the best before it; the best is kept. The greedy moves differ with the shift, so
// a larger one is not always better (a coarse CAD model, mpi_triang: 3 left at 0.01, 2 at 0.02, 0
// at 0.05, 1 at 0.1).
void untangle_images(const TriMesh& model, Finished& out, double max_shift, double shift_cap, const Progress& progress) {
  if ((out.bad_p() == 0 && out.bad_m() == 0) || max_shift <= 0) return;
  const double start = progress.elapsed_seconds();
  progress.stage("untangle", std::to_string(out.bad_p()) + " / " + std::to_string(out.bad_m()) +
                                 " bad image triangles (P to M / M to P): moving single images");
  const TriMesh& P = out.polycube->mesh;
  ImageUntangleOptions options;
  options.max_shift = max_shift;
  for (const double factor : {2.0, 5.0, 10.0})
    if (factor * max_shift <= shift_cap * (1 + 1e-12)) options.wider_shifts.push_back(factor * max_shift);
  // Each run's outcome as it ends (a run can take minutes on a large map of a CAD model that
  // passes through itself: OpenSCAD's bad-stl-wing.stl, 2 580 bad triangles, 10 minutes).
  auto run = [&options, &progress](const TriMesh& source, Eigen::MatrixX3d& image, const TriMesh& target, const std::string& direction) {
    options.after_run = [&progress, direction](double shift, int bad_left) {
      std::ostringstream line;
      line << direction << ", room " << 100 * shift << " % of the diagonal: " << bad_left << " left";
      progress.stage("untangle", line.str());
    };
    const ImageUntangleResult result = untangle_image(source, image, target, options);
    image = result.image;
    return nlohmann::json{{"bad_before", result.bad_before}, {"bad_after", result.bad_after}, {"moved", result.moved},
                          {"max_shift", result.max_shift}, {"shift_allowed", result.shift_allowed}};
  };
  out.untangling = nlohmann::json::object();
  // Only the direction moved is audited again (and the distortion, which P → M defines).
  MapAudit& audit = out.audit;
  if (out.bad_p() > 0) {
    out.untangling["polycube_to_model"] = run(P, out.on_model_xyz, model, "P to M");
    audit.polycube_to_model = audit_map_direction(P, out.on_model_xyz, model);
    audit.distortion = map_distortion(P, out.on_model_xyz);
  }
  if (out.bad_m() > 0) {
    out.untangling["model_to_polycube"] = run(model, out.on_polycube_xyz, P, "M to P");
    audit.model_to_polycube = audit_map_direction(model, out.on_polycube_xyz, P);
  }
  audit.ok = audit.polycube_to_model.ok && audit.model_to_polycube.ok;
  out.untangle_seconds = progress.elapsed_seconds() - start;
  out.untangling["seconds"] = out.untangle_seconds;
  progress.stage("untangle", std::to_string(out.bad_p()) + " / " + std::to_string(out.bad_m()) + " left");
}

// Stage 5 (§3.5) on a given P and sampling: the smoothing, which never adds a flip in either
// direction, then the second refinement of P's sampling; the audit of the result.
std::unique_ptr<Finished> finish_map(const TriMesh& model, const std::vector<double>& planes_z, const Polycube& P,
                                     const PolycubeMap& sampled, const MapOptions& options, const Progress& progress) {
  auto out = std::make_unique<Finished>();
  out->polycube = &P;
  out->on_model_xyz = sampled.polycube_on_model_xyz;
  out->on_polycube_xyz = sampled.model_on_polycube_xyz;
  if (options.smooth_sweeps > 0) {
    progress.stage("smooth", "harmonic relaxation of the images on the model, flips guarded");
    MapSmoothingOptions smooth_options;
    smooth_options.sweeps = options.smooth_sweeps;
    // Returns its input when it neither removes flips nor lowers ε_angle (smoothed.kept).
    const MapSmoothingResult smoothed = smooth_map(model, P, sampled, smooth_options);
    out->on_model_xyz = smoothed.polycube_on_model_xyz;
    out->on_polycube_xyz = smoothed.model_on_polycube_xyz;
    out->smooth_seconds = smoothed.seconds;
    const DistortionStats& before = smoothed.distortion_before;
    out->smoothing = {{"kept", smoothed.kept},
                      {"eps_angle_after", smoothed.distortion_after.eps_angle},
                      {"sweeps", smoothed.sweeps},
                      {"rounds", smoothed.rounds},
                      {"moves", smoothed.moves},
                      {"rejected", smoothed.rejected},
                      {"frozen_polycube_vertices", smoothed.frozen},
                      {"relocated_model_vertices", smoothed.relocated},
                      {"seconds", smoothed.seconds},
                      {"before", {{"polycube_to_model_flipped", smoothed.flipped_before[0]},
                                  {"model_to_polycube_flipped", smoothed.flipped_before[1]},
                                  {"eps_angle", before.eps_angle},
                                  {"eps_area", before.eps_area},
                                  {"angle_p95", before.angle_p95},
                                  {"angle_max", before.angle_max}}}};
    progress.stage("smooth", std::to_string(smoothed.flipped_before[0]) + " / " + std::to_string(smoothed.flipped_before[1]) +
                                 " flipped before, " + std::to_string(smoothed.flipped_after[0]) + " / " +
                                 std::to_string(smoothed.flipped_after[1]) + " after" +
                                 (smoothed.kept ? "" : "; not kept (eps_angle " + std::to_string(before.eps_angle) + " -> " +
                                                           std::to_string(smoothed.distortion_after.eps_angle) + ")"));
    if (options.refine) {
      progress.stage("refine", "again where the smoothed map's chords flip or lose area");
      PolycubeMap samples;
      samples.polycube_on_model = smoothed.polycube_on_model;
      samples.polycube_on_model_xyz = smoothed.polycube_on_model_xyz;
      samples.model_on_polycube = smoothed.model_on_polycube;
      samples.model_on_polycube_xyz = smoothed.model_on_polycube_xyz;
      // Nothing moves the images after this: refine only where the audit's 2 % is not met
      // (it then aims at half of that).
      MapRefinementOptions resample_options;
      resample_options.area_tolerance = MapAuditOptions().area_tolerance;
      out->resampling = std::make_unique<MapRefinementResult>(refine_vertex_map_sampling(model, P, planes_z, samples, resample_options));
      out->polycube = &out->resampling->polycube;
      out->on_model_xyz = out->resampling->map.polycube_on_model_xyz;
      out->on_polycube_xyz = out->resampling->map.model_on_polycube_xyz;
      out->resample_seconds = out->resampling->seconds;
      out->resampling_report = refinement_json(*out->resampling);
      progress.stage("refine", refinement_line(*out->resampling));
    }
  }
  out->audit = audit_map(model, out->polycube->mesh, out->on_model_xyz, out->on_polycube_xyz);
  untangle_images(model, *out, options.untangle_shift, options.untangle_shift_max, progress);
  return out;
}

// The exact sampling of φ (map_overlay.h): P triangulated by the common refinement of every
// piece pair's two disk triangulations, on which φ is affine, so P's image tiles the model with
// every triangle inside one model face, oriented as that face; the model's vertices at φ⁻¹
// (vertices of that triangulation). Not smoothed (it is φ itself), untangled like any finished
// map where the model's triangles, chords on P, still flip.
std::unique_ptr<Finished> exact_map(const TriMesh& model, const Polycube& P, const PolycubeMap& map, const MapOptions& options,
                                    const Progress& progress) {
  progress.stage("exact", "P triangulated by both disk triangulations of every piece: the map exact on each triangle");
  const MapOverlay overlay = overlay_map(map);
  auto out = std::make_unique<Finished>();
  out->overlay_polycube = std::make_unique<Polycube>(P);
  Polycube& R = *out->overlay_polycube;
  R.mesh = overlay.polycube;
  R.face_axis.resize(R.mesh.num_faces());
  R.face_patch.resize(R.mesh.num_faces());
  for (int f = 0; f < R.mesh.num_faces(); ++f) {
    R.face_axis[f] = P.face_axis[overlay.face_parent[f]];
    R.face_patch[f] = P.face_patch[overlay.face_parent[f]];
  }
  out->polycube = &R;
  out->on_model_xyz = overlay.on_model_xyz;
  out->on_polycube_xyz = map.model_on_polycube_xyz;
  out->audit = audit_map(model, R.mesh, out->on_model_xyz, out->on_polycube_xyz);
  out->overlay = {{"triangles", R.mesh.num_faces()}, {"vertices", R.mesh.num_vertices()}, {"cells", overlay.cells},
                  {"collapsed", overlay.collapsed}, {"flipped_edges", overlay.flipped_edges}, {"seconds", overlay.seconds}};
  progress.stage("exact", std::to_string(R.mesh.num_faces()) + " triangles; " + std::to_string(out->bad_p()) + " / " +
                              std::to_string(out->bad_m()) + " flipped or degenerate (P to M / M to P), image area " +
                              std::to_string(out->audit.polycube_to_model.area_ratio));
  untangle_images(model, *out, options.untangle_shift, options.untangle_shift_max, progress);
  return out;
}

// The stages of one orientation that the search did not build (all of them with --align none),
// up to the stage asked; with the map, its refinement and finish. P's sampling of φ is refined
// where its chords flip or lose area (issue 5) before the smoothing (φ itself at the new
// vertices) and after it (the smoothed chords projected on the model): P's surface stays the
// same, its triangulation gets finer, and every later step and file uses the refined one.
void run_stages(Attempt& a, const TriMesh& input, const MapOptions& options, const Progress& progress) {
  const double start = progress.elapsed_seconds();
  a.model = rotated(input, a.rotation);
  progress.stage("topology", "harmonic function, critical points, cutting planes, slicing");
  if (!a.topology) {
    TopologyOptions topology = options.topology;
    topology.length_scales = a.scales;
    a.topology = std::make_shared<TopologyResult>(analyse_topology(a.model, topology));
  }
  progress.stage("topology", std::to_string(a.topology->critical.saddle_count()) + " saddles, " +
                                 std::to_string(a.topology->planes_z.size()) + " planes, " +
                                 std::to_string(a.topology->sliced.pieces.size()) + " genus-0 pieces");
  if (runs(options.stage, "polycube")) {
    progress.stage("polycube", "axis-aligned contours, stacking, triangulation, checks");
    if (!a.polycube) a.polycube = std::make_shared<PolycubeResult>(build_polycube(a.model, *a.topology, options.polycube));
    for (const std::string& repair : a.polycube->repairs) progress.warning("polycube: " + repair);
    progress.stage("polycube", std::to_string(a.polycube->polycube.corners.size()) + " corners, " +
                                   std::to_string(a.polycube->polycube.faces.size()) + " faces, " +
                                   std::to_string(a.polycube->polycube_sliced.pieces.size()) + " pieces matched");
  }
  if (runs(options.stage, "map")) {
    progress.stage("map", "boundary maps, slits, disk maps of " + std::to_string(a.polycube->piece_match.size()) + " piece pairs");
    if (!a.map) a.map = std::make_shared<PolycubeMap>(build_polycube_map(a.model, *a.polycube));
    // What is finished: the model turned, P and φ sampled at its vertices (unrefined and refined).
    std::vector<double> planes_z = a.polycube->planes_z;
    const Polycube* unrefined_polycube = &a.polycube->polycube;
    const PolycubeMap* unrefined_map = a.map.get();
    if (options.refine) {
      progress.stage("refine", "bisecting P's triangles where the map sampled at its vertices flips or loses area");
      a.refinement = std::make_unique<MapRefinementResult>(refine_map_sampling(a.model, *a.polycube, *a.map));
      progress.stage("refine", refinement_line(*a.refinement));
      a.refinement_report = {{"map", refinement_json(*a.refinement)}};
      a.refine_seconds = a.refinement->seconds;
    }
    const Polycube* refined_polycube = a.refinement ? &a.refinement->polycube : nullptr;
    const PolycubeMap* refined_map = a.refinement ? &a.refinement->map : nullptr;
    if (a.scaled()) {
      // The copy's P and φ taken back to the model (turned by `unscaled`), finished there: the
      // smoothing then works against the model's own angles.
      std::ostringstream said;
      said << std::setprecision(3) << "the copy's P and map taken back to the model (x, y, z divided by " << a.scales(0) << ", "
           << a.scales(1) << ", " << a.scales(2) << ")";
      progress.stage("equalise", said.str());
      a.model = rotated(*a.unscaled_source, a.unscaled);
      a.rotation = a.unscaled;
      for (double& z : planes_z) z /= a.scales(2);
      a.real_polycubes[0] = std::make_unique<Polycube>(unscaled_polycube(*unrefined_polycube, a.scales));
      a.real_maps[0] = std::make_unique<PolycubeMap>(unscaled_samples(*unrefined_map, a.scales));
      unrefined_polycube = a.real_polycubes[0].get();
      unrefined_map = a.real_maps[0].get();
      if (refined_polycube) {
        a.real_polycubes[1] = std::make_unique<Polycube>(unscaled_polycube(*refined_polycube, a.scales));
        a.real_maps[1] = std::make_unique<PolycubeMap>(unscaled_samples(*refined_map, a.scales));
        refined_polycube = a.real_polycubes[1].get();
        refined_map = a.real_maps[1].get();
      }
    }
    if (!options.refine) {
      a.finished = finish_map(a.model, planes_z, *unrefined_polycube, *unrefined_map, options, progress);
    } else {
      const MapRefinementResult& refinement = *a.refinement;
      // The smoothing of a refined sampling can end worse than that of the unrefined one (it is
      // a different problem): the refined result is kept only if neither direction has more bad
      // triangles, or both together have fewer, than the unrefined P's result. The two are
      // independent, so with two threads or more the unrefined one is finished alongside (its
      // progress not shown): their untanglings, which run on one thread, overlap. The future,
      // declared after what its thread uses, waits for it when destroyed (the refined finish
      // may throw).
      GlobalOptions quiet_options;
      quiet_options.quiet = true;
      const Progress quiet(quiet_options);
      auto finish_unrefined = [&](const Progress& shown) {
        return finish_map(a.model, planes_z, *unrefined_polycube, *unrefined_map, options, shown);
      };
      std::future<std::unique_ptr<Finished>> alongside;
      if (refinement.refined && threads_for(0) > 1) {
        progress.stage("refine", "the unrefined P's map finished alongside, for comparison");
        alongside = std::async(std::launch::async, finish_unrefined, std::cref(quiet));
      }
      std::unique_ptr<Finished> refined = finish_map(a.model, planes_z, *refined_polycube, *refined_map, options, progress);
      std::unique_ptr<Finished> unrefined;
      if (alongside.valid()) {
        unrefined = alongside.get();
      } else if (refinement.refined) {
        progress.stage("refine", "comparing with the unrefined P's smoothed map");
        unrefined = finish_unrefined(progress);
      }
      a.refine_seconds += refined->resample_seconds;
      a.refinement_report["smoothed"] = refined->resampling_report;
      if (refinement.refined) {
        a.refine_seconds += unrefined->resample_seconds;
        const bool keep = (refined->bad_p() <= unrefined->bad_p() && refined->bad_m() <= unrefined->bad_m()) ||
                          refined->bad_p() + refined->bad_m() < unrefined->bad_p() + unrefined->bad_m();
        a.refinement_report["kept"] = keep;
        a.refinement_report["unrefined"] = {{"polycube_to_model", direction_json(unrefined->audit.polycube_to_model)},
                                            {"model_to_polycube", direction_json(unrefined->audit.model_to_polycube)},
                                            {"smoothed", unrefined->resampling_report}};
        a.smooth_unrefined_seconds = unrefined->smooth_seconds;
        progress.stage("refine", std::string(keep ? "kept" : "dropped") + " (refined P " + std::to_string(refined->bad_p()) + " / " +
                                     std::to_string(refined->bad_m()) + " flipped, unrefined P " + std::to_string(unrefined->bad_p()) +
                                     " / " + std::to_string(unrefined->bad_m()) + ")");
        a.finished = keep ? std::move(refined) : std::move(unrefined);
      } else {
        a.refinement_report["kept"] = false;
        a.finished = std::move(refined);
      }
    }
  }
  a.seconds = progress.elapsed_seconds() - start;
}

int run_map(const MapOptions& options, const GlobalOptions& global) {
  const Progress progress(global);
  const PreparedMesh prepared = load_mesh(options.input, progress);
  require_mappable(prepared.diagnosis);

  const std::filesystem::path dir(options.output_dir);
  std::error_code ec;
  // A run that fails before writing anything leaves no directory it made behind.
  struct RemoveIfLeftEmpty {
    std::filesystem::path path;
    bool created = false;
    ~RemoveIfLeftEmpty() {
      std::error_code ec;
      if (created && std::filesystem::is_empty(path, ec) && !ec) std::filesystem::remove(path, ec);
    }
  } made{dir, !std::filesystem::exists(dir, ec)};
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw OutputError("cannot create output directory " + options.output_dir + (ec ? ": " + ec.message() : ""));

  nlohmann::json report;
  report["input"] = diagnosis_json(prepared);
  report["input"]["file"] = options.input.path;
  report["parameters"] = {{"dz", options.topology.dz}, {"da", options.polycube.da}, {"stage", options.stage}};
  report["parameters"]["align"] = options.align;
  report["parameters"]["untangle_shift"] = options.untangle_shift;
  report["parameters"]["untangle_shift_max"] = options.untangle_shift_max;
  report["parameters"]["finer_contours"] = options.finer_contours;
  report["parameters"]["more_orientations"] = options.more_orientations;
  TimeLimit time_limit = options.time_limit;
  std::vector<std::string> outputs;
  // Self-intersecting: every stage runs on the separated copy; P's images on it go back to the
  // model at the end, where the files are audited (below).
  // When the smoothing cannot pull the crossings apart, none: the stages run on the model as read
  // (as with --separate never; the map is intrinsic, and the audit judges the files on the model
  // either way. OpenSCAD's adns2610_dev_circuit_inv.stl: 26 crossing pairs, 82 after 20 rounds).
  const std::optional<Separation> separation =
      options.separate == "always" ? separated_for_stages(prepared, progress, report) : std::nullopt;
  const TriMesh& source = separation ? separation->mesh : prepared.mesh;

  // The pipeline runs on the model turned into the chosen frame; outputs go back to the input's.
  // One pass: the orientation search (with --align auto) and the finished maps of its candidates
  // in order, until one meets the contract (Finished::meets_contract); the best by rank is kept.
  std::vector<std::unique_ptr<Attempt>> attempts;
  Attempt* kept = nullptr;
  double align_seconds = 0;
  std::string first_choice;  // the first search's orientation
  const auto shortfall = [&]() {
    const Finished& f = kept->judged();
    return "the finished map has " + std::to_string(f.bad_p()) + " / " + std::to_string(f.bad_m()) + " flipped, image area " +
           std::to_string(f.audit.polycube_to_model.area_ratio) + (kept->on_model ? " on the model" : "") + "; ";
  };
  // A separated model's finished map (of attempt a) taken to the model and audited there, where
  // the files are written: the copy's audit can meet the contract where the model's does not
  // (images moved back turn against the model where its sheets pass near each other, or the
  // area shrinks), and the attempts compete by what will be written. Null without separation.
  const auto on_model_of = [&](const Attempt& a, const Finished& f) -> std::unique_ptr<Finished> {
    if (!separation) return nullptr;
    const TriMesh model = rotated(prepared.mesh, a.rotation);
    auto m = std::make_unique<Finished>();
    m->polycube = f.polycube;
    m->on_model_xyz = to_original_surface(a.model, model, f.on_model_xyz);
    m->on_polycube_xyz = f.on_polycube_xyz;
    m->audit = audit_map(model, f.polycube->mesh, m->on_model_xyz, m->on_polycube_xyz);
    if (m->bad_p() > f.bad_p() || m->bad_m() > f.bad_m()) {
      progress.stage("audit", "on the model itself: " + std::to_string(m->bad_p()) + " / " + std::to_string(m->bad_m()) +
                                  " flipped or degenerate image triangles, against " + std::to_string(f.bad_p()) + " / " +
                                  std::to_string(f.bad_m()) + " on the separated copy");
      untangle_images(model, *m, options.untangle_shift, options.untangle_shift_max, progress);
    }
    return m;
  };
  // Finishes attempts [first, end) in order until one meets the contract; the best by rank is
  // kept. An attempt stopped before the map (--stage) ends the pass unfinished; with
  // skip_failures, one whose stages fail is left unfinished (a warning) and the next follows.
  auto finish_attempts = [&](size_t first, const MapOptions& pass, const TriMesh& stages_source, bool skip_failures) {
    for (size_t i = first; i < attempts.size(); ++i) {
      Attempt& a = *attempts[i];
      if (kept && time_limit.spent(progress)) return;
      if (const Attempt* same = repeated_attempt(attempts, a)) {
        a.same_as = same->name;
        progress.stage("retry", a.name + ": the same polycube as " + same->name + ", not mapped again");
        continue;
      }
      if (kept) progress.stage("retry", shortfall() + "finishing " + a.name);
      try {
        run_stages(a, stages_source, pass, progress);
      } catch (const Error& e) {
        if (!skip_failures) throw;
        progress.warning(a.name + ": " + e.what());
        a.finished.reset();
        continue;
      }
      if (a.finished) a.on_model = on_model_of(a, *a.finished);
      if (!a.finished) {
        kept = &a;
        return;
      }
      if (!kept || a.judged().rank() < kept->judged().rank()) kept = &a;
      if (kept->judged().meets_contract()) return;
    }
  };
  // The first search's other orientations built (Alignment::reserve) with their names.
  std::vector<std::pair<AlignedStages, std::string>> reserve;
  // A pass on a long model's scaled copy (equalised) runs its stages on the copy.
  auto run_pass = [&](const MapOptions& pass, nlohmann::json& alignment_report, const std::string& suffix,
                      const EqualisedCopy* equalised = nullptr) {
    const TriMesh& stages_source = equalised ? equalised->copy : source;
    Alignment alignment;
    if (pass.align == "auto" && pass.stage != "topology") {
      const double align_start = progress.elapsed_seconds();
      progress.stage("align", "orientations (input frame, principal axes, normal axes): polycubes, then maps of the 2 with fewest corners (the rest if both flip), scored by flips");
      // A later search (there is a map already) ends where the time limit is spent.
      AlignmentOptions align_options;
      if (kept) align_options.stop = time_limit.stop_for(progress);
      align_options.input_frame_only = equalised != nullptr;
      if (equalised) {
        align_options.axis_scales = equalised->scales;
        align_options.input_frame_is_principal = true;
      }
      alignment = choose_alignment(stages_source, pass.topology, pass.polycube, align_options);
      nlohmann::json candidates = nlohmann::json::array();
      for (const AlignmentCandidate& c : alignment.candidates)
        candidates.push_back({{"name", c.name}, {"corners", c.corners}, {"flipped", c.flipped}, {"eps_angle", c.eps_angle}, {"eps_area", c.eps_area},
                              {"fallback_budget", c.fallback_budget}, {"failing_slabs", c.failing_slabs}, {"rasterized_cells", c.rasterized_cells}, {"seconds", c.seconds}, {"error", c.error}});
      alignment_report["candidates"] = candidates;
      alignment_report["proxy_faces"] = alignment.proxy_faces;
      if (alignment.proxy_faces > 0)
        progress.stage("align", "scored on a simplified copy of " + std::to_string(alignment.proxy_faces) + " faces");
      align_seconds += progress.elapsed_seconds() - align_start;
      if (alignment.stopped) {
        progress.stage("align", "stopped: the time limit is spent");
        time_limit.spent(progress);
        alignment_report["stopped"] = true;
        return;
      }
      if (alignment.chosen < 0)  // every orientation failed, with the full budget too: say why the input frame did
        throw AlgorithmError("no orientation gives a valid polycube; in the input frame: " + alignment.candidates.front().error);
      const AlignmentCandidate& chosen = alignment.candidates[alignment.chosen];
      alignment_report["chosen"] = chosen.name + suffix;
      if (!equalised && reserve.empty() && &pass == &options)
        for (const AlignedStages& r : alignment.reserve) reserve.emplace_back(r, alignment.candidates[r.candidate].name + suffix);
      progress.stage("align", chosen.name + suffix + " (" + std::to_string(chosen.corners) + " corners)");
    }
    const size_t first = attempts.size();
    for (const AlignedStages& stages : alignment.stages_in_order()) {
      if (attempts.size() > first && !runs(pass.stage, "map")) break;  // alternatives compete by their maps
      attempts.push_back(std::make_unique<Attempt>());
      static_cast<AlignedStages&>(*attempts.back()) = stages;
      attempts.back()->name = (stages.candidate >= 0 ? alignment.candidates[stages.candidate].name : std::string("input frame")) + suffix;
      attempts.back()->da = pass.polycube.da;
      if (equalised) {
        // The candidate's rotation only permutes the copy's axes (input frame only).
        Attempt& a = *attempts.back();
        a.scales = equalised->turned_scales(a.rotation);
        a.unscaled = equalised->turned_axes(a.rotation);
        a.unscaled_source = &source;
      }
    }
    if (first_choice.empty()) first_choice = attempts[first]->name;
    finish_attempts(first, pass, stages_source, false);
  };
  // A model much longer than wide: first on its scaled copy (equalised_copy); the model itself
  // follows when that map misses the contract, is far from conformal (kEqualiseKeepAngle) or
  // cannot be built, and the two compete by rank.
  const std::optional<EqualisedCopy> equalised =
      options.equalise_axes == "auto" && options.align == "auto" && runs(options.stage, "map") ? equalised_copy(source) : std::nullopt;
  if (equalised) {
    say_equalised_copy(*equalised, progress, report["alignment"]["equalised"]);
    try {
      run_pass(options, report["alignment"]["equalised"], ", on a copy scaled along them", &*equalised);
    } catch (const Error& e) {
      progress.warning(std::string("the scaled copy: ") + e.what());
      report["alignment"]["equalised"]["error"] = e.what();
    }
  }
  if (!kept || (kept->finished && (!kept->judged().meets_contract() || kept->judged().audit.distortion.eps_angle > kEqualiseKeepAngle))) {
    if (kept) {
      const Finished& copy = kept->judged();
      progress.stage("equalise", (copy.meets_contract() ? "the copy's map has eps_angle " + std::to_string(copy.audit.distortion.eps_angle) + "; "
                                                         : shortfall()) +
                                     "now the model itself");
      // The copy's map stands when the model's own pass fails (a model too thin for the quadtree).
      try {
        run_pass(options, report["alignment"], "");
      } catch (const Error& e) {
        progress.warning(std::string("the model itself: ") + e.what());
        report["alignment"]["error"] = e.what();
      }
    } else {
      run_pass(options, report["alignment"], "");
    }
  }
  // Still short of the contract: everything once more with finer contours. Where the quadtree
  // drops a thin part of a cross-section (a tail, a horn, a hoof), P has nothing for it and the
  // map squeezes it towards a point, where the chords of P's images miss its area (bull: a horn
  // 7 % of the diagonal from P's image, 0.972 of the area at d_a 0.3; at 0.1 the orientations
  // rank differently and the new first one gives 0.981). A finer P can also flip more: the
  // maps compete by rank.
  if (kept && kept->finished && !kept->judged().meets_contract() && options.finer_contours > 1 && !time_limit.spent(progress)) {
    MapOptions finer = options;
    finer.polycube.da = options.polycube.da / options.finer_contours;
    std::ostringstream suffix;
    suffix << ", finer contours (d_a " << finer.polycube.da << ")";
    progress.stage("retry", shortfall() + "all over again with d_a " + std::to_string(finer.polycube.da));
    try {
      run_pass(finer, report["alignment"]["finer_contours"], suffix.str());
    } catch (const Error& e) {
      progress.warning(std::string("finer contours: ") + e.what());
    }
  }
  // The exact sampling of a finished attempt's unsmoothed φ (exact_map), kept in its place where
  // it ranks better; the kept attempt updated.
  auto try_exact = [&](Attempt* a) {
    progress.stage("retry", shortfall() + "the exact sampling of " + a->name);
    const double start = progress.elapsed_seconds();
    std::unique_ptr<Finished> exact;
    try {
      exact = exact_map(a->model, a->polycube->polycube, *a->map, options, progress);
    } catch (const AlgorithmError& e) {
      // Not a result: the finished map stands.
      progress.warning(std::string("exact sampling not made: ") + e.what());
      a->finished->overlay = {{"error", e.what()}};
      a->seconds += progress.elapsed_seconds() - start;
      return;
    }
    std::unique_ptr<Finished> exact_on_model = on_model_of(*a, *exact);
    const Finished &judged_exact = exact_on_model ? *exact_on_model : *exact, &judged_before = a->judged();
    const bool better = judged_exact.rank() < judged_before.rank();
    progress.stage("exact", std::string(better ? "kept" : "not kept") + " (" + std::to_string(judged_exact.bad_p()) + " / " +
                                std::to_string(judged_exact.bad_m()) + " flipped, image area " +
                                std::to_string(judged_exact.audit.polycube_to_model.area_ratio) + " against " +
                                std::to_string(judged_before.bad_p()) + " / " + std::to_string(judged_before.bad_m()) + ", " +
                                std::to_string(judged_before.audit.polycube_to_model.area_ratio) +
                                (exact_on_model ? ", on the model)" : ")"));
    nlohmann::json tried = exact->overlay;
    tried["kept"] = better;
    tried["polycube_to_model"] = direction_json(exact->audit.polycube_to_model);
    tried["model_to_polycube"] = direction_json(exact->audit.model_to_polycube);
    tried["seconds_total"] = progress.elapsed_seconds() - start;  // the sampling and its untangling
    if (better) {
      a->finished = std::move(exact);
      a->on_model = std::move(exact_on_model);
    }
    a->finished->overlay = tried;
    a->seconds += progress.elapsed_seconds() - start;
    if (a->judged().rank() < kept->judged().rank()) kept = a;
  };
  // (A scaled copy's map data is the copy's: no exact sampling of it.)
  const auto exact_possible = [&](const Attempt& a) { return options.exact && a.finished && a.map && !a.scaled(); };
  // Still short after every orientation and the finer contours: the exact sampling of each
  // finished map, best-ranked first, until one meets the contract. Not earlier: where a smoothed
  // map meets the contract it has the lower distortion (joint: ε_angle 1.03 smoothed, after its
  // second orientation, against 2.10 exact on its first).
  if (options.exact && kept && kept->finished && !kept->judged().meets_contract()) {
    std::vector<Attempt*> order;
    for (const auto& a : attempts)
      if (exact_possible(*a)) order.push_back(a.get());
    std::stable_sort(order.begin(), order.end(), [](const Attempt* x, const Attempt* y) { return x->judged().rank() < y->judged().rank(); });
    for (Attempt* a : order) {
      if (time_limit.spent(progress)) break;
      try_exact(a);
      if (kept->judged().meets_contract()) break;
    }
  }
  // Still short after the exact samplings too: the first search's other orientations (its
  // reserve), best by its score first, each finished and, short of the contract, sampled exactly;
  // each started while those before took less than --more-orientations times the run's time before
  // them. The score (unsmoothed flips) is a weak guide to the finished map: on Cura's
  // Hellbot_Magna_2_230 plate (260 triangles) the three maps finished first, their finer contours
  // and exact samplings all missed; the fourth more orientation's exact sampling met the contract.
  // Last, so that a map meeting the contract before keeps its files and its time.
  if (kept && kept->finished && !kept->judged().meets_contract() && !reserve.empty() && options.more_orientations > 0 &&
      !time_limit.spent(progress)) {
    const double start = progress.elapsed_seconds(), budget = options.more_orientations * start;
    progress.stage("retry", shortfall() + "more of the search's orientations (" + std::to_string(reserve.size()) + " built)");
    int more = 0;
    for (const auto& [stages, name] : reserve) {
      if (progress.elapsed_seconds() - start >= budget && more > 0) break;
      attempts.push_back(std::make_unique<Attempt>());
      static_cast<AlignedStages&>(*attempts.back()) = stages;
      attempts.back()->name = name;
      attempts.back()->da = options.polycube.da;
      ++more;
      finish_attempts(attempts.size() - 1, options, source, true);
      Attempt& a = *attempts.back();
      if (!kept->judged().meets_contract() && exact_possible(a) && !time_limit.spent(progress)) try_exact(&a);  // (a misses too)
      if (kept->judged().meets_contract() || time_limit.spent(progress)) break;
    }
    report["alignment"]["more_orientations"] = more;
  }
  reserve.clear();
  time_limit.warn(progress, "other orientations, finer contours and exact samplings");
  if (time_limit.seconds > 0) report["time_limit"] = {{"seconds", time_limit.seconds}, {"reached", time_limit.reached}};
  if (separation && kept->finished) {
    // P's images on the copy, moved to the same faces and barycentric coordinates of the model
    // (on_model_of: untangled there where they flip only there); the audit on the copy goes to
    // the report, the files' audit on the model is made below.
    Finished& finished = *kept->finished;
    report["separation"]["on_copy"] = {{"polycube_to_model", direction_json(finished.audit.polycube_to_model)},
                                       {"model_to_polycube", direction_json(finished.audit.model_to_polycube)},
                                       {"eps_angle", finished.audit.distortion.eps_angle}};
    finished.on_model_xyz = kept->on_model->on_model_xyz;
    finished.on_polycube_xyz = kept->on_model->on_polycube_xyz;
    if (!kept->on_model->untangling.is_null()) report["separation"]["untangling_on_model"] = kept->on_model->untangling;
  }
  const Attempt& chosen = *kept;
  const Eigen::Matrix3d rotation = chosen.rotation;
  const auto finished_attempts = std::count_if(attempts.begin(), attempts.end(), [](const auto& a) { return a->finished != nullptr; });
  report["alignment"]["chosen"] = chosen.name;
  if (chosen.name != first_choice) progress.stage("retry", "kept " + chosen.name);
  if (chosen.scaled() && chosen.finished && chosen.finished->audit.distortion.eps_angle > kEqualiseKeepAngle)
    progress.warning("the map kept is the scaled copy's, far from conformal on the model (eps_angle " +
                     std::to_string(chosen.finished->audit.distortion.eps_angle) + "): the model itself gave none better");
  if (finished_attempts > 1) {
    nlohmann::json finished = nlohmann::json::array();
    for (const std::unique_ptr<Attempt>& a : attempts) {
      if (!a->finished) continue;
      const Finished& f = a->judged();  // on the model itself when separated
      finished.push_back({{"name", a->name},
                          {"polycube_to_model_flipped", f.bad_p()},
                          {"model_to_polycube_flipped", f.bad_m()},
                          {"area_ratio", f.audit.polycube_to_model.area_ratio},
                          {"eps_angle", f.audit.distortion.eps_angle},
                          {"eps_area", f.audit.distortion.eps_area},
                          {"meets_contract", f.meets_contract()},
                          {"kept", a.get() == kept},
                          {"seconds", a->seconds}});
    }
    report["alignment"]["finished"] = finished;
  }
  nlohmann::json repeated = nlohmann::json::array();
  for (const std::unique_ptr<Attempt>& a : attempts)
    if (!a->same_as.empty()) repeated.push_back({{"name", a->name}, {"same_polycube_as", a->same_as}});
  if (!repeated.empty()) report["alignment"]["repeated"] = repeated;
  report["alignment"]["rotation"] = {{rotation(0, 0), rotation(0, 1), rotation(0, 2)},
                                     {rotation(1, 0), rotation(1, 1), rotation(1, 2)},
                                     {rotation(2, 0), rotation(2, 1), rotation(2, 2)}};
  // The scales of the copy the stages ran on (1 unless scaled): its x, y, z are the turned
  // frame's times these.
  report["alignment"]["axis_scales"] = {chosen.scales(0), chosen.scales(1), chosen.scales(2)};
  const TriMesh& model = chosen.model;
  // Positions of the turned frame back in the input's (x = rotation^T x_turned).
  auto to_input = [&rotation](const Eigen::MatrixX3d& V) -> Eigen::MatrixX3d { return V * rotation; };
  auto mesh_to_input = [&](const TriMesh& m) {
    TriMesh out = m;
    out.V = to_input(m.V);
    return out;
  };
  const TopologyResult& topology = *chosen.topology;
  report["topology"] = topology_json(topology);
  // A scaled copy's heights, in the turned frame (divided by its z scale).
  const auto turned_heights = [&chosen](std::vector<double> z) {
    for (double& h : z) h /= chosen.scales(2);
    return z;
  };
  if (chosen.scaled()) report["topology"]["cutting_planes"] = turned_heights(topology.planes_z);
  nlohmann::json seconds = {{"align", align_seconds}, {"topology", topology.seconds_total}};
  if (finished_attempts > 1) {
    double retry_seconds = 0;
    for (const std::unique_ptr<Attempt>& a : attempts)
      if (a.get() != kept) retry_seconds += a->seconds;
    seconds["retry"] = retry_seconds;
  }
  const SlicedMesh* model_pieces = &topology.sliced;
  const PolycubeResult* polycube = chosen.polycube.get();
  // The search maps its candidates whatever the stage asked; only a finished map is written.
  const PolycubeMap* map = chosen.finished ? chosen.map.get() : nullptr;
  const Polycube* written_polycube = nullptr;  // P as written: refined when the map refines its sampling
  Eigen::MatrixX3d on_polycube_xyz;             // the map at the model's vertices, smoothed when asked
  if (polycube) {
    model_pieces = &polycube->model_sliced;
    report["polycube"] = polycube_json(*polycube);
    if (chosen.scaled()) report["polycube"]["planes"] = turned_heights(polycube->planes_z);
    report["polycube"]["da"] = chosen.da;
    seconds["polycube"] = polycube->seconds_total;
    written_polycube = &polycube->polycube;
  }
  const std::string polycube_path = (dir / "polycube.obj").string();
  if (polycube && !map) {
    write_mesh(polycube_path, placed_as_input(prepared, mesh_to_input(polycube->polycube.mesh)));
    outputs.push_back(polycube_path);
  }
  if (map) {
    const Finished& finished = *chosen.finished;
    seconds["map"] = map->seconds;
    int flipped_disks = 0, ricci_pieces = 0, ricci_iterations = 0, flat_slits = 0, slits = 0, decrowded = 0, decrowd_iterations = 0;
    double ricci_residual = 0, min_disk_area = INFINITY, crowding_before = 1, crowding_after = 1;
    for (const PieceMapStats& p : map->pieces) {
      flipped_disks += p.flipped_model_disk + p.flipped_polycube_disk;
      ricci_pieces += p.ricci_iterations > 0;
      ricci_iterations = std::max(ricci_iterations, p.ricci_iterations);
      ricci_residual = std::max(ricci_residual, p.ricci_residual);
      flat_slits += p.flat_slits;
      slits += p.slits;
      min_disk_area = std::min(min_disk_area, p.min_disk_area);
      decrowded += p.decrowd_iterations > 0;
      decrowd_iterations = std::max(decrowd_iterations, p.decrowd_iterations);
      crowding_before = std::min(crowding_before, p.min_area_ratio_before);
      crowding_after = std::min(crowding_after, p.min_area_ratio);
    }
    if (options.refine) seconds["refine"] = chosen.refine_seconds;
    if (chosen.smooth_unrefined_seconds > 0) seconds["smooth_unrefined"] = chosen.smooth_unrefined_seconds;
    if (options.smooth_sweeps > 0) seconds["smooth"] = finished.smooth_seconds;
    if (finished.untangle_seconds > 0) seconds["untangle"] = finished.untangle_seconds;
    if (!finished.overlay.is_null()) seconds["exact"] = finished.overlay.value("seconds_total", 0.0);
    written_polycube = finished.polycube;
    const Polycube& P = *written_polycube;
    on_polycube_xyz = finished.on_polycube_xyz;
    // The files as written, in the input frame and on the model, audited there: the rotation's
    // rounding can decide a near tie on an edge of P the other way (elk: a model triangle 0
    // flipped in the turned frame, 1 in the input's). (A separated model's images were moved
    // back, audited and untangled on the model already: on_model_of.) The report gives the files'
    // figures; what flips only there is untangled there.
    Polycube P_input = P;
    P_input.mesh = mesh_to_input(P.mesh);
    Finished written;
    written.polycube = &P_input;
    written.on_model_xyz = to_input(finished.on_model_xyz);
    written.on_polycube_xyz = to_input(finished.on_polycube_xyz);
    const Finished& judged = chosen.judged();  // on the model in the turned frame
    written.audit = rotation.isIdentity(0) ? judged.audit
                                           : audit_map(prepared.mesh, P_input.mesh, written.on_model_xyz, written.on_polycube_xyz);
    if (written.bad_p() > judged.bad_p() || written.bad_m() > judged.bad_m()) {
      progress.stage("audit", "the files as written: " + std::to_string(written.bad_p()) + " / " + std::to_string(written.bad_m()) +
                                  " flipped or degenerate image triangles, against " + std::to_string(judged.bad_p()) + " / " +
                                  std::to_string(judged.bad_m()) + " in the turned frame");
      untangle_images(prepared.mesh, written, options.untangle_shift, options.untangle_shift_max, progress);
      report["written"] = {{"untangling", written.untangling}};
    }
    write_mesh(polycube_path, placed_as_input(prepared, P_input.mesh));
    outputs.push_back(polycube_path);
    const MapAudit& audit = written.audit;
    report["map"] = {{"contours", map->contours},
                     {"pieces", map->pieces.size()},
                     {"slits", slits},
                     {"slits_by_flat_metric", flat_slits},
                     {"ricci", {{"pieces", ricci_pieces}, {"max_iterations", ricci_iterations}, {"max_residual", ricci_residual}}},
                     {"flipped_disk_triangles", flipped_disks},
                     {"min_disk_triangle_area", min_disk_area},
                     {"crowding",
                      {{"pieces", decrowded}, {"max_iterations", decrowd_iterations}, {"min_area_ratio_before", crowding_before},
                       {"min_area_ratio", crowding_after}}},
                     {"polycube_to_model", direction_json(audit.polycube_to_model)},
                     {"model_to_polycube", direction_json(audit.model_to_polycube)},
                     {"eps_angle", audit.distortion.eps_angle},
                     {"eps_area", audit.distortion.eps_area},
                     {"angle_p50", audit.distortion.angle_p50},
                     {"angle_p95", audit.distortion.angle_p95},
                     {"angle_max", audit.distortion.angle_max},
                     {"area_p95", audit.distortion.area_p95},
                     {"area_max", audit.distortion.area_max},
                     {"refinement", chosen.refinement_report},
                     {"smoothing", finished.smoothing},
                     {"untangling", finished.untangling},
                     {"exact", finished.overlay}};
    TriMesh on_model = P.mesh;
    on_model.V = written.on_model_xyz;
    const std::string on_model_path = (dir / "polycube_on_model.obj").string();
    write_mesh(on_model_path, placed_as_input(prepared, on_model));
    outputs.push_back(on_model_path);
    TriMesh on_polycube = prepared.mesh;
    on_polycube.V = written.on_polycube_xyz;
    const std::string on_polycube_path = (dir / "model_on_polycube.obj").string();
    write_mesh(on_polycube_path, placed_as_input(prepared, on_polycube));
    outputs.push_back(on_polycube_path);
    progress.stage("map", std::to_string(flipped_disks) + " flipped disk triangles; " + std::to_string(audit.polycube_to_model.flipped) + " / " +
                              std::to_string(audit.model_to_polycube.flipped) + " flipped image triangles (P to M / M to P), eps_angle " +
                              std::to_string(audit.distortion.eps_angle));
    // The best map found is written either way; what it misses is said, and in the report.
    report["map"]["meets_contract"] = written.meets_contract();
    if (!written.meets_contract()) progress.warning("the map falls short of its contract: " + written.shortfall());
  }

  const std::string pieces_path = (dir / "pieces.ply").string();
  SlicedMesh pieces_in_input = *model_pieces;
  // (The slicing of a scaled copy's model, taken back: slicing by planes commutes with scaling.)
  pieces_in_input.mesh.V = placed_as_input(prepared, to_input(model_pieces->mesh.V * chosen.scales.cwiseInverse().asDiagonal()));
  write_pieces(pieces_path, pieces_in_input);
  outputs.push_back(pieces_path);
  const std::string preview_path = (dir / "preview.png").string();
  if (map)
    write_map_preview(preview_path, model, *written_polycube, on_polycube_xyz);
  else if (polycube)
    write_polycube_preview(preview_path, *polycube);
  else
    write_pieces_preview(preview_path, *model_pieces);
  outputs.push_back(preview_path);

  seconds["total"] = progress.elapsed_seconds();
  report["seconds"] = seconds;
  const std::string report_path = (dir / "report.json").string();
  report["outputs"] = outputs;
  write_text_atomically(report_path, [&](std::ostream& out) { out << report.dump(2) << "\n"; });
  outputs.push_back(report_path);
  progress.stage("done", "wrote " + std::to_string(outputs.size()) + " files in " + options.output_dir);
  return kSuccess;
}

}  // namespace

void add_map_command(CLI::App& app, const GlobalOptions& global, CommandRunner& runner) {
  auto options = std::make_shared<MapOptions>();
  CLI::App* command = app.add_subcommand("map", "Build the polycube and the map for a closed mesh");
  add_mesh_input_options(*command, options->input);
  command->add_option("-o,--output", options->output_dir, "Output directory (created if missing)")->required();
  command->add_option("--dz", options->topology.dz, "Largest gap between cutting planes, unit-cube units (paper's d_z)")
      ->capture_default_str()
      ->check(CLI::Range(1e-3, 1.0));
  command->add_option("--da", options->polycube.da, "Area tolerance of the axis-aligned contours (paper's d_a)")
      ->capture_default_str()
      ->check(CLI::Range(1e-3, 1.0));
  command->add_option("--polycube-vertices", options->polycube.target_vertices,
                      "About how many vertices the triangulated polycube gets (0: as many as the model; under 5000, --align auto also tries 20000)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  command->add_option("--align", options->align,
                      "auto: try the input frame, the principal axes and (for CAD-like parts) the normals' frame, each axis as the "
                      "sweep direction; map the two polycubes with the fewest corners (all, when both flip) and keep the map with the "
                      "fewest flipped triangles; none: keep the input's orientation")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "none"}));
  command->add_option("--equalise-axes", options->equalise_axes,
                      "auto: a model far longer than wide (its largest principal deviation over 100 times the next) is mapped "
                      "first on a copy with its principal axes scaled to within 4 times of each other (P, built along them, "
                      "scaled back is still a polycube; the map is finished on the model); the model itself too when that map "
                      "misses the contract or has eps_angle above 1.1, the better kept; never: only the model itself. Only "
                      "with --align auto")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "never"}));
  command->add_option("--separate", options->separate,
                      "A model that intersects itself: always: build everything on a copy pulled apart round the crossings "
                      "(local smoothing; a cutting plane's contours must not cross), P's images moved back onto the model at the "
                      "end and audited there (when the smoothing leaves crossings, the model itself, with a warning); never: on the model "
                      "itself")
      ->capture_default_str()
      ->check(CLI::IsMember({"always", "never"}));
  command->add_option("--smooth-sweeps", options->smooth_sweeps,
                      "Sweeps per round of the map's smoothing (paper §3.5; never adds a flipped triangle); 0: no smoothing")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  command->add_flag("--no-refine{false}", options->refine,
                   "Keep P's triangulation as built: do not refine it where the map sampled at its vertices flips or loses area");
  command->add_option("--untangle-shift", options->untangle_shift,
                      "Where an image triangle of the finished map is still flipped, move single vertex images on the other "
                      "surface by at most this fraction of its bounding-box diagonal to unfold it; 0: write the sampled map as is")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.1));
  command->add_option("--untangle-shift-max", options->untangle_shift_max,
                      "When moves within --untangle-shift leave a flipped triangle, untangle again with 2, 5 and 10 times that shift, "
                      "at most this fraction of the diagonal, while each run leaves fewer (the best is kept)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.5));
  command->add_option("--finer-contours", options->finer_contours,
                      "When the finished map still has flipped triangles or misses area, finish the kept orientation once more with d_a "
                      "divided by this (finer contours keep thin parts such as tails and horns); 1: never")
      ->check(CLI::Range(1.0, 100.0))
      ->capture_default_str();
  command->add_option("--more-orientations", options->more_orientations,
                      "When no map meets the contract after the finer contours and the exact samplings, finish more of the "
                      "orientations the search built (and sample each exactly when it misses), best by its score first, until one "
                      "meets it, each started while they have taken less than this many times the run's time before them (the first "
                      "always); 0: none")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  add_time_limit_option(*command, options->time_limit);
  command->add_flag("--no-exact{false}", options->exact,
                   "When no finished map is free of flipped triangles with the area within 2 %, do not try the exact sampling "
                   "last (P triangulated by both disk triangulations of every piece, where the unsmoothed map is affine on each "
                   "triangle)");
  command->add_option("--stage", options->stage, "Stop after this stage")
      ->capture_default_str()
      ->check(CLI::IsMember(kStages));
  command->callback([options, &global, &runner] { runner = [options, &global] { return run_map(*options, global); }; });
}

}  // namespace polycube::cli
