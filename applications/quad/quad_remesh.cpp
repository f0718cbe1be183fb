#include "applications/quad/quad_remesh.h"

#include <algorithm>
#include <chrono>
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
  QuadRemeshResult result;
  report("grid", "quad layout of the polycube's faces, chords split into near-squares");
  auto start = std::chrono::steady_clock::now();
  result.grid = build_polycube_grid(polycube, options.grid, options.size_on_model ? to_model : SurfaceMap());
  result.seconds_grid = since(start);
  const PolycubeGrid& grid = result.grid;
  report("grid", std::to_string(grid.mesh.num_quads()) + " quads, " + std::to_string(grid.corners.size()) + " corners, " +
                     std::to_string(grid.layout.num_quads()) + " layout cells (" + std::to_string(grid.free_loops) +
                     " free loops removed), cell size " + format("%.4g", grid.cell_size));

  report("carry", std::to_string(grid.mesh.num_vertices()) + " vertices through the map");
  start = std::chrono::steady_clock::now();
  result.mesh = carry_grid(grid, to_model, options.carry);
  result.seconds_carry = since(start);

  if (options.smooth.sweeps > 0) {
    report("smooth", "up to " + std::to_string(options.smooth.sweeps) + " relaxation sweeps towards right angles");
    start = std::chrono::steady_clock::now();
    result.smoothing = smooth_quads(result.mesh, model, options.smooth);
    result.mesh = result.smoothing.mesh;
    result.smoothing.mesh = QuadMesh{};  // one copy is enough
    result.seconds_smooth = since(start);
    report("smooth", std::to_string(result.smoothing.sweeps) + " sweeps" + (result.smoothing.converged ? " (converged), " : ", ") +
                         std::to_string(result.smoothing.moves) + " moves, " + std::to_string(result.smoothing.rejected) +
                         " refused (would flip a quad or leave the surface under the vertex)");
  }

  if (options.fit.passes > 0) {
    report("fit", "corners pulled onto the model's vertices the quads miss");
    start = std::chrono::steady_clock::now();
    result.fitting = fit_quads(result.mesh, model, options.fit);
    result.mesh = result.fitting.mesh;
    result.fitting.mesh = QuadMesh{};
    if (result.fitting.snapped > 0 && options.smooth.sweeps > 0 && options.refit_sweeps > 0) {
      QuadSmoothOptions again = options.smooth;
      again.sweeps = std::min(options.refit_sweeps, options.smooth.sweeps);
      result.refitting = smooth_quads(result.mesh, model, again, result.fitting.pinned);
      result.mesh = std::move(result.refitting.mesh);
      result.refitting.mesh = QuadMesh{};
    }
    result.seconds_fit = since(start);
    report("fit", std::to_string(result.fitting.snapped) + " corners pulled, farthest model vertex " +
                      format("%.4g -> %.4g from the quads", result.fitting.farthest_before, result.fitting.farthest_after));
  }

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
