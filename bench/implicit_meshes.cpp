// Closed meshes of implicit surfaces, made by CGAL's surface mesher: shapes no one tuned polycube
// on (springs with tight coils, a thin sheet, plates with 4 and 16 holes, crossed rings, a
// gyroid ball of genus 8, two spheres almost touching; since the thirtieth session also a torus
// knot, linked rings, a rounded and a drilled cube, spikes, tentacles, a thin bowl). Built and run by
// bench/make_implicit_meshes.sh; the results are in bench/unseen.md.
//
// Usage: implicit_meshes NAME SIZE OUT.off
//   NAME  one of the shapes below; SIZE  the mesher's largest Delaunay ball radius (its distance
//   bound is a quarter of that), in the shape's units (about 1).
#include <CGAL/Complex_2_in_triangulation_3.h>
#include <CGAL/IO/facets_in_complex_2_to_triangle_mesh.h>
#include <CGAL/Implicit_surface_3.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_default_criteria_3.h>
#include <CGAL/Surface_mesh_default_triangulation_3.h>
#include <CGAL/make_surface_mesh.h>
#include <CGAL/Random.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace {

using Tr = CGAL::Surface_mesh_default_triangulation_3;
using GT = Tr::Geom_traits;
using Point = GT::Point_3;
using Vec = std::array<double, 3>;

// Negative inside.
std::function<double(double, double, double)> field;
GT::FT evaluate(Point p) { return field(p.x(), p.y(), p.z()); }

double segment_distance(const Vec& p, const Vec& a, const Vec& b) {
  const Vec d{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double t = ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1] + (p[2] - a[2]) * d[2]) / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  t = std::clamp(t, 0.0, 1.0);
  const Vec e{p[0] - a[0] - t * d[0], p[1] - a[1] - t * d[1], p[2] - a[2] - t * d[2]};
  return std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
}

// Distance to a polyline.
double polyline_distance(const std::vector<Vec>& line, const Vec& p) {
  double d = INFINITY;
  for (size_t i = 0; i + 1 < line.size(); ++i) d = std::min(d, segment_distance(p, line[i], line[i + 1]));
  return d;
}

// Smooth minimum (polynomial, blend width k).
double smooth_min(double a, double b, double k) {
  const double h = std::max(k - std::fabs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

std::vector<Vec> helix(int turns, double height, int samples) {
  std::vector<Vec> line;
  for (int i = 0; i <= samples; ++i) {
    const double t = 2 * M_PI * turns * i / samples;
    line.push_back({std::cos(t), std::sin(t), -height / 2 + height * i / samples});
  }
  return line;
}

struct Shape {
  std::function<double(double, double, double)> field;
  Vec inside;     // a point inside (the mesher starts there)
  double radius;  // a ball round `inside` holding the whole shape
};

std::map<std::string, Shape> shapes() {
  std::map<std::string, Shape> s;
  static const std::vector<Vec> spring = helix(4, 3.2, 400), tight = helix(6, 2.4, 600);
  static const std::vector<Vec> hook = [] {
    std::vector<Vec> line;
    for (int i = 0; i <= 200; ++i) {
      const double t = 1.5 * M_PI * i / 200;
      line.push_back({std::cos(t), std::sin(t), 0.3 * std::sin(2 * t)});
    }
    return line;
  }();
  // 4 coils, tube radius 0.22, 0.36 apart.
  s["spring"] = {[](double x, double y, double z) { return polyline_distance(spring, {x, y, z}) - 0.22; }, spring[0], 5};
  // 6 coils, tube radius 0.17, 0.06 apart (1.4 % of the diagonal).
  s["tightspring"] = {[](double x, double y, double z) { return polyline_distance(tight, {x, y, z}) - 0.17; }, tight[0], 5};
  s["hook"] = {[](double x, double y, double z) { return polyline_distance(hook, {x, y, z}) - 0.18; }, hook[0], 2.5};
  // 40 : 2 : 3 ellipsoid.
  s["needle"] = {[](double x, double y, double z) { return x * x / 4 + y * y / 0.01 + z * z / 0.0225 - 1; }, {0, 0, 0}, 2.5};
  // A sphere with 6 × 6 bumps.
  s["bumpy"] = {[](double x, double y, double z) {
                  const double r = std::sqrt(x * x + y * y + z * z);
                  const double theta = std::acos(z / std::max(r, 1e-12)), phi = std::atan2(y, x);
                  return r - (1 + 0.12 * std::sin(6 * theta) * std::sin(6 * phi));
                },
                {0, 0, 0}, 2};
  // A torus whose tube is 1/15 of its radius.
  s["thinring"] = {[](double x, double y, double z) {
                     const double q = std::sqrt(x * x + y * y) - 1.5;
                     return std::sqrt(q * q + z * z) - 0.1;
                   },
                   {1.5, 0, 0}, 3.5};
  // Two tori in perpendicular planes through one centre, blended (genus 3).
  s["crossrings"] = {[](double x, double y, double z) {
                       const double q = std::sqrt(x * x + y * y) - 1, a = std::sqrt(q * q + z * z) - 0.25;
                       const double r = std::sqrt(x * x + z * z) - 1, b = std::sqrt(r * r + y * y) - 0.25;
                       return smooth_min(a, b, 0.15);
                     },
                     {1, 0, 0}, 3};
  // A ball, two smaller balls and a thin rod, blended (genus 0).
  s["blob3"] = {[](double x, double y, double z) {
                  const double a = std::sqrt(x * x + y * y + z * z) - 0.8;
                  const double b = std::sqrt((x - 1.3) * (x - 1.3) + y * y + z * z) - 0.5;
                  const double c = std::sqrt(x * x + (y - 1.2) * (y - 1.2) + (z - 0.5) * (z - 0.5)) - 0.45;
                  const double d = segment_distance({x, y, z}, {0, 0, 0}, {-1.8, -0.6, 1.0}) - 0.12;
                  return smooth_min(smooth_min(smooth_min(a, b, 0.3), c, 0.3), d, 0.2);
                },
                {0, 0, 0}, 3};
  // A rounded plate with 4 holes in a row (genus 4), and a square one with 4 × 4 (genus 16).
  s["plate4"] = {[](double x, double y, double z) {
                   const double box = std::pow(std::pow(x / 2, 8) + std::pow(y / 0.8, 8) + std::pow(z / 0.3, 8), 1.0 / 8) - 1;
                   double hole = INFINITY;
                   for (int i = 0; i < 4; ++i) hole = std::min(hole, std::sqrt((x - (-1.5 + i)) * (x - (-1.5 + i)) + y * y) - 0.28);
                   return std::max(box, -hole);
                 },
                 {-1, 0, 0}, 3.5};
  s["plate16"] = {[](double x, double y, double z) {
                    const double box = std::pow(std::pow(x / 2, 8) + std::pow(y / 2, 8) + std::pow(z / 0.25, 8), 1.0 / 8) - 1;
                    double hole = INFINITY;
                    for (int i = 0; i < 4; ++i)
                      for (int j = 0; j < 4; ++j) {
                        const double hx = -1.5 + i, hy = -1.5 + j;
                        hole = std::min(hole, std::sqrt((x - hx) * (x - hx) + (y - hy) * (y - hy)) - 0.3);
                      }
                    return std::max(box, -hole);
                  },
                  {-1, 0, 0}, 4};
  // A thin disk: 100 : 75 : 2 (a leaf or a sheet).
  s["sheet"] = {[](double x, double y, double z) { return std::pow(x * x / 4 + y * y / 2.25, 2) + z * z / 0.0016 - 1; }, {0, 0, 0}, 2.5};
  // Two unit spheres 0.04 apart (0.9 % of the diagonal), joined by a bridge above the gap.
  s["neargap"] = {[](double x, double y, double z) {
                    const double a = std::sqrt((x + 1.02) * (x + 1.02) + y * y + z * z) - 1;
                    const double b = std::sqrt((x - 1.02) * (x - 1.02) + y * y + z * z) - 1;
                    double u = std::min(a, b);
                    if (std::fabs(x) < 1.2) u = smooth_min(u, std::sqrt(y * y + (z - 0.9) * (z - 0.9)) - 0.15, 0.1);
                    return u;
                  },
                  {-1, 0, 0}, 3.5};
  // A gyroid cut by a ball (genus 8).
  s["gyroid"] = {[](double x, double y, double z) {
                   const double g = std::sin(3 * x) * std::cos(3 * y) + std::sin(3 * y) * std::cos(3 * z) + std::sin(3 * z) * std::cos(3 * x);
                   return std::max(g - 0.5, std::sqrt(x * x + y * y + z * z) - 1.6);
                 },
                 {0, 0, 0}, 2};
  // Second batch (2026-12-06, thirtieth session).
  // A (2, 5) torus knot, tube radius 0.22 (genus 1, knotted).
  static const std::vector<Vec> knot25 = [] {
    std::vector<Vec> line;
    for (int i = 0; i <= 1000; ++i) {
      const double t = 2 * M_PI * i / 1000, r = 2 + std::cos(5 * t);
      line.push_back({r * std::cos(2 * t), r * std::sin(2 * t), -std::sin(5 * t)});
    }
    return line;
  }();
  s["knot25"] = {[](double x, double y, double z) { return polyline_distance(knot25, {x, y, z}) - 0.22; }, knot25[0], 7};
  // A superquadric cube |x|^10 + |y|^10 + |z|^10 = 1: flat faces, rounded edges (CAD-like).
  s["roundcube"] = {[](double x, double y, double z) {
                      return std::pow(std::pow(x, 10) + std::pow(y, 10) + std::pow(z, 10), 0.1) - 1;
                    },
                    {0, 0, 0}, 2.5};
  // The same cube drilled through along each axis by a square tunnel (genus 5).
  s["drilledcube"] = {[](double x, double y, double z) {
                        const double box = std::pow(std::pow(x, 10) + std::pow(y, 10) + std::pow(z, 10), 0.1) - 1;
                        const auto tunnel = [](double a, double b) { return std::pow(std::pow(a / 0.4, 8) + std::pow(b / 0.4, 8), 1.0 / 8) - 1; };
                        return std::max(box, -0.4 * std::min({tunnel(x, y), tunnel(y, z), tunnel(z, x)}));
                      },
                      {0.7, 0.7, 0.7}, 3.5};
  // A ball with 14 thin spikes (to the cube's corners and faces), tapering to their tips.
  s["spiky"] = {[](double x, double y, double z) {
                  double d = std::sqrt(x * x + y * y + z * z) - 0.7;
                  std::vector<Vec> tips;
                  for (int i = -1; i <= 1; i += 2)
                    for (int j = -1; j <= 1; j += 2)
                      for (int k = -1; k <= 1; k += 2) tips.push_back({0.95 * i, 0.95 * j, 0.95 * k});
                  for (int a = 0; a < 3; ++a)
                    for (int sign = -1; sign <= 1; sign += 2) {
                      Vec t{0, 0, 0};
                      t[a] = 1.65 * sign;
                      tips.push_back(t);
                    }
                  for (const Vec& t : tips) {
                    const double len = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
                    const double u = std::clamp((x * t[0] + y * t[1] + z * t[2]) / (len * len), 0.0, 1.0);
                    d = smooth_min(d, segment_distance({x, y, z}, {0, 0, 0}, t) - (0.16 - 0.13 * u), 0.1);
                  }
                  return d;
                },
                {0, 0, 0}, 2.5};
  // A body with 6 thin curling tentacles (tube radius 0.07).
  static const std::vector<std::vector<Vec>> tentacles = [] {
    std::vector<std::vector<Vec>> all;
    for (int k = 0; k < 6; ++k) {
      std::vector<Vec> line;
      const double a = 2 * M_PI * k / 6;
      for (int i = 0; i <= 120; ++i) {
        const double t = i / 120.0, r = 0.5 + 1.6 * t, swirl = a + 1.2 * t * t;
        line.push_back({r * std::cos(swirl), r * std::sin(swirl), -0.3 - 0.8 * t + 0.6 * t * t * std::sin(3 * t + k)});
      }
      all.push_back(line);
    }
    return all;
  }();
  s["octopus"] = {[](double x, double y, double z) {
                    double d = std::sqrt(x * x + y * y + (z - 0.2) * (z - 0.2) / 1.6) - 0.7;
                    for (const auto& line : tentacles) d = smooth_min(d, polyline_distance(line, {x, y, z}) - 0.07, 0.08);
                    return d;
                  },
                  {0, 0, 0}, 3};
  // A hemispherical bowl 0.08 thick with a rounded rim (genus 0, two close sheets).
  s["bowl"] = {[](double x, double y, double z) {
                 const double r = std::sqrt(x * x + y * y + z * z);
                 const double shell = std::fabs(r - 1) - 0.04;
                 if (z <= 0) return shell;
                 const double q = std::sqrt(x * x + y * y) - 1;  // past the rim: distance to the rim circle
                 return std::sqrt(q * q + z * z) - 0.04;
               },
               {0, 0, -1}, 2};
  // Two linked rings joined by a bridge (genus 2, the handles linked).
  s["linked"] = {[](double x, double y, double z) {
                   const double q = std::sqrt(x * x + y * y) - 1, a = std::sqrt(q * q + z * z) - 0.2;
                   const double r = std::sqrt((x - 1) * (x - 1) + z * z) - 1, b = std::sqrt(r * r + y * y) - 0.2;
                   const double bridge = segment_distance({x, y, z}, {-1, 0, 0}, {0, 0, 0}) - 0.12;
                   return smooth_min(std::min(a, b), bridge, 0.1);
                 },
                 {-1, 0, 0}, 4};
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  const auto all = shapes();
  if (argc != 4 || !all.count(argv[1])) {
    std::fprintf(stderr, "usage: implicit_meshes NAME SIZE OUT.off; NAME one of:");
    for (const auto& [name, shape] : all) std::fprintf(stderr, " %s", name.c_str());
    std::fprintf(stderr, "\n");
    return 2;
  }
  // The mesher's initial points are random, and CGAL seeds its default generator from the clock.
  CGAL::get_default_random() = CGAL::Random(1);
  const Shape& shape = all.at(argv[1]);
  const double size = std::stod(argv[2]);
  field = shape.field;
  Tr triangulation;
  CGAL::Complex_2_in_triangulation_3<Tr> complex(triangulation);
  const CGAL::Implicit_surface_3<GT, GT::FT (*)(Point)> surface(
      evaluate, GT::Sphere_3(Point(shape.inside[0], shape.inside[1], shape.inside[2]), shape.radius * shape.radius));
  const CGAL::Surface_mesh_default_criteria_3<Tr> criteria(30., size, size / 4);
  CGAL::make_surface_mesh(complex, surface, criteria, CGAL::Manifold_tag());
  CGAL::Surface_mesh<Point> mesh;
  CGAL::facets_in_complex_2_to_triangle_mesh(complex, mesh);
  std::ofstream out(argv[3]);
  out.precision(12);
  out << mesh;
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", argv[3]);
    return 1;
  }
  std::printf("%s: %zu vertices, %zu faces\n", argv[1], static_cast<size_t>(mesh.number_of_vertices()),
              static_cast<size_t>(mesh.number_of_faces()));
  return 0;
}
