#include "polycube/polycube_distance.h"

#include "polycube/parallel.h"
#include "polycube/triangle_tree.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace polycube {

namespace {

using namespace triangle_tree;

// Vertices plus area-weighted random points of the surface.
std::vector<Point> samples_of(const TriMesh& mesh, int count, unsigned seed) {
  std::vector<Point> samples;
  for (int v = 0; v < mesh.num_vertices(); ++v) samples.emplace_back(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2));
  const Eigen::VectorXd area = face_areas(mesh);
  std::vector<double> cumulative(area.size());
  double total = 0;
  for (Eigen::Index f = 0; f < area.size(); ++f) cumulative[f] = total += area[f];
  if (!(total > 0)) return samples;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int k = 0; k < count; ++k) {
    const double pick = uniform(random) * total;
    const int f = static_cast<int>(std::min<size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin(), cumulative.size() - 1));
    double s = uniform(random), t = uniform(random);
    if (s + t > 1) {
      s = 1 - s;
      t = 1 - t;
    }
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d p = a + s * (b - a) + t * (c - a);
    samples.emplace_back(p.x(), p.y(), p.z());
  }
  return samples;
}

// Largest and mean distance from the samples of `from` to the surface of `to`, and the sample
// farthest away.
struct OneSided {
  double largest = 0;
  double mean = 0;
  Eigen::Vector3d farthest = Eigen::Vector3d::Zero();
};

OneSided one_sided(const TriMesh& from, const TriMesh& to, const HausdorffOptions& options) {
  const std::vector<Triangle> triangles = triangles_of(to);
  Tree tree(triangles.begin(), triangles.end());
  tree.accelerate_distance_queries();
  OneSided result;
  double sum = 0;
  const std::vector<Point> samples = samples_of(from, options.samples, options.seed);
  std::vector<double> distance(samples.size());
  parallel_range(static_cast<int>(samples.size()), options.threads,
                 [&](int k) { distance[k] = std::sqrt(tree.squared_distance(samples[k])); });
  for (size_t k = 0; k < samples.size(); ++k) {
    const Point& p = samples[k];
    const double d = distance[k];
    if (d > result.largest) {
      result.largest = d;
      result.farthest = {p.x(), p.y(), p.z()};
    }
    sum += d;
  }
  result.mean = samples.empty() ? 0.0 : sum / samples.size();
  return result;
}

}  // namespace

HausdorffDistance hausdorff_distance(const TriMesh& a, const TriMesh& b, const HausdorffOptions& options) {
  if (a.num_faces() == 0 || b.num_faces() == 0) throw std::invalid_argument("hausdorff_distance: empty mesh");
  HausdorffDistance result;
  const OneSided ab = one_sided(a, b, options), ba = one_sided(b, a, options);
  result.a_to_b = ab.largest;
  result.mean_a_to_b = ab.mean;
  result.a_farthest = ab.farthest;
  result.b_to_a = ba.largest;
  result.mean_b_to_a = ba.mean;
  result.b_farthest = ba.farthest;
  result.hausdorff = std::max(result.a_to_b, result.b_to_a);
  return result;
}

}  // namespace polycube
