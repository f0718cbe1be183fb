#include "polycube/align.h"

#include "polycube/errors.h"
#include "polycube/map_audit.h"
#include "polycube/parallel.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <tuple>
#include <numeric>

namespace polycube {

Eigen::Matrix3d principal_axes(const TriMesh& mesh) {
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
  if (!(area_sum > 0)) return Eigen::Matrix3d::Identity();
  mean /= area_sum;
  const Eigen::Matrix3d covariance = second / area_sum - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  Eigen::Matrix3d axes;
  for (int i = 0; i < 3; ++i) axes.row(i) = solver.eigenvectors().col(2 - i).transpose();  // largest first
  if (axes.determinant() < 0) axes.row(2) *= -1;
  // Axes within 5 degrees of the coordinate axes are the coordinate axes: a model already aligned
  // (up to noise) must not be tilted by a hair, which would put its flat faces almost on planes.
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

TriMesh rotated(const TriMesh& mesh, const Eigen::Matrix3d& rotation) {
  TriMesh out = mesh;
  out.V = mesh.V * rotation.transpose();
  return out;
}

Alignment choose_alignment(const TriMesh& mesh, const TopologyOptions& topology, const PolycubeOptions& polycube,
                           const AlignmentOptions& options) {
  Alignment out;
  const Eigen::Matrix3d pca = principal_axes(mesh);
  // Cyclic permutations keep the handedness: which frame axis becomes z.
  const Eigen::Matrix3d cycles[3] = {Eigen::Matrix3d::Identity(),
                                     (Eigen::Matrix3d() << 0, 1, 0, 0, 0, 1, 1, 0, 0).finished(),
                                     (Eigen::Matrix3d() << 0, 0, 1, 1, 0, 0, 0, 1, 0).finished()};
  const char* input_names[3] = {"input frame, z up", "input frame, x up", "input frame, y up"};
  const char* principal_names[3] = {"principal axes, least-spread axis up", "principal axes, longest axis up",
                                    "principal axes, middle axis up"};
  for (int frame = 0; frame < 2; ++frame)
    for (int k = 0; k < 3; ++k) {
      AlignmentCandidate c;
      c.name = frame == 0 ? input_names[k] : principal_names[k];
      c.rotation = cycles[k] * (frame == 0 ? Eigen::Matrix3d::Identity() : pca);
      out.candidates.push_back(c);
    }
  PolycubeOptions scoring = polycube;
  scoring.max_rounds = std::min(scoring.max_rounds, options.max_rounds);
  scoring.max_inserted_planes = std::min(scoring.max_inserted_planes, options.max_inserted_planes);
  scoring.max_plane_cells = std::min(scoring.max_plane_cells, options.max_plane_cells);
  scoring.max_repair_level = std::min(scoring.max_repair_level, options.max_repair_level);
  const int n = static_cast<int>(out.candidates.size());
  std::vector<std::shared_ptr<TopologyResult>> topologies(n);
  std::vector<std::shared_ptr<PolycubeResult>> polycubes(n);
  std::vector<TriMesh> turned(n);
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  parallel_for_each(order, options.threads, "orientation", [&](int i) {
    AlignmentCandidate& c = out.candidates[i];
    const auto start = std::chrono::steady_clock::now();
    try {
      turned[i] = rotated(mesh, c.rotation);
      topologies[i] = std::make_shared<TopologyResult>(analyse_topology(turned[i], topology));
      polycubes[i] = std::make_shared<PolycubeResult>(build_polycube(turned[i], *topologies[i], scoring));
      c.corners = static_cast<int>(polycubes[i]->polycube.corners.size());
    } catch (const Error& e) {
      c.error = e.what();
      topologies[i].reset();
      polycubes[i].reset();
    }
    c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  });
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
      const auto start = std::chrono::steady_clock::now();
      try {
        maps[i] = std::make_shared<PolycubeMap>(build_polycube_map(turned[i], *polycubes[i]));
        const MapAudit audit = audit_map(turned[i], polycubes[i]->polycube.mesh, maps[i]->polycube_on_model_xyz, maps[i]->model_on_polycube_xyz);
        c.flipped = audit.polycube_to_model.flipped + audit.model_to_polycube.flipped + audit.polycube_to_model.degenerate +
                    audit.model_to_polycube.degenerate;
        c.eps_angle = audit.distortion.eps_angle;
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
    // Still flips in every map tried: the others get their map too.
    bool clean = false;
    for (size_t k = 0; k < first; ++k) clean = clean || (maps[mapped[k]] && out.candidates[mapped[k]].flipped == 0);
    if (!clean && first < mapped.size()) map_candidates(std::vector<int>(mapped.begin() + first, mapped.end()));
  }
  // Fewest flips, then least ε_angle, then fewest corners, then the earlier candidate.
  auto key = [&](int i) {
    const AlignmentCandidate& c = out.candidates[i];
    return std::make_tuple(maps[i] ? 0 : 1, maps[i] ? c.flipped : 0, maps[i] ? c.eps_angle : 0.0, c.corners, i);
  };
  for (int i = 0; i < n; ++i) {
    if (!polycubes[i]) continue;
    if (out.chosen < 0 || key(i) < key(out.chosen)) out.chosen = i;
  }
  if (out.chosen >= 0) {
    out.topology = topologies[out.chosen];
    out.polycube = polycubes[out.chosen];
    out.map = maps[out.chosen];
  }
  if (out.chosen >= 0) out.rotation = out.candidates[out.chosen].rotation;
  return out;
}

}  // namespace polycube
