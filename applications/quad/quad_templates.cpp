#include "applications/quad/quad_templates.h"

#include <array>
#include <map>
#include <stdexcept>
#include <tuple>

namespace polycube {

std::vector<char> close_template_marks(const Eigen::MatrixX4i& Q, std::vector<char> marked) {
  for (bool changed = true; changed;) {
    changed = false;
    for (int q = 0; q < Q.rows(); ++q) {
      int count = 0;
      for (int k = 0; k < 4; ++k) count += marked[Q(q, k)] ? 1 : 0;
      const bool opposite = count == 2 && marked[Q(q, 0)] == marked[Q(q, 2)];
      if (count == 3 || opposite) {
        for (int k = 0; k < 4; ++k) marked[Q(q, k)] = 1;
        changed = true;
      }
    }
  }
  return marked;
}

PolycubeGrid refine_grid_by_templates(const PolycubeGrid& grid, std::vector<char> marked,
                                      const std::function<SurfacePoint(const Eigen::Vector3d&)>& on_polycube,
                                      std::vector<int>* parents) {
  const Eigen::MatrixX4i& Q = grid.mesh.Q;
  const int nv = grid.mesh.num_vertices();
  if (static_cast<int>(marked.size()) != nv)
    throw std::invalid_argument("template marks for " + std::to_string(marked.size()) + " of " + std::to_string(nv) + " vertices");
  marked = close_template_marks(Q, std::move(marked));

  std::vector<Eigen::Vector3d> points;  // the new vertices' positions on P
  // Points on edges: (lower end, higher end, thirds from the lower end) -> vertex.
  std::map<std::tuple<int, int, int>, int> on_edge;
  const auto position = [&](int v) -> Eigen::Vector3d { return v < nv ? Eigen::Vector3d(grid.mesh.V.row(v)) : points[v - nv]; };
  const auto add = [&](const Eigen::Vector3d& x) {
    points.push_back(x);
    return nv + static_cast<int>(points.size()) - 1;
  };
  // The point `thirds` thirds of the way from a to b.
  const auto edge_point = [&](int a, int b, int thirds) {
    const auto key = a < b ? std::make_tuple(a, b, thirds) : std::make_tuple(b, a, 3 - thirds);
    const auto found = on_edge.find(key);
    if (found != on_edge.end()) return found->second;
    const int v = add(position(a) + thirds / 3.0 * (position(b) - position(a)));
    on_edge.emplace(key, v);
    return v;
  };

  std::vector<std::array<int, 4>> quads;
  std::vector<int> parent;
  for (int q = 0; q < Q.rows(); ++q) {
    int count = 0, first = -1;
    for (int k = 0; k < 4; ++k)
      if (marked[Q(q, k)]) {
        ++count;
        // The first marked corner going round from an unmarked one: for two adjacent marked
        // corners the one the marked edge leaves from.
        if (first < 0 || !marked[Q(q, (k + 3) % 4)]) first = k;
      }
    if (count == 0) {
      quads.push_back({Q(q, 0), Q(q, 1), Q(q, 2), Q(q, 3)});
      parent.push_back(q);
      continue;
    }
    if (count == 4) first = 0;
    // Local corners, counter-clockwise, marked ones first; s runs from v0 to v1, t from v0 to v3.
    const std::array<int, 4> v = {Q(q, first), Q(q, (first + 1) % 4), Q(q, (first + 2) % 4), Q(q, (first + 3) % 4)};
    const auto inside = [&](double s, double t) {
      return add((1 - s) * (1 - t) * position(v[0]) + s * (1 - t) * position(v[1]) + s * t * position(v[2]) +
                 (1 - s) * t * position(v[3]));
    };
    const auto emit = [&](int a, int b, int c, int d) {
      quads.push_back({a, b, c, d});
      parent.push_back(q);
    };
    if (count == 1) {
      const int a = edge_point(v[0], v[1], 1), b = edge_point(v[0], v[3], 1), m = inside(1.0 / 3, 1.0 / 3);
      emit(v[0], a, m, b);
      emit(a, v[1], v[2], m);
      emit(b, m, v[2], v[3]);
    } else if (count == 2) {
      const int p1 = edge_point(v[0], v[1], 1), p2 = edge_point(v[0], v[1], 2);
      const int b = edge_point(v[0], v[3], 1), c = edge_point(v[1], v[2], 1);
      const int m1 = inside(1.0 / 3, 1.0 / 3), m2 = inside(2.0 / 3, 1.0 / 3);
      const int s = inside(1.0 / 3, 2.0 / 3), u = inside(2.0 / 3, 2.0 / 3);
      emit(v[0], p1, m1, b);
      emit(p1, p2, m2, m1);
      emit(p2, v[1], c, m2);
      emit(v[3], b, m1, s);
      emit(m1, m2, u, s);
      emit(m2, c, v[2], u);
      emit(s, u, v[2], v[3]);
    } else {
      std::array<std::array<int, 4>, 4> lattice;  // [i along s][j along t]
      lattice[0][0] = v[0];
      lattice[3][0] = v[1];
      lattice[3][3] = v[2];
      lattice[0][3] = v[3];
      for (int k = 1; k < 3; ++k) {
        lattice[k][0] = edge_point(v[0], v[1], k);
        lattice[3][k] = edge_point(v[1], v[2], k);
        lattice[k][3] = edge_point(v[3], v[2], k);
        lattice[0][k] = edge_point(v[0], v[3], k);
      }
      for (int i = 1; i < 3; ++i)
        for (int j = 1; j < 3; ++j) lattice[i][j] = inside(i / 3.0, j / 3.0);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) emit(lattice[i][j], lattice[i + 1][j], lattice[i + 1][j + 1], lattice[i][j + 1]);
    }
  }

  PolycubeGrid refined = grid;
  const int total = nv + static_cast<int>(points.size());
  refined.mesh.V.resize(total, 3);
  refined.mesh.V.topRows(nv) = grid.mesh.V;
  refined.on_polycube.resize(total);
  for (size_t i = 0; i < points.size(); ++i) {
    refined.mesh.V.row(nv + i) = points[i].transpose();
    refined.on_polycube[nv + i] = on_polycube(points[i]);
  }
  const int nq = static_cast<int>(quads.size());
  refined.mesh.Q.resize(nq, 4);
  refined.quad_axis.resize(nq);
  refined.quad_cell.resize(nq);
  refined.quad_refined_by = Eigen::VectorXi::Constant(nq, -1);
  for (int q = 0; q < nq; ++q) {
    for (int k = 0; k < 4; ++k) refined.mesh.Q(q, k) = quads[q][k];
    refined.quad_axis[q] = grid.quad_axis[parent[q]];
    refined.quad_cell[q] = grid.quad_cell[parent[q]];
  }
  if (parents) *parents = std::move(parent);
  return refined;
}

}  // namespace polycube
