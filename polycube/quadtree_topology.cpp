#include "polycube/quadtree_topology.h"

#include "polycube/disjoint_sets.h"
#include "polycube/quadtree_raster.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace polycube {

namespace {

// The 4-connected components of equal face among the tiles; the outside face's tiles on the
// border of the unit square join element tiles.size(), which stands for the padding ring.
DisjointSets face_components(const LeafLocator& tiles, const std::vector<TileCorner>& corners) {
  return tile_components(
      tiles, corners, [&](int s, int t) { return tiles.face(s) == tiles.face(t); },
      [&](int t) { return tiles.face(t) == 0; });
}

}  // namespace

std::string check_section_topology(const PlaneSection& section, const std::vector<QuadLeaf>& leaves,
                                   std::vector<char>& mark) {
  {
    std::vector<int> xs, ys;
    grid_lines({&leaves}, xs, ys);
    charge_raster_cells(xs, ys, 1);
  }
  const LeafLocator tiles(leaves);
  const int n = tiles.leaves(), nt = tiles.size(), nf = section.num_faces();
  mark.assign(leaves.size(), 0);
  std::string problem;
  auto note = [&](const std::string& text) {
    if (problem.empty()) problem = text;
  };
  auto face = [&](int t) { return t < 0 ? 0 : tiles.face(t); };
  auto mark_tile = [&](int t) {
    if (t >= 0 && t < n) mark[t] = 1;
  };
  const std::vector<TileCorner> corners = tile_corners(tiles);

  // Components of every face (the outside joins the padding ring).
  DisjointSets sets = face_components(tiles, corners);
  std::vector<int> root(nf, -1);
  std::vector<char> split_face(nf, 0);
  root[0] = sets.find(nt);
  for (int t = 0; t < nt; ++t) {
    const int f = face(t), r = sets.find(t);
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
  for (const TileCorner& corner : corners)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const int a = face(corner.around[i]), b = face(corner.around[j]);
        if (a == b || section.contour_between(a, b) >= 0) continue;
        if (problem.empty())
          problem = "faces " + std::to_string(std::min(a, b)) + " and " + std::to_string(std::max(a, b)) + " touch";
        mark_tile(corner.around[i]);
        mark_tile(corner.around[j]);
      }

  // No vertex with solid and empty cells alternating around it.
  for (const TileCorner& corner : corners) {
    const auto& a = corner.around;
    const bool sw = section.face_solid[face(a[0])], se = section.face_solid[face(a[1])];
    const bool ne = section.face_solid[face(a[2])], nw = section.face_solid[face(a[3])];
    if (sw == ne && se == nw && sw != se) {
      note("cells touch diagonally only");
      for (int t : a) mark_tile(t);
    }
  }
  return problem;
}

std::vector<std::pair<int, int>> section_topology_relabels(const PlaneSection& section,
                                                           const std::vector<QuadLeaf>& leaves) {
  // The relabellings are defined on the common grid of the leaves' sides (quadtree_raster.h):
  // every grid vertex in a raster scan, a leaf keeping the first face it is given. Its vertices
  // that are no tile corner lie inside a side two tiles share, and repeat that side's contact.
  std::vector<int> xs, ys;
  grid_lines({&leaves}, xs, ys);
  charge_raster_cells(xs, ys, 1);
  const LeafLocator tiles(leaves);
  const int n = tiles.leaves();
  auto leaf_of = [&](int t) { return t >= 0 && t < n ? t : -1; };
  auto label = [&](int t) { return t < 0 ? 0 : tiles.face(t); };
  // Fraction of a leaf covered by face f in truth.
  auto fraction = [&](int l, int f) {
    if (l < 0) return f == 0 ? 1.0 : 0.0;
    const QuadLeaf& leaf = leaves[l];
    if (!leaf.mixed) return leaf.face == f ? 1.0 : 0.0;
    return leaf.area_of(f) * std::ldexp(1.0, 2 * leaf.cell.level);
  };
  // (grid vertex y, x, order at the vertex) -> (leaf, face)
  struct Relabel {
    int y, x, order, leaf, face;
  };
  std::vector<Relabel> found;
  // Edge contacts between faces no contour separates: the tile with less of its own face takes
  // the face between them (s first on a tie).
  auto contact = [&](int y, int x, int order, int s, int t) {
    const int a = label(s), b = label(t);
    if (a == b || section.contour_between(a, b) >= 0) return;
    int between = -1;
    if (a > 0 && section.contour_between(section.face_parent[a], b) >= 0) between = section.face_parent[a];
    else if (b > 0 && section.contour_between(section.face_parent[b], a) >= 0) between = section.face_parent[b];
    if (between < 0) return;
    const int ls = leaf_of(s), lt = leaf_of(t);
    found.push_back({y, x, order, fraction(ls, a) <= fraction(lt, b) ? ls : lt, between});
  };
  auto on_grid = [](const std::vector<int>& lines, int v) { return std::binary_search(lines.begin(), lines.end(), v); };
  const std::vector<TileCorner> corners = tile_corners(tiles);
  for (const TileCorner& corner : corners) {
    const int x = corner.x, y = corner.y;
    if (!on_grid(xs, x) || !on_grid(ys, y)) continue;
    int lab[4], leaf[4];
    for (int k = 0; k < 4; ++k) {
      lab[k] = label(corner.around[k]);
      leaf[k] = leaf_of(corner.around[k]);
    }
    for (int k = 0; k < 2; ++k) {
      // Solid and empty alternating: join one of the diagonal pairs, through the cell with the
      // most of the face it takes.
      const int f = lab[k], g = lab[k + 1];
      if (lab[k + 2] != f || lab[(k + 3) % 4] != g || section.face_solid[f] == section.face_solid[g]) continue;
      const int candidates[4][2] = {{leaf[k + 1], f}, {leaf[(k + 3) % 4], f}, {leaf[k], g}, {leaf[k + 2], g}};
      int best = -1;
      double most = -1;
      for (int c = 0; c < 4; ++c) {
        if (candidates[c][0] < 0) continue;
        const double share = fraction(candidates[c][0], candidates[c][1]);
        if (share > most) {
          most = share;
          best = c;
        }
      }
      if (best >= 0) found.push_back({y, x, k, candidates[best][0], candidates[best][1]});
    }
    // Sides from the vertex: below (SW, SE), right (SE, NE), above (NE, NW), left (NW, SW).
    for (int k = 0; k < 4; ++k) contact(y, x, 2 + k, corner.around[k], corner.around[(k + 1) % 4]);
    // The sides starting here to the right and upwards: their first grid vertex inside repeats
    // the contact, the lower (left) tile first.
    for (bool upwards : {false, true}) {
      const TileSide side = side_from(tiles, corner, upwards);
      if (side.from == side.to) continue;
      const std::vector<int>& lines = upwards ? ys : xs;
      const auto next = std::upper_bound(lines.begin(), lines.end(), upwards ? y : x);
      if (next == lines.end() || *next >= side.end) continue;
      const int vy = upwards ? *next : y, vx = upwards ? x : *next;
      // Right: (SE, NE) then (NW, SW) there; upwards: (SW, SE) then (NE, NW).
      contact(vy, vx, upwards ? 2 + 0 : 2 + 1, side.from, side.to);
      contact(vy, vx, upwards ? 2 + 2 : 2 + 3, side.to, side.from);
    }
  }
  std::stable_sort(found.begin(), found.end(), [](const Relabel& a, const Relabel& b) {
    return a.y != b.y ? a.y < b.y : a.x != b.x ? a.x < b.x : a.order < b.order;
  });
  std::map<int, int> relabel;  // leaf -> face
  auto set = [&](int l, int f) {
    if (l >= 0 && leaves[l].face != f) relabel.emplace(l, f);
  };
  for (const Relabel& r : found) set(r.leaf, r.face);

  if (relabel.empty()) {
    // Stray components: all but the largest component of each face (in grid cells) take their
    // neighbours' face, by the vote of the four neighbours of the leaf's first grid cell (in a
    // raster scan) that has a neighbour of another face.
    const int nt = tiles.size();
    DisjointSets sets = face_components(tiles, corners);
    auto index = [](const std::vector<int>& lines, int v) {
      return static_cast<int>(std::lower_bound(lines.begin(), lines.end(), v) - lines.begin());
    };
    std::map<int, long long> size;  // root -> grid cells
    for (int t = 0; t < nt; ++t) {
      const QuadCell& c = tiles.cell(t);
      size[sets.find(t)] += static_cast<long long>(index(xs, c.x1()) - index(xs, c.x0())) * (index(ys, c.y1()) - index(ys, c.y0()));
    }
    std::map<int, int> largest;  // face -> its largest root
    largest[0] = sets.find(nt);
    for (const auto& [root, count] : size) {
      if (root == largest[0] || label(root) == 0) continue;
      const int f = label(root);
      auto it = largest.find(f);
      if (it == largest.end() || count > size[it->second]) largest[f] = root;
    }
    for (int l = 0; l < n; ++l) {
      const int f = label(l);
      if (sets.find(l) == largest[f]) continue;
      const QuadCell& c = tiles.cell(l);
      const int cx0 = index(xs, c.x0()), cx1 = index(xs, c.x1()), cy0 = index(ys, c.y0()), cy1 = index(ys, c.y1());
      int best = -1;
      for (int cy = cy0; cy < cy1 && best < 0; ++cy)
        for (int cx = cx0; cx < cx1 && best < 0; ++cx) {
          if (cy != cy0 && cy != cy1 - 1 && cx != cx0 && cx != cx1 - 1) cx = cx1 - 1;  // inside the leaf
          const int around[4] = {cx > cx0 ? f : label(tiles.at(c.x0() - 1, ys[cy])),
                                 cx < cx1 - 1 ? f : label(tiles.at(c.x1(), ys[cy])),
                                 cy > cy0 ? f : label(tiles.at(xs[cx], c.y0() - 1)),
                                 cy < cy1 - 1 ? f : label(tiles.at(xs[cx], c.y1()))};
          std::map<int, int> votes;
          for (int g : around)
            if (g != f) ++votes[g];
          int count = 0;
          for (const auto& [g, v] : votes)
            if (v > count) {
              best = g;
              count = v;
            }
        }
      if (best >= 0) set(l, best);
    }
  }
  return {relabel.begin(), relabel.end()};
}


}  // namespace polycube
