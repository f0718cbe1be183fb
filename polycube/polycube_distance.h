// How far apart two surfaces are: a sampled two-sided Hausdorff distance, used to report how
// closely the polycube follows the model (§4, Fig. 10: smaller d_z, d_a give a closer polycube).
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

namespace polycube {

struct HausdorffOptions {
  // Sample points per surface: all vertices plus this many random points, area-weighted.
  int samples = 20000;
  // Seed of the sampler (the result is deterministic for a seed).
  unsigned seed = 1;
  // Threads for the distance queries (0: one per hardware thread); the result does not depend on
  // it.
  int threads = 0;
};

// Distances between the surfaces of a and b (input units).
//   a_to_b  largest distance from a sample of a to the surface of b (and b_to_a the other way)
//   hausdorff  max(a_to_b, b_to_a)
//   mean_a_to_b, mean_b_to_a  mean sample distances
//   a_farthest, b_farthest  the sample of a farthest from b (at a_to_b), and of b from a
struct HausdorffDistance {
  double a_to_b = 0;
  double b_to_a = 0;
  double hausdorff = 0;
  double mean_a_to_b = 0;
  double mean_b_to_a = 0;
  Eigen::Vector3d a_farthest = Eigen::Vector3d::Zero();
  Eigen::Vector3d b_farthest = Eigen::Vector3d::Zero();
};

// Samples each surface and measures the exact distance of every sample to the other surface
// (CGAL AABB tree). Throws std::invalid_argument for a mesh without faces.
HausdorffDistance hausdorff_distance(const TriMesh& a, const TriMesh& b, const HausdorffOptions& options = {});

}  // namespace polycube
