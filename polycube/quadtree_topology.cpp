#include "polycube/quadtree_topology.h"

#include "polycube/quadtree_raster.h"

#include <numeric>

namespace polycube {

namespace {

struct DisjointSets {
  std::vector<int> parent;
  explicit DisjointSets(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

}  // namespace

std::string check_section_topology(const PlaneSection& section, const std::vector<QuadLeaf>& leaves,
                                   std::vector<char>& mark) {
  const QuadRaster raster = rasterize({&leaves});
  const int nx = raster.nx(), ny = raster.ny(), nf = section.num_faces();
  mark.assign(leaves.size(), 0);
  std::string problem;
  auto note = [&](const std::string& text) {
    if (problem.empty()) problem = text;
  };
  auto label = [&](int cx, int cy) {
    const int l = raster.leaf_at(0, cx, cy);
    return l < 0 ? 0 : leaves[l].face;
  };
  auto mark_cell = [&](int cx, int cy) {
    const int l = raster.leaf_at(0, cx, cy);
    if (l >= 0) mark[l] = 1;
  };

  // Components of every face (4-connected; the outside joins the padding ring).
  const int border = nx * ny;
  DisjointSets sets(nx * ny + 1);
  for (int cy = 0; cy < ny; ++cy)
    for (int cx = 0; cx < nx; ++cx) {
      const int f = label(cx, cy), id = cy * nx + cx;
      if (cx + 1 < nx && label(cx + 1, cy) == f) sets.unite(id, id + 1);
      if (cy + 1 < ny && label(cx, cy + 1) == f) sets.unite(id, id + nx);
      if (f == 0 && (cx == 0 || cy == 0 || cx == nx - 1 || cy == ny - 1)) sets.unite(id, border);
    }
  std::vector<int> root(nf, -1);
  std::vector<char> split_face(nf, 0);
  root[0] = sets.find(border);
  for (int cy = 0; cy < ny; ++cy)
    for (int cx = 0; cx < nx; ++cx) {
      const int f = label(cx, cy), r = sets.find(cy * nx + cx);
      if (root[f] < 0) root[f] = r;
      else if (root[f] != r) split_face[f] = 1;
    }
  for (int f = 0; f < nf; ++f) {
    if (root[f] >= 0 && !split_face[f]) continue;
    note(root[f] < 0 ? "face " + std::to_string(f) + " (" + (section.face_solid[f] ? "region" : "hole") +
                           ") has no cell"
                     : "the cells of face " + std::to_string(f) + " are not connected");
    for (size_t l = 0; l < leaves.size(); ++l)
      if (leaves[l].face != f && leaves[l].area_of(f) > 0) mark[l] = 1;
  }

  // Cells of faces no contour separates must not touch, not even at a corner.
  const int offsets[4][2] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}};
  for (int cy = -1; cy <= ny; ++cy)
    for (int cx = -1; cx <= nx; ++cx) {
      const int a = label(cx, cy);
      for (const auto& d : offsets) {
        const int ox = cx + d[0], oy = cy + d[1];
        if (ox < -1 || ox > nx || oy > ny) continue;
        const int b = label(ox, oy);
        if (a == b || section.contour_between(a, b) >= 0) continue;
        note("faces " + std::to_string(a) + " and " + std::to_string(b) + " touch");
        mark_cell(cx, cy);
        mark_cell(ox, oy);
      }
    }

  // No vertex with solid and empty cells alternating around it.
  for (int vy = 0; vy <= ny; ++vy)
    for (int vx = 0; vx <= nx; ++vx) {
      const bool sw = section.face_solid[label(vx - 1, vy - 1)], se = section.face_solid[label(vx, vy - 1)];
      const bool ne = section.face_solid[label(vx, vy)], nw = section.face_solid[label(vx - 1, vy)];
      if (sw == ne && se == nw && sw != se) {
        note("cells touch diagonally only");
        mark_cell(vx - 1, vy - 1);
        mark_cell(vx, vy - 1);
        mark_cell(vx, vy);
        mark_cell(vx - 1, vy);
      }
    }
  return problem;
}

}  // namespace polycube
