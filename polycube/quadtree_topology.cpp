#include "polycube/quadtree_topology.h"

#include "polycube/disjoint_sets.h"
#include "polycube/quadtree_raster.h"

#include <cmath>
#include <map>

namespace polycube {

namespace {

// The 4-connected components of equal face among the raster's cells (cell (cx, cy) is element
// cy * nx + cx); the outside face's cells on the border of the unit square join element nx * ny,
// which stands for the padding ring.
template <typename Label>
DisjointSets face_components(int nx, int ny, const Label& label) {
  const int border = nx * ny;
  DisjointSets sets(nx * ny + 1);
  for (int cy = 0; cy < ny; ++cy)
    for (int cx = 0; cx < nx; ++cx) {
      const int f = label(cx, cy), id = cy * nx + cx;
      if (cx + 1 < nx && label(cx + 1, cy) == f) sets.unite(id, id + 1);
      if (cy + 1 < ny && label(cx, cy + 1) == f) sets.unite(id, id + nx);
      if (f == 0 && (cx == 0 || cy == 0 || cx == nx - 1 || cy == ny - 1)) sets.unite(id, border);
    }
  return sets;
}

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
  const size_t row = static_cast<size_t>(nx) + 2;
  const std::vector<int> faces = padded_faces(raster, 0, leaves);
  auto label = [&](int cx, int cy) { return faces[(cy + 1) * row + cx + 1]; };
  auto mark_cell = [&](int cx, int cy) {
    const int l = raster.leaf_at(0, cx, cy);
    if (l >= 0) mark[l] = 1;
  };

  // Components of every face (4-connected; the outside joins the padding ring).
  const int border = nx * ny;
  DisjointSets sets = face_components(nx, ny, label);
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

std::vector<std::pair<int, int>> section_topology_relabels(const PlaneSection& section,
                                                           const std::vector<QuadLeaf>& leaves) {
  const QuadRaster raster = rasterize({&leaves});
  const int nx = raster.nx(), ny = raster.ny();
  auto leaf_at = [&](int cx, int cy) { return raster.leaf_at(0, cx, cy); };
  const size_t row = static_cast<size_t>(nx) + 2;
  const std::vector<int> faces = padded_faces(raster, 0, leaves);
  auto label = [&](int cx, int cy) { return faces[(cy + 1) * row + cx + 1]; };
  // Fraction of a cell's leaf covered by face f in truth.
  auto fraction = [&](int l, int f) {
    if (l < 0) return f == 0 ? 1.0 : 0.0;
    const QuadLeaf& leaf = leaves[l];
    if (!leaf.mixed) return leaf.face == f ? 1.0 : 0.0;
    return leaf.area_of(f) * std::ldexp(1.0, 2 * leaf.cell.level);
  };
  std::map<int, int> relabel;  // leaf -> face
  auto set = [&](int l, int f) {
    if (l >= 0 && leaves[l].face != f) relabel.emplace(l, f);
  };

  // Diagonal-only touches and forbidden contacts around every vertex.
  for (int vy = 0; vy <= ny; ++vy)
    for (int vx = 0; vx <= nx; ++vx) {
      const int cells[4][2] = {{vx - 1, vy - 1}, {vx, vy - 1}, {vx, vy}, {vx - 1, vy}};  // SW SE NE NW
      int lab[4], leaf[4];
      for (int k = 0; k < 4; ++k) {
        lab[k] = label(cells[k][0], cells[k][1]);
        leaf[k] = leaf_at(cells[k][0], cells[k][1]);
      }
      for (int k = 0; k < 2; ++k) {
        // Solid and empty alternating: join one of the diagonal pairs, through the cell with
        // the most of the face it takes.
        const int f = lab[k], g = lab[k + 1];
        if (lab[k + 2] != f || lab[(k + 3) % 4] != g || section.face_solid[f] == section.face_solid[g]) continue;
        const int candidates[4][2] = {{leaf[k + 1], f}, {leaf[(k + 3) % 4], f}, {leaf[k], g}, {leaf[k + 2], g}};
        int best = -1;
        double most = -1;
        for (int c = 0; c < 4; ++c) {
          if (candidates[c][0] < 0) continue;
          const double x = fraction(candidates[c][0], candidates[c][1]);
          if (x > most) {
            most = x;
            best = c;
          }
        }
        if (best >= 0) set(candidates[best][0], candidates[best][1]);
      }
      // Edge contacts between faces no contour separates: the cell with less of its own face
      // takes the face between them.
      for (int k = 0; k < 4; ++k) {
        const int m = (k + 1) % 4;
        const int a = lab[k], b = lab[m];
        if (a == b || section.contour_between(a, b) >= 0) continue;
        int between = -1;
        if (a > 0 && section.contour_between(section.face_parent[a], b) >= 0) between = section.face_parent[a];
        else if (b > 0 && section.contour_between(section.face_parent[b], a) >= 0) between = section.face_parent[b];
        if (between < 0) continue;
        if (fraction(leaf[k], a) <= fraction(leaf[m], b)) set(leaf[k], between);
        else set(leaf[m], between);
      }
    }
  if (relabel.empty()) {
    // Stray components: all but the largest component of each face take their neighbours' face.
    const int border = nx * ny;
    DisjointSets sets = face_components(nx, ny, label);
    std::map<int, int> size;  // root -> cells
    for (int c = 0; c < nx * ny; ++c) ++size[sets.find(c)];
    std::map<int, int> largest;  // face -> its largest root
    largest[0] = sets.find(border);
    for (const auto& [root, count] : size) {
      if (root == largest[0]) continue;
      const int f = label(root % nx, root / nx);
      if (f == 0) continue;
      auto it = largest.find(f);
      if (it == largest.end() || count > size[it->second]) largest[f] = root;
    }
    for (int cy = 0; cy < ny; ++cy)
      for (int cx = 0; cx < nx; ++cx) {
        const int f = label(cx, cy);
        if (sets.find(cy * nx + cx) == largest[f]) continue;
        std::map<int, int> votes;
        const int around[4][2] = {{cx - 1, cy}, {cx + 1, cy}, {cx, cy - 1}, {cx, cy + 1}};
        for (const auto& n : around)
          if (label(n[0], n[1]) != f) ++votes[label(n[0], n[1])];
        int best = -1, count = 0;
        for (const auto& [g, v] : votes)
          if (v > count) {
            best = g;
            count = v;
          }
        if (best >= 0) set(leaf_at(cx, cy), best);
      }
  }
  return {relabel.begin(), relabel.end()};
}

}  // namespace polycube
