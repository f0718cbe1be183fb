#include "polycube/cutting_planes.h"

#include "polycube/errors.h"
#include "polycube/plane_placement.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace polycube {

std::vector<double> longest_contours(const TriMesh& mesh, const std::vector<double>& z, const Eigen::Vector3d& scales) {
  const int n = static_cast<int>(z.size());
  // Per plane, the segments of its contour: the two crossed edges (keys) and the length.
  struct Segment {
    std::uint64_t a, b;
    double length;
  };
  std::vector<std::vector<Segment>> segments(n);
  const auto key = [](int u, int v) {
    return (static_cast<std::uint64_t>(std::min(u, v)) << 32) | static_cast<std::uint32_t>(std::max(u, v));
  };
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int v[3] = {mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)};
    const double h[3] = {mesh.V(v[0], 2), mesh.V(v[1], 2), mesh.V(v[2], 2)};
    const double lo = std::min({h[0], h[1], h[2]}), hi = std::max({h[0], h[1], h[2]});
    // The planes with a corner below (z < plane) and one at or above it.
    const int first = static_cast<int>(std::upper_bound(z.begin(), z.end(), lo) - z.begin());
    const int end = static_cast<int>(std::upper_bound(z.begin(), z.end(), hi) - z.begin());
    for (int p = first; p < end; ++p) {
      Eigen::Vector3d point[2];
      std::uint64_t edge[2];
      int found = 0;
      for (int k = 0; k < 3 && found < 2; ++k) {
        const int i = k, j = (k + 1) % 3;
        if ((h[i] < z[p]) == (h[j] < z[p])) continue;
        const double t = (z[p] - h[i]) / (h[j] - h[i]);
        point[found] = mesh.V.row(v[i]).transpose() + t * (mesh.V.row(v[j]) - mesh.V.row(v[i])).transpose();
        edge[found++] = key(v[i], v[j]);
      }
      if (found == 2) segments[p].push_back({edge[0], edge[1], (point[1] - point[0]).cwiseQuotient(scales).norm()});
    }
  }
  std::vector<double> longest(n, 0);
  for (int p = 0; p < n; ++p) {
    std::vector<std::uint64_t> keys;
    keys.reserve(2 * segments[p].size());
    for (const Segment& s : segments[p]) keys.insert(keys.end(), {s.a, s.b});
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    const auto index = [&](std::uint64_t k) { return static_cast<int>(std::lower_bound(keys.begin(), keys.end(), k) - keys.begin()); };
    std::vector<int> parent(keys.size());
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&](int a) {
      while (parent[a] != a) a = parent[a] = parent[parent[a]];
      return a;
    };
    for (const Segment& s : segments[p]) parent[find(index(s.a))] = find(index(s.b));
    std::vector<double> length(keys.size(), 0);
    for (const Segment& s : segments[p]) length[find(index(s.a))] += s.length;
    for (size_t i = 0; i < keys.size(); ++i)
      if (find(static_cast<int>(i)) == static_cast<int>(i)) longest[p] = std::max(longest[p], length[i]);
  }
  return longest;
}

CuttingPlanes cutting_planes(const TriMesh& mesh, const CriticalPoints& critical, const CuttingPlaneOptions& options) {
  if (!(options.dz > 0)) throw std::invalid_argument("cutting_planes: dz must be positive");
  if (!(options.level_merge >= 0)) throw std::invalid_argument("cutting_planes: level_merge must be >= 0");
  if (!(options.girth_ratio >= 0) || (options.girth_ratio > 0 && !(options.girth_spacing > 0)) || options.girth_max_planes < 0 ||
      !(options.length_scales.minCoeff() > 0))
    throw std::invalid_argument("cutting_planes: girth_ratio must be >= 0, girth_spacing > 0, girth_max_planes >= 0 and length_scales > 0");
  const BoundingBox box = bounding_box(mesh.V);
  const double z_min = box.min.z(), z_max = box.max.z();
  if (!(z_max > z_min)) throw MeshError("cutting_planes: mesh has no height (all z equal)");
  const double extent = box.extent().maxCoeff();
  const double height = z_max - z_min;

  std::vector<double> heights(mesh.V.col(2).data(), mesh.V.col(2).data() + mesh.V.rows());
  std::sort(heights.begin(), heights.end());

  // Critical heights, with the ends of the z range (the global minimum and maximum of f sit
  // there by construction, but the ends must be levels in any case).
  std::vector<double> zc = {z_min, z_max};
  for (const auto* list : {&critical.minima, &critical.saddles, &critical.maxima})
    for (int v : *list) zc.push_back(mesh.V(v, 2));
  std::sort(zc.begin(), zc.end());

  // Levels as [bottom, top] ranges: single linkage with threshold level_merge * height.
  std::vector<std::pair<double, double>> levels;
  for (double z : zc) {
    if (!levels.empty() && z - levels.back().second <= options.level_merge * height)
      levels.back().second = z;
    else
      levels.push_back({z, z});
  }

  CuttingPlanes result;
  result.levels = static_cast<int>(levels.size());
  // Boundaries of the gaps to subdivide: ends of the range, then level planes.
  std::vector<double> bounds = {z_min};
  for (size_t i = 0; i + 1 < levels.size(); ++i) {
    const double lo = levels[i].second, hi = levels[i + 1].first;
    bounds.push_back(place_plane(heights, 0.5 * (lo + hi), lo, hi, 0.25 * (hi - lo)));
  }
  bounds.push_back(z_max);
  result.level_planes = static_cast<int>(bounds.size()) - 2;

  const double dz = options.dz * extent;
  std::vector<double> planes;
  for (size_t i = 0; i + 1 < bounds.size(); ++i) {
    if (i > 0) planes.push_back(bounds[i]);
    const bool end_gap = i == 0 || i + 2 == bounds.size();
    if (end_gap && !options.split_end_gaps) continue;
    const double lo = bounds[i], hi = bounds[i + 1], gap = hi - lo;
    if (!(gap > dz)) continue;
    const int extra = static_cast<int>(std::floor(gap / dz));
    const double step = gap / (extra + 1);  // < dz
    // Moving each plane by at most (dz - step) / 2 keeps every gap within dz.
    const double window = std::min(0.25 * step, 0.5 * (dz - step));
    for (int k = 1; k <= extra; ++k) {
      planes.push_back(place_plane(heights, lo + k * step, lo, hi, window));
      ++result.spacing_planes;
    }
  }
  std::sort(planes.begin(), planes.end());
  planes.erase(std::unique(planes.begin(), planes.end()), planes.end());

  // The girth rule: gaps long against the sections bounding them are split; the new planes'
  // sections may be thinner still (a tapering rod), so a few passes.
  for (int pass = 0; pass < 3 && options.girth_ratio > 0 && result.girth_planes < options.girth_max_planes; ++pass) {
    const std::vector<double> longest = longest_contours(mesh, planes, options.length_scales);
    std::vector<double> added;
    const int n = static_cast<int>(planes.size());
    for (int g = 0; g <= n; ++g) {
      if ((g == 0 || g == n) && !options.split_end_gaps) continue;
      const double lo = g == 0 ? z_min : planes[g - 1], hi = g == n ? z_max : planes[g];
      const double girth = std::max(g > 0 ? longest[g - 1] : 0.0, g < n ? longest[g] : 0.0);
      const double gap = (hi - lo) / options.length_scales(2);
      if (!(girth > 0) || !(gap > options.girth_ratio * girth)) continue;
      // Capped in doubles first: a contour of a hair's length asks for more planes than an int.
      const double room = options.girth_max_planes - result.girth_planes - static_cast<double>(added.size());
      const int extra = static_cast<int>(std::min(room, std::ceil(gap / (options.girth_spacing * girth)) - 1));
      const double step = (hi - lo) / (extra + 1);
      for (int k = 1; k <= extra; ++k) added.push_back(place_plane(heights, lo + k * step, lo, hi, 0.25 * step));
    }
    if (added.empty()) break;
    const size_t before = planes.size();
    planes.insert(planes.end(), added.begin(), added.end());
    std::sort(planes.begin(), planes.end());
    planes.erase(std::unique(planes.begin(), planes.end()), planes.end());
    result.girth_planes += static_cast<int>(planes.size() - before);  // distinct new heights
    if (planes.size() == before) break;
  }
  result.z = planes;
  for (double z : planes) result.z_normalised.push_back((z - z_min) / extent);
  return result;
}

}  // namespace polycube
