#include "polycube/align.h"

#include "polycube/errors.h"
#include "polycube/map_audit.h"
#include "polycube/parallel.h"
#include "polycube/quadtree_raster.h"
#include "polycube/simplify.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <numeric>
#include <tuple>

namespace polycube {

namespace {

// Axes within 5 degrees of the coordinate axes are the coordinate axes: a model already aligned
// (up to noise) must not be tilted by a hair, which would put its flat faces almost on planes.
Eigen::Matrix3d snapped_to_coordinate_axes(const Eigen::Matrix3d& axes) {
  Eigen::Matrix3d snapped = Eigen::Matrix3d::Zero();
  bool near = true;
  for (int i = 0; i < 3 && near; ++i) {
    Eigen::Index k;
    const double c = axes.row(i).cwiseAbs().maxCoeff(&k);
    near = c > std::cos(5.0 * 3.14159265358979 / 180);
    snapped(i, k) = axes(i, k) > 0 ? 1 : -1;
  }
  if (near && std::abs(snapped.determinant() - 1) < 1e-12) return snapped;
  return axes;
}

// principal_axes, with the variances along the returned rows (when asked).
Eigen::Matrix3d principal_axes(const TriMesh& mesh, double* spread, Eigen::Vector3d* variances) {
  // Second moments of the surface, each triangle integrated exactly (vertices and centroid rule).
  double area_sum = 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const double area = 0.5 * (b - a).cross(c - a).norm();
    area_sum += area;
    mean += area * (a + b + c) / 3;
    // ∫ x x^T over a triangle = A/12 (sum x_i x_i^T + (sum x_i)(sum x_i)^T)
    const Eigen::Vector3d s = a + b + c;
    second += area / 12 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  if (spread) *spread = 1;
  if (variances) variances->setZero();
  if (!(area_sum > 0)) return Eigen::Matrix3d::Identity();
  mean /= area_sum;
  const Eigen::Matrix3d covariance = second / area_sum - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  if (spread && solver.eigenvalues()(0) > 0) *spread = solver.eigenvalues()(2) / solver.eigenvalues()(0);
  Eigen::Matrix3d axes;
  for (int i = 0; i < 3; ++i) axes.row(i) = solver.eigenvectors().col(2 - i).transpose();  // largest first
  if (axes.determinant() < 0) axes.row(2) *= -1;
  axes = snapped_to_coordinate_axes(axes);
  if (variances)
    for (int i = 0; i < 3; ++i) (*variances)(i) = axes.row(i) * covariance * axes.row(i).transpose();
  return axes;
}

}  // namespace

Eigen::Matrix3d principal_axes(const TriMesh& mesh, double* spread) { return principal_axes(mesh, spread, nullptr); }

std::optional<EqualisedCopy> equalised_copy(const TriMesh& model, const EqualisedCopyOptions& options) {
  EqualisedCopy out;
  Eigen::Vector3d variances;
  out.axes = principal_axes(model, nullptr, &variances);
  const Eigen::Vector3d& sigma = out.deviations = variances.cwiseMax(0).cwiseSqrt();
  if (!(sigma(0) > options.long_ratio * sigma(1)) || !(sigma.minCoeff() > 0) || !(sigma.maxCoeff() > options.max_ratio * sigma.minCoeff()))
    return std::nullopt;
  const double mean = std::cbrt(sigma.prod()), band = std::sqrt(options.max_ratio);
  for (int i = 0; i < 3; ++i) out.scales(i) = std::clamp(sigma(i), mean / band, mean * band) / sigma(i);
  out.scales /= std::cbrt(out.scales.prod());
  out.copy = rotated(model, out.scales.asDiagonal() * out.axes);
  return out;
}

Polycube unscaled_polycube(const Polycube& P, const Eigen::Vector3d& scales) {
  Polycube out = P;
  const Eigen::Vector3d inverse = scales.cwiseInverse();
  out.mesh.V = P.mesh.V * inverse.asDiagonal();
  for (PolycubeFace& f : out.faces) {
    f.coordinate *= inverse(f.axis);
    f.area *= inverse((f.axis + 1) % 3) * inverse((f.axis + 2) % 3);
  }
  for (std::vector<SectionPolygon>& plane : out.sections)
    for (SectionPolygon& polygon : plane)
      for (Eigen::Vector2d& q : polygon.points) q = q.cwiseProduct(inverse.head<2>());
  for (double& z : out.levels) z *= inverse(2);
  out.spacing = 0;
  for (const PolycubeEdge& e : out.edges)
    for (size_t k = 0; k + 1 < e.vertices.size(); ++k)
      out.spacing = std::max(out.spacing, (out.mesh.V.row(e.vertices[k + 1]) - out.mesh.V.row(e.vertices[k])).norm());
  return out;
}

PolycubeMap unscaled_samples(const PolycubeMap& map, const Eigen::Vector3d& scales) {
  PolycubeMap out;
  out.polycube_on_model = map.polycube_on_model;
  out.model_on_polycube = map.model_on_polycube;
  out.polycube_on_model_xyz = map.polycube_on_model_xyz * scales.cwiseInverse().asDiagonal();
  out.model_on_polycube_xyz = map.model_on_polycube_xyz * scales.cwiseInverse().asDiagonal();
  out.pieces = map.pieces;
  out.contours = map.contours;
  out.seconds = map.seconds;
  return out;
}

Eigen::Matrix3d normal_axes(const TriMesh& mesh, int max_faces, double* misalignment) {
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> areas;
  const int nf = mesh.num_faces();
  const int stride = std::max(1, (nf + std::max(1, max_faces) - 1) / std::max(1, max_faces));
  for (int f = 0; f < nf; f += stride) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double length = n.norm();
    if (!(length > 0)) continue;
    normals.push_back(n / length);
    areas.push_back(length / 2);
  }
  if (misalignment) *misalignment = 0;
  if (normals.empty()) return Eigen::Matrix3d::Identity();
  // Σ area (x²y² + y²z² + z²x²) of the normals in the frame whose axes are the rows of R.
  auto energy = [&](const Eigen::Matrix3d& R) {
    double e = 0;
    for (size_t i = 0; i < normals.size(); ++i) {
      const Eigen::Vector3d m = R * normals[i];
      const Eigen::Vector3d q = m.cwiseProduct(m);
      e += areas[i] * (q.x() * q.y() + q.y() * q.z() + q.z() * q.x());
    }
    return e;
  };
  // Start rotations: the identity and 999 more spread over SO(3) (Halton points through
  // Shoemake's uniform quaternions), deterministic.
  auto halton = [](int i, int base) {
    double f = 1, r = 0;
    for (; i > 0; i /= base) {
      f /= base;
      r += f * (i % base);
    }
    return r;
  };
  constexpr double kTwoPi = 6.28318530717958647692;
  std::vector<std::pair<double, Eigen::Matrix3d>> starts;
  starts.emplace_back(energy(Eigen::Matrix3d::Identity()), Eigen::Matrix3d::Identity());
  for (int i = 1; i < 1000; ++i) {
    const double u1 = halton(i, 2), u2 = halton(i, 3), u3 = halton(i, 5);
    const Eigen::Quaterniond q(std::sqrt(u1) * std::cos(kTwoPi * u3), std::sqrt(1 - u1) * std::sin(kTwoPi * u2),
                               std::sqrt(1 - u1) * std::cos(kTwoPi * u2), std::sqrt(u1) * std::sin(kTwoPi * u3));
    const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
    starts.emplace_back(energy(R), R);
  }
  std::sort(starts.begin(), starts.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  // The best few refined by small turns about the axes, halving the angle when none helps.
  Eigen::Matrix3d best = starts.front().second;
  double best_energy = starts.front().first;
  for (size_t k = 0; k < std::min<size_t>(4, starts.size()); ++k) {
    Eigen::Matrix3d R = starts[k].second;
    double e = starts[k].first;
    for (double step = 5 * kTwoPi / 360; step > 1e-4;) {
      bool improved = false;
      for (int axis = 0; axis < 3; ++axis)
        for (const double sign : {1.0, -1.0}) {
          const Eigen::Matrix3d turned = Eigen::AngleAxisd(sign * step, Eigen::Vector3d::Unit(axis)).toRotationMatrix() * R;
          const double et = energy(turned);
          if (et < e) {
            R = turned;
            e = et;
            improved = true;
          }
        }
      if (!improved) step /= 2;
    }
    if (e < best_energy) {
      best_energy = e;
      best = R;
    }
  }
  if (misalignment) *misalignment = best_energy / std::accumulate(areas.begin(), areas.end(), 0.0);
  // Of the cube's 24 equivalent frames, the one closest to the input's (largest trace).
  Eigen::Matrix3d chosen = best;
  double chosen_trace = -INFINITY;
  const int permutations[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  for (const auto& p : permutations)
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d candidate;
      for (int i = 0; i < 3; ++i) candidate.row(i) = (signs >> i & 1 ? -1.0 : 1.0) * best.row(p[i]);
      if (candidate.determinant() < 0) continue;
      if (candidate.trace() > chosen_trace) {
        chosen_trace = candidate.trace();
        chosen = candidate;
      }
    }
  return snapped_to_coordinate_axes(chosen);
}

bool same_axes(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b, double degrees) {
  const Eigen::Matrix3d m = a * b.transpose();
  const double c = std::cos(degrees * 3.14159265358979 / 180);
  for (int i = 0; i < 3; ++i)
    if (m.row(i).cwiseAbs().maxCoeff() < c) return false;
  return true;
}

TriMesh rotated(const TriMesh& mesh, const Eigen::Matrix3d& rotation) {
  TriMesh out = mesh;
  out.V = mesh.V * rotation.transpose();
  return out;
}

std::vector<AlignedStages> Alignment::stages_in_order() const {
  std::vector<AlignedStages> out;
  if (chosen < 0) return {AlignedStages{}};
  out.push_back({chosen, rotation, topology, polycube, map});
  out.insert(out.end(), alternatives.begin(), alternatives.end());
  return out;
}

Alignment choose_alignment(const TriMesh& mesh, const TopologyOptions& topology, const PolycubeOptions& polycube,
                           const AlignmentOptions& options) {
  Alignment out;
  static const char* const kStopped = "not built: the search was stopped";
  // True once the caller's stop says so (and from then on: one answer for the whole search).
  std::atomic<bool> stopped{false};
  const auto stopping = [&]() {
    if (!stopped && options.stop && options.stop()) stopped = true;
    return stopped.load();
  };
  // The search given up: nothing chosen, nothing built kept.
  const auto given_up = [&]() {
    Alignment none;
    none.candidates = std::move(out.candidates);
    none.proxy_faces = out.proxy_faces;
    none.stopped = true;
    return none;
  };
  // A scaled copy's axes, as each candidate turns them (AlignmentOptions::axis_scales).
  const auto turned_topology = [&](const Eigen::Matrix3d& rotation) {
    TopologyOptions turned = topology;
    // (Only the input frame's axes, permuted, are candidates then.)
    if (options.axis_scales != Eigen::Vector3d::Ones()) turned.length_scales = rotation.cwiseAbs() * options.axis_scales;  // as EqualisedCopy::turned_scales
    return turned;
  };
  double spread = 1;
  const Eigen::Matrix3d pca = principal_axes(mesh, &spread);
  const bool reserve_principal = !options.input_frame_only && !(spread >= options.principal_axes_spread);
  // A large model is scored on a coarser copy (same topology); the winner's stages are then built
  // on the model itself.
  TriMesh proxy;
  const bool use_proxy = options.proxy_above > 0 && mesh.num_faces() > options.proxy_above;
  if (use_proxy) {
    proxy = simplified_mesh(mesh, options.proxy_faces);
    out.proxy_faces = proxy.num_faces();
  }
  const TriMesh& scored = use_proxy ? proxy : mesh;
  // Cyclic permutations keep the handedness: which frame axis becomes z.
  const Eigen::Matrix3d cycles[3] = {Eigen::Matrix3d::Identity(),
                                     (Eigen::Matrix3d() << 0, 1, 0, 0, 0, 1, 1, 0, 0).finished(),
                                     (Eigen::Matrix3d() << 0, 0, 1, 1, 0, 0, 0, 1, 0).finished()};
  const char* input_names[3] = {"input frame, z up", "input frame, x up", "input frame, y up"};
  const char* principal_names[3] = {"principal axes, least-spread axis up", "principal axes, longest axis up",
                                    "principal axes, middle axis up"};
  const char* normal_names[3] = {"normal axes, z up", "normal axes, x up", "normal axes, y up"};
  // The normals' frame when the faces align with it markedly (misalignment below 0.12: CAD parts
  // 0.06–0.11 on the shipped meshes, organic ones 0.13–0.20, 0.2 for normals spread evenly), and
  // otherwise in reserve: tried only when no other candidate passes the scoring budget. Never when
  // it is one of the others (a CAD part in its own frame, or a box, already has it).
  double misalignment = 0;
  const Eigen::Matrix3d normals =
      options.input_frame_only ? Eigen::Matrix3d::Identity() : normal_axes(mesh, 20000, &misalignment);
  const bool distinct_normals =
      !options.input_frame_only && !same_axes(normals, Eigen::Matrix3d::Identity()) && !same_axes(normals, pca);
  const bool reserve_normals = distinct_normals && !(misalignment < options.normal_axes_misalignment);
  // A frame's candidates, less any whose rotation is exactly one already there: principal axes
  // snapped to the coordinate axes can be a cyclic permutation of them, and then a candidate is
  // an earlier one again, with the same stages and map, filling one of the few mapped and
  // alternative places (Cura's printer plate twotrees235x235_generic.stl: four of its ten
  // candidates, and two of the map's retries, repeated the input frame's). Turned by 180° about
  // an axis (other signs) is another sampling of the same orientation, not the same stages: kept.
  auto add_frame = [&](int frame) {
    for (int k = 0; k < 3; ++k) {
      AlignmentCandidate c;
      c.name = frame == 0 ? (options.input_frame_is_principal ? principal_names[k] : input_names[k])
                          : frame == 1 ? principal_names[k] : normal_names[k];
      c.rotation = cycles[k] * (frame == 0 ? Eigen::Matrix3d::Identity() : frame == 1 ? pca : normals);
      const bool repeated = std::any_of(out.candidates.begin(), out.candidates.end(),
                                        [&](const AlignmentCandidate& earlier) { return earlier.rotation == c.rotation; });
      if (!repeated) out.candidates.push_back(c);
    }
  };
  add_frame(0);
  if (!reserve_principal && !options.input_frame_only) add_frame(1);
  if (distinct_normals && !reserve_normals) add_frame(2);
  PolycubeOptions scoring = polycube;
  scoring.max_rounds = std::min(scoring.max_rounds, options.max_rounds);
  scoring.max_inserted_planes = std::min(scoring.max_inserted_planes, options.max_inserted_planes);
  scoring.max_plane_cells = std::min(scoring.max_plane_cells, options.max_plane_cells);
  scoring.max_repair_level = std::min(scoring.max_repair_level, options.max_repair_level);
  // The smaller positive limit of the caller's and the scoring's (0: none).
  const auto cap = [](double caller, double budget) {
    return caller > 0 && budget > 0 ? std::min(caller, budget) : std::max(caller, budget);
  };
  scoring.max_rasterized_cells = cap(polycube.max_rasterized_cells, options.max_rasterized_cells);
  // One factorised Laplacian for every candidate's harmonic function (they are turned copies of
  // one mesh); a mesh it cannot be built for fails in each candidate as before.
  std::unique_ptr<HarmonicSolver> harmonic;
  try {
    harmonic = std::make_unique<HarmonicSolver>(scored, topology.harmonic);
  } catch (const Error&) {
  }
  std::vector<std::shared_ptr<TopologyResult>> topologies;
  std::vector<std::shared_ptr<PolycubeResult>> polycubes;
  std::vector<TriMesh> turned;
  // Candidate i's stages that are missing (turned copy, topology), then its polycube under
  // `budget`; a failure is recorded in the candidate (polycubes[i] null).
  auto build = [&](int i, const PolycubeOptions& budget) {
    AlignmentCandidate& c = out.candidates[i];
    if (stopping()) {
      c.error = kStopped;
      return;
    }
    const auto start = std::chrono::steady_clock::now();
    const long long work = rasterized_cells();
    try {
      if (turned[i].num_faces() == 0) turned[i] = rotated(scored, c.rotation);
      if (!topologies[i])
        topologies[i] = std::make_shared<TopologyResult>(analyse_topology(turned[i], turned_topology(c.rotation), harmonic.get()));
      polycubes[i] = std::make_shared<PolycubeResult>(build_polycube(turned[i], *topologies[i], budget));
      c.corners = static_cast<int>(polycubes[i]->polycube.corners.size());
      c.failing_slabs = 0;
    } catch (const RepairRoundsExhausted& e) {
      c.error = e.what();
      c.failing_slabs = e.failing_slabs;
      polycubes[i].reset();
    } catch (const Error& e) {
      c.error = e.what();
      c.failing_slabs = 0;
      polycubes[i].reset();
    }
    c.rasterized_cells = rasterized_cells() - work;
    c.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  // Runs `step` on the candidates [first, end) (those just added), in parallel; returns end.
  auto run_added = [&](int first, const std::function<void(int)>& step) {
    const int end = static_cast<int>(out.candidates.size());
    topologies.resize(end);
    polycubes.resize(end);
    turned.resize(end);
    std::vector<int> order(end - first);
    std::iota(order.begin(), order.end(), first);
    parallel_for_each(order, options.threads, "orientation", step);
    return end;
  };
  // Topology and polycube, under the scoring budget, of candidates [first, end).
  auto score = [&](int first) { run_added(first, [&](int i) { build(i, scoring); }); };
  // Four times the scoring budget (capped by the caller's), for candidates given a second chance.
  PolycubeOptions larger = polycube;
  larger.max_rounds = std::min(polycube.max_rounds, 4 * scoring.max_rounds);
  larger.max_inserted_planes = std::min(polycube.max_inserted_planes, 4 * scoring.max_inserted_planes);
  larger.max_plane_cells = std::min(polycube.max_plane_cells, 4 * scoring.max_plane_cells);
  larger.max_repair_level = std::min(polycube.max_repair_level, scoring.max_repair_level + 3);
  larger.max_rasterized_cells = cap(polycube.max_rasterized_cells, options.max_fallback_rasterized_cells);
  auto build_fallback = [&](int i, const PolycubeOptions& budget) {
    out.candidates[i].error.clear();
    build(i, budget);
    out.candidates[i].fallback_budget = polycubes[i] != nullptr;
  };
  score(0);
  auto any_passed = [&]() { return std::any_of(polycubes.begin(), polycubes.end(), [](const auto& p) { return p != nullptr; }); };
  // The normals' frame in reserve (the faces do not align with it), when no candidate passed.
  if (!any_passed() && reserve_normals) {
    const int first = static_cast<int>(out.candidates.size());
    add_frame(2);
    score(first);
  }
  int n = static_cast<int>(out.candidates.size());
  int first_finer = n;  // candidates from here on are finer-P variants
  // The few with the fewest corners get their map built and audited (vertex-sampled flips both
  // ways, ε_angle): corners alone do not tell a good map from a bad one.
  std::vector<int> mapped;
  for (int i = 0; i < n; ++i)
    if (polycubes[i]) mapped.push_back(i);
  std::stable_sort(mapped.begin(), mapped.end(), [&](int a, int b) { return out.candidates[a].corners < out.candidates[b].corners; });
  std::vector<std::shared_ptr<PolycubeMap>> maps(n);
  auto map_candidates = [&](const std::vector<int>& which) {
    parallel_for_each(which, options.threads, "orientation", [&](int i) {
      AlignmentCandidate& c = out.candidates[i];
      if (stopping()) return;
      const auto start = std::chrono::steady_clock::now();
      try {
        maps[i] = std::make_shared<PolycubeMap>(build_polycube_map(turned[i], *polycubes[i]));
        const MapAudit audit = audit_map(turned[i], polycubes[i]->polycube.mesh, maps[i]->polycube_on_model_xyz, maps[i]->model_on_polycube_xyz);
        c.flipped = audit.polycube_to_model.flipped + audit.model_to_polycube.flipped + audit.polycube_to_model.degenerate +
                    audit.model_to_polycube.degenerate;
        c.eps_angle = audit.distortion.eps_angle;
        c.eps_area = audit.distortion.eps_area;
      } catch (const Error& e) {
        c.error = e.what();
        maps[i].reset();
      }
      c.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    });
  };
  if (options.mapped_candidates > 0) {
    const size_t first = std::min(mapped.size(), static_cast<size_t>(options.mapped_candidates));
    map_candidates(std::vector<int>(mapped.begin(), mapped.begin() + first));
    // Some map built so far without a flipped triangle?
    auto any_clean = [&]() {
      for (size_t i = 0; i < maps.size(); ++i)
        if (maps[i] && out.candidates[i].flipped == 0) return true;
      return false;
    };
    // Still flips in every map tried: the others get their map too.
    if (!any_clean() && first < mapped.size()) map_candidates(std::vector<int>(mapped.begin() + first, mapped.end()));
    // Still flips in every map: the near misses — candidates whose repair rounds ran out with at
    // most near_miss_slabs slabs still failing — get four times the scoring budget and are mapped
    // when they build. The repairs of one orientation can need a few rounds more for a turned copy
    // of the same mesh (cow turned: its principal axes failed by one non-manifold vertex after 12
    // rounds, and only the normals' frame, 167 / 66 flips, was left to map; in its own frame they
    // build, 641 corners, 2 / 9). Other failures are not retried: with four times the budget, one
    // of the same cow's (8 slabs failing) took 118 s to fail again.
    if (!any_clean() && !mapped.empty() && options.near_miss_slabs > 0) {
      std::vector<int> failed;
      for (int i = 0; i < n; ++i)
        if (!polycubes[i] && out.candidates[i].failing_slabs > 0 && out.candidates[i].failing_slabs <= options.near_miss_slabs)
          failed.push_back(i);
      parallel_for_each(failed, options.threads, "orientation", [&](int i) { build_fallback(i, larger); });
      std::vector<int> built;
      for (int i : failed)
        if (polycubes[i]) built.push_back(i);
      map_candidates(built);
    }
  }
  // A model with few vertices: the mapped candidates once more with a finer P (the same topology
  // and polycube, triangulated with at least fine_polycube_vertices vertices), as further
  // candidates. The map's harmonic maps live on P's triangulation; P as fine as a coarse model is
  // often too coarse for a smooth map, but not always worse (bench/map.md), so both compete.
  if (options.fine_polycube_vertices > 0 && polycube.target_vertices == 0 && !use_proxy &&
      scored.num_vertices() < options.coarse_below && options.fine_polycube_vertices > scored.num_vertices()) {
    PolycubeOptions finer = scoring;
    finer.min_vertices = std::max(polycube.min_vertices, options.fine_polycube_vertices);
    std::vector<int> variants;
    first_finer = n;
    for (int i = 0; i < n; ++i) {
      if (!maps[i]) continue;
      AlignmentCandidate c = out.candidates[i];
      c.name += ", finer P";
      c.flipped = -1;
      c.eps_angle = -1;
      c.eps_area = -1;
      c.seconds = 0;
      c.error.clear();
      variants.push_back(static_cast<int>(out.candidates.size()));
      out.candidates.push_back(c);
      topologies.push_back(topologies[i]);
      turned.push_back(turned[i]);
      polycubes.push_back(nullptr);
      maps.push_back(nullptr);
    }
    PolycubeOptions finer_larger = larger;
    finer_larger.min_vertices = finer.min_vertices;
    parallel_for_each(variants, options.threads, "orientation",
                      [&](int j) { out.candidates[j].fallback_budget ? build_fallback(j, finer_larger) : build(j, finer); });
    std::vector<int> built;
    for (int j : variants)
      if (polycubes[j]) built.push_back(j);
    map_candidates(built);
    for (int j : variants)
      if (!maps[j]) polycubes[j].reset();  // a variant competes only with its map
    n = static_cast<int>(out.candidates.size());
  }
  if (stopping()) return given_up();
  // Fewest flips, then least ε_angle, then fewest corners, then the earlier candidate.
  auto key = [&](int i) {
    const AlignmentCandidate& c = out.candidates[i];
    return std::make_tuple(maps[i] ? 0 : 1, maps[i] ? c.flipped : 0, maps[i] ? c.eps_angle : 0.0, c.corners, i);
  };
  for (int i = 0; i < n; ++i) {
    if (!polycubes[i]) continue;
    if (out.chosen < 0 || key(i) < key(out.chosen)) out.chosen = i;
  }
  if (out.chosen < 0 && options.full_budget_fallback) {
    // Nothing passed the scoring budget: four times that budget for every candidate at once (the
    // one with the fewest corners wins), then the caller's full budget candidate by candidate, the
    // first that builds. (The full budget alone can take minutes per candidate that fails.)
    std::vector<int> all(n);
    std::iota(all.begin(), all.end(), 0);
    parallel_for_each(all, options.threads, "orientation", [&](int i) { build_fallback(i, larger); });
    if (!any_passed() && reserve_principal) {
      // The principal axes in reserve (the variances hardly differ), only now: they are any axes,
      // and a turned box is slow to fail (cheese: 481, 701 and 306 s under the scoring budget,
      // where its own frame passed four times that budget in 11 s).
      const int first = n;
      add_frame(1);
      n = run_added(first, [&](int i) { build_fallback(i, larger); });
      maps.resize(n);
    }
    for (int i = 0; i < n; ++i)
      if (polycubes[i] && (out.chosen < 0 || out.candidates[i].corners < out.candidates[out.chosen].corners)) out.chosen = i;
    for (int i = 0; i < n && out.chosen < 0; ++i) {
      build_fallback(i, polycube);
      if (polycubes[i]) out.chosen = i;
    }
  }
  if (stopping()) return given_up();
  if (out.chosen >= 0 && use_proxy) {
    // Scored on the coarse copy: the stages of the model itself, in the order of the scoring (the
    // fallback's choice first), with the caller's budget; the first orientation that builds wins.
    std::vector<int> ranked;
    for (int i = 0; i < n; ++i)
      if (polycubes[i] && i != out.chosen) ranked.push_back(i);
    std::stable_sort(ranked.begin(), ranked.end(), [&](int a, int b) { return key(a) < key(b); });
    ranked.insert(ranked.begin(), out.chosen);
    out.chosen = -1;
    for (int i : ranked) {
      if (stopping()) return given_up();
      AlignmentCandidate& c = out.candidates[i];
      const auto start = std::chrono::steady_clock::now();
      try {
        const TriMesh full = rotated(mesh, c.rotation);
        auto full_topology = std::make_shared<TopologyResult>(analyse_topology(full, turned_topology(c.rotation)));
        auto full_polycube = std::make_shared<PolycubeResult>(build_polycube(full, *full_topology, polycube));
        out.topology = std::move(full_topology);
        out.polycube = std::move(full_polycube);
        out.chosen = i;
      } catch (const Error& e) {
        c.error = std::string("on the model itself: ") + e.what();
      }
      c.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (out.chosen >= 0) break;
    }
  } else if (out.chosen >= 0) {
    out.topology = topologies[out.chosen];
    out.polycube = polycubes[out.chosen];
    out.map = maps[out.chosen];
    // The next best mapped candidates, the best of the winner's other P density first.
    std::vector<int> others;
    for (int i = 0; i < n; ++i)
      if (i != out.chosen && maps[i] && polycubes[i]) others.push_back(i);
    std::stable_sort(others.begin(), others.end(), [&](int a, int b) { return key(a) < key(b); });
    const bool chosen_finer = out.chosen >= first_finer;
    const auto twin = std::find_if(others.begin(), others.end(), [&](int i) { return (i >= first_finer) != chosen_finer; });
    if (twin != others.end()) std::rotate(others.begin(), twin, twin + 1);
    for (int i : others) {
      if (static_cast<int>(out.alternatives.size()) < options.alternatives)
        out.alternatives.push_back({i, out.candidates[i].rotation, topologies[i], polycubes[i], maps[i]});
      else
        out.reserve.push_back({i, out.candidates[i].rotation, topologies[i], polycubes[i], nullptr});
    }
    // Then those built but not mapped (the search found a clean map among the first), fewest
    // corners first.
    std::vector<int> unmapped;
    for (int i = 0; i < n; ++i)
      if (i != out.chosen && !maps[i] && polycubes[i] && out.candidates[i].error.empty()) unmapped.push_back(i);  // (not a failed map)
    std::stable_sort(unmapped.begin(), unmapped.end(), [&](int a, int b) { return key(a) < key(b); });
    for (int i : unmapped) out.reserve.push_back({i, out.candidates[i].rotation, topologies[i], polycubes[i], nullptr});
  }
  if (out.chosen >= 0) out.rotation = out.candidates[out.chosen].rotation;
  return out;
}

bool same_stages(const AlignedStages& a, const AlignedStages& b) {
  return a.polycube && b.polycube && a.rotation == b.rotation && same_polycube(*a.polycube, *b.polycube);
}

}  // namespace polycube
