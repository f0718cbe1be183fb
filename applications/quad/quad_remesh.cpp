#include "applications/quad/quad_remesh.h"

#include "applications/quad/quad_collapse.h"
#include "applications/quad/quad_guard.h"
#include "applications/quad/quad_templates.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>
#include <utility>

namespace polycube {

namespace {
double since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The refinement's misses are measured at sample points (find_quad_misses); the Hausdorff
// distance, on denser samples of both surfaces, can come out a few % higher (gargoyle, before
// the misses were sampled along M's edges and the quads' edges too: 0.498 % against 0.506 %).
// The bound is aimed at with this margin.
constexpr double kBoundMargin = 0.9;
// Past the rounds and budget asked for, a round refines at the misses within this fraction of the
// farthest (and beyond the bound).
constexpr double kExtendedWorstFraction = 0.85;
// ... and adds at most this factor of quads (a round of gargoyle's added 13 000 to 12 000 for
// misses of 0.51-0.60 % spread over the model; rounds of 15-20 % met the bound with about half).
constexpr double kExtendedRoundGrowth = 1.2;
// Once a round's place cut a line by a bad quad, places within this many times the quad's size
// on P (centre to farthest corner) of it are not refined again.
constexpr double kBlockRadius = 3;
// The mending of inverted and sharp corners at the end: tries, the distance slack (the quads may miss the
// model by this factor of before), and the radius, in mean quad sizes, round the farthest misses
// within which moved vertices are held for the next try.
constexpr int kMendTries = 4;
constexpr double kMendSlack = 1.01;
constexpr double kMendHoldRadius = 3;

// A pass's quads and what made them, into `to` (whose stage times and refinement figures stay).
void take_pass(QuadRemeshResult& to, QuadRemeshResult pass) {
  to.grid = std::move(pass.grid);
  to.mesh = std::move(pass.mesh);
  to.smoothing = std::move(pass.smoothing);
  to.fitting = std::move(pass.fitting);
  to.refitting = std::move(pass.refitting);
  to.untangling = std::move(pass.untangling);
}

std::string format(const char* pattern, double a, double b = 0, double c = 0) {
  char text[160];
  std::snprintf(text, sizeof text, pattern, a, b, c);
  return text;
}

// measure_quads on the result, its time and a line of progress.
void measure_result(QuadRemeshResult& result, const SurfaceProjector& model, const QuadRemeshOptions& options,
                    const std::function<void(const std::string&, const std::string&)>& report) {
  report("quality", options.quality.hausdorff ? "angles, flips, Hausdorff distance" : "angles, flips");
  const auto start = std::chrono::steady_clock::now();
  result.quality = measure_quads(result.mesh, model, result.grid.corners, options.quality);
  result.seconds_quality = since(start);
  const QuadQuality& q = result.quality;
  std::string message = std::to_string(q.quads) + " quads, " + std::to_string(q.irregular_vertices) + " irregular (" +
                        std::to_string(q.irregular_at_corners) + " at polycube corners), angle deviation " +
                        format("%.2f / %.2f / %.1f deg (mean / p95 / max)", q.angle_deviation_mean, q.angle_deviation_p95,
                               q.angle_deviation_max) +
                        ", " + std::to_string(q.flipped_quads) + " flipped, " + std::to_string(q.degenerate_quads) +
                        " degenerate, " + std::to_string(q.inverted_corners) + " inverted and " +
                        std::to_string(q.sharp_corners) + " sharp corners";
  if (q.hausdorff_measured) message += format(", Hausdorff %.3f %% of the diagonal", q.hausdorff_percent);
  report("quality", message);
}
}  // namespace

void mend_quad_corners(QuadRemeshResult& result, const SurfaceProjector& model, const QuadRemeshOptions& options,
                       const QuadProgress& progress) {
  const auto report = [&](const std::string& stage, const std::string& message) {
    if (progress) progress(stage, message);
  };
  // Corners turned against the quad (non-convex quads, a negative Jacobian there) and sharp ones
  // (nearly shut or flat, options.quality.sharp_degrees from 90°): the vertices of those quads
  // moved, and patches round them laid out again, while that lowers (bad quads, inverted corners,
  // sharp corners) in that order; first with the fitted corners held, then, for inverted corners
  // left, with those free too. Kept when it lowers them and the quads miss the model no farther
  // (1 % slack for the sampling); when they do miss farther, the moved vertices near the farthest
  // misses are held and it is tried again (at most kMendTries times). Not kept at all: the
  // same for the inverted corners alone.
  if (options.untangle.passes > 0) {
    QuadQualityOptions topology_only = options.quality;
    topology_only.hausdorff = false;
    // (result.quality, when measured, is of result.mesh: remesh_quads measures after this.)
    const bool measured = result.quality.quads == result.mesh.num_quads() && result.quality.quads > 0;
    const QuadQuality before = measured ? result.quality : measure_quads(result.mesh, model, result.grid.corners, topology_only);
    result.inverted_before_mending = before.inverted_corners;
    result.sharp_before_mending = before.sharp_corners;
    const auto corner_badness = [](const QuadQuality& q) {
      return std::make_tuple(q.flipped_quads + q.degenerate_quads, q.inverted_corners, q.sharp_corners);
    };
    if (before.inverted_corners > 0 || before.sharp_corners > 0) {
      const auto begin = std::chrono::steady_clock::now();
      const double diagonal = bounding_box(model.surface().V).diagonal();
      const HausdorffOptions sampling = options.quality.sampling;
      const double miss_before = measured && result.quality.hausdorff_measured
                                     ? result.quality.hausdorff
                                     : hausdorff_distance(triangulate_quads(result.mesh), model.sampled(), sampling).hausdorff;
      const double bound = options.refine.bound_percent / 100 * diagonal;
      const int nv = result.mesh.num_vertices();
      const double size = mean_quad_size(result.mesh);
      // One mending, with sharp corners counted beyond sharp_degrees (0: not counted); true when kept.
      const auto mend = [&](double sharp_degrees) {
        QuadUntangleOptions corners = options.untangle;
        corners.inverted = true;
        corners.sharp_degrees = sharp_degrees;
        QuadUntangleOptions tangles = corners;  // for the fitted corners: tangles only
        tangles.sharp_degrees = 0;
        QuadQualityOptions counted = topology_only;
        counted.sharp_degrees = sharp_degrees > 0 ? sharp_degrees : 180;
        const QuadQuality was =
            sharp_degrees == options.quality.sharp_degrees ? before : measure_quads(result.mesh, model, result.grid.corners, counted);
        std::vector<char> held(nv, 0);  // vertices held for the distance
        for (int attempt = 0; attempt < kMendTries; ++attempt) {
          std::vector<char> pinned = held;
          for (int v = 0; v < nv && v < static_cast<int>(result.fitting.pinned.size()); ++v)
            pinned[v] = pinned[v] || result.fitting.pinned[v];
          ++result.mending_tries;
          QuadUntangleResult fixed = untangle_quads(result.mesh, model, corners, pinned);
          QuadQuality after = measure_quads(fixed.mesh, model, result.grid.corners, counted);
          if (after.inverted_corners > 0 && pinned != held) {
            // Some are at fitted corners: those free too, for the inverted corners only (a sharp
            // corner is not worth moving a vertex off the tip it was fitted to).
            const int moves = fixed.moves, patches = fixed.patches;
            fixed = untangle_quads(fixed.mesh, model, tangles, held);
            fixed.moves += moves;
            fixed.patches += patches;
            after = measure_quads(fixed.mesh, model, result.grid.corners, counted);
          }
          if (!(corner_badness(after) < corner_badness(was))) return false;
          const HausdorffDistance miss = hausdorff_distance(triangulate_quads(fixed.mesh), model.sampled(), sampling);
          // No farther (the slack), and not out of the bound when within it.
          const bool kept = miss.hausdorff <= kMendSlack * miss_before && (miss.hausdorff <= bound || miss_before > bound);
          std::string what = std::to_string(was.inverted_corners) + " inverted";
          if (sharp_degrees > 0) what += " and " + std::to_string(was.sharp_corners) + " sharp";
          what += " corners -> " + std::to_string(after.inverted_corners);
          if (sharp_degrees > 0) what += " and " + std::to_string(after.sharp_corners);
          report("untangle", what + " (" + std::to_string(fixed.moves) + " moves, " + std::to_string(fixed.patches) +
                                 " patches; misses the model by " +
                                 format("%.3f -> %.3f %% of the diagonal): ", 100 * miss_before / diagonal,
                                        100 * miss.hausdorff / diagonal) +
                                 (kept ? "kept" : "not kept"));
          if (kept) {
            result.mending_kept = true;
            result.mesh = std::move(fixed.mesh);
            result.quality = QuadQuality{};  // not of this mesh any more (measured below if asked)
            result.untangling.moves += fixed.moves;
            result.untangling.patches += fixed.patches;
            return true;
          }
          // Hold the moved vertices near where the quads now miss the model most.
          int newly = 0;
          for (int v = 0; v < nv; ++v) {
            if (held[v] || fixed.mesh.V.row(v) == result.mesh.V.row(v)) continue;
            const Eigen::Vector3d p = result.mesh.V.row(v).transpose();
            if ((p - miss.a_farthest).norm() <= kMendHoldRadius * size ||
                (p - miss.b_farthest).norm() <= kMendHoldRadius * size) {
              held[v] = 1;
              ++newly;
            }
          }
          if (newly == 0) return false;
        }
        return false;
      };
      // Sharp corners too; if that is not kept, inverted corners alone.
      if (!mend(options.quality.sharp_degrees) && before.inverted_corners > 0 && options.quality.sharp_degrees > 0) mend(0);
      result.seconds_untangle += since(begin);
    }
  }
  if (options.measure) measure_result(result, model, options, report);
}

QuadRemeshResult remesh_quads(const TriMesh& polycube, const SurfaceMap& to_model, const SurfaceProjector& model,
                              const QuadRemeshOptions& options, const QuadProgress& progress) {
  const auto report = [&](const std::string& stage, const std::string& message) {
    if (progress) progress(stage, message);
  };
  const SurfaceMap size_map = options.size_on_model ? to_model : SurfaceMap();
  QuadRemeshResult result;
  report("grid", "quad layout of the polycube's faces, chords split into near-squares");
  auto start = std::chrono::steady_clock::now();
  result.grid = build_polycube_grid(polycube, options.grid, size_map);
  result.seconds_grid = since(start);
  {
    const PolycubeGrid& grid = result.grid;
    report("grid", std::to_string(grid.mesh.num_quads()) + " quads, " + std::to_string(grid.corners.size()) + " corners, " +
                       std::to_string(grid.layout.num_quads()) + " layout cells (" + std::to_string(grid.free_loops) +
                       " free loops removed), cell size " + format("%.4g", grid.cell_size));
  }

  // One pass: carry the grid, relax, fit.
  // A refinement round's pass (from: the quads it refines) starts where from's relaxation and fit
  // left the vertices it keeps, the added ones carried by the map (carry_refined_grid; without
  // through_map, as template rounds do, placed on from's quads where they split them), and
  // relaxes with fewer sweeps (QuadRefineOptions::warm_sweeps).
  const auto run_pass = [&](QuadRemeshResult& pass, bool quiet, const QuadRemeshResult* from, bool through_map = true) {
    QuadSmoothOptions smooth = options.smooth;
    const bool warm = from && options.refine.warm_sweeps > 0;
    if (warm) smooth.sweeps = std::min(smooth.sweeps, options.refine.warm_sweeps);
    const auto say = [&](const std::string& stage, const std::string& message) {
      if (!quiet) report(stage, message);
    };
    say("carry", std::to_string(pass.grid.mesh.num_vertices()) + " vertices through the map");
    auto begin = std::chrono::steady_clock::now();
    std::vector<int> same;  // per vertex, the vertex of from's grid at its place (-1: none)
    if (warm) {
      RefinedCarry carried =
          carry_refined_grid(pass.grid, through_map ? to_model : SurfaceMap(), from->grid, from->mesh, model, options.carry);
      pass.mesh = std::move(carried.mesh);
      same = std::move(carried.same);
    } else {
      pass.mesh = carry_grid(pass.grid, to_model, options.carry);
    }
    pass.seconds_carry += since(begin);
    // A round's vertices that the quads it refines had pulled onto the model's tips start there
    // and stay, unless a line was added next to them (a quad round them has a new corner): the
    // fit is not undone where nothing changed, and is done again where lines were added.
    const Eigen::MatrixX4i& Q = pass.grid.mesh.Q;
    const int nv = pass.grid.mesh.num_vertices();
    std::vector<char> added;  // per quad of a warm round: it has a new corner
    if (warm) {
      added.assign(Q.rows(), 0);
      for (int q = 0; q < Q.rows(); ++q) added[q] = same[Q(q, 0)] < 0 || same[Q(q, 1)] < 0 || same[Q(q, 2)] < 0 || same[Q(q, 3)] < 0;
    }
    std::vector<char> fitted;
    if (warm && !from->fitting.pinned.empty()) {
      fitted.assign(nv, 0);
      for (int v = 0; v < nv; ++v) fitted[v] = same[v] >= 0 && from->fitting.pinned[same[v]];
      for (int q = 0; q < Q.rows(); ++q)
        if (added[q])
          for (int k = 0; k < 4; ++k) fitted[Q(q, k)] = 0;
    }
    // A warm round relaxes only round the lines it added (quads with a new corner and
    // options.refine.local_rings rings of quads round them); elsewhere the vertices keep the places
    // the quads it refines gave them, so what those quads already fitted does not move about.
    std::vector<char> held = fitted;
    if (warm && options.refine.local_rings >= 0) {
      std::vector<char> free(nv, 0);
      for (int q = 0; q < Q.rows(); ++q)
        if (added[q])
          for (int k = 0; k < 4; ++k) free[Q(q, k)] = 1;
      for (int ring = 0; ring < options.refine.local_rings; ++ring) {
        std::vector<char> next = free;
        for (int q = 0; q < Q.rows(); ++q)
          if (free[Q(q, 0)] || free[Q(q, 1)] || free[Q(q, 2)] || free[Q(q, 3)])
            for (int k = 0; k < 4; ++k) next[Q(q, k)] = 1;
        free = std::move(next);
      }
      held.resize(nv, 0);
      for (int v = 0; v < nv; ++v) held[v] = held[v] || !free[v];
    }
    if (smooth.sweeps > 0) {
      say("smooth", "up to " + std::to_string(smooth.sweeps) + " relaxation sweeps towards right angles");
      begin = std::chrono::steady_clock::now();
      pass.smoothing = smooth_quads(pass.mesh, model, smooth, held);
      pass.mesh = std::move(pass.smoothing.mesh);
      pass.smoothing.mesh = QuadMesh{};  // one copy is enough
      pass.seconds_smooth += since(begin);
      say("smooth", std::to_string(pass.smoothing.sweeps) + " sweeps" + (pass.smoothing.converged ? " (converged), " : ", ") +
                        std::to_string(pass.smoothing.moves) + " moves, " + std::to_string(pass.smoothing.rejected) +
                        " refused (would flip a quad or leave the surface under the vertex)");
    }
    if (options.fit.passes > 0) {
      say("fit", "corners pulled onto the points of the model the quads miss (vertices, creases)");
      begin = std::chrono::steady_clock::now();
      pass.fitting = fit_quads(pass.mesh, model, options.fit, fitted);
      pass.mesh = std::move(pass.fitting.mesh);
      pass.fitting.mesh = QuadMesh{};
      if (pass.fitting.snapped > 0 && smooth.sweeps > 0 && options.refit_sweeps > 0) {
        QuadSmoothOptions again = smooth;
        again.sweeps = std::min(options.refit_sweeps, smooth.sweeps);
        std::vector<char> pinned = pass.fitting.pinned;
        for (size_t v = 0; v < pinned.size() && v < held.size(); ++v) pinned[v] = pinned[v] || held[v];
        pass.refitting = smooth_quads(pass.mesh, model, again, pinned);
        pass.mesh = std::move(pass.refitting.mesh);
        pass.refitting.mesh = QuadMesh{};
      }
      pass.seconds_fit += since(begin);
      say("fit", std::to_string(pass.fitting.snapped) + " corners pulled (" + std::to_string(pass.fitting.stretched) +
                     " with rings following), farthest model point " +
                     format("%.4g -> %.4g from the quads", pass.fitting.farthest_before, pass.fitting.farthest_after));
    }
    if (options.untangle.passes > 0) {
      // Quads the map folded: their vertices moved apart where that unflips them (the fitted ones
      // first kept, then, if quads stay flipped, free too).
      begin = std::chrono::steady_clock::now();
      // Flipped quads only, by vertex moves: moving collapsed ones apart here changed which
      // refinement rounds cow kept (5.68 % off the model, not 2.49 %), and laying patches out
      // again hid flips from the rounds that then retry through the map (hole's finer P: 0.312 %
      // -> 0.670 %); the last untangling does both.
      QuadUntangleOptions untangle = options.untangle;
      untangle.collapsed = false;
      untangle.patch_rings = 0;
      pass.untangling = untangle_quads(pass.mesh, model, untangle, pass.fitting.pinned);
      if (pass.untangling.flipped_after > 0 && !pass.fitting.pinned.empty()) {
        const int flipped_before = pass.untangling.flipped_before, moves = pass.untangling.moves;
        pass.untangling = untangle_quads(pass.untangling.mesh, model, untangle);
        pass.untangling.flipped_before = flipped_before;
        pass.untangling.moves += moves;
      }
      pass.mesh = std::move(pass.untangling.mesh);
      pass.untangling.mesh = QuadMesh{};
      pass.seconds_untangle += since(begin);
      if (pass.untangling.flipped_before > 0)
        say("untangle", std::to_string(pass.untangling.flipped_before) + " flipped quads -> " +
                            std::to_string(pass.untangling.flipped_after) + ", " + std::to_string(pass.untangling.moves) +
                            " vertex moves");
    }
  };
  run_pass(result, false, nullptr);

  // Refinement: where the finished quads miss the model, the grid's chords there get their parts
  // halved and the pass runs again; the round that misses least, flipping nothing more, is kept.
  if (options.refine.rounds > 0) {
    const auto begin = std::chrono::steady_clock::now();
    const double diagonal = bounding_box(model.surface().V).diagonal();
    const double goal = options.refine.target_percent / 100 * diagonal;
    const PreimageLocator locator(polycube, to_model, options.refine.threads);
    PolycubeGridOptions grid_options = options.grid;
    const double base_quads = result.grid.mesh.num_quads();
    grid_options.refine_max_quads = static_cast<long long>(options.refine.max_growth * base_quads);
    QuadQualityOptions topology_only = options.quality;
    topology_only.hausdorff = false;
    // (flipped + degenerate quads, inverted corners) of quads on the grid's connectivity.
    const auto bad_of = [&](const QuadMesh& quads, const PolycubeGrid& grid) {
      const QuadQuality q = measure_quads(quads, model, grid.corners, topology_only);
      return std::make_pair(q.flipped_quads + q.degenerate_quads, q.inverted_corners);
    };
    const auto bad = [&](const QuadRemeshResult& r) { return bad_of(r.mesh, r.grid); };
    auto best_bad = bad(result);
    QuadMiss miss = find_quad_misses(result.grid, result.mesh, model, locator, goal, result.grid.cell_size, options.refine.threads);
    result.refine_miss_before = result.refine_miss_after = miss.farthest;
    report("refine", "the quads miss the model by up to " +
                         format("%.3f %%", 100 * miss.farthest / diagonal) + " of the diagonal at " + std::to_string(miss.points.size()) +
                         " places beyond " + format("%.3g %%", options.refine.target_percent));
    // When the rounds or the budget are spent with the quads still beyond the bound: more of both,
    // once.
    int rounds = options.refine.rounds;
    bool extended = false;
    long long bound_budget = 0;
    const double bound = kBoundMargin * options.refine.bound_percent / 100 * diagonal;
    const auto extend = [&](int round) {
      if (extended || !(bound > 0) || result.refine_miss_after <= bound || options.refine.bound_rounds <= 0) return false;
      extended = true;
      rounds = round + options.refine.bound_rounds;
      bound_budget = std::max(grid_options.refine_max_quads, static_cast<long long>(options.refine.bound_growth * base_quads));
      report("refine", "still beyond the bound of " + format("%.3g %%", options.refine.bound_percent) + ": up to " +
                           std::to_string(options.refine.bound_rounds) + " more rounds, up to " + std::to_string(bound_budget) +
                           " quads");
      return true;
    };
    // The rounds go on from the latest pass (`current`) even when it misses no less than the best
    // so far (the farthest miss moves about from pass to pass: the relaxation and the fit differ
    // where lines were added); the best is kept, and two rounds in a row without a better one end
    // the refinement. A round with more flipped or degenerate quads than the best is not taken
    // (see blame below).
    QuadRemeshResult current = result;
    int without_gain = 0;
    // Where a round's quads came out flipped or degenerate (the map folds there): the round's
    // places that cut a line bounding a bad quad or a quad round one are dropped, and balls on P
    // round those places (kBlockRadius times the bad quad's size on P) are not refined again.
    std::vector<std::pair<Eigen::Vector3d, double>> blocked;
    const auto is_blocked = [&](const SurfacePoint& p) {
      if (blocked.empty()) return false;
      const Eigen::Vector3d x = surface_position(polycube, p);
      for (const auto& [centre, radius] : blocked)
        if ((x - centre).norm() <= radius) return true;
      return false;
    };
    // The places of `places` (pass's last round) to blame for pass's bad quads, blocked; returns
    // how many.
    const auto blame = [&](const QuadRemeshResult& pass, std::vector<GridRefinement>& places) {
      const PolycubeGrid& g = pass.grid;
      const Eigen::MatrixX4i& Q = g.mesh.Q;
      std::vector<double> size_of(places.size(), -1);  // per blamed place: its bad quad's size on P
      std::vector<std::vector<int>> quads_of(g.mesh.num_vertices());
      for (int q = 0; q < Q.rows(); ++q)
        for (int k = 0; k < 4; ++k) quads_of[Q(q, k)].push_back(q);
      for (int q : bad_quads(pass.mesh, model, options.quality)) {
        Eigen::Vector3d centre = Eigen::Vector3d::Zero();
        for (int k = 0; k < 4; ++k) centre += g.mesh.V.row(Q(q, k)).transpose() / 4;
        double size = 0;
        for (int k = 0; k < 4; ++k) size = std::max(size, (g.mesh.V.row(Q(q, k)).transpose() - centre).norm());
        for (int k = 0; k < 4; ++k)
          for (int r : quads_of[Q(q, k)]) {
            const int n = g.quad_refined_by[r];
            if (n >= 0 && n < static_cast<int>(places.size())) size_of[n] = std::max(size_of[n], size);
          }
      }
      int blamed = 0;
      for (size_t n = 0; n < places.size(); ++n)
        if (size_of[n] >= 0) {
          blocked.emplace_back(surface_position(polycube, places[n].point), kBlockRadius * size_of[n]);
          ++blamed;
        }
      return blamed;
    };
    for (int round = 0; !miss.points.empty(); ++round) {
      if (extended && result.refine_miss_after <= bound) break;  // what the extension was for
      if (round >= rounds && !extend(round)) break;
      // The round's places: the worst misses, as many as the budget allows (past the rounds and
      // budget, only the very worst of those beyond the bound: every chord part halved is a line
      // of quads, and gargoyle took 13 000 more quads at once for the 0.6 worst fraction).
      grid_options.refine_rounds.emplace_back();
      if (extended)
        grid_options.refine_max_quads =
            std::min(bound_budget, static_cast<long long>(kExtendedRoundGrowth * current.grid.mesh.num_quads()));
      const double worst = extended ? std::max(bound, kExtendedWorstFraction * miss.farthest)
                                    : options.refine.worst_fraction * miss.farthest;
      // A miss d times the goal halves its parts about log4(d) times at once (at most 3): a tip
      // far out needs many lines through its small preimage.
      for (size_t k = 0; k < miss.points.size() && miss.distances[k] >= worst; ++k) {
        const int halvings = std::clamp(static_cast<int>(std::lround(std::log2(miss.distances[k] / goal) / 2)), 1, 3);
        grid_options.refine_rounds.back().push_back({miss.points[k], halvings});
      }
      std::vector<GridRefinement>& places = grid_options.refine_rounds.back();
      places.erase(std::remove_if(places.begin(), places.end(), [&](const GridRefinement& r) { return is_blocked(r.point); }),
                   places.end());
      // The round's pass (into pass, next, pass_bad); false, and nothing changed, when the grid
      // gains no part (the budget is spent, or every place was blocked).
      QuadRemeshResult pass;
      QuadMiss next;
      std::pair<int, int> pass_bad;
      const auto attempt = [&]() {
        PolycubeGrid grid = build_polycube_grid(polycube, grid_options, size_map);
        if (grid.refined_parts == current.grid.refined_parts) return false;
        pass = QuadRemeshResult{};
        pass.grid = std::move(grid);
        run_pass(pass, true, &current);
        next = find_quad_misses(pass.grid, pass.mesh, model, locator, goal, pass.grid.cell_size, options.refine.threads);
        pass_bad = bad(pass);
        if (pass_bad.first > best_bad.first && options.refine.warm_sweeps > 0) {
          // Started from the quads it refines, the round flipped a quad: the round's grid again as
          // the first pass ran, carried by the map and relaxed with all the sweeps.
          report("refine", "round " + std::to_string(round + 1) + ": " + std::to_string(pass_bad.first) +
                               " flipped or degenerate quads from the quads it refines; again through the map");
          QuadRemeshResult cold;
          cold.grid = std::move(pass.grid);
          run_pass(cold, true, nullptr);
          pass = std::move(cold);
          next = find_quad_misses(pass.grid, pass.mesh, model, locator, goal, pass.grid.cell_size, options.refine.threads);
          pass_bad = bad(pass);
        }
        return true;
      };
      bool refined = attempt();
      int blamed = -1;  // places blamed for this pass's bad quads (-1: not yet)
      if (refined && pass_bad.first > best_bad.first) {
        // The map folds where the round's lines went: once more without the places near the bad
        // quads (nor, in later rounds, near any bad quad met).
        const size_t before = places.size();
        const std::vector<GridRefinement> kept_places = places;
        blamed = blame(pass, places);
        places.erase(std::remove_if(places.begin(), places.end(), [&](const GridRefinement& r) { return is_blocked(r.point); }),
                     places.end());
        report("refine", "round " + std::to_string(round + 1) + ": " + std::to_string(pass_bad.first) +
                             " flipped or degenerate quads; again without the " + std::to_string(before - places.size()) +
                             " of its " + std::to_string(before) + " places whose lines run by them");
        // Else, or when that gains no part, the bad pass stays (with the places it was made from).
        if (before == places.size() || places.empty() || !attempt())
          places = kept_places;
        else
          blamed = -1;  // a new pass
      }
      if (!refined) {  // the budget is spent
        grid_options.refine_rounds.pop_back();
        if (extend(round)) {
          --round;
          continue;
        }
        break;
      }
      report("refine", "round " + std::to_string(round + 1) + ": " + std::to_string(pass.grid.refined_parts) +
                           " chord parts halved, " + std::to_string(pass.grid.mesh.num_quads()) + " quads, misses by up to " +
                           format("%.3f %%", 100 * next.farthest / diagonal) + ", " + std::to_string(pass_bad.first) +
                           " flipped or degenerate quads, " + std::to_string(pass_bad.second) + " inverted corners (best so far " +
                           format("%.3f %%, ", 100 * result.refine_miss_after / diagonal) + std::to_string(best_bad.first) + ", " +
                           std::to_string(best_bad.second) + ")");
      if (pass_bad.first > best_bad.first) {
        // Not taken; the next round refines elsewhere (no place near the ones blamed). With none
        // blamed it would make the same grid: the end.
        if (blamed < 0) blamed = blame(pass, grid_options.refine_rounds.back());
        grid_options.refine_rounds.pop_back();
        if (blamed == 0 || ++without_gain == 2) break;
        continue;
      }
      // The stage times stay the first pass's (the refinement's, its passes included, is apart).
      take_pass(current, std::move(pass));
      miss = next;
      if (next.farthest < result.refine_miss_after) {
        take_pass(result, current);
        result.refine_miss_after = next.farthest;
        result.refine_rounds = round + 1;
        best_bad = pass_bad;
        without_gain = 0;
      } else if (++without_gain == 2) {
        break;
      }
    }
    if (result.refine_rounds > 0 && options.refine.polish_sweeps > 0 && options.smooth.sweeps > 0) {
      // The kept rounds relaxed only round their lines: all of it once more (fitted corners held),
      // kept if it flips nothing more and misses the model no farther, or within the bound's aim.
      QuadSmoothOptions polish = options.smooth;
      polish.sweeps = std::min(options.refine.polish_sweeps, options.smooth.sweeps);
      QuadSmoothResult polished = smooth_quads(result.mesh, model, polish, result.fitting.pinned);
      const QuadMiss after =
          find_quad_misses(result.grid, polished.mesh, model, locator, goal, result.grid.cell_size, options.refine.threads);
      const bool kept = (after.farthest <= result.refine_miss_after || after.farthest <= bound) &&
                        bad_of(polished.mesh, result.grid).first <= best_bad.first;
      report("refine", std::string("a last relaxation of every vertex: ") + (kept ? "kept" : "not kept") + " (misses by up to " +
                           format("%.3f %%", 100 * after.farthest / diagonal) + ")");
      if (kept) {
        result.mesh = std::move(polished.mesh);
        result.refine_miss_after = after.farthest;
      }
    }
    if (options.refine.template_rounds > 0 && bound > 0 && result.refine_miss_after > bound && best_bad.first == 0) {
      // Still beyond the bound: the quads at the misses split by templates (quad_templates.h),
      // which spend quads only there, at the price of irregular vertices off P's corners. Not
      // where quads are flipped already: a round could only be kept by flipping fewer, and on
      // every such pass logged (camel, mpi) the splits flipped more; they only cost time.
      QuadMiss at = find_quad_misses(result.grid, result.mesh, model, locator, goal, result.grid.cell_size, options.refine.threads);
      const auto budget = static_cast<long long>(options.refine.template_growth * result.grid.mesh.num_quads());
      for (int round = 0; round < options.refine.template_rounds && at.farthest > bound; ++round) {
        const SurfaceProjector on_grid(triangulate_quads(result.grid.mesh));
        // The quads on P holding the misses beyond the bound, each once (the worst first).
        const Eigen::MatrixX4i& Q = result.grid.mesh.Q;
        std::vector<int> place_quads;
        std::vector<char> placed(Q.rows(), 0);
        for (size_t k = 0; k < at.points.size() && at.distances[k] > bound; ++k) {
          const int q = on_grid.closest(surface_position(polycube, at.points[k])).face / 2;
          if (!placed[q]) place_quads.push_back(q);
          placed[q] = 1;
        }
        std::vector<char> dropped(place_quads.size(), 0);
        // A pass from the places not dropped: their quads' corners marked, the worse half of them
        // again while that is over budget; false when nothing fits.
        QuadRemeshResult pass;
        std::vector<int> parents;
        QuadMiss next;
        std::pair<int, int> pass_bad;
        const auto attempt = [&]() {
          std::vector<int> taken;
          for (size_t k = 0; k < place_quads.size(); ++k)
            if (!dropped[k]) taken.push_back(place_quads[k]);
          pass = QuadRemeshResult{};
          for (size_t take = taken.size(); take > 0 && pass.grid.mesh.num_quads() == 0; take /= 2) {
            std::vector<char> marked(result.grid.mesh.num_vertices(), 0);
            for (size_t k = 0; k < take; ++k)
              for (int c = 0; c < 4; ++c) marked[Q(taken[k], c)] = 1;
            PolycubeGrid grid = refine_grid_by_templates(
                result.grid, std::move(marked), [&](const Eigen::Vector3d& x) { return locator.on_polycube(x); }, &parents);
            if (grid.mesh.num_quads() <= budget) pass.grid = std::move(grid);
          }
          if (pass.grid.mesh.num_quads() == 0) return false;
          run_pass(pass, true, &result, false);
          next = find_quad_misses(pass.grid, pass.mesh, model, locator, goal, pass.grid.cell_size, options.refine.threads);
          pass_bad = bad(pass);
          return true;
        };
        bool made = attempt();
        // More quads flipped (split quads bent round a crease or a fold of the quads, or quads next
        // to them moved by the relaxation): the places whose quads touch the quads the bad ones
        // come from are dropped, and the round made again.
        for (int again = 0; made && pass_bad.first > best_bad.first && again < 3; ++again) {
          std::vector<char> near(result.grid.mesh.num_vertices(), 0);
          for (int q : bad_quads(pass.mesh, model, options.quality))
            for (int c = 0; c < 4; ++c) near[Q(parents[q], c)] = 1;
          int newly = 0;
          for (size_t k = 0; k < place_quads.size(); ++k) {
            bool touches = false;
            for (int c = 0; c < 4; ++c) touches = touches || near[Q(place_quads[k], c)];
            if (touches && !dropped[k]) {
              dropped[k] = 1;
              ++newly;
            }
          }
          if (newly == 0) break;
          report("refine", "templates " + std::to_string(round + 1) + ": " + std::to_string(pass_bad.first) +
                               " flipped or degenerate quads; again without the " + std::to_string(newly) + " quads next to them");
          made = attempt();
        }
        if (!made) break;
        const bool better = pass_bad.first <= best_bad.first && next.farthest < result.refine_miss_after;
        report("refine", "templates " + std::to_string(round + 1) + ": " + std::to_string(pass.grid.mesh.num_quads()) +
                             " quads, misses by up to " + format("%.3f %%", 100 * next.farthest / diagonal) + ", " +
                             std::to_string(pass_bad.first) + " flipped or degenerate quads" + (better ? "" : ": not kept"));
        if (!better) break;
        take_pass(result, std::move(pass));
        result.refine_miss_after = next.farthest;
        result.template_rounds = round + 1;
        best_bad = pass_bad;
        at = next;
      }
    }
    result.seconds_refine = since(begin);
    report("refine", std::to_string(result.refine_rounds) + " rounds kept, " + std::to_string(result.grid.refined_parts) +
                         " chord parts halved, " + std::to_string(result.template_rounds) + " template rounds, " +
                         std::to_string(result.grid.mesh.num_quads()) + " quads, farthest miss " +
                         format("%.3f -> %.3f %% of the diagonal", 100 * result.refine_miss_before / diagonal,
                                100 * result.refine_miss_after / diagonal));
  }
  // Quads the last steps left flipped (a kept round's relaxation, pinned corners): untangled once
  // more with every vertex free, taken if that leaves fewer flipped or degenerate quads.
  if (options.untangle.passes > 0) {
    QuadQualityOptions topology_only = options.quality;
    topology_only.hausdorff = false;
    const std::vector<int> bad_before = bad_quads(result.mesh, model, topology_only);
    if (!bad_before.empty()) {
      const auto begin = std::chrono::steady_clock::now();
      QuadUntangleResult last = untangle_quads(result.mesh, model, options.untangle);
      const size_t bad_after = bad_quads(last.mesh, model, topology_only).size();
      if (bad_after < bad_before.size()) {
        report("untangle", "the result's " + std::to_string(bad_before.size()) + " flipped or degenerate quads -> " +
                               std::to_string(bad_after) + " with every vertex free (" + std::to_string(last.patches) +
                               " patches laid out again)");
        result.mesh = std::move(last.mesh);
        result.untangling.moves += last.moves;
        result.untangling.patches += last.patches;
        result.untangling.flipped_after = last.flipped_after;
      }
      if (bad_after > 0 && options.collapse_bad) {
        // Still bad: removed by diagonal collapses (irregular vertices off P's corners).
        const QuadCollapseResult collapsed =
            collapse_bad_quads(result.mesh, result.grid, result.fitting.pinned, model, topology_only, options.untangle);
        if (collapsed.collapsed > 0) {
          report("untangle", std::to_string(collapsed.bad_before) + " flipped or degenerate quads left -> " +
                                 std::to_string(collapsed.bad_after) + " by " + std::to_string(collapsed.collapsed) +
                                 " diagonal collapses (irregular vertices " +
                                 (collapsed.irregular_added >= 0 ? "+" : "") + std::to_string(collapsed.irregular_added) +
                                 ")");
          result.collapsed_quads += collapsed.collapsed;
        }
      }
      result.seconds_untangle += since(begin);
    }
  }
  if (options.mend_corners)
    mend_quad_corners(result, model, options, progress);  // measures too
  else if (options.measure)
    measure_result(result, model, options, report);
  return result;
}

}  // namespace polycube
