#include "polycube/contour_map.h"

#include "polycube/errors.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace polycube {

namespace {

double wrap01(double x) {
  x -= std::floor(x);
  return x >= 1 ? 0 : x;
}

double circular_distance(double a, double b) {
  const double d = std::abs(wrap01(a) - wrap01(b));
  return std::min(d, 1 - d);
}

// Vertices ordered counter-clockwise in xy (by the shoelace area).
std::vector<int> counter_clockwise(const std::vector<int>& loop, const Eigen::MatrixX3d& V) {
  double area = 0;
  for (size_t i = 0; i < loop.size(); ++i) {
    const auto a = V.row(loop[i]);
    const auto b = V.row(loop[(i + 1) % loop.size()]);
    area += a.x() * b.y() - b.x() * a.y();
  }
  return area >= 0 ? loop : std::vector<int>(loop.rbegin(), loop.rend());
}

// Normalised cumulative arc length of the loop's vertices (first 0).
std::vector<double> arc_length(const std::vector<int>& loop, const Eigen::MatrixX3d& V) {
  std::vector<double> s(loop.size(), 0.0);
  double total = 0;
  for (size_t i = 0; i < loop.size(); ++i) {
    if (i > 0) s[i] = total;
    total += (V.row(loop[(i + 1) % loop.size()]) - V.row(loop[i])).norm();
  }
  if (!(total > 0)) throw std::invalid_argument("contour of zero length");
  for (double& x : s) x /= total;
  return s;
}

// Position on a closed loop at parameter t, the vertices having increasing parameters `param`
// cyclically (one wrap-around). Returns the loop position (vertex + fraction towards the next).
LoopPosition locate(const std::vector<double>& param, double t) {
  const int n = static_cast<int>(param.size());
  // Rotation start: the vertex of smallest parameter.
  const int r = static_cast<int>(std::min_element(param.begin(), param.end()) - param.begin());
  auto at = [&](int k) { return param[(r + k) % n]; };  // ascending in k
  t = wrap01(t);
  // Largest k with at(k) <= t; -1 when t is below all (then on the wrap edge from the last).
  int lo = 0, hi = n - 1, k = -1;
  while (lo <= hi) {
    const int mid = (lo + hi) / 2;
    if (at(mid) <= t) {
      k = mid;
      lo = mid + 1;
    } else {
      hi = mid - 1;
    }
  }
  if (k < 0) k = n - 1;
  const double a = at(k);
  if (a == t) return {(r + k) % n, 0.0};
  double b = at((k + 1) % n);
  double tt = t;
  if (b <= a) b += 1;
  if (tt < a) tt += 1;
  return {(r + k) % n, std::clamp((tt - a) / (b - a), 0.0, 1.0)};
}

Eigen::Vector3d position(const std::vector<int>& loop, const Eigen::MatrixX3d& V, const LoopPosition& p) {
  const Eigen::Vector3d a = V.row(loop[p.index]);
  const Eigen::Vector3d b = V.row(loop[(p.index + 1) % loop.size()]);
  return (1 - p.fraction) * a + p.fraction * b;
}

}  // namespace

ContourMap start_contour_map(const std::vector<int>& model_loop, const Eigen::MatrixX3d& model_V,
                             const std::vector<int>& polycube_loop, const Eigen::MatrixX3d& polycube_V) {
  if (model_loop.size() < 3 || polycube_loop.size() < 3) throw std::invalid_argument("contour loop with fewer than 3 vertices");
  ContourMap map;
  map.model_vertices = counter_clockwise(model_loop, model_V);
  map.polycube_vertices = counter_clockwise(polycube_loop, polycube_V);
  map.model_u = arc_length(map.model_vertices, model_V);
  map.polycube_u = arc_length(map.polycube_vertices, polycube_V);

  // Eq. 6 over rotations: sample both curves uniformly in arc length, correlate cyclically, then
  // refine the best rotation by golden-section search on the exact curves.
  const int samples = 256;
  std::vector<Eigen::Vector3d> p(samples), m(samples);
  for (int k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) / samples;
    p[k] = position(map.polycube_vertices, polycube_V, locate(map.polycube_u, t));
    m[k] = position(map.model_vertices, model_V, locate(map.model_u, t));
  }
  int best = 0;
  double best_cost = INFINITY;
  for (int j = 0; j < samples; ++j) {
    double cost = 0;
    for (int k = 0; k < samples && cost < best_cost; ++k) cost += (p[k] - m[(k + j) % samples]).squaredNorm();
    if (cost < best_cost) {
      best_cost = cost;
      best = j;
    }
  }
  auto cost_at = [&](double offset) {
    double cost = 0;
    for (int k = 0; k < samples; ++k)
      cost += (p[k] - position(map.model_vertices, model_V, locate(map.model_u, static_cast<double>(k) / samples + offset))).squaredNorm();
    return cost;
  };
  double lo = (best - 1.0) / samples, hi = (best + 1.0) / samples;
  const double golden = 0.5 * (std::sqrt(5.0) - 1);
  double x1 = hi - golden * (hi - lo), x2 = lo + golden * (hi - lo);
  double f1 = cost_at(x1), f2 = cost_at(x2);
  for (int it = 0; it < 40; ++it) {
    if (f1 < f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - golden * (hi - lo);
      f1 = cost_at(x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + golden * (hi - lo);
      f2 = cost_at(x2);
    }
  }
  map.offset = wrap01(0.5 * (lo + hi));

  // Eq. 6 over monotone correspondences: dynamic programming on samples P_i, i = 0..K, against
  // M_j at arc length offset + j / K, from (0, 0) to (K, K); steps (1,1), (1,0), (0,1), the last
  // two penalised by the squared sample spacing so that the correspondence only bends where it
  // brings points closer.
  const int K = 512;
  std::vector<Eigen::Vector3d> pk(K + 1), mk(K + 1);
  double spacing = 0;
  for (int k = 0; k <= K; ++k) {
    pk[k] = position(map.polycube_vertices, polycube_V, locate(map.polycube_u, static_cast<double>(k) / K));
    mk[k] = position(map.model_vertices, model_V, locate(map.model_u, map.offset + static_cast<double>(k) / K));
    if (k > 0) spacing += (mk[k] - mk[k - 1]).norm() + (pk[k] - pk[k - 1]).norm();
  }
  spacing /= 2 * K;
  const double penalty = 4 * spacing * spacing;
  const int band = K / 4;  // |i - j| <= band
  const int width = 2 * band + 1;
  std::vector<double> cost((K + 1) * width, INFINITY);
  std::vector<unsigned char> step((K + 1) * width, 0);
  auto at = [&](int i, int j) { return i * width + (j - i + band); };
  auto inside = [&](int i, int j) { return j >= 0 && j <= K && std::abs(i - j) <= band; };
  cost[at(0, 0)] = 0;
  for (int i = 0; i <= K; ++i)
    for (int j = std::max(0, i - band); j <= std::min(K, i + band); ++j) {
      if (i == 0 && j == 0) continue;
      const double d = (pk[i] - mk[j]).squaredNorm();
      double best = INFINITY;
      unsigned char from = 0;
      if (i > 0 && j > 0 && inside(i - 1, j - 1) && cost[at(i - 1, j - 1)] + d < best) {
        best = cost[at(i - 1, j - 1)] + d;
        from = 1;
      }
      if (i > 0 && inside(i - 1, j) && cost[at(i - 1, j)] + d + penalty < best) {
        best = cost[at(i - 1, j)] + d + penalty;
        from = 2;
      }
      if (j > 0 && inside(i, j - 1) && cost[at(i, j - 1)] + d + penalty < best) {
        best = cost[at(i, j - 1)] + d + penalty;
        from = 3;
      }
      cost[at(i, j)] = best;
      step[at(i, j)] = from;
    }
  // Trace back; per P sample the mean matched M sample.
  std::vector<double> sum(K + 1, 0.0), count(K + 1, 0.0);
  for (int i = K, j = K; i > 0 || j > 0;) {
    sum[i] += j;
    count[i] += 1;
    const unsigned char from = step[at(i, j)];
    if (from == 1) {
      --i;
      --j;
    } else if (from == 2) {
      --i;
    } else if (from == 3) {
      --j;
    } else {
      break;
    }
  }
  sum[0] += 0;
  count[0] += 1;
  std::vector<double> shift(K + 1);  // matched j minus i
  for (int i = 0; i <= K; ++i) shift[i] = sum[i] / count[i] - i;
  // Smooth the staircase of the sampled path (cyclic moving average over ±8 samples).
  std::vector<double> smooth(K + 1);
  for (int i = 0; i <= K; ++i) {
    double acc = 0;
    for (int w = -8; w <= 8; ++w) acc += shift[((i + w) % K + K) % K];
    smooth[i] = acc / 17;
  }
  smooth[K] = smooth[0];
  map.psi_p.resize(K + 1);
  map.psi_m.resize(K + 1);
  for (int i = 0; i <= K; ++i) {
    map.psi_p[i] = static_cast<double>(i) / K;
    map.psi_m[i] = map.offset + (i + smooth[i]) / K;
  }
  // Strictly increasing, ending one turn after the start.
  map.psi_m[K] = map.psi_m[0] + 1;
  for (int i = 1; i <= K; ++i) map.psi_m[i] = std::max(map.psi_m[i], map.psi_m[i - 1] + 1e-9);
  if (map.psi_m[K] > map.psi_m[0] + 1 + 1e-12) {
    // Rounding pushed the end: rescale to one turn.
    const double span = map.psi_m[K] - map.psi_m[0];
    for (int i = 1; i <= K; ++i) map.psi_m[i] = map.psi_m[0] + (map.psi_m[i] - map.psi_m[0]) / span;
  }
  return map;
}

namespace {

// F⁻¹: the P arc length (in [0, 1)) corresponding to model arc length s.
double model_to_polycube_length(const ContourMap& map, double s) {
  if (map.psi_m.empty()) return wrap01(s - map.offset);
  const double lo = map.psi_m.front();
  const double t = lo + wrap01(s - lo);
  const size_t k = std::upper_bound(map.psi_m.begin(), map.psi_m.end(), t) - map.psi_m.begin();
  if (k == 0) return 0;
  if (k >= map.psi_m.size()) return wrap01(map.psi_p.back());
  const double f = (t - map.psi_m[k - 1]) / (map.psi_m[k] - map.psi_m[k - 1]);
  return wrap01(map.psi_p[k - 1] + f * (map.psi_p[k] - map.psi_p[k - 1]));
}

}  // namespace

void add_anchor(ContourMap& map, int model_index) {
  for (const auto& a : map.anchors)
    if (a.first == model_index) return;
  map.anchors.emplace_back(model_index, -1);
}

int anchor_of(const ContourMap& map, int model_index) {
  for (const auto& a : map.anchors)
    if (a.first == model_index) return a.second;
  throw std::out_of_range("anchor_of: not an anchor");
}

namespace {

// Assigns polycube vertices to the anchors (sorted by model arc length from the first), keeping
// their cyclic order: each the closest to its target among the vertices after the previous one
// that leave room for the rest.
void pin_anchors(ContourMap& map, std::vector<std::pair<int, int>>& anchors) {
  const int n = static_cast<int>(map.polycube_vertices.size());
  const int k_count = static_cast<int>(anchors.size());
  if (k_count > n) throw AlgorithmError("a contour's polygon has fewer vertices (" + std::to_string(n) + ") than slit ends (" + std::to_string(k_count) + ")");
  auto target = [&](int k) { return model_to_polycube_length(map, map.model_u[anchors[k].first]); };
  int first = 0;
  for (int i = 1; i < n; ++i)
    if (circular_distance(map.polycube_u[i], target(0)) < circular_distance(map.polycube_u[first], target(0))) first = i;
  anchors[0].second = first;
  // Distances along the loop forwards from the first anchor's vertex, where the later anchors
  // follow it (F keeps the model's order), not around it either way: a vertex just behind the
  // first is a whole turn ahead. By circular distance, a second slit end 0.13 % of a contour after
  // the first, pinned behind it when the first took the only vertex between them, made the pinned
  // map squeeze the rest of the contour into that vertex's edge (a thin-walled pipe's bands: P's
  // image 6.8 times the model's area).
  const double u_first = map.polycube_u[first];
  const double lead = wrap01(target(0) - u_first + 0.5) - 0.5;  // target(0) from the first vertex, in [-0.5, 0.5)
  int previous = first;
  for (int k = 1; k < k_count; ++k) {
    // Candidates: steps 1 .. n - 1 - (k_count - 1 - k) - (offset of previous from first) after previous.
    const int used = ((previous - first) % n + n) % n;
    const int last_step = n - 1 - (k_count - 1 - k) - used;
    const double ahead = lead + wrap01(target(k) - target(0));
    int best = -1;
    double best_distance = INFINITY;
    for (int step = 1; step <= last_step; ++step) {
      const int i = (previous + step) % n;
      const double d = std::abs(wrap01(map.polycube_u[i] - u_first) - ahead);
      if (d < best_distance) {
        best_distance = d;
        best = i;
      }
    }
    if (best < 0) throw AlgorithmError("cannot pin the slit ends of a contour in order");
    anchors[k].second = best;
    previous = best;
  }
}

}  // namespace

void finish_contour_map(ContourMap& map, const Eigen::MatrixX3d& model_V, const Eigen::MatrixX3d& polycube_V) {
  const std::vector<double> s_poly = map.polycube_u;
  // Model vertices in P's arc length through F⁻¹ (monotone, so the order is kept).
  std::vector<double> s_model = map.model_u;
  for (double& x : s_model) x = model_to_polycube_length(map, x);
  if (map.anchors.empty()) {
    map.model_u = s_model;
  } else {
    std::vector<std::pair<int, int>> anchors = map.anchors;
    const double m0 = s_model[anchors.front().first];
    std::sort(anchors.begin(), anchors.end(), [&](const auto& a, const auto& b) {
      return wrap01(s_model[a.first] - m0) < wrap01(s_model[b.first] - m0);
    });
    pin_anchors(map, anchors);
    const double m_start = s_model[anchors.front().first], p_start = s_poly[anchors.front().second];
    std::vector<double> m_knot, p_knot;
    for (const auto& [m, p] : anchors) {
      m_knot.push_back(wrap01(s_model[m] - m_start));
      p_knot.push_back(wrap01(s_poly[p] - p_start));
    }
    for (size_t k = 1; k < p_knot.size(); ++k)
      if (!(p_knot[k] > p_knot[k - 1]))
        throw AlgorithmError("slit ends on a contour are in a different order on the model (" + std::to_string(anchors.size()) +
                             " ends) than on the polycube");
    m_knot.push_back(1);
    p_knot.push_back(1);
    for (double& u : map.polycube_u) u = wrap01(u - p_start);
    for (size_t i = 0; i < map.model_u.size(); ++i) {
      double& u = map.model_u[i];
      const double rel = wrap01(s_model[i] - m_start);
      const size_t k = std::upper_bound(m_knot.begin(), m_knot.end(), rel) - m_knot.begin() - 1;
      const double span = m_knot[k + 1] - m_knot[k];
      u = p_knot[k] + (span > 0 ? (rel - m_knot[k]) / span : 0.0) * (p_knot[k + 1] - p_knot[k]);
      u = wrap01(u);
    }
    map.anchors = anchors;
  }

  // Model vertices next to a polycube vertex in u share its u; then the union.
  std::vector<double> sorted_poly = map.polycube_u;
  std::sort(sorted_poly.begin(), sorted_poly.end());
  for (double& u : map.model_u) {
    auto it = std::lower_bound(sorted_poly.begin(), sorted_poly.end(), u);
    if (it != sorted_poly.end() && std::abs(*it - u) < 1e-10) u = *it;
    else if (it != sorted_poly.begin() && std::abs(*(it - 1) - u) < 1e-10) u = *(it - 1);
  }
  map.u = sorted_poly;
  map.u.insert(map.u.end(), map.model_u.begin(), map.model_u.end());
  std::sort(map.u.begin(), map.u.end());
  map.u.erase(std::unique(map.u.begin(), map.u.end()), map.u.end());
  map.model_at.clear();
  map.polycube_at.clear();
  for (double u : map.u) {
    map.model_at.push_back(locate(map.model_u, u));
    map.polycube_at.push_back(locate(map.polycube_u, u));
  }
  double sum = 0;
  for (size_t i = 0; i < map.polycube_vertices.size(); ++i) {
    const Eigen::Vector3d pv = polycube_V.row(map.polycube_vertices[i]);
    sum += (pv - position(map.model_vertices, model_V, locate(map.model_u, map.polycube_u[i]))).squaredNorm();
  }
  map.rms_distance = std::sqrt(sum / map.polycube_vertices.size());
}

}  // namespace polycube
