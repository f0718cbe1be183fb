#include "polycube/cutting_planes.h"

#include "polycube/errors.h"
#include "polycube/plane_placement.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace polycube {

CuttingPlanes cutting_planes(const TriMesh& mesh, const CriticalPoints& critical, const CuttingPlaneOptions& options) {
  if (!(options.dz > 0)) throw std::invalid_argument("cutting_planes: dz must be positive");
  if (!(options.level_merge >= 0)) throw std::invalid_argument("cutting_planes: level_merge must be >= 0");
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
  result.z = planes;
  for (double z : planes) result.z_normalised.push_back((z - z_min) / extent);
  return result;
}

}  // namespace polycube
