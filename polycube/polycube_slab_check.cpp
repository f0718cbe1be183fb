#include "polycube/polycube_slab_check.h"

#include "polycube/disjoint_sets.h"
#include "polycube/quadtree_raster.h"

#include <algorithm>
#include <array>
#include <map>
#include <sstream>

namespace polycube {

namespace {

// The link of a vertex of a union of octants is the octahedron's faces (octants) marked inside;
// the surface there is the cone over the boundary of that set, a disk iff the boundary is one
// simple cycle. Link vertices are the 6 half-axes (axis a, side s) -> 2a + s; the quarter-face
// between two octants differing in bit a joins the half-axes of the other two bits.
std::array<bool, 256> manifold_table() {
  std::array<bool, 256> table{};
  for (int m = 0; m < 256; ++m) {
    if (m == 0 || m == 255) {
      table[m] = true;
      continue;
    }
    std::array<int, 6> degree{};
    DisjointSets sets(6);
    int edges = 0;
    for (int o = 0; o < 8; ++o)
      for (int a = 0; a < 3; ++a) {
        const int p = o ^ (1 << a);
        if (p < o || ((m >> o) & 1) == ((m >> p) & 1)) continue;
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        const int u = 2 * b + ((o >> b) & 1), v = 2 * c + ((o >> c) & 1);
        ++degree[u];
        ++degree[v];
        sets.unite(u, v);
        ++edges;
      }
    bool ok = true;
    int used = 0, root = -1;
    for (int u = 0; u < 6; ++u) {
      if (degree[u] == 0) continue;
      if (degree[u] != 2) ok = false;
      ++used;
      if (root < 0) root = sets.find(u);
      else if (sets.find(u) != root) ok = false;
    }
    table[m] = ok && used == edges;
  }
  return table;
}

const PlaneSection& empty_section() {
  static const PlaneSection section = [] {
    PlaneSection s;
    s.face_solid = {0};
    s.face_parent = {-1};
    s.face_area = {0};
    return s;
  }();
  return section;
}

const std::vector<QuadLeaf>& empty_leaves() {
  static const std::vector<QuadLeaf> leaves(1);
  return leaves;
}

}  // namespace

bool octants_manifold(int occupancy) {
  static const std::array<bool, 256> table = manifold_table();
  return table[occupancy & 255];
}

SlabCheck check_slab(const CrossSections& sections, const SlabSide& lo, const SlabSide& hi,
                     const std::vector<std::vector<int>>& model_pieces) {
  SlabCheck result;
  const PlaneSection* side_section[2];
  const std::vector<QuadLeaf>* side_leaves[2];
  const SlabSide* sides[2] = {&lo, &hi};
  for (int s = 0; s < 2; ++s) {
    const bool present = sides[s]->plane >= 0;
    side_section[s] = present ? &sections.planes[sides[s]->plane] : &empty_section();
    side_leaves[s] = present ? sides[s]->leaves : &empty_leaves();
  }
  // The check is defined on the common grid of the two quadtrees (quadtree_raster.h) and runs
  // on their common refinement: the finer of the two leaves everywhere, each tile inside one
  // leaf (or none) of either side. Grid vertices that are no tile corner lie inside a tile or
  // inside a side two tiles share, and repeat what holds along that side.
  std::vector<int> xs, ys;
  grid_lines({side_leaves[0], side_leaves[1]}, xs, ys);
  charge_raster_cells(xs, ys, 2);
  const LeafLocator side_tiles[2] = {LeafLocator(*side_leaves[0]), LeafLocator(*side_leaves[1])};
  std::vector<QuadLeaf> common;
  std::vector<std::array<int, 2>> common_leaf;  // per tile: the leaf of each side, -1 for none
  for (std::vector<QuadCell> stack = {QuadCell{}}; !stack.empty();) {
    const QuadCell c = stack.back();
    stack.pop_back();
    const int found[2] = {side_tiles[0].find(c), side_tiles[1].find(c)};
    if (found[0] == LeafLocator::kSubdivided || found[1] == LeafLocator::kSubdivided) {
      for (int q = 0; q < 4; ++q) stack.push_back({c.level + 1, 2 * c.ix + (q & 1), 2 * c.iy + (q >> 1)});
      continue;
    }
    QuadLeaf tile;
    tile.cell = c;
    common.push_back(tile);
    std::array<int, 2> leaf;
    for (int s = 0; s < 2; ++s) {
      const int t = found[s] >= 0 ? found[s] : side_tiles[s].at(c.x0(), c.y0());
      leaf[s] = t < side_tiles[s].leaves() ? t : -1;
    }
    common_leaf.push_back(leaf);
  }
  const LeafLocator tiles(common);
  const int nt = tiles.size();
  const std::vector<TileCorner> corners = tile_corners(tiles);
  auto leaf = [&](int s, int t) { return t < 0 ? -1 : common_leaf[t][s]; };
  auto face = [&](int s, int t) {
    const int l = leaf(s, t);
    return l < 0 ? 0 : (*side_leaves[s])[l].face;
  };
  auto solid = [&](int s, int t) { return side_section[s]->face_solid[face(s, t)] != 0; };
  std::vector<char> refine[2];
  refine[0].assign(side_leaves[0]->size(), 0);
  refine[1].assign(side_leaves[1]->size(), 0);
  auto mark = [&](int s, int l) {
    if (l >= 0 && (*side_leaves[s])[l].mixed) refine[s][l] = 1;
  };
  auto note = [&](const std::string& text) {
    if (result.problem.empty()) result.problem = text;
  };
  auto on_grid = [](const std::vector<int>& lines, int v) { return std::binary_search(lines.begin(), lines.end(), v); };
  // The grid lines strictly inside a side (from, to).
  auto lines_inside = [](const std::vector<int>& lines, int from, int to) {
    return std::make_pair(std::upper_bound(lines.begin(), lines.end(), from), std::lower_bound(lines.begin(), lines.end(), to));
  };

  // Manifold at every grid vertex of height m.
  struct Bad {
    int y, x;
    std::array<int, 8> around;
  };
  std::vector<Bad> bad;
  auto check_vertex = [&](int x, int y, const std::array<int, 4>& quadrant) {  // tiles SW, SE, NW, NE
    int occupancy = 0;
    for (int s = 0; s < 2; ++s)
      for (int q = 0; q < 4; ++q)
        if (solid(s, quadrant[q])) occupancy |= 1 << (q + 4 * s);
    if (octants_manifold(occupancy)) return;
    std::array<int, 8> around;
    for (int s = 0; s < 2; ++s)
      for (int q = 0; q < 4; ++q) around[4 * s + q] = leaf(s, quadrant[q]);
    bad.push_back({y, x, around});
  };
  for (const TileCorner& corner : corners) {
    const auto& a = corner.around;
    if (on_grid(xs, corner.x) && on_grid(ys, corner.y)) check_vertex(corner.x, corner.y, {a[0], a[1], a[3], a[2]});
    const TileSide right = side_from(tiles, corner, false), up = side_from(tiles, corner, true);
    if (right.from != right.to) {
      const auto [first, last] = lines_inside(xs, corner.x, right.end);
      for (auto x = first; x < last; ++x) check_vertex(*x, corner.y, {right.from, right.from, right.to, right.to});
    }
    if (up.from != up.to) {
      const auto [first, last] = lines_inside(ys, corner.y, up.end);
      for (auto y = first; y < last; ++y) check_vertex(corner.x, *y, {up.from, up.to, up.from, up.to});
    }
  }
  std::stable_sort(bad.begin(), bad.end(), [](const Bad& a, const Bad& b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
  for (const Bad& b : bad) {
    result.nonmanifold.push_back(b.around);
    for (int s = 0; s < 2; ++s)
      for (int q = 0; q < 4; ++q) mark(s, b.around[4 * s + q]);
  }
  result.nonmanifold_vertices = static_cast<int>(bad.size());
  if (result.nonmanifold_vertices > 0)
    note(std::to_string(result.nonmanifold_vertices) + " non-manifold vertices between the extrusions");

  // The complex X: closed tiles of Q_lo Δ Q_hi and the boundary sides of both, joined at the
  // tile corners (elements 0 .. corners - 1; the tiles follow).
  const int nc = static_cast<int>(corners.size());
  auto corner_at = [&](int x, int y) {
    const auto it = std::lower_bound(corners.begin(), corners.end(), std::make_pair(y, x),
                                     [](const TileCorner& c, const std::pair<int, int>& p) {
                                       return std::make_pair(c.y, c.x) < p;
                                     });
    return static_cast<int>(it - corners.begin());
  };
  DisjointSets x_sets(nc + nt);
  for (int c = 0; c < nc; ++c)
    for (int t : corners[c].around)
      if (t >= 0 && solid(0, t) != solid(1, t)) x_sets.unite(c, nc + t);
  std::map<int, int> contour_root;  // contour id -> a corner of its loop
  bool loops_consistent = true;
  for (int c = 0; c < nc; ++c)
    for (bool upwards : {false, true}) {
      const TileSide side = side_from(tiles, corners[c], upwards);
      if (side.from == side.to) continue;
      const int far = upwards ? corner_at(corners[c].x, side.end) : corner_at(side.end, corners[c].y);
      for (int s = 0; s < 2; ++s) {
        if (solid(s, side.from) == solid(s, side.to)) continue;
        x_sets.unite(c, far);
        const int local = side_section[s]->contour_between(face(s, side.from), face(s, side.to));
        if (local < 0) {
          loops_consistent = false;
          continue;
        }
        contour_root.emplace(side_section[s]->contours[local], c);
      }
    }
  if (!loops_consistent) note("a boundary edge of Q separates faces no contour separates");

  // Bounded components of the complement of X (tiles in both or in neither), each counted for
  // the component of X that contains the top left corner of its topmost (then leftmost) tile.
  auto both_or_neither = [&](int t) { return t >= 0 && solid(0, t) == solid(1, t); };
  DisjointSets c_sets = tile_components(
      tiles, corners,
      [&](int s, int t) { return both_or_neither(s) && both_or_neither(t) && solid(0, s) == solid(0, t); },
      [&](int t) { return both_or_neither(t) && !solid(0, t); });
  std::map<int, int> top_tile;  // complement root -> its topmost (then leftmost) tile
  for (int t = 0; t < nt; ++t) {
    if (!both_or_neither(t)) continue;
    const int r = c_sets.find(t);
    if (r == c_sets.find(nt)) continue;
    const auto it = top_tile.find(r);
    const QuadCell& c = tiles.cell(t);
    if (it == top_tile.end()) {
      top_tile.emplace(r, t);
      continue;
    }
    const QuadCell& best = tiles.cell(it->second);
    if (c.y1() > best.y1() || (c.y1() == best.y1() && c.x0() < best.x0())) it->second = t;
  }
  std::map<int, int> holes;  // X root -> bounded complement components it surrounds
  for (const auto& [root, t] : top_tile) {
    (void)root;
    ++holes[x_sets.find(corner_at(tiles.cell(t).x0(), tiles.cell(t).y1()))];
  }

  // Pieces of P: components of X, with their loops.
  std::map<int, int> piece_of_root;
  for (const auto& [contour, c] : contour_root) {
    const int r = x_sets.find(c);
    auto it = piece_of_root.find(r);
    if (it == piece_of_root.end()) {
      it = piece_of_root.emplace(r, static_cast<int>(result.pieces.size())).first;
      result.pieces.emplace_back();
    }
    result.pieces[it->second].push_back(contour);
  }
  result.piece_genus.assign(result.pieces.size(), 0);
  for (const auto& [r, p] : piece_of_root) {
    const int b = static_cast<int>(result.pieces[p].size());
    const auto it = holes.find(r);
    const int h = it == holes.end() ? 0 : it->second;
    result.piece_genus[p] = (1 + h - b) % 2 == 0 ? (1 + h - b) / 2 : -1000;
  }

  // Match the model's pieces.
  result.model_match.assign(model_pieces.size(), -1);
  std::vector<int> piece_used(result.pieces.size(), 0);
  int unmatched = 0;
  for (size_t m = 0; m < model_pieces.size(); ++m) {
    int piece = -2;
    for (int c : model_pieces[m]) {
      const auto it = contour_root.find(c);
      const int p = it == contour_root.end() ? -1 : piece_of_root[x_sets.find(it->second)];
      if (piece == -2) piece = p;
      else if (piece != p) piece = -1;
    }
    const bool match = piece >= 0 && result.pieces[piece].size() == model_pieces[m].size() &&
                       result.piece_genus[piece] == 0 && piece_used[piece] == 0;
    if (match) {
      result.model_match[m] = piece;
      piece_used[piece] = 1;
      continue;
    }
    ++unmatched;
    // Refine where the regions of this model piece's contours (and of the P pieces they fell
    // into) on the two planes meet: the cells where both are present, wholly or in part.
    std::vector<int> contours = model_pieces[m];
    for (int c : model_pieces[m]) {
      const auto it = contour_root.find(c);
      if (it == contour_root.end()) continue;
      const auto& others = result.pieces[piece_of_root[x_sets.find(it->second)]];
      contours.insert(contours.end(), others.begin(), others.end());
    }
    std::vector<int> regions[2];
    for (int c : contours) {
      const SectionContour& contour = sections.contours[c];
      for (int s = 0; s < 2; ++s) {
        if (sides[s]->plane != contour.plane) continue;
        const PlaneSection& section = *side_section[s];
        const int inner = contour.local + 1;
        regions[s].push_back(section.face_solid[inner] ? inner : section.face_parent[inner]);
      }
    }
    if (regions[0].empty() || regions[1].empty()) continue;
    auto present = [&](int s, int leaf) {
      if (leaf < 0) return false;
      const QuadLeaf& q = (*side_leaves[s])[leaf];
      for (int r : regions[s])
        if (q.face == r || (q.mixed && q.area_of(r) > 0)) return true;
      return false;
    };
    for (int t = 0; t < nt; ++t) {
      const int a = leaf(0, t), b = leaf(1, t);
      if (!present(0, a) || !present(1, b)) continue;
      mark(0, a);
      mark(1, b);
    }
  }
  if (unmatched > 0) {
    std::ostringstream message;
    message << unmatched << " of " << model_pieces.size() << " model pieces have no polycube piece with the same loops"
            << " and genus 0 (" << result.pieces.size() << " polycube pieces)";
    note(message.str());
  }
  for (int s = 0; s < 2; ++s)
    for (size_t l = 0; l < refine[s].size(); ++l)
      if (refine[s][l]) (s == 0 ? result.lo_refine : result.hi_refine).push_back(static_cast<int>(l));
  if (lo.plane < 0) result.lo_refine.clear();
  if (hi.plane < 0) result.hi_refine.clear();
  return result;
}

}  // namespace polycube
