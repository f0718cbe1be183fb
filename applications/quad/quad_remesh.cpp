#include "applications/quad/quad_remesh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

namespace polycube {

namespace {
double since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string format(const char* pattern, double a, double b = 0, double c = 0) {
  char text[160];
  std::snprintf(text, sizeof text, pattern, a, b, c);
  return text;
}
}  // namespace

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
  const auto run_pass = [&](QuadRemeshResult& pass, bool quiet) {
    const QuadSmoothOptions& smooth = options.smooth;
    const auto say = [&](const std::string& stage, const std::string& message) {
      if (!quiet) report(stage, message);
    };
    say("carry", std::to_string(pass.grid.mesh.num_vertices()) + " vertices through the map");
    auto begin = std::chrono::steady_clock::now();
    pass.mesh = carry_grid(pass.grid, to_model, options.carry);
    pass.seconds_carry += since(begin);
    if (options.smooth.sweeps > 0) {
      say("smooth", "up to " + std::to_string(options.smooth.sweeps) + " relaxation sweeps towards right angles");
      begin = std::chrono::steady_clock::now();
      pass.smoothing = smooth_quads(pass.mesh, model, smooth);
      pass.mesh = std::move(pass.smoothing.mesh);
      pass.smoothing.mesh = QuadMesh{};  // one copy is enough
      pass.seconds_smooth += since(begin);
      say("smooth", std::to_string(pass.smoothing.sweeps) + " sweeps" + (pass.smoothing.converged ? " (converged), " : ", ") +
                        std::to_string(pass.smoothing.moves) + " moves, " + std::to_string(pass.smoothing.rejected) +
                        " refused (would flip a quad or leave the surface under the vertex)");
    }
    if (options.fit.passes > 0) {
      say("fit", "corners pulled onto the model's vertices the quads miss");
      begin = std::chrono::steady_clock::now();
      pass.fitting = fit_quads(pass.mesh, model, options.fit);
      pass.mesh = std::move(pass.fitting.mesh);
      pass.fitting.mesh = QuadMesh{};
      if (pass.fitting.snapped > 0 && options.smooth.sweeps > 0 && options.refit_sweeps > 0) {
        QuadSmoothOptions again = smooth;
        again.sweeps = std::min(options.refit_sweeps, smooth.sweeps);
        pass.refitting = smooth_quads(pass.mesh, model, again, pass.fitting.pinned);
        pass.mesh = std::move(pass.refitting.mesh);
        pass.refitting.mesh = QuadMesh{};
      }
      pass.seconds_fit += since(begin);
      say("fit", std::to_string(pass.fitting.snapped) + " corners pulled, farthest model vertex " +
                     format("%.4g -> %.4g from the quads", pass.fitting.farthest_before, pass.fitting.farthest_after));
    }
  };
  run_pass(result, false);

  // Refinement: where the finished quads miss the model, the grid's chords there get their parts
  // halved and the pass runs again; a round is kept when it misses less and flips nothing more.
  if (options.refine.rounds > 0) {
    const auto begin = std::chrono::steady_clock::now();
    const double diagonal = bounding_box(model.surface().V).diagonal();
    const double goal = options.refine.target_percent / 100 * diagonal;
    const PreimageLocator locator(polycube, to_model, options.refine.threads);
    PolycubeGridOptions grid_options = options.grid;
    grid_options.refine_max_quads = static_cast<long long>(options.refine.max_growth * result.grid.mesh.num_quads());
    QuadQualityOptions topology_only = options.quality;
    topology_only.hausdorff = false;
    const auto bad = [&](const QuadRemeshResult& r) {
      const QuadQuality q = measure_quads(r.mesh, model, r.grid.corners, topology_only);
      return std::make_pair(q.flipped_quads + q.degenerate_quads, q.inverted_corners);
    };
    auto best_bad = bad(result);
    QuadMiss miss = find_quad_misses(result.grid, result.mesh, model, locator, goal, result.grid.cell_size, options.refine.threads);
    result.refine_miss_before = result.refine_miss_after = miss.farthest;
    report("refine", "the quads miss the model by up to " +
                         format("%.3f %%", 100 * miss.farthest / diagonal) + " of the diagonal at " + std::to_string(miss.points.size()) +
                         " places beyond " + format("%.3g %%", options.refine.target_percent));
    for (int round = 0; round < options.refine.rounds && !miss.points.empty(); ++round) {
      // The round's places: the worst misses, as many as the budget allows.
      grid_options.refine_rounds.emplace_back();
      // A miss d times the goal halves its parts about log4(d) times at once (at most 3): a tip
      // far out needs many lines through its small preimage.
      for (size_t k = 0; k < miss.points.size() && miss.distances[k] >= options.refine.worst_fraction * miss.farthest; ++k) {
        const int halvings = std::clamp(static_cast<int>(std::lround(std::log2(miss.distances[k] / goal) / 2)), 1, 3);
        grid_options.refine_rounds.back().push_back({miss.points[k], halvings});
      }
      QuadRemeshResult pass;
      pass.grid = build_polycube_grid(polycube, grid_options, size_map);
      if (pass.grid.refined_parts == result.grid.refined_parts) {  // the budget is spent
        grid_options.refine_rounds.pop_back();
        break;
      }
      run_pass(pass, true);
      const QuadMiss next = find_quad_misses(pass.grid, pass.mesh, model, locator, goal, pass.grid.cell_size, options.refine.threads);
      const auto pass_bad = bad(pass);
      report("refine", "round " + std::to_string(round + 1) + ": " + std::to_string(pass.grid.refined_parts) +
                           " chord parts halved, " + std::to_string(pass.grid.mesh.num_quads()) + " quads, misses by up to " +
                           format("%.3f %%", 100 * next.farthest / diagonal) + ", " + std::to_string(pass_bad.first) +
                           " flipped or degenerate quads, " + std::to_string(pass_bad.second) + " inverted corners (were " +
                           std::to_string(best_bad.first) + ", " + std::to_string(best_bad.second) + ")");
      if (next.farthest >= miss.farthest || pass_bad.first > best_bad.first) {
        grid_options.refine_rounds.pop_back();  // not better: this round's places are not refined again
        break;
      }
      // The round's quads are kept; the stage times stay the first pass's (the refinement's,
      // its passes included, is apart).
      result.grid = std::move(pass.grid);
      result.mesh = std::move(pass.mesh);
      result.smoothing = std::move(pass.smoothing);
      result.fitting = std::move(pass.fitting);
      result.refitting = std::move(pass.refitting);
      result.refine_miss_after = next.farthest;
      result.refine_rounds = round + 1;
      best_bad = pass_bad;
      miss = next;
    }
    result.seconds_refine = since(begin);
    report("refine", std::to_string(result.refine_rounds) + " rounds kept, " + std::to_string(result.grid.refined_parts) +
                         " chord parts halved, " + std::to_string(result.grid.mesh.num_quads()) + " quads, farthest miss " +
                         format("%.3f -> %.3f %% of the diagonal", 100 * result.refine_miss_before / diagonal,
                                100 * result.refine_miss_after / diagonal));
  }
  const PolycubeGrid& grid = result.grid;

  if (options.measure) {
    report("quality", options.quality.hausdorff ? "angles, flips, Hausdorff distance" : "angles, flips");
    start = std::chrono::steady_clock::now();
    result.quality = measure_quads(result.mesh, model, grid.corners, options.quality);
    result.seconds_quality = since(start);
    const QuadQuality& q = result.quality;
    std::string message = std::to_string(q.quads) + " quads, " + std::to_string(q.irregular_vertices) + " irregular (" +
                          std::to_string(q.irregular_at_corners) + " at polycube corners), angle deviation " +
                          format("%.2f / %.2f / %.1f deg (mean / p95 / max)", q.angle_deviation_mean, q.angle_deviation_p95,
                                 q.angle_deviation_max) +
                          ", " + std::to_string(q.flipped_quads) + " flipped, " + std::to_string(q.degenerate_quads) +
                          " degenerate";
    if (q.hausdorff_measured) message += format(", Hausdorff %.3f %% of the diagonal", q.hausdorff_percent);
    report("quality", message);
  }
  return result;
}

}  // namespace polycube
