#include "polycube/ricci_mesh.h"

#include "polycube/errors.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

namespace polycube::ricci {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Coefficients a_k = 2 zeta(2k) / (2k (2k+1)) of the series
//   Cl2(t) = t - t log t + t * sum_k a_k (t / 2pi)^(2k),  0 <= t < 2pi.
struct ClausenSeries {
  static constexpr int kTerms = 30;
  std::array<double, kTerms> a{};
  ClausenSeries() {
    for (int k = 1; k <= kTerms; ++k) {
      double zeta;
      const double pi2 = kPi * kPi;
      if (k == 1) {
        zeta = pi2 / 6;
      } else if (k == 2) {
        zeta = pi2 * pi2 / 90;
      } else if (k == 3) {
        zeta = pi2 * pi2 * pi2 / 945;
      } else if (k == 4) {
        zeta = pi2 * pi2 * pi2 * pi2 / 9450;
      } else {
        // The tail beyond n = 200 is below 200^(1-2k) / (2k-1) < 1e-20 for k >= 5.
        zeta = 0;
        for (int n = 200; n >= 1; --n) zeta += std::pow(static_cast<double>(n), -2.0 * k);
      }
      a[k - 1] = 2 * zeta / (2.0 * k * (2.0 * k + 1));
    }
  }
};

// Clausen's function Cl2(t) for 0 <= t <= pi.
double clausen_reduced(double t) {
  static const ClausenSeries series;
  if (t <= 0) return 0;
  // Terms decrease at least 4-fold (y <= 1/4, a_k decreasing): stop below 1e-17 of the sum.
  const double y = (t / (2 * kPi)) * (t / (2 * kPi));
  double power = y, sum = 0;
  for (int k = 0; k < ClausenSeries::kTerms; ++k) {
    const double term = series.a[k] * power;
    sum += term;
    if (term < 1e-17 * sum) break;
    power *= y;
  }
  return t - t * std::log(t) + t * sum;
}

}  // namespace

double lobachevsky(double x) {
  // L(x) = Cl2(2x) / 2; Cl2 is 2pi-periodic and odd.
  double t = std::fmod(2 * x, 2 * kPi);
  if (t < 0) t += 2 * kPi;
  if (t <= kPi) return 0.5 * clausen_reduced(t);
  return -0.5 * clausen_reduced(2 * kPi - t);
}

bool triangle_angles(const double x[3], double opposite[3], double cot[3]) {
  const double m = std::max({x[0], x[1], x[2]});
  double l[3] = {std::exp(x[0] - m), std::exp(x[1] - m), std::exp(x[2] - m)};
  // Order the edges a >= b >= c (Kahan's ordering for an accurate Heron product).
  int ia = 0, ib = 1, ic = 2;
  if (l[ia] < l[ib]) std::swap(ia, ib);
  if (l[ia] < l[ic]) std::swap(ia, ic);
  if (l[ib] < l[ic]) std::swap(ib, ic);
  const double a = l[ia], b = l[ib], c = l[ic];
  const double qa = c - (a - b);  // b + c - a
  if (!(qa > 0)) {
    opposite[ia] = kPi;
    opposite[ib] = opposite[ic] = 0;
    cot[0] = cot[1] = cot[2] = 0;
    return false;
  }
  const double qb = c + (a - b);  // a - b + c
  const double qc = a + (b - c);  // a + b - c
  const double p = a + (b + c);
  const double root = std::sqrt(p * qa * qb * qc);  // 4 * area
  const double pq[3] = {p * qa, p * qb, p * qc};
  const double qq[3] = {qb * qc, qa * qc, qa * qb};
  const int idx[3] = {ia, ib, ic};
  for (int s = 0; s < 3; ++s) {
    opposite[idx[s]] = 2 * std::atan2(std::sqrt(qq[s]), std::sqrt(pq[s]));
    cot[idx[s]] = (pq[s] - qq[s]) / (2 * root);
  }
  return true;
}

bool cyclic_polygon(const std::vector<double>& x, double& rho, std::vector<double>& phi) {
  const int n = static_cast<int>(x.size());
  phi.assign(n, 0.0);
  if (n < 2) return false;
  const int longest = static_cast<int>(std::max_element(x.begin(), x.end()) - x.begin());
  const double m = x[longest];
  // w_e = l_e / l_max; s = l_max / (2R) in (0, 1]; l_e = 2R sin(phi_e) means phi_e = asin(s w_e).
  std::vector<double> w(n);
  double others = 0;
  for (int e = 0; e < n; ++e) {
    w[e] = std::exp(x[e] - m);
    if (e != longest) others += w[e];
  }
  if (!(others > 1)) return false;  // no polygon: the longest edge is not shorter than the rest
  double sum_at_one = 0.5 * kPi;     // centre on the longest edge (s = 1)
  for (int e = 0; e < n; ++e)
    if (e != longest) sum_at_one += std::asin(std::min(1.0, w[e]));
  const bool centre_inside = sum_at_one >= kPi;
  // f(s) = sum of half central angles - pi; increasing in s when the centre is inside, and
  // changes sign once on (0, 1) otherwise (negative at s = 1, positive for small s).
  auto f = [&](double s, double& derivative) {
    double value = -kPi, d = 0;
    for (int e = 0; e < n; ++e) {
      const double sw = std::min(1.0, s * w[e]);
      const double c = std::sqrt(std::max(1e-300, (1 - sw) * (1 + sw)));
      if (!centre_inside && e == longest) {
        value += kPi - std::asin(sw);
        d -= w[e] / c;
      } else {
        value += std::asin(sw);
        d += w[e] / c;
      }
    }
    derivative = d;
    return value;
  };
  // Bracket [lo, hi] with f(lo) < 0 < f(hi) (centre inside) or f(lo) > 0 > f(hi) (outside).
  double lo, hi;
  double d;
  if (centre_inside) {
    lo = 0;
    hi = 1;
  } else {
    hi = 1;
    lo = 0.5;
    int guard = 0;
    while (f(lo, d) <= 0 && guard++ < 1100) lo *= 0.5;
    if (f(lo, d) <= 0) return false;
  }
  const double sign = centre_inside ? 1.0 : -1.0;  // sign * f increases with s on the bracket
  // Start from the length-share estimate R = L / 2pi, clamped into the bracket.
  double s = std::clamp(kPi / (others + 1), lo, hi);
  for (int iter = 0; iter < 200; ++iter) {
    const double value = sign * f(s, d);
    if (value == 0) break;
    if (value < 0)
      lo = s;
    else
      hi = s;
    double next = s - f(s, d) / d;
    if (!(next > lo && next < hi) || !std::isfinite(next)) next = 0.5 * (lo + hi);
    if (std::abs(next - s) <= 1e-15 * s) {
      s = next;
      break;
    }
    s = next;
  }
  for (int e = 0; e < n; ++e) {
    const double sw = std::min(1.0, s * w[e]);
    phi[e] = (!centre_inside && e == longest) ? kPi - std::asin(sw) : std::asin(sw);
  }
  rho = m - std::log(2 * s);
  return true;
}

RicciMesh build_ricci_mesh(const TriMesh& mesh, double log_scale, const char* caller) {
  const int nf = mesh.num_faces();
  const int nv = mesh.num_vertices();
  RicciMesh r;
  r.num_vertices = nv;
  r.next.resize(3 * nf);
  r.twin.assign(3 * nf, -1);
  r.vert.resize(3 * nf);
  r.face.resize(3 * nf);
  r.lambda.resize(3 * nf);
  r.face_halfedge.resize(nf);
  std::vector<std::pair<long long, int>> keys;
  keys.reserve(3 * nf);
  for (int f = 0; f < nf; ++f) {
    r.face_halfedge[f] = 3 * f;
    for (int i = 0; i < 3; ++i) {
      const int h = 3 * f + i;
      const int a = mesh.F(f, i), b = mesh.F(f, (i + 1) % 3);
      if (a == b || a < 0 || b < 0 || a >= nv || b >= nv)
        throw MeshError(std::string(caller) + ": face " + std::to_string(f) + " has bad or repeated vertex ids");
      r.next[h] = 3 * f + (i + 1) % 3;
      r.vert[h] = a;
      r.face[h] = f;
      const double len = (mesh.V.row(a) - mesh.V.row(b)).norm();
      if (!(len > 0) || !std::isfinite(len))
        throw MeshError(std::string(caller) + ": edge (" + std::to_string(a) + ", " + std::to_string(b) + ") has length " +
                        std::to_string(len));
      r.lambda[h] = std::log(len) - log_scale;
      keys.emplace_back(static_cast<long long>(a) * nv + b, h);
    }
  }
  std::sort(keys.begin(), keys.end());
  for (size_t k = 1; k < keys.size(); ++k)
    if (keys[k].first == keys[k - 1].first)
      throw MeshError(std::string(caller) + ": faces " + std::to_string(keys[k - 1].second / 3) + " and " +
                      std::to_string(keys[k].second / 3) +
                      " traverse an edge in the same direction (non-manifold or inconsistently oriented)");
  for (const auto& [key, h] : keys) {
    const long long a = key / nv, b = key % nv;
    const long long reverse = b * nv + a;
    const auto it = std::lower_bound(keys.begin(), keys.end(), std::make_pair(reverse, -1));
    if (it != keys.end() && it->first == reverse) r.twin[h] = it->second;
  }
  r.boundary_vertex.assign(nv, 0);
  for (int h = 0; h < 3 * nf; ++h)
    if (r.twin[h] < 0) {
      r.boundary_vertex[r.vert[h]] = 1;
      r.boundary_vertex[r.head(h)] = 1;
    }
  return r;
}

namespace {

// cos of the angle opposite the edge of length 1 in a triangle with the other two edges b, c.
double cos_opposite_unit(double b, double c) { return (b * b + c * c - 1) / (2 * b * c); }

// cos(alpha) + cos(beta) for the edge of h (alpha in h's face, beta in its twin's).
double cos_sum(const RicciMesh& m, int h, const Eigen::VectorXd& u) {
  const int t = m.twin[h];
  const double xa = m.log_length(h, u);
  const int h1 = m.next[h], h2 = m.next[h1], t1 = m.next[t], t2 = m.next[t1];
  return cos_opposite_unit(std::exp(m.log_length(h1, u) - xa), std::exp(m.log_length(h2, u) - xa)) +
         cos_opposite_unit(std::exp(m.log_length(t1, u) - xa), std::exp(m.log_length(t2, u) - xa));
}

// Flip of the edge of h inside the quad of its two faces (A != B). Before: h = i->j, next j->k,
// k->i in face A; twin t = j->i, next i->l, l->j in face B. After: A = (k, i, l), B = (l, j, k)
// with the new edge h = l->k, t = k->l.
void flip(RicciMesh& m, int h, double new_lambda) {
  const int t = m.twin[h];
  const int h1 = m.next[h], h2 = m.next[h1];
  const int t1 = m.next[t], t2 = m.next[t1];
  const int A = m.face[h], B = m.face[t];
  const int k = m.vert[h2], l = m.vert[t2];
  m.vert[h] = l;
  m.vert[t] = k;
  m.next[h] = h2;
  m.next[h2] = t1;
  m.next[t1] = h;
  m.next[t] = t2;
  m.next[t2] = h1;
  m.next[h1] = t;
  m.face[t1] = A;
  m.face[h1] = B;
  m.face_halfedge[A] = h;
  m.face_halfedge[B] = t;
  m.lambda[h] = m.lambda[t] = new_lambda;
  ++m.flips;
  ++m.connectivity_version;
}

// Length of the other diagonal k-l of the quad around the edge of h (lengths relative to the
// edge's own length), from a planar layout of its two triangles; NaN if one is not a triangle.
double euclidean_diagonal(double jk, double ki, double il, double lj) {
  auto height = [](double b, double c) {  // of the triangle (1, b, c) over its unit edge
    const double p = (1 + b + c) * (-1 + b + c) * (1 - b + c) * (1 + b - c);
    return p > 0 ? 0.5 * std::sqrt(p) : std::nan("");
  };
  // i at the origin, j at (1, 0), k above the axis, l below it.
  const double xk = (1 + ki * ki - jk * jk) / 2, yk = height(jk, ki);
  const double xl = (1 + il * il - lj * lj) / 2, yl = height(il, lj);
  return std::hypot(xk - xl, yk + yl);
}

}  // namespace

long long make_delaunay(RicciMesh& m, const Eigen::VectorXd& u, const FlipRules& rules) {
  const int nh = m.num_halfedges();
  std::vector<int> stack;
  std::vector<char> queued(nh, 0);
  stack.reserve(nh / 2);
  for (int h = nh - 1; h >= 0; --h)
    if (m.twin[h] > h) {
      stack.push_back(h);
      queued[h] = 1;
    }
  std::vector<int> degree;
  if (rules.keep_links_simple) {
    degree.assign(m.num_vertices, 0);
    for (int h = 0; h < nh; ++h) ++degree[m.vert[h]];
  }
  long long flips = 0;
  while (!stack.empty() && flips < rules.max_flips) {
    const int h = stack.back();
    stack.pop_back();
    queued[h] = 0;
    const int t = m.twin[h];
    if (m.face[h] == m.face[t]) continue;
    if (cos_sum(m, h, u) >= -rules.tolerance) continue;
    const int h1 = m.next[h], h2 = m.next[h1], t1 = m.next[t], t2 = m.next[t1];
    const int i = m.vert[h], j = m.vert[t], k = m.vert[h2], l = m.vert[t2];
    if (rules.keep_links_simple && (k == l || degree[i] <= 3 || degree[j] <= 3)) continue;
    const double xa = m.log_length(h, u);
    const double jk = m.log_length(h1, u) - xa, ki = m.log_length(h2, u) - xa;
    const double il = m.log_length(t1, u) - xa, lj = m.log_length(t2, u) - xa;
    double x_new;  // log-length of the new edge at u
    if (rules.euclidean) {
      const double d = euclidean_diagonal(std::exp(jk), std::exp(ki), std::exp(il), std::exp(lj));
      if (!(d > 0) || !std::isfinite(d)) continue;
      x_new = xa + std::log(d);
    } else {
      // Ptolemy: l_kl = (l_ki l_lj + l_il l_jk) / l_ij, in logarithms.
      const double p = ki + lj, q = il + jk;
      x_new = xa + std::max(p, q) + std::log1p(std::exp(-std::abs(p - q)));
    }
    flip(m, h, x_new - 0.5 * (u[k] + u[l]));
    ++flips;
    if (rules.keep_links_simple) {
      --degree[i];
      --degree[j];
      ++degree[k];
      ++degree[l];
    }
    for (int g : {h1, h2, t1, t2}) {
      const int tg = m.twin[g];
      if (tg < 0) continue;
      const int rep = std::min(g, tg);
      if (!queued[rep]) {
        queued[rep] = 1;
        stack.push_back(rep);
      }
    }
  }
  return flips;
}

double cotan_sum(const RicciMesh& m, int h, const Eigen::VectorXd& u) {
  double sum = 0;
  for (int g : {h, m.twin[h]}) {
    const double x[3] = {m.log_length(g, u), m.log_length(m.next[g], u), m.log_length(m.next[m.next[g]], u)};
    double angle[3], cot[3];
    triangle_angles(x, angle, cot);
    sum += cot[0];
  }
  return sum;
}

namespace {

// Log-length of the median from the apex to the midpoint of the edge of length exp(xa) in the
// triangle with the other two log-lengths xb, xc; NaN if not a triangle.
double log_median(double xa, double xb, double xc) {
  const double b = std::exp(xb - xa), c = std::exp(xc - xa);  // relative to the split edge
  if (!(b + c > 1 && 1 + b > c && 1 + c > b)) return std::nan("");
  const double m2 = 0.5 * (b * b + c * c) - 0.25;
  return m2 > 0 ? xa + 0.5 * std::log(m2) : std::nan("");
}

}  // namespace

int split_edge(RicciMesh& m, int h, Eigen::VectorXd& u) {
  const int t = m.twin[h];
  if (t >= 0 && m.face[t] == m.face[h]) return -1;
  const int h1 = m.next[h], h2 = m.next[h1];
  const int a = m.vert[h], b = m.vert[h1], c = m.vert[h2];
  const double xab = m.log_length(h, u);
  const double xmc = log_median(xab, m.log_length(h1, u), m.log_length(h2, u));
  if (!std::isfinite(xmc)) return -1;
  int t1 = -1, t2 = -1, d = -1;
  double xmd = 0;
  if (t >= 0) {
    t1 = m.next[t];
    t2 = m.next[t1];
    d = m.vert[t2];
    xmd = log_median(xab, m.log_length(t1, u), m.log_length(t2, u));
    if (!std::isfinite(xmd)) return -1;
  }
  const int vm = m.num_vertices++;
  u.conservativeResize(vm + 1);
  u[vm] = 0.5 * (u[a] + u[b]);
  m.boundary_vertex.push_back(t < 0 ? 1 : 0);
  const double xhalf = xab - std::log(2.0);
  auto new_halfedge = [&](int vert, int face, double x, int head) {
    m.next.push_back(-1);
    m.twin.push_back(-1);
    m.vert.push_back(vert);
    m.face.push_back(face);
    m.lambda.push_back(x - 0.5 * (u[vert] + u[head]));
    return static_cast<int>(m.next.size()) - 1;
  };
  const int A = m.face[h];
  const int A2 = m.num_faces();
  m.face_halfedge.push_back(-1);
  // Face A: a->m (h), m->c (e1), c->a (h2). Face A2: m->b (n1), b->c (h1), c->m (e2).
  const int n1 = new_halfedge(vm, A2, xhalf, b);
  const int e1 = new_halfedge(vm, A, xmc, c);
  const int e2 = new_halfedge(c, A2, xmc, vm);
  m.lambda[h] = xhalf - 0.5 * (u[a] + u[vm]);
  m.next[h] = e1;
  m.next[e1] = h2;
  m.next[h2] = h;
  m.next[n1] = h1;
  m.next[h1] = e2;
  m.next[e2] = n1;
  m.face[h1] = A2;
  m.twin[e1] = e2;
  m.twin[e2] = e1;
  m.face_halfedge[A] = h;
  m.face_halfedge[A2] = n1;
  if (t >= 0) {
    const int B = m.face[t];
    const int B2 = m.num_faces();
    m.face_halfedge.push_back(-1);
    // Face B: b->m (t), m->d (f1), d->b (t2). Face B2: m->a (n2), a->d (t1), d->m (f2).
    const int n2 = new_halfedge(vm, B2, xhalf, a);
    const int f1 = new_halfedge(vm, B, xmd, d);
    const int f2 = new_halfedge(d, B2, xmd, vm);
    m.lambda[t] = xhalf - 0.5 * (u[b] + u[vm]);
    m.next[t] = f1;
    m.next[f1] = t2;
    m.next[t2] = t;
    m.next[n2] = t1;
    m.next[t1] = f2;
    m.next[f2] = n2;
    m.face[t1] = B2;
    m.twin[f1] = f2;
    m.twin[f2] = f1;
    m.twin[h] = n2;
    m.twin[n2] = h;
    m.twin[n1] = t;
    m.twin[t] = n1;
    m.face_halfedge[B] = t;
    m.face_halfedge[B2] = n2;
  }
  ++m.connectivity_version;
  return n1;
}

int count_non_delaunay(const RicciMesh& m, const Eigen::VectorXd& u, double tolerance) {
  int count = 0;
  for (int h = 0; h < m.num_halfedges(); ++h)
    if (m.twin[h] > h && m.face[h] != m.face[m.twin[h]] && cos_sum(m, h, u) < -tolerance) ++count;
  return count;
}

}  // namespace polycube::ricci
