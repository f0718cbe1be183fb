#include "polycube/quadtree_simplify.h"

#include "polycube/quadtree_raster.h"
#include "polycube/quadtree_topology.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace polycube {

namespace {

double cell_area(const QuadCell& cell) { return std::ldexp(1.0, -2 * cell.level); }

// The face covering most of a mixed leaf.
int largest_face(const QuadLeaf& leaf) {
  int face = leaf.face;
  double best = -1;
  for (const auto& [f, a] : leaf.face_areas)
    if (a > best) {
      best = a;
      face = f;
    }
  return face;
}

// Adds sign times the leaf's share of area(Q_f Δ R_f) to error[f] for every solid face f. Only
// mixed leaves count, as in approximate_section: a leaf no contour crosses is exact.
void add_error(const PlaneSection& section, const QuadLeaf& leaf, double sign, std::vector<double>& error) {
  if (!leaf.mixed) return;
  double own = 0;
  for (const auto& [f, a] : leaf.face_areas) {
    if (f == leaf.face) own = a;
    else if (section.face_solid[f]) error[f] += sign * a;
  }
  if (section.face_solid[leaf.face]) error[leaf.face] += sign * std::max(0.0, cell_area(leaf.cell) - own);
}

// The parent of four sibling leaves as one leaf, labelled with the face covering most of it.
QuadLeaf merged_leaf(const QuadCell& parent, const std::array<const QuadLeaf*, 4>& children) {
  QuadLeaf leaf;
  leaf.cell = parent;
  leaf.face = children[0]->face;
  std::map<int, double> areas;
  for (const QuadLeaf* child : children) {
    leaf.accuracy_level = std::max(leaf.accuracy_level, child->accuracy_level);
    leaf.mixed = leaf.mixed || child->mixed || child->face != children[0]->face;
    if (child->mixed)
      for (const auto& [f, a] : child->face_areas) areas[f] += a;
    else
      areas[child->face] += cell_area(child->cell);
  }
  if (!leaf.mixed) return leaf;
  double best = -1;
  for (const auto& [f, a] : areas) {
    if (!(a > 0)) continue;
    leaf.face_areas.emplace_back(f, a);
    if (a > best) {
      best = a;
      leaf.face = f;
    }
  }
  return leaf;
}

// A candidate change: the current leaves it replaces, the leaf replacing them, and what it
// adds to each face's area difference.
struct Change {
  std::vector<int> removed;
  QuadLeaf leaf;
  std::vector<std::pair<int, double>> added_error;
  double cost = 0;  // largest added error relative to its face's limit
};

// Applies batches of changes to a plane's leaves, as many as the error limits and the checks
// allow.
class Simplifier {
 public:
  Simplifier(const PlaneSection& section, const std::vector<QuadLeaf>& leaves, double da,
             const CoarseningCheck& check)
      : section_(section), check_(check), leaves_(leaves) {
    const int nf = section.num_faces();
    error_.assign(nf, 0.0);
    limit_.assign(nf, 0.0);
    for (const QuadLeaf& leaf : leaves) add_error(section, leaf, +1, error_);
    for (int f = 0; f < nf; ++f) limit_[f] = std::max(da * section.face_area[f], error_[f]) * (1 + 1e-12);
  }

  const std::vector<QuadLeaf>& leaves() const { return leaves_; }

  CoarsenedSection result() && {
    CoarsenedSection result;
    result.leaves = std::move(leaves_);
    result.merges = applied_;
    result.undone = undone_;
    return result;
  }

  // A change replacing `removed` by `leaf`, with its added error and cost.
  Change change(std::vector<int> removed, QuadLeaf leaf) const {
    Change c;
    c.removed = std::move(removed);
    c.leaf = std::move(leaf);
    std::vector<double> delta(section_.num_faces(), 0.0);
    std::vector<int> touched;
    auto note = [&](const QuadLeaf& leaf, double sign) {
      add_error(section_, leaf, sign, delta);
      for (const auto& [f, a] : leaf.face_areas) touched.push_back(f);
      touched.push_back(leaf.face);
    };
    note(c.leaf, +1);
    for (int l : c.removed) note(leaves_[l], -1);
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    for (int f : touched) {
      if (delta[f] <= 1e-18) continue;
      c.added_error.emplace_back(f, delta[f]);
      c.cost = std::max(c.cost, limit_[f] > 0 ? delta[f] / limit_[f] : 1e300);
    }
    return c;
  }

  // Chooses the cheapest changes that fit the error limits together, then tries them and undoes
  // those the checks implicate until the rest pass. Changes must not share leaves. Changes that
  // keep every removed leaf's face (merges of siblings labelled alike) leave the labelling of
  // the plane as it is and are made without checks.
  void apply(std::vector<Change> changes) {
    std::vector<Change> silent, loud;
    for (Change& c : changes) {
      bool same = true;
      for (int l : c.removed) same = same && leaves_[l].face == c.leaf.face;
      (same ? silent : loud).push_back(std::move(c));
    }
    if (!silent.empty()) {
      std::vector<char> removed(leaves_.size(), 0);
      for (const Change& c : silent)
        for (int l : c.removed) removed[l] = 1;
      std::vector<QuadLeaf> kept;
      std::vector<int> index(leaves_.size(), -1);
      for (size_t l = 0; l < leaves_.size(); ++l)
        if (!removed[l]) {
          index[l] = static_cast<int>(kept.size());
          kept.push_back(std::move(leaves_[l]));
        }
      for (Change& c : silent) kept.push_back(std::move(c.leaf));
      applied_ += static_cast<int>(silent.size());
      leaves_ = std::move(kept);
      for (Change& c : loud)
        for (int& l : c.removed) l = index[l];
    }
    changes = std::move(loud);
    std::stable_sort(changes.begin(), changes.end(), [](const Change& a, const Change& b) { return a.cost < b.cost; });
    std::vector<double> trial_error = error_;
    std::vector<int> chosen;
    for (int m = 0; m < static_cast<int>(changes.size()); ++m) {
      bool fits = true;
      for (const auto& [f, d] : changes[m].added_error) fits = fits && trial_error[f] + d <= limit_[f];
      if (!fits) continue;
      for (const auto& [f, d] : changes[m].added_error) trial_error[f] += d;
      chosen.push_back(m);
    }
    for (int attempt = 0; !chosen.empty(); ++attempt) {
      std::vector<char> removed(leaves_.size(), 0);
      std::vector<QuadLeaf> trial;
      std::vector<int> origin;  // per trial leaf: the index into chosen of its change, -1 if kept
      for (int k : chosen)
        for (int l : changes[k].removed) removed[l] = 1;
      for (size_t l = 0; l < leaves_.size(); ++l)
        if (!removed[l]) {
          trial.push_back(leaves_[l]);
          origin.push_back(-1);
        }
      for (int k = 0; k < static_cast<int>(chosen.size()); ++k) {
        trial.push_back(changes[chosen[k]].leaf);
        origin.push_back(k);
      }
      std::vector<char> mark;
      bool ok = check_section_topology(section_, trial, mark).empty();
      if (ok) {
        mark.assign(trial.size(), 0);
        ok = check_(trial, mark);
      }
      if (ok) {
        for (int k : chosen)
          for (const auto& [f, d] : changes[k].added_error) error_[f] += d;
        applied_ += static_cast<int>(chosen.size());
        leaves_ = std::move(trial);
        return;
      }
      std::vector<char> drop(chosen.size(), 0);
      bool any = false;
      for (size_t l = 0; l < trial.size(); ++l)
        if (mark[l] && origin[l] >= 0) drop[origin[l]] = any = true;
      if (!any || attempt >= 8) {
        // Nothing to blame, or no end in sight: keep half of them, the cheapest, for another try.
        if (chosen.size() == 1) {
          ++undone_;
          return;
        }
        for (size_t k = chosen.size() / 2; k < chosen.size(); ++k) drop[k] = 1;
      }
      std::vector<int> kept;
      for (size_t k = 0; k < chosen.size(); ++k)
        if (drop[k]) ++undone_;
        else kept.push_back(chosen[k]);
      chosen = std::move(kept);
    }
  }

 private:
  const PlaneSection& section_;
  const CoarseningCheck& check_;
  std::vector<QuadLeaf> leaves_;
  std::vector<double> error_, limit_;
  int applied_ = 0, undone_ = 0;
};

}  // namespace

std::vector<double> region_errors(const PlaneSection& section, const std::vector<QuadLeaf>& leaves) {
  std::vector<double> error(section.num_faces(), 0.0);
  for (const QuadLeaf& leaf : leaves) add_error(section, leaf, +1, error);
  for (int f = 0; f < section.num_faces(); ++f)
    error[f] = section.face_solid[f] && section.face_area[f] > 0 ? error[f] / section.face_area[f] : 0;
  return error;
}

CoarsenedSection coarsen_section(const PlaneSection& section, const std::vector<QuadLeaf>& leaves, double da,
                                 int coarsest_level, const CoarseningCheck& check) {
  Simplifier simplifier(section, leaves, da, check);
  int deepest = 0;
  for (const QuadLeaf& leaf : leaves) deepest = std::max(deepest, leaf.cell.level);
  for (int level = deepest; level >= std::max(1, coarsest_level + 1); --level) {
    const std::vector<QuadLeaf>& current = simplifier.leaves();
    // Sibling groups of leaves at this level.
    std::map<QuadCell, std::array<int, 4>> groups;
    for (int l = 0; l < static_cast<int>(current.size()); ++l) {
      const QuadCell& c = current[l].cell;
      if (c.level != level) continue;
      const QuadCell parent{level - 1, c.ix >> 1, c.iy >> 1};
      auto it = groups.emplace(parent, std::array<int, 4>{-1, -1, -1, -1}).first;
      it->second[(c.ix & 1) + 2 * (c.iy & 1)] = l;
    }
    std::vector<Change> merges;
    for (const auto& [parent, children] : groups) {
      if (std::find(children.begin(), children.end(), -1) != children.end()) continue;
      bool mergeable = true;
      std::array<const QuadLeaf*, 4> child_leaves;
      for (int q = 0; q < 4; ++q) {
        const QuadLeaf* child = child_leaves[q] = &current[children[q]];
        mergeable = mergeable && child->accuracy_level <= parent.level &&
                    !(child->mixed && child->face != largest_face(*child));
      }
      if (mergeable)
        merges.push_back(simplifier.change({children.begin(), children.end()}, merged_leaf(parent, child_leaves)));
    }
    if (!merges.empty()) simplifier.apply(std::move(merges));
  }
  return std::move(simplifier).result();
}

// Whether a polycube vertex with the given occupancy of its 8 octants (bit dx + 2 dy + 4 dz) is a
// corner: along each axis an edge leaves it, i.e. on one of the two half-axes the four octants
// around it are not split by a plane (neither all alike nor two halves).
bool corner_occupancy(int occupancy) {
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    bool edge = false;
    for (int side = 0; side < 2 && !edge; ++side) {
      bool v[2][2];
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) v[i][j] = (occupancy >> ((side << a) | (i << b) | (j << c))) & 1;
      const bool flat = (v[0][0] == v[1][0] && v[0][1] == v[1][1]) || (v[0][0] == v[0][1] && v[1][0] == v[1][1]);
      edge = !flat;
    }
    if (!edge) return false;
  }
  return true;
}

CoarsenedSection snap_section(const PlaneSection& section, const std::vector<QuadLeaf>& leaves, double da,
                              int coarsest_level, const SnapNeighbour& below, const SnapNeighbour& above,
                              bool follow_below, const CoarseningCheck& check) {
  static const std::array<bool, 256> corner = [] {
    std::array<bool, 256> table{};
    for (int m = 0; m < 256; ++m) table[m] = corner_occupancy(m);
    return table;
  }();
  Simplifier simplifier(section, leaves, da, check);
  static const std::vector<QuadLeaf> nothing(1);
  const std::vector<QuadLeaf>* layers[3] = {below.leaves ? below.leaves : &nothing, &leaves,
                                            above.leaves ? above.leaves : &nothing};
  const QuadRaster raster = rasterize({layers[0], layers[1], layers[2]});
  const int nx = raster.nx(), ny = raster.ny();
  // Solidity per layer on the raster with its padding ring.
  const size_t row = static_cast<size_t>(nx) + 2;
  std::vector<char> solid[3];
  const PlaneSection* layer_sections[3] = {below.section, &section, above.section};
  for (int k = 0; k < 3; ++k) {
    const std::vector<int> faces = padded_faces(raster, k, *layers[k]);
    solid[k].resize(faces.size());
    for (size_t c = 0; c < faces.size(); ++c)
      solid[k][c] = layer_sections[k] && layer_sections[k]->face_solid[faces[c]];
  }
  auto at = [&](int cx, int cy) { return (cy + 1) * row + cx + 1; };
  // Per leaf: its raster cells, and whether the snapped-to neighbour is solid (1), empty (2) or
  // both (3) over them.
  const int target = follow_below ? 0 : 2;
  std::vector<std::array<int, 4>> range(leaves.size(), {nx, ny, -1, -1});
  std::vector<int> seen(leaves.size(), 0);
  for (int cy = 0; cy < ny; ++cy)
    for (int cx = 0; cx < nx; ++cx) {
      const int l = raster.leaf[1][static_cast<size_t>(cy) * nx + cx];
      auto& r = range[l];
      r = {std::min(r[0], cx), std::min(r[1], cy), std::max(r[2], cx), std::max(r[3], cy)};
      seen[l] |= solid[target][at(cx, cy)] ? 1 : 2;
    }
  // Corners at the levels below and above this plane among the vertices of a leaf's cells.
  auto corners_over = [&](const std::array<int, 4>& r) {
    int count = 0;
    for (int vy = r[1]; vy <= r[3] + 1; ++vy)
      for (int vx = r[0]; vx <= r[2] + 1; ++vx)
        for (int level = 0; level < 2; ++level) {
          int occupancy = 0;
          for (int dz = 0; dz < 2; ++dz)
            for (int dy = 0; dy < 2; ++dy)
              for (int dx = 0; dx < 2; ++dx)
                if (solid[level + dz][at(vx - 1 + dx, vy - 1 + dy)]) occupancy |= 1 << (dx + 2 * dy + 4 * dz);
          count += corner[occupancy];
        }
    return count;
  };
  std::vector<Change> relabels;
  for (int l = 0; l < static_cast<int>(leaves.size()); ++l) {
    const QuadLeaf& leaf = leaves[l];
    if (!leaf.mixed || seen[l] == 3 || leaf.cell.level <= coarsest_level) continue;
    const bool want_solid = seen[l] == 1;
    if ((section.face_solid[leaf.face] != 0) == want_solid) continue;
    int face = -1;
    double best = 0;
    for (const auto& [f, a] : leaf.face_areas)
      if ((section.face_solid[f] != 0) == want_solid && a > best) {
        best = a;
        face = f;
      }
    if (face < 0) continue;
    // Only where it removes corners.
    const auto& r = range[l];
    const int before = corners_over(r);
    for (int cy = r[1]; cy <= r[3]; ++cy)
      for (int cx = r[0]; cx <= r[2]; ++cx) solid[1][at(cx, cy)] = want_solid;
    const int after = corners_over(r);
    for (int cy = r[1]; cy <= r[3]; ++cy)
      for (int cx = r[0]; cx <= r[2]; ++cx) solid[1][at(cx, cy)] = !want_solid;
    if (after >= before) continue;
    QuadLeaf relabelled = leaf;
    relabelled.face = face;
    relabels.push_back(simplifier.change({l}, relabelled));
  }
  if (!relabels.empty()) simplifier.apply(std::move(relabels));
  return std::move(simplifier).result();
}

}  // namespace polycube
