#include "polycube/ricci_layout.h"

#include "polycube/errors.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <deque>
#include <string>

namespace polycube::ricci {

namespace {

// Angle at each corner of a triangle with edge lengths l[0..2] (edge i from corner i to i+1):
// corner i lies between edges i-1 and i, opposite edge i+1. Half-angle formula, stable for
// needles and slivers.
void corner_angles(const double l[3], double angle[3]) {
  for (int i = 0; i < 3; ++i) {
    const double a = l[(i + 1) % 3], b = l[i], c = l[(i + 2) % 3];  // a opposite corner i
    const double s = 0.5 * (a + b + c);
    const double num = std::max(0.0, (s - b) * (s - c)), den = std::max(0.0, s * (s - a));
    angle[i] = 2 * std::atan2(std::sqrt(num), std::sqrt(den));
  }
}

double wrap(double x) { return std::remainder(x, 2 * 3.14159265358979323846); }

}  // namespace

std::vector<Eigen::Vector2d> unfold(const IntrinsicTriangulation& T, int num_vertices) {
  const int nf = static_cast<int>(T.F.rows());
  std::vector<Eigen::Vector2d> position(num_vertices, Eigen::Vector2d::Zero());
  if (nf == 0) return position;
  // The face farthest (in face steps) from the boundary, so the unfolding paths stay short.
  std::vector<int> depth(nf, -1);
  std::deque<int> queue;
  for (int f = 0; f < nf; ++f)
    for (int i = 0; i < 3; ++i)
      if (T.adjacent(f, i) < 0 && depth[f] < 0) {
        depth[f] = 0;
        queue.push_back(f);
      }
  int root = 0;
  while (!queue.empty()) {
    const int f = queue.front();
    queue.pop_front();
    root = f;
    for (int i = 0; i < 3; ++i) {
      const int g = T.adjacent(f, i);
      if (g >= 0 && depth[g] < 0) {
        depth[g] = depth[f] + 1;
        queue.push_back(g);
      }
    }
  }
  // Breadth-first over faces, carrying edge directions rather than positions: the direction of
  // edge i + 1 of a face is that of edge i turned by pi minus the corner angle between them, and
  // a neighbour's shared edge points the opposite way. Vertices are then placed along one edge
  // from an already placed corner, so rounding errors add up along the path instead of being
  // amplified by needle-shaped triangles (as placing a vertex from a short base would).
  std::vector<double> direction(nf, 0.0);  // of edge 0 of each face
  std::vector<char> visited(nf, 0), placed(num_vertices, 0);
  auto edge_direction = [&](int f, int i, const double angle[3]) {
    double d = direction[f];
    for (int k = 1; k <= i; ++k) d += 3.14159265358979323846 - angle[k];
    return wrap(d);
  };
  auto place = [&](int f, const double angle[3]) {
    for (int pass = 0; pass < 2; ++pass)
      for (int i = 0; i < 3; ++i) {
        const int a = T.F(f, i), b = T.F(f, (i + 1) % 3);
        if (placed[a] && !placed[b]) {
          const double d = edge_direction(f, i, angle);
          position[b] = position[a] + T.length(f, i) * Eigen::Vector2d(std::cos(d), std::sin(d));
          placed[b] = 1;
        }
      }
  };
  double angle[3], l[3];
  visited[root] = 1;
  placed[T.F(root, 0)] = 1;
  for (int i = 0; i < 3; ++i) l[i] = T.length(root, i);
  corner_angles(l, angle);
  place(root, angle);
  queue.push_back(root);
  int reached = 1;
  while (!queue.empty()) {
    const int f = queue.front();
    queue.pop_front();
    for (int i = 0; i < 3; ++i) l[i] = T.length(f, i);
    corner_angles(l, angle);
    for (int i = 0; i < 3; ++i) {
      const int g = T.adjacent(f, i);
      if (g < 0 || visited[g]) continue;
      visited[g] = 1;
      ++reached;
      queue.push_back(g);
      const int j = T.adjacent_edge(f, i);
      double lg[3], ag[3];
      for (int k = 0; k < 3; ++k) lg[k] = T.length(g, k);
      corner_angles(lg, ag);
      double d = edge_direction(f, i, angle) + 3.14159265358979323846;  // edge j of g
      for (int k = j; k >= 1; --k) d -= 3.14159265358979323846 - ag[k];
      direction[g] = wrap(d);
      place(g, ag);
    }
  }
  if (reached != nf)
    throw AlgorithmError("flat metric layout: the triangulation is not connected (" + std::to_string(reached) +
                         " of " + std::to_string(nf) + " faces reached)");
  return position;
}

void fit_circle(const std::vector<Eigen::Vector2d>& points, Eigen::Vector2d& centre, double& radius) {
  const int n = static_cast<int>(points.size());
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= std::max(n, 1);
  double scale = 0;
  for (const auto& p : points) scale = std::max(scale, (p - mean).norm());
  if (n < 3 || !(scale > 0)) {
    centre = mean;
    radius = scale;
    return;
  }
  std::vector<Eigen::Vector2d> q(n);
  for (int i = 0; i < n; ++i) q[i] = (points[i] - mean) / scale;
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    A(i, 0) = 2 * q[i].x();
    A(i, 1) = 2 * q[i].y();
    A(i, 2) = 1;
    b[i] = q[i].squaredNorm();
  }
  const Eigen::Vector3d s = A.colPivHouseholderQr().solve(b);
  Eigen::Vector2d c(s[0], s[1]);
  double r = std::sqrt(std::max(0.0, s[2] + c.squaredNorm()));
  for (int iter = 0; iter < 20; ++iter) {
    Eigen::MatrixXd J(n, 3);
    Eigen::VectorXd residual(n);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d d = q[i] - c;
      const double len = std::max(d.norm(), 1e-300);
      residual[i] = len - r;
      J(i, 0) = -d.x() / len;
      J(i, 1) = -d.y() / len;
      J(i, 2) = -1;
    }
    const Eigen::Vector3d step = J.colPivHouseholderQr().solve(-residual);
    c += step.head<2>();
    r += step[2];
    if (step.norm() < 1e-15) break;
  }
  centre = mean + scale * c;
  radius = scale * r;
}

}  // namespace polycube::ricci
