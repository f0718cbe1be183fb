// Internal to flat_metric / circle_domain: planar layout of a flat intrinsic triangulation,
// circle fitting. Not a public header.
#pragma once

#include "polycube/intrinsic_delaunay.h"

#include <Eigen/Core>

#include <vector>

namespace polycube::ricci {

// Positions of the num_vertices vertices of T (a flat triangulation, possibly with boundary)
// unfolded breadth-first from the face farthest from the boundary; each vertex keeps its first
// placement. Throws AlgorithmError if the faces are not connected.
std::vector<Eigen::Vector2d> unfold(const IntrinsicTriangulation& T, int num_vertices);

// Circle minimising the sum of squared distances of the points to it (Kåsa's fit refined by
// Gauss–Newton), computed around the centroid and at the points' scale.
void fit_circle(const std::vector<Eigen::Vector2d>& points, Eigen::Vector2d& centre, double& radius);

}  // namespace polycube::ricci
