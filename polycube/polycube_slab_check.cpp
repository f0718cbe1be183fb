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
  const QuadRaster raster = rasterize({side_leaves[0], side_leaves[1]});
  const int nx = raster.nx(), ny = raster.ny();
  const size_t row = static_cast<size_t>(nx) + 2;
  std::vector<int> faces[2];
  std::vector<char> solids[2];
  for (int s = 0; s < 2; ++s) {
    faces[s] = padded_faces(raster, s, *side_leaves[s]);
    solids[s].resize(faces[s].size());
    for (size_t k = 0; k < faces[s].size(); ++k) solids[s][k] = side_section[s]->face_solid[faces[s][k]];
  }
  auto face = [&](int s, int cx, int cy) { return faces[s][(cy + 1) * row + cx + 1]; };
  auto solid = [&](int s, int cx, int cy) { return solids[s][(cy + 1) * row + cx + 1] != 0; };
  std::vector<char> refine[2];
  refine[0].assign(side_leaves[0]->size(), 0);
  refine[1].assign(side_leaves[1]->size(), 0);
  auto mark = [&](int s, int cx, int cy) {
    const int l = raster.leaf_at(s, cx, cy);
    if (l >= 0 && (*side_leaves[s])[l].mixed) refine[s][l] = 1;
  };
  auto note = [&](const std::string& text) {
    if (result.problem.empty()) result.problem = text;
  };
  auto vid = [&](int vx, int vy) { return vy * (nx + 1) + vx; };

  // Manifold at every grid vertex of height m.
  for (int vy = 0; vy <= ny; ++vy)
    for (int vx = 0; vx <= nx; ++vx) {
      int occupancy = 0;
      for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx)
            if (solid(dz, vx - 1 + dx, vy - 1 + dy)) occupancy |= 1 << (dx + 2 * dy + 4 * dz);
      if (octants_manifold(occupancy)) continue;
      ++result.nonmanifold_vertices;
      std::array<int, 8> around;
      for (int s = 0; s < 2; ++s)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) around[4 * s + 2 * dy + dx] = raster.leaf_at(s, vx - 1 + dx, vy - 1 + dy);
      result.nonmanifold.push_back(around);
      for (int s = 0; s < 2; ++s)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) mark(s, vx - 1 + dx, vy - 1 + dy);
    }
  if (result.nonmanifold_vertices > 0)
    note(std::to_string(result.nonmanifold_vertices) + " non-manifold vertices between the extrusions");

  // The complex X: closed cells of Q_lo Δ Q_hi and the boundary edges of both, joined at vertices.
  DisjointSets x_sets((nx + 1) * (ny + 1));
  for (int cy = 0; cy < ny; ++cy)
    for (int cx = 0; cx < nx; ++cx)
      if (solid(0, cx, cy) != solid(1, cx, cy)) {
        x_sets.unite(vid(cx, cy), vid(cx + 1, cy));
        x_sets.unite(vid(cx, cy), vid(cx, cy + 1));
        x_sets.unite(vid(cx, cy), vid(cx + 1, cy + 1));
      }
  std::map<int, int> contour_root;  // contour id -> root vertex of its component
  bool loops_consistent = true;
  // Boundary edge between cells a and b (a below/left of b) running from vertex v to w.
  auto boundary_edge = [&](int ax, int ay, int bx, int by, int v, int w) {
    for (int s = 0; s < 2; ++s) {
      if (solid(s, ax, ay) == solid(s, bx, by)) continue;
      x_sets.unite(v, w);
      const int local = side_section[s]->contour_between(face(s, ax, ay), face(s, bx, by));
      if (local < 0) {
        loops_consistent = false;
        continue;
      }
      contour_root.emplace(side_section[s]->contours[local], v);
    }
  };
  for (int cy = 0; cy <= ny; ++cy)
    for (int cx = 0; cx < nx; ++cx) boundary_edge(cx, cy - 1, cx, cy, vid(cx, cy), vid(cx + 1, cy));
  for (int cy = 0; cy < ny; ++cy)
    for (int cx = 0; cx <= nx; ++cx) boundary_edge(cx - 1, cy, cx, cy, vid(cx, cy), vid(cx, cy + 1));
  if (!loops_consistent) note("a boundary edge of Q separates faces no contour separates");

  // Bounded components of the complement of X (cells in both or in neither), each counted for
  // the component of X that contains the top edge of its topmost cell.
  const int infinity = nx * ny;
  DisjointSets c_sets(nx * ny + 1);
  auto both_or_neither = [&](int cx, int cy) { return solid(0, cx, cy) == solid(1, cx, cy); };
  for (int cy = 0; cy < ny; ++cy)
    for (int cx = 0; cx < nx; ++cx) {
      if (!both_or_neither(cx, cy)) continue;
      const bool in = solid(0, cx, cy);
      const int c = cy * nx + cx;
      if (cx + 1 < nx && both_or_neither(cx + 1, cy) && solid(0, cx + 1, cy) == in) c_sets.unite(c, c + 1);
      if (cy + 1 < ny && both_or_neither(cx, cy + 1) && solid(0, cx, cy + 1) == in) c_sets.unite(c, c + nx);
      if (!in && (cx == 0 || cy == 0 || cx == nx - 1 || cy == ny - 1)) c_sets.unite(c, infinity);
    }
  std::map<int, int> top_cell;  // complement root -> its topmost (then leftmost) cell
  for (int cy = 0; cy < ny; ++cy)
    for (int cx = nx - 1; cx >= 0; --cx) {
      if (!both_or_neither(cx, cy)) continue;
      const int r = c_sets.find(cy * nx + cx);
      if (r == c_sets.find(infinity)) continue;
      top_cell[r] = cy * nx + cx;  // later rows and then smaller cx overwrite
    }
  std::map<int, int> holes;  // X root -> bounded complement components it surrounds
  for (const auto& [root, cell] : top_cell) {
    (void)root;
    const int cx = cell % nx, cy = cell / nx;
    ++holes[x_sets.find(vid(cx, cy + 1))];
  }

  // Pieces of P: components of X, with their loops.
  std::map<int, int> piece_of_root;
  for (const auto& [contour, v] : contour_root) {
    const int r = x_sets.find(v);
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
    for (int cy = 0; cy < ny; ++cy)
      for (int cx = 0; cx < nx; ++cx) {
        const int a = raster.leaf_at(0, cx, cy), b = raster.leaf_at(1, cx, cy);
        if (!present(0, a) || !present(1, b)) continue;
        if ((*side_leaves[0])[a].mixed) refine[0][a] = 1;
        if ((*side_leaves[1])[b].mixed) refine[1][b] = 1;
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
