#include "polycube/polycube_surface.h"

#include "polycube/errors.h"
#include "polycube/quadtree_raster.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <list>
#include <map>
#include <sstream>
#include <unordered_map>

namespace polycube {

namespace {

// A point of the polycube's integer lattice: x and y in quadtree units, z as a level index.
using Int3 = std::array<int64_t, 3>;

constexpr double kUnit = 1.0 / kQuadGridSize;

// ---- connected regions of a 2D raster and their boundary loops ----------------------------------

// Components of equal non-zero value (4-connected) of an nu x nv raster, with their boundary
// loops as raster vertices (u, v) at the corners, the region on the left (counter-clockwise
// around it in (u, v)). Where a component touches itself at a vertex, the loops turn left there,
// so each loop is simple (loops may share such a vertex).
struct RasterRegions {
  int nu = 0, nv = 0;
  std::vector<int> component;  // per cell (cv * nu + cu): its component, -1 for value 0
  std::vector<int> value;      // per component
  std::vector<std::vector<std::vector<std::array<int, 2>>>> loops;  // per component
  // Per component and loop: the cells left (inside) and right of the loop's first edge.
  std::vector<std::vector<std::array<int, 4>>> first_cells;
};

RasterRegions trace_regions(int nu, int nv, const std::vector<int>& values) {
  RasterRegions r;
  r.nu = nu;
  r.nv = nv;
  r.component.assign(static_cast<size_t>(nu) * nv, -1);
  std::vector<int> stack;
  for (int c = 0; c < nu * nv; ++c) {
    if (values[c] == 0 || r.component[c] >= 0) continue;
    const int id = static_cast<int>(r.value.size());
    r.value.push_back(values[c]);
    r.component[c] = id;
    stack.push_back(c);
    while (!stack.empty()) {
      const int d = stack.back();
      stack.pop_back();
      const int du = d % nu, dv = d / nu;
      const int neighbours[4][2] = {{du - 1, dv}, {du + 1, dv}, {du, dv - 1}, {du, dv + 1}};
      for (const auto& n : neighbours) {
        if (n[0] < 0 || n[1] < 0 || n[0] >= nu || n[1] >= nv) continue;
        const int e = n[1] * nu + n[0];
        if (values[e] != values[c] || r.component[e] >= 0) continue;
        r.component[e] = id;
        stack.push_back(e);
      }
    }
  }
  const int num_components = static_cast<int>(r.value.size());
  r.loops.resize(num_components);
  r.first_cells.resize(num_components);

  // Unit boundary steps, counter-clockwise around the cells of each component.
  struct Step {
    int from, to, component;
    std::array<int, 4> cells;  // left u, v, right u, v
  };
  const int row = nu + 1;
  auto vid = [row](int u, int v) { return v * row + u; };
  auto comp_at = [&](int u, int v) { return u < 0 || v < 0 || u >= nu || v >= nv ? -1 : r.component[v * nu + u]; };
  std::vector<Step> steps;
  for (int cv = 0; cv < nv; ++cv)
    for (int cu = 0; cu < nu; ++cu) {
      const int k = r.component[cv * nu + cu];
      if (k < 0) continue;
      if (comp_at(cu, cv - 1) != k) steps.push_back({vid(cu, cv), vid(cu + 1, cv), k, {cu, cv, cu, cv - 1}});
      if (comp_at(cu + 1, cv) != k) steps.push_back({vid(cu + 1, cv), vid(cu + 1, cv + 1), k, {cu, cv, cu + 1, cv}});
      if (comp_at(cu, cv + 1) != k) steps.push_back({vid(cu + 1, cv + 1), vid(cu, cv + 1), k, {cu, cv, cu, cv + 1}});
      if (comp_at(cu - 1, cv) != k) steps.push_back({vid(cu, cv + 1), vid(cu, cv), k, {cu, cv, cu - 1, cv}});
    }
  std::unordered_map<int, std::vector<int>> outgoing;
  for (int s = 0; s < static_cast<int>(steps.size()); ++s) outgoing[steps[s].from].push_back(s);
  auto direction = [&](const Step& s) {
    return std::array<int, 2>{s.to % row - s.from % row, s.to / row - s.from / row};
  };
  std::vector<char> used(steps.size(), 0);
  std::vector<int> vertices;
  for (int s0 = 0; s0 < static_cast<int>(steps.size()); ++s0) {
    if (used[s0]) continue;
    vertices.clear();
    int s = s0;
    while (true) {
      used[s] = 1;
      vertices.push_back(steps[s].from);
      const std::array<int, 2> d = direction(steps[s]);
      int next = -1;
      for (int t : outgoing[steps[s].to]) {
        if (steps[t].component != steps[s].component) continue;
        if (next < 0) {
          next = t;
          continue;
        }
        const std::array<int, 2> e = direction(steps[t]);
        if (d[0] * e[1] - d[1] * e[0] > 0) next = t;  // two ways on: take the left turn
      }
      if (next < 0) throw AlgorithmError("build_polycube_surface: open boundary while tracing a face");
      if (next == s0) break;
      if (used[next]) throw AlgorithmError("build_polycube_surface: boundary loops of a face cross");
      s = next;
    }
    // Keep the corners.
    std::vector<std::array<int, 2>> loop;
    const int n = static_cast<int>(vertices.size());
    for (int i = 0; i < n; ++i) {
      const int a = vertices[(i + n - 1) % n], b = vertices[i], c = vertices[(i + 1) % n];
      const int d0u = b % row - a % row, d0v = b / row - a / row, d1u = c % row - b % row, d1v = c / row - b / row;
      if (d0u == d1u && d0v == d1v) continue;
      loop.push_back({b % row, b / row});
    }
    const int k = steps[s0].component;
    r.loops[k].push_back(std::move(loop));
    r.first_cells[k].push_back(steps[s0].cells);
  }
  return r;
}

// ---- the stacked solid's faces --------------------------------------------------------------------

// Faces on one axis-aligned plane, found on a raster of that plane.
//   axis        normal axis; key its coordinate (level index for z, quadtree units otherwise)
//   u_axis, v_axis  the 3D axes of the raster's u and v
//   u_int, v_int    raster lines in lattice coordinates; u_in, v_in the same in input coordinates
struct Group {
  int axis = 2;
  int64_t key = 0;
  int u_axis = 0, v_axis = 1;
  std::vector<int64_t> u_int, v_int;
  std::vector<double> u_in, v_in;
  RasterRegions regions;
};

struct Face {
  int group = -1;
  int component = -1;
  int axis = 2;
  int sign = 1;
  std::vector<std::vector<Int3>> loops;  // corners, the face on the left seen from outside
};

struct AtomicEdge {
  int faces[2] = {-1, -1};  // the face using it from its smaller to its larger end, and the other
  std::vector<int> points;  // mesh vertices from the smaller end to the larger
};

// CGAL constrained Delaunay triangulation with a mesh vertex id per vertex and a nesting depth
// per face (odd: inside the polygon).
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<int, Kernel>;
struct FaceInfo {
  int nesting = -1;
};
using FaceBaseInfo = CGAL::Triangulation_face_base_with_info_2<FaceInfo, Kernel>;
using FaceBase = CGAL::Constrained_triangulation_face_base_2<Kernel, FaceBaseInfo>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::No_constraint_intersection_tag>;

// Nesting depth of every face: 0 outside, +1 across each constraint.
void mark_nesting(Cdt& cdt) {
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info().nesting = -1;
  std::list<Cdt::Edge> border;
  auto flood = [&](Cdt::Face_handle start, int depth) {
    if (start->info().nesting != -1) return;
    std::vector<Cdt::Face_handle> queue{start};
    start->info().nesting = depth;
    while (!queue.empty()) {
      const Cdt::Face_handle f = queue.back();
      queue.pop_back();
      for (int i = 0; i < 3; ++i) {
        const Cdt::Face_handle n = f->neighbor(i);
        if (n->info().nesting != -1) continue;
        if (cdt.is_constrained(Cdt::Edge(f, i))) {
          border.push_back(Cdt::Edge(f, i));
        } else {
          n->info().nesting = depth;
          queue.push_back(n);
        }
      }
    }
  };
  flood(cdt.infinite_face(), 0);
  while (!border.empty()) {
    const Cdt::Edge e = border.front();
    border.pop_front();
    const Cdt::Face_handle n = e.first->neighbor(e.second);
    if (n->info().nesting == -1) flood(n, e.first->info().nesting + 1);
  }
}

class SurfaceBuilder {
 public:
  SurfaceBuilder(const CrossSections& sections, const std::vector<std::vector<QuadLeaf>>& leaves, double z_min,
                 double z_max, const PolycubeSurfaceOptions& options)
      : sections_(sections), leaves_(leaves), options_(options), avoid_z_(options.avoid_z) {
    std::sort(avoid_z_.begin(), avoid_z_.end());
    const int n = static_cast<int>(sections.planes.size());
    levels_.push_back(z_min);
    for (int i = 1; i < n; ++i) levels_.push_back(0.5 * (sections.planes[i - 1].z + sections.planes[i].z));
    levels_.push_back(z_max);
    for (size_t j = 0; j + 1 < levels_.size(); ++j)
      if (!(levels_[j] < levels_[j + 1]) || (j < static_cast<size_t>(n) && !(levels_[j] < sections.planes[j].z &&
                                                                             sections.planes[j].z < levels_[j + 1])))
        throw AlgorithmError("build_polycube_surface: the planes are too close to separate their extrusions");
  }

  Polycube build() {
    Polycube result;
    result.levels = levels_;
    collect_walls_and_sections(result);
    collect_horizontal_faces();
    collect_wall_faces();
    split_at_breakpoints();
    place_vertices(result);
    triangulate(result);
    return result;
  }

 private:
  double lattice_to_input(int axis, int64_t value) const {
    if (axis == 2) return levels_[value];
    return sections_.frame.origin[axis] + sections_.frame.scale * (static_cast<double>(value) * kUnit);
  }
  Eigen::Vector3d position(const Int3& p) const {
    return {lattice_to_input(0, p[0]), lattice_to_input(1, p[1]), lattice_to_input(2, p[2])};
  }
  bool solid(int plane, int face) const { return sections_.planes[plane].face_solid[face] != 0; }

  // Walls: per plane, the boundary of Q_i on its own raster, as intervals per grid line. Also the
  // loops of Q_i for the report.
  struct Interval {
    int layer;
    int64_t lo, hi;
    int sign;
  };
  void collect_walls_and_sections(Polycube& result) {
    const int n = static_cast<int>(leaves_.size());
    result.sections.resize(n);
    for (int i = 0; i < n; ++i) {
      const PlaneSection& section = sections_.planes[i];
      const QuadRaster raster = rasterize({&leaves_[i]});
      const int nx = raster.nx(), ny = raster.ny();
      auto face_at = [&](int cx, int cy) {
        const int l = raster.leaf_at(0, cx, cy);
        return l < 0 ? 0 : leaves_[i][l].face;
      };
      auto in = [&](int cx, int cy) { return solid(i, face_at(cx, cy)); };
      // x-walls (normal +-x) on vertical lines, merged along y.
      for (int k = 0; k <= nx; ++k) {
        int start = -1, sign = 0;
        for (int cy = 0; cy <= ny; ++cy) {
          int s = 0;
          if (cy < ny && in(k - 1, cy) != in(k, cy)) s = in(k - 1, cy) ? 1 : -1;
          if (s != sign) {
            if (sign != 0) x_walls_[raster.xs[k]].push_back({i, raster.ys[start], raster.ys[cy], sign});
            start = cy;
            sign = s;
          }
        }
      }
      for (int k = 0; k <= ny; ++k) {
        int start = -1, sign = 0;
        for (int cx = 0; cx <= nx; ++cx) {
          int s = 0;
          if (cx < nx && in(cx, k - 1) != in(cx, k)) s = in(cx, k - 1) ? 1 : -1;
          if (s != sign) {
            if (sign != 0) y_walls_[raster.ys[k]].push_back({i, raster.xs[start], raster.xs[cx], sign});
            start = cx;
            sign = s;
          }
        }
      }
      // Loops of Q_i with the contours they stand for.
      std::vector<int> values(static_cast<size_t>(nx) * ny);
      for (int cy = 0; cy < ny; ++cy)
        for (int cx = 0; cx < nx; ++cx) values[cy * nx + cx] = in(cx, cy) ? 1 : 0;
      const RasterRegions regions = trace_regions(nx, ny, values);
      for (size_t k = 0; k < regions.loops.size(); ++k)
        for (size_t l = 0; l < regions.loops[k].size(); ++l) {
          SectionPolygon polygon;
          for (const auto& p : regions.loops[k][l])
            polygon.points.emplace_back(lattice_to_input(0, raster.xs[p[0]]), lattice_to_input(1, raster.ys[p[1]]));
          const auto& cells = regions.first_cells[k][l];
          const int local = section.contour_between(face_at(cells[0], cells[1]), face_at(cells[2], cells[3]));
          polygon.contour = local < 0 ? -1 : section.contours[local];
          result.sections[i].push_back(std::move(polygon));
        }
    }
  }

  void add_faces(Group&& group) {
    const int g = static_cast<int>(groups_.size());
    groups_.push_back(std::move(group));
    const Group& gr = groups_.back();
    // Traced counter-clockwise in (u, v), i.e. seen from e_u x e_v.
    const int seen_from = (gr.u_axis == 0 && gr.v_axis == 2) ? -1 : 1;
    for (size_t k = 0; k < gr.regions.loops.size(); ++k) {
      Face face;
      face.group = g;
      face.component = static_cast<int>(k);
      face.axis = gr.axis;
      face.sign = gr.regions.value[k];
      for (const auto& loop : gr.regions.loops[k]) {
        std::vector<Int3> points;
        for (const auto& p : loop) {
          Int3 q;
          q[gr.axis] = gr.key;
          q[gr.u_axis] = gr.u_int[p[0]];
          q[gr.v_axis] = gr.v_int[p[1]];
          points.push_back(q);
        }
        if (face.sign != seen_from) std::reverse(points.begin(), points.end());
        face.loops.push_back(std::move(points));
      }
      faces_.push_back(std::move(face));
    }
  }

  // Horizontal faces at each level: Q_{j-1} \ Q_j faces up, Q_j \ Q_{j-1} down.
  void collect_horizontal_faces() {
    const int n = static_cast<int>(leaves_.size());
    static const std::vector<QuadLeaf> nothing(1);
    for (int j = 0; j <= n; ++j) {
      const std::vector<QuadLeaf>& lo = j > 0 ? leaves_[j - 1] : nothing;
      const std::vector<QuadLeaf>& hi = j < n ? leaves_[j] : nothing;
      const QuadRaster raster = rasterize({&lo, &hi});
      const int nx = raster.nx(), ny = raster.ny();
      std::vector<int> values(static_cast<size_t>(nx) * ny, 0);
      bool any = false;
      for (int cy = 0; cy < ny; ++cy)
        for (int cx = 0; cx < nx; ++cx) {
          const bool a = j > 0 && solid(j - 1, lo[raster.leaf_at(0, cx, cy)].face);
          const bool b = j < n && solid(j, hi[raster.leaf_at(1, cx, cy)].face);
          values[cy * nx + cx] = a == b ? 0 : (a ? 1 : -1);
          any = any || a != b;
        }
      if (!any) continue;
      Group group;
      group.axis = 2;
      group.key = j;
      group.u_axis = 0;
      group.v_axis = 1;
      group.u_int.assign(raster.xs.begin(), raster.xs.end());
      group.v_int.assign(raster.ys.begin(), raster.ys.end());
      for (int64_t x : group.u_int) group.u_in.push_back(lattice_to_input(0, x));
      for (int64_t y : group.v_int) group.v_in.push_back(lattice_to_input(1, y));
      group.regions = trace_regions(nx, ny, values);
      add_faces(std::move(group));
    }
  }

  // Vertical faces on each grid line: the wall intervals of all layers on that line.
  void collect_wall_faces() {
    const int n = static_cast<int>(leaves_.size());
    for (int axis : {0, 1}) {
      for (const auto& [line, intervals] : axis == 0 ? x_walls_ : y_walls_) {
        Group group;
        group.axis = axis;
        group.key = line;
        group.u_axis = 1 - axis;
        group.v_axis = 2;
        for (const Interval& iv : intervals) {
          group.u_int.push_back(iv.lo);
          group.u_int.push_back(iv.hi);
        }
        std::sort(group.u_int.begin(), group.u_int.end());
        group.u_int.erase(std::unique(group.u_int.begin(), group.u_int.end()), group.u_int.end());
        for (int j = 0; j <= n; ++j) group.v_int.push_back(j);
        const int nu = static_cast<int>(group.u_int.size()) - 1;
        std::vector<int> values(static_cast<size_t>(nu) * n, 0);
        for (const Interval& iv : intervals) {
          const int a = static_cast<int>(std::lower_bound(group.u_int.begin(), group.u_int.end(), iv.lo) - group.u_int.begin());
          const int b = static_cast<int>(std::lower_bound(group.u_int.begin(), group.u_int.end(), iv.hi) - group.u_int.begin());
          for (int cu = a; cu < b; ++cu) values[iv.layer * nu + cu] = iv.sign;
        }
        for (int64_t u : group.u_int) group.u_in.push_back(lattice_to_input(group.u_axis, u));
        for (int64_t v : group.v_int) group.v_in.push_back(lattice_to_input(2, v));
        group.regions = trace_regions(nu, n, values);
        add_faces(std::move(group));
      }
    }
  }

  // Every corner of every face is a polycube vertex; each face side is split at all of them on
  // its line, so that neighbouring faces share the same atomic edges.
  void split_at_breakpoints() {
    std::map<Int3, std::vector<int64_t>> lines;  // (axis, other two coordinates) -> breakpoints
    auto line_of = [](const Int3& p, int axis) { return Int3{axis, p[(axis + 1) % 3], p[(axis + 2) % 3]}; };
    auto axis_of = [](const Int3& p, const Int3& q) {
      int axis = -1, differ = 0;
      for (int a = 0; a < 3; ++a)
        if (p[a] != q[a]) {
          axis = a;
          ++differ;
        }
      if (differ != 1) throw AlgorithmError("build_polycube_surface: a face side is not axis-aligned");
      return axis;
    };
    for (const Face& face : faces_)
      for (const auto& loop : face.loops)
        for (size_t i = 0; i < loop.size(); ++i) {
          const Int3& p = loop[i];
          const Int3& q = loop[(i + 1) % loop.size()];
          const int axis = axis_of(p, q);
          auto& points = lines[line_of(p, axis)];
          points.push_back(p[axis]);
          points.push_back(q[axis]);
        }
    for (auto& [line, points] : lines) {
      (void)line;
      std::sort(points.begin(), points.end());
      points.erase(std::unique(points.begin(), points.end()), points.end());
    }
    for (int f = 0; f < static_cast<int>(faces_.size()); ++f) {
      Face& face = faces_[f];
      for (auto& loop : face.loops) {
        std::vector<Int3> expanded;
        for (size_t i = 0; i < loop.size(); ++i) {
          const Int3& p = loop[i];
          const Int3& q = loop[(i + 1) % loop.size()];
          const int axis = axis_of(p, q);
          const std::vector<int64_t>& points = lines[line_of(p, axis)];
          const int64_t lo = std::min(p[axis], q[axis]), hi = std::max(p[axis], q[axis]);
          auto first = std::lower_bound(points.begin(), points.end(), lo);
          auto last = std::upper_bound(points.begin(), points.end(), hi);
          std::vector<int64_t> between(first, last);
          if (p[axis] > q[axis]) std::reverse(between.begin(), between.end());
          for (size_t k = 0; k + 1 < between.size(); ++k) {
            Int3 r = p;
            r[axis] = between[k];
            expanded.push_back(r);
          }
        }
        for (size_t i = 0; i < expanded.size(); ++i) {
          const Int3& a = expanded[i];
          const Int3& b = expanded[(i + 1) % expanded.size()];
          AtomicEdge& edge = edges_[a < b ? std::make_pair(a, b) : std::make_pair(b, a)];
          int& slot = edge.faces[a < b ? 0 : 1];
          if (slot >= 0)
            throw AlgorithmError("build_polycube_surface: an edge is used twice in the same direction (non-manifold)");
          slot = f;
        }
        loop = std::move(expanded);
      }
    }
    for (const auto& [ends, edge] : edges_)
      if (edge.faces[0] < 0 || edge.faces[1] < 0) {
        std::ostringstream message;
        message << "build_polycube_surface: the surface is not closed at the edge (" << ends.first[0] << ", "
                << ends.first[1] << ", " << ends.first[2] << ") - (" << ends.second[0] << ", " << ends.second[1]
                << ", " << ends.second[2] << ")";
        throw AlgorithmError(message.str());
      }
  }

  int add_vertex(const Eigen::Vector3d& p) {
    positions_.push_back(p);
    return static_cast<int>(positions_.size()) - 1;
  }

  bool avoided(double z) const { return std::binary_search(avoid_z_.begin(), avoid_z_.end(), z); }

  // Polycube vertices, the spacing h and the points along every atomic edge.
  void place_vertices(Polycube& result) {
    std::map<Int3, std::array<char, 3>> axes;
    for (const auto& [ends, edge] : edges_) {
      (void)edge;
      for (const Int3* p : {&ends.first, &ends.second}) {
        if (!vertex_id_.count(*p)) {
          const Eigen::Vector3d q = position(*p);
          if (avoided(q.z())) throw AlgorithmError("build_polycube_surface: a polycube vertex lies on a cutting plane");
          vertex_id_[*p] = add_vertex(q);
        }
      }
      for (int a = 0; a < 3; ++a)
        if (ends.first[a] != ends.second[a]) axes[ends.first][a] = axes[ends.second][a] = 1;
    }
    for (const auto& [p, id] : vertex_id_) {
      result.vertices.push_back(id);
      const auto& ax = axes[p];
      if (ax[0] && ax[1] && ax[2]) result.corners.push_back(id);
    }
    std::sort(result.vertices.begin(), result.vertices.end());
    std::sort(result.corners.begin(), result.corners.end());

    // h from the target: about area / h^2 lattice points plus length / h boundary points.
    double length = 0, area = 0;
    for (const auto& [ends, edge] : edges_) {
      (void)edge;
      length += (position(ends.second) - position(ends.first)).norm();
    }
    face_area_.assign(faces_.size(), 0.0);
    for (size_t f = 0; f < faces_.size(); ++f) {
      const Group& g = groups_[faces_[f].group];
      for (int cv = 0; cv < g.regions.nv; ++cv)
        for (int cu = 0; cu < g.regions.nu; ++cu)
          if (g.regions.component[cv * g.regions.nu + cu] == faces_[f].component)
            face_area_[f] += (g.u_in[cu + 1] - g.u_in[cu]) * (g.v_in[cv + 1] - g.v_in[cv]);
      area += face_area_[f];
    }
    const double target = std::max(1, options_.target_vertices);
    h_ = (length + std::sqrt(length * length + 4 * target * area)) / (2 * target);
    result.spacing = h_;

    for (auto& [ends, edge] : edges_) {
      const Eigen::Vector3d a = position(ends.first), b = position(ends.second);
      int axis = 0;
      while (ends.first[axis] == ends.second[axis]) ++axis;
      int parts = std::max(1, static_cast<int>(std::ceil((b[axis] - a[axis]) / h_ - 1e-9)));
      auto valid = [&](int count) {
        if (axis != 2) return true;
        for (int k = 1; k < count; ++k)
          if (avoided(a.z() + (b.z() - a.z()) * k / count)) return false;
        return true;
      };
      while (!valid(parts)) ++parts;
      edge.points.push_back(vertex_id_.at(ends.first));
      for (int k = 1; k < parts; ++k) {
        Eigen::Vector3d p = a;
        p[axis] = a[axis] + (b[axis] - a[axis]) * k / parts;
        edge.points.push_back(add_vertex(p));
      }
      edge.points.push_back(vertex_id_.at(ends.second));
      PolycubeEdge out;
      out.vertices = edge.points;
      out.axis = axis;
      out.faces[0] = edge.faces[0];
      out.faces[1] = edge.faces[1];
      result.edges.push_back(std::move(out));
    }
  }

  // Constrained Delaunay triangulation of every face.
  void triangulate(Polycube& result) {
    std::vector<std::array<int, 3>> triangles;
    std::vector<int> patch;
    for (int f = 0; f < static_cast<int>(faces_.size()); ++f) {
      const Face& face = faces_[f];
      const Group& group = groups_[face.group];
      const int a_axis = (face.axis + 1) % 3, b_axis = (face.axis + 2) % 3;
      Cdt cdt;
      std::unordered_map<int, Cdt::Vertex_handle> handle;
      auto insert = [&](int id) {
        auto it = handle.find(id);
        if (it != handle.end()) return it->second;
        const Eigen::Vector3d& p = positions_[id];
        Cdt::Vertex_handle v = cdt.insert(Kernel::Point_2(p[a_axis], p[b_axis]));
        v->info() = id;
        handle.emplace(id, v);
        return v;
      };
      // Boundary segments, also bucketed for the distance test of lattice points.
      std::vector<std::array<int, 2>> segments;
      for (const auto& loop : face.loops)
        for (size_t i = 0; i < loop.size(); ++i) {
          const Int3& p = loop[i];
          const Int3& q = loop[(i + 1) % loop.size()];
          const AtomicEdge& edge = edges_.at(p < q ? std::make_pair(p, q) : std::make_pair(q, p));
          for (size_t k = 0; k + 1 < edge.points.size(); ++k) segments.push_back({edge.points[k], edge.points[k + 1]});
        }
      try {
        for (const auto& s : segments) cdt.insert_constraint(insert(s[0]), insert(s[1]));
      } catch (const std::exception& e) {
        throw AlgorithmError(std::string("build_polycube_surface: boundary of face ") + std::to_string(f) +
                             " cannot be triangulated (" + e.what() + ")");
      }

      double a_min = std::numeric_limits<double>::infinity(), a_max = -a_min, b_min = a_min, b_max = -a_min;
      std::unordered_map<int64_t, std::vector<int>> buckets;
      auto bucket_key = [](int64_t i, int64_t j) { return (i << 32) ^ (j & 0xffffffff); };
      for (int s = 0; s < static_cast<int>(segments.size()); ++s) {
        const Eigen::Vector3d& p = positions_[segments[s][0]];
        const Eigen::Vector3d& q = positions_[segments[s][1]];
        a_min = std::min({a_min, p[a_axis], q[a_axis]});
        a_max = std::max({a_max, p[a_axis], q[a_axis]});
        b_min = std::min({b_min, p[b_axis], q[b_axis]});
        b_max = std::max({b_max, p[b_axis], q[b_axis]});
        const int64_t i0 = static_cast<int64_t>(std::floor(std::min(p[a_axis], q[a_axis]) / h_));
        const int64_t i1 = static_cast<int64_t>(std::floor(std::max(p[a_axis], q[a_axis]) / h_));
        const int64_t j0 = static_cast<int64_t>(std::floor(std::min(p[b_axis], q[b_axis]) / h_));
        const int64_t j1 = static_cast<int64_t>(std::floor(std::max(p[b_axis], q[b_axis]) / h_));
        for (int64_t i = i0; i <= i1; ++i)
          for (int64_t j = j0; j <= j1; ++j) buckets[bucket_key(i, j)].push_back(s);
      }
      auto far_from_boundary = [&](double a, double b) {
        const int64_t i = static_cast<int64_t>(std::floor(a / h_)), j = static_cast<int64_t>(std::floor(b / h_));
        const Eigen::Vector2d x(a, b);
        for (int64_t di = -1; di <= 1; ++di)
          for (int64_t dj = -1; dj <= 1; ++dj) {
            auto it = buckets.find(bucket_key(i + di, j + dj));
            if (it == buckets.end()) continue;
            for (int s : it->second) {
              const Eigen::Vector3d& p3 = positions_[segments[s][0]];
              const Eigen::Vector3d& q3 = positions_[segments[s][1]];
              const Eigen::Vector2d p(p3[a_axis], p3[b_axis]), q(q3[a_axis], q3[b_axis]);
              const double t = std::clamp((x - p).dot(q - p) / (q - p).squaredNorm(), 0.0, 1.0);
              if ((p + t * (q - p) - x).norm() < 0.5 * h_) return false;
            }
          }
        return true;
      };
      auto in_face = [&](const Eigen::Vector3d& p) {
        const double u = p[group.u_axis], v = p[group.v_axis];
        const int cu = static_cast<int>(std::upper_bound(group.u_in.begin(), group.u_in.end(), u) - group.u_in.begin()) - 1;
        const int cv = static_cast<int>(std::upper_bound(group.v_in.begin(), group.v_in.end(), v) - group.v_in.begin()) - 1;
        if (cu < 0 || cv < 0 || cu >= group.regions.nu || cv >= group.regions.nv) return false;
        return group.regions.component[cv * group.regions.nu + cu] == face.component;
      };
      // Interior lattice points.
      const double plane = lattice_to_input(face.axis, face.loops.front().front()[face.axis]);
      Cdt::Face_handle hint;
      for (int64_t i = static_cast<int64_t>(std::ceil(a_min / h_ - 0.5)); (i + 0.5) * h_ < a_max; ++i)
        for (int64_t j = static_cast<int64_t>(std::ceil(b_min / h_ - 0.5)); (j + 0.5) * h_ < b_max; ++j) {
          const double a = (i + 0.5) * h_, b = (j + 0.5) * h_;
          Eigen::Vector3d p;
          p[face.axis] = plane;
          p[a_axis] = a;
          p[b_axis] = b;
          if (!in_face(p) || !far_from_boundary(a, b) || (face.axis != 2 && avoided(p.z()))) continue;
          const Cdt::Vertex_handle v = cdt.insert(Kernel::Point_2(a, b), hint);
          v->info() = add_vertex(p);
          hint = v->face();
        }
      mark_nesting(cdt);
      for (auto fh = cdt.finite_faces_begin(); fh != cdt.finite_faces_end(); ++fh) {
        if (fh->info().nesting % 2 != 1) continue;
        std::array<int, 3> t = {fh->vertex(0)->info(), fh->vertex(1)->info(), fh->vertex(2)->info()};
        if (face.sign < 0) std::swap(t[1], t[2]);
        triangles.push_back(t);
        patch.push_back(f);
      }
      PolycubeFace out;
      out.axis = face.axis;
      out.sign = face.sign;
      out.coordinate = plane;
      out.area = face_area_[f];
      result.faces.push_back(out);
    }
    result.mesh.V.resize(static_cast<Eigen::Index>(positions_.size()), 3);
    for (size_t v = 0; v < positions_.size(); ++v) result.mesh.V.row(v) = positions_[v].transpose();
    result.mesh.F.resize(static_cast<Eigen::Index>(triangles.size()), 3);
    result.face_axis.resize(static_cast<Eigen::Index>(triangles.size()));
    result.face_patch.resize(static_cast<Eigen::Index>(triangles.size()));
    for (size_t t = 0; t < triangles.size(); ++t) {
      result.mesh.F.row(t) << triangles[t][0], triangles[t][1], triangles[t][2];
      const Face& face = faces_[patch[t]];
      result.face_axis[t] = face.sign * (face.axis + 1);
      result.face_patch[t] = patch[t];
    }
  }

  const CrossSections& sections_;
  const std::vector<std::vector<QuadLeaf>>& leaves_;
  const PolycubeSurfaceOptions& options_;
  std::vector<double> avoid_z_;
  std::vector<double> levels_;
  std::map<int64_t, std::vector<Interval>> x_walls_, y_walls_;
  std::vector<Group> groups_;
  std::vector<Face> faces_;
  std::map<std::pair<Int3, Int3>, AtomicEdge> edges_;
  std::map<Int3, int> vertex_id_;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<double> face_area_;
  double h_ = 1;
};

}  // namespace

Polycube build_polycube_surface(const CrossSections& sections, const std::vector<std::vector<QuadLeaf>>& leaves,
                                double z_min, double z_max, const PolycubeSurfaceOptions& options) {
  if (leaves.size() != sections.planes.size())
    throw std::invalid_argument("build_polycube_surface: one quadtree per plane expected");
  if (leaves.empty()) throw std::invalid_argument("build_polycube_surface: at least one plane expected");
  if (!(z_min < z_max)) throw std::invalid_argument("build_polycube_surface: z_min must be below z_max");
  return SurfaceBuilder(sections, leaves, z_min, z_max, options).build();
}

}  // namespace polycube
