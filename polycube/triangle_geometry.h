// Triangle quantities from edge lengths alone (intrinsic geometry), shared by the Laplacian,
// the intrinsic Delaunay flips and the flat metric.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>

namespace polycube {

// Area of a triangle from its edge lengths (Kahan's stable form of Heron's formula); 0 when the
// lengths violate the triangle inequality by rounding.
inline double triangle_area(double a, double b, double c) {
  if (a < b) std::swap(a, b);
  if (a < c) std::swap(a, c);
  if (b < c) std::swap(b, c);
  const double p = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
  return p > 0 ? 0.25 * std::sqrt(p) : 0.0;
}

// Cotangent of the angle opposite edge a in the triangle with edge lengths a, b, c. Degenerate
// triangles give large finite values with the right sign instead of infinities.
inline double cotan_opposite(double a, double b, double c) {
  const double area = triangle_area(a, b, c);
  const double scale = a * a + b * b + c * c;
  return (b * b + c * c - a * a) / std::max(4 * area, 1e-300 + 1e-16 * scale);
}

}  // namespace polycube
