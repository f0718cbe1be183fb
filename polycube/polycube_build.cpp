#include "polycube/polycube_build.h"

#include "polycube/errors.h"
#include "polycube/mesh_topology.h"
#include "polycube/plane_placement.h"
#include "polycube/polycube_slab_check.h"
#include "polycube/polycube_verify.h"
#include "polycube/quadtree_raster.h"
#include "polycube/quadtree_sampled.h"
#include "polycube/quadtree_section.h"
#include "polycube/quadtree_simplify.h"
#include "polycube/quadtree_topology.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

namespace polycube {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// The surface the topology stage sliced (the model, or the model with degenerate saddles split):
// its vertices are the first input_vertices of the sliced mesh, and each of its faces is the
// union of the refined faces with that origin. Corners are the original vertices among them,
// ordered like the refined faces' (their area vectors add up to the face's).
TriMesh sliced_surface(const SlicedMesh& sliced) {
  const int nv = sliced.input_vertices;
  const int nf = sliced.face_origin.size() ? sliced.face_origin.maxCoeff() + 1 : 0;
  TriMesh surface;
  surface.V = sliced.mesh.V.topRows(nv);
  std::vector<std::array<int, 3>> corners(nf, {-1, -1, -1});
  std::vector<Eigen::Vector3d> area(nf, Eigen::Vector3d::Zero());
  const Eigen::MatrixX3d& V = sliced.mesh.V;
  for (int f = 0; f < sliced.mesh.num_faces(); ++f) {
    const int o = sliced.face_origin[f];
    const Eigen::Vector3d a = V.row(sliced.mesh.F(f, 0)), b = V.row(sliced.mesh.F(f, 1)), c = V.row(sliced.mesh.F(f, 2));
    area[o] += (b - a).cross(c - a);
    for (int i = 0; i < 3; ++i) {
      const int v = sliced.mesh.F(f, i);
      if (v >= nv) continue;
      auto& k = corners[o];
      if (k[0] == v || k[1] == v || k[2] == v) continue;
      for (int& slot : k)
        if (slot < 0) {
          slot = v;
          break;
        }
    }
  }
  surface.F.resize(nf, 3);
  for (int o = 0; o < nf; ++o) {
    auto k = corners[o];
    if (k[2] < 0) throw AlgorithmError("build_polycube: cannot recover face " + std::to_string(o) + " of the sliced surface");
    const Eigen::Vector3d a = V.row(k[0]), b = V.row(k[1]), c = V.row(k[2]);
    if ((b - a).cross(c - a).dot(area[o]) < 0) std::swap(k[1], k[2]);
    surface.F.row(o) << k[0], k[1], k[2];
  }
  // Must be consistently oriented.
  const EdgeDefects defects = edge_defects(surface.F, build_edge_map(surface.F));
  if (defects.boundary || defects.nonmanifold)
    throw AlgorithmError("build_polycube: the recovered sliced surface is not closed");
  if (defects.misoriented)
    throw AlgorithmError("build_polycube: the recovered sliced surface is not consistently oriented");
  return surface;
}

// A plane's quadtree, kept per plane height across rounds, with the edits the repairs made.
struct PlaneState {
  QuadtreeEdits edits;
  bool dirty = true;  // edits changed since the quadtree was built
  int version = 0;    // of the quadtree, unique over all planes and rebuilds
  QuadtreeSection quadtree;
  std::shared_ptr<std::vector<QuadLeaf>> sampled;  // the finely sampled section, when needed
  bool sampled_faithful = false;                   // it has the contours' topology
};

// How badly a slab fails: non-manifold vertices, and far worse, unmatched model pieces.
int severity(const SlabCheck& check) {
  int unmatched = 0;
  for (int m : check.model_match) unmatched += m < 0;
  return check.nonmanifold_vertices + 1000 * unmatched;
}

// Label edits of one side of a slab (0 below, 1 above) that make the 2x2 cells around every
// non-manifold vertex nested: grow = the side takes the other side's solid cells there (with
// the face of a solid neighbour of the cell on its own side), shrink = it gives up its solid
// cells the other side lacks (taking the face of an empty neighbour). A cell is the finer of
// the two leaves over it.
std::vector<std::pair<QuadCell, int>> nesting_edits(const SlabCheck& check, const std::vector<QuadLeaf>* const leaves[2],
                                                    const PlaneSection* const sections[2], int side, bool grow) {
  std::map<QuadCell, int> edits;
  const int other = 1 - side;
  auto solid = [&](int k, int leaf) {
    return sections[k] && leaf >= 0 && sections[k]->face_solid[(*leaves[k])[leaf].face] != 0;
  };
  for (const auto& around : check.nonmanifold)
    for (int q = 0; q < 4; ++q) {
      const int mine = around[4 * side + q], theirs = around[4 * other + q];
      if (mine < 0) continue;
      if (grow ? (solid(side, mine) || !solid(other, theirs)) : (!solid(side, mine) || solid(other, theirs))) continue;
      int face = -1;
      for (int r : {q ^ 1, q ^ 2}) {
        const int neighbour = around[4 * side + r];
        if (neighbour >= 0 && solid(side, neighbour) == grow) {
          face = (*leaves[side])[neighbour].face;
          break;
        }
      }
      if (face < 0) continue;
      QuadCell cell = (*leaves[side])[mine].cell;
      if (sections[other] && theirs >= 0 && (*leaves[other])[theirs].cell.level > cell.level)
        cell = (*leaves[other])[theirs].cell;
      edits[cell] = face;
    }
  return {edits.begin(), edits.end()};
}

}  // namespace

PolycubeResult build_polycube(const TriMesh& model, const TopologyResult& topology, const PolycubeOptions& options) {
  const auto start = Clock::now();
  if (topology.sliced.pieces.empty() || topology.sliced.planes.empty())
    throw std::invalid_argument("build_polycube: the topology stage has no planes or pieces");
  for (const Piece& piece : topology.sliced.pieces)
    if (piece.genus != 0) throw std::invalid_argument("build_polycube: the topology stage left a piece of positive genus");
  if (options.da <= 0) throw std::invalid_argument("build_polycube: da must be positive");
  if (!(options.feature_distance >= 0)) throw std::invalid_argument("build_polycube: feature_distance must be >= 0");

  PolycubeResult result;
  result.genus = topology.genus;
  // The checks' work so far (quadtree_raster.h), against options.max_rasterized_cells.
  const long long work_start = rasterized_cells();
  const auto check_work = [&](const std::string& where) {
    result.rasterized_cells = rasterized_cells() - work_start;
    if (options.max_rasterized_cells > 0 && static_cast<double>(result.rasterized_cells) > options.max_rasterized_cells)
      throw AlgorithmError("build_polycube: the checks rasterized " + std::to_string(result.rasterized_cells) +
                           " cells " + where + ", more than the budget of " +
                           std::to_string(static_cast<long long>(options.max_rasterized_cells)));
  };
  const BoundingBox box = bounding_box(model.V);
  NormalisedFrame frame;
  frame.origin = box.min;
  frame.scale = box.extent().maxCoeff();
  if (!(frame.scale > 0)) throw std::invalid_argument("build_polycube: the model has no extent");

  // The surface to re-slice when planes are inserted.
  TriMesh surface;
  const bool same_surface = topology.split_saddles == 0 && topology.sliced.input_vertices == model.num_vertices();
  if (same_surface) surface = model;
  else surface = sliced_surface(topology.sliced);
  std::vector<double> heights(surface.V.col(2).data(), surface.V.col(2).data() + surface.V.rows());
  std::sort(heights.begin(), heights.end());
  const double z_min = heights.front(), z_max = heights.back(), height = z_max - z_min;

  QuadtreeOptions quadtree_options;
  quadtree_options.da = options.da;
  quadtree_options.feature_distance = options.feature_distance;
  quadtree_options.max_level = options.max_level;
  quadtree_options.max_repair_level = options.max_repair_level;
  quadtree_options.max_leaves = options.max_plane_cells;
  const int max_repair_level = std::min(std::max(options.max_repair_level, options.max_level), kQuadGridBits);

  SlicedMesh sliced = topology.sliced;
  std::map<double, PlaneState> states;  // per plane height
  std::map<std::pair<double, double>, int> slab_attempts;
  std::map<std::pair<double, double>, int> plane_moves;
  std::map<std::pair<double, double>, std::pair<std::pair<int, int>, SlabCheck>> check_cache;
  int next_version = 1;
  const std::set<double> original_planes(topology.sliced.planes.begin(), topology.sliced.planes.end());
  CrossSections sections;
  std::vector<const std::vector<QuadLeaf>*> leaves;
  const double below_all = -std::numeric_limits<double>::infinity(), above_all = -below_all;
  for (int round = 1;; ++round) {
    result.rounds = round;
    auto t = Clock::now();
    sections = cross_sections(sliced, frame);
    const int n = static_cast<int>(sliced.planes.size());
    leaves.assign(n, nullptr);
    std::vector<int> unusable;  // inserted planes whose section cannot be approximated
    for (int i = 0; i < n; ++i) {
      PlaneState& state = states[sliced.planes[i]];
      if (state.dirty) {
        state.quadtree = approximate_section(sections, i, state.edits, quadtree_options);
        state.dirty = false;
        state.version = next_version++;
        if (!state.quadtree.valid && !state.edits.labels.empty()) {
          // Later subdivisions made earlier label edits inconsistent: drop them.
          result.repairs.push_back("plane " + std::to_string(i) + ": dropped " +
                                   std::to_string(state.edits.labels.size()) + " cell relabellings (" +
                                   state.quadtree.problem + ")");
          state.edits.labels.clear();
          state.quadtree = approximate_section(sections, i, state.edits, quadtree_options);
        }
        if (!state.quadtree.valid && !original_planes.count(sliced.planes[i])) {
          unusable.push_back(i);
          continue;
        }
        if (!state.quadtree.valid) {
          // Name the likely cause: a self-intersecting surface cut where it meets itself.
          Eigen::Vector2d at;
          const int crossings = count_contour_crossings(sections, i, &at);
          std::string cause;
          if (crossings > 0) {
            const Eigen::Vector2d xy = frame.origin.head<2>() + frame.scale * at;
            std::ostringstream where;
            where << "; its contours cross each other at " << crossings << " point" << (crossings > 1 ? "s" : "") << ", e.g. ("
                  << xy.x() << ", " << xy.y() << ", " << sliced.planes[i]
                  << "): the surface intersects itself there (remove the self-intersections `inspect` counts)";
            cause = where.str();
          }
          throw AlgorithmError("build_polycube: cross-section cannot be approximated with its topology: " +
                               state.quadtree.problem + cause);
        }
      }
      leaves[i] = &state.quadtree.leaves;
    }
    result.seconds_quadtrees += seconds_since(t);
    if (!unusable.empty()) {
      // An inserted plane passes too close to a saddle (a neck or gap finer than the deepest
      // cells): move it elsewhere in its slab.
      t = Clock::now();
      std::vector<double> planes;
      for (int i = 0; i < n; ++i)
        if (std::find(unusable.begin(), unusable.end(), i) == unusable.end()) planes.push_back(sliced.planes[i]);
      for (int i : unusable) {
        const double lo = i > 0 ? sliced.planes[i - 1] : z_min, hi = i + 1 < n ? sliced.planes[i + 1] : z_max;
        const int moves = ++plane_moves[{lo, hi}];
        if (moves > 6)
          throw AlgorithmError("build_polycube: no plane between z = " + std::to_string(lo) + " and " +
                               std::to_string(hi) + " has an approximable cross-section: " +
                               states[sliced.planes[i]].quadtree.problem);
        const double fraction = moves % 2 == 1 ? 0.3 : 0.7;
        const double z = place_plane(heights, lo + fraction * (hi - lo), lo, hi, 0.1 * (hi - lo));
        planes.push_back(z);
        result.repairs.push_back("plane at z = " + std::to_string(sliced.planes[i]) + " moved to " +
                                 std::to_string(z) + ": " + states[sliced.planes[i]].quadtree.problem);
        states.erase(sliced.planes[i]);
      }
      sliced = slice_mesh(surface, planes);
      result.seconds_checks += seconds_since(t);
      if (round >= options.max_rounds)
        throw AlgorithmError("build_polycube: still moving planes after " + std::to_string(round) + " rounds");
      continue;
    }

    // Slabs: s between planes s-1 and s (0 below the first plane, n above the last).
    t = Clock::now();
    std::vector<std::vector<std::vector<int>>> model_pieces(n + 1);
    for (size_t p = 0; p < sliced.pieces.size(); ++p)
      model_pieces[sliced.pieces[p].plane_below + 1].push_back(sections.piece_contours[p]);
    auto leaves_of = [&](int plane) { return plane >= 0 && plane < n ? leaves[plane] : nullptr; };
    auto check = [&](int s, const std::vector<QuadLeaf>* lo_leaves, const std::vector<QuadLeaf>* hi_leaves) {
      SlabSide lo, hi;
      if (s > 0) lo = {s - 1, lo_leaves};
      if (s < n) hi = {s, hi_leaves};
      return check_slab(sections, lo, hi, model_pieces[s]);
    };
    // Checks of slabs whose planes did not change are kept from earlier rounds.
    std::vector<SlabCheck> checks(n + 1);
    for (int s = 0; s <= n; ++s) {
      const std::pair<double, double> key{s > 0 ? sliced.planes[s - 1] : below_all, s < n ? sliced.planes[s] : above_all};
      const std::pair<int, int> versions{s > 0 ? states[key.first].version : 0, s < n ? states[key.second].version : 0};
      auto it = check_cache.find(key);
      if (it != check_cache.end() && it->second.first == versions) {
        checks[s] = it->second.second;
        continue;
      }
      checks[s] = check(s, leaves_of(s - 1), leaves_of(s));
      check_cache[key] = {versions, checks[s]};
    }

    std::vector<double> inserted;
    std::vector<char> changed(n, 0);  // planes edited this round: their slabs are checked again next round
    int failing = 0;
    std::string first_problem;
    for (int s = 0; s <= n; ++s) {
      const SlabCheck& failed = checks[s];
      if (failed.ok()) continue;
      ++failing;
      const double z_lo = s > 0 ? sliced.planes[s - 1] : z_min, z_hi = s < n ? sliced.planes[s] : z_max;
      std::ostringstream where;
      where << "slab " << s << " (z " << z_lo << " .. " << z_hi << "): " << failed.problem;
      if (first_problem.empty()) first_problem = where.str();
      if ((s > 0 && changed[s - 1]) || (s < n && changed[s])) continue;

      // 1. Non-manifold touches: make the cells around each such vertex nested (grow or shrink
      //    one side's cells there); nested 2x2 configurations of two manifold cross-sections are
      //    always manifold. Accepted when the edited plane keeps its topology and neither of its
      //    slabs gets worse.
      bool repaired = false;
      if (!failed.nonmanifold.empty()) {
        const std::vector<QuadLeaf>* side_leaves[2] = {leaves_of(s - 1), leaves_of(s)};
        const PlaneSection* side_sections[2] = {s > 0 ? &sections.planes[s - 1] : nullptr,
                                                s < n ? &sections.planes[s] : nullptr};
        const int order[4][2] = {{1, 1}, {0, 1}, {0, 0}, {1, 0}};  // (side, grow): grow hi, grow lo, shrink lo, shrink hi
        for (const auto& [side, grow] : order) {
          const int plane = side == 0 ? s - 1 : s;
          if (plane < 0 || plane >= n) continue;
          const auto edits = nesting_edits(failed, side_leaves, side_sections, side, grow != 0);
          if (edits.empty()) continue;
          PlaneState trial = states[sliced.planes[plane]];
          trial.edits.labels.insert(trial.edits.labels.end(), edits.begin(), edits.end());
          trial.quadtree = approximate_section(sections, plane, trial.edits, quadtree_options);
          if (!trial.quadtree.valid) continue;
          const int other = side == 0 ? s - 1 : s + 1;
          const SlabCheck again = side == 0 ? check(s, &trial.quadtree.leaves, leaves_of(s))
                                            : check(s, leaves_of(s - 1), &trial.quadtree.leaves);
          const SlabCheck neighbour = side == 0 ? check(other, leaves_of(other - 1), &trial.quadtree.leaves)
                                                : check(other, &trial.quadtree.leaves, leaves_of(other));
          if (!(severity(again) < severity(failed) && severity(neighbour) <= severity(checks[other]))) continue;
          trial.version = next_version++;
          states[sliced.planes[plane]] = std::move(trial);
          changed[plane] = 1;
          result.relabelled_cells += static_cast<int>(edits.size());
          result.repairs.push_back(where.str() + "; " + (grow ? "grew " : "shrank ") + std::to_string(edits.size()) +
                                   " cells of plane " + std::to_string(plane));
          repaired = true;
          break;
        }
      }
      if (repaired) continue;

      // 2. Subdivide the cells where the slab's regions meet when the contours themselves,
      //    sampled finely, give the model's pieces (the quadtree lost what they have).
      const int attempts = ++slab_attempts[{s > 0 ? z_lo : below_all, s < n ? z_hi : above_all}];
      int requested = 0;
      if (attempts <= options.refine_attempts) {
        // When the sampled sections themselves lack the contours' topology (a gap or neck
        // finer than the samples), the reference says nothing: subdivide too.
        const std::vector<QuadLeaf>* sampled[2] = {nullptr, nullptr};
        bool faithful = true;
        for (int side = 0; side < 2; ++side) {
          const int plane = side == 0 ? s - 1 : s;
          if (plane < 0 || plane >= n) continue;
          PlaneState& state = states[sliced.planes[plane]];
          if (!state.sampled) {
            state.sampled = std::make_shared<std::vector<QuadLeaf>>(sample_section(sections, plane, 256));
            std::vector<char> unused;
            state.sampled_faithful = check_section_topology(sections.planes[plane], *state.sampled, unused).empty();
          }
          sampled[side] = state.sampled.get();
          faithful = faithful && state.sampled_faithful;
        }
        const SlabCheck reference = check(s, sampled[0], sampled[1]);
        const bool repairable = !faithful || std::find(reference.model_match.begin(), reference.model_match.end(), -1) ==
                                                 reference.model_match.end();
        for (int side = 0; side < 2 && repairable; ++side) {
          const int plane = side == 0 ? s - 1 : s;
          if (plane < 0 || plane >= n) continue;
          PlaneState& state = states[sliced.planes[plane]];
          const std::vector<int>& refine = side == 0 ? failed.lo_refine : failed.hi_refine;
          if (leaves[plane]->size() + 3 * refine.size() > static_cast<size_t>(options.max_plane_cells / 2)) continue;
          for (int l : refine) {
            const QuadCell& cell = (*leaves[plane])[l].cell;
            if (cell.level >= max_repair_level) continue;
            state.edits.splits.push_back(cell);
            state.dirty = true;
            changed[plane] = 1;
            ++requested;
          }
        }
      }
      if (requested > 0) {
        result.stacking_splits += requested;
        result.repairs.push_back(where.str() + "; subdivided " + std::to_string(requested) + " cells");
        continue;
      }

      // 3. A plane in the middle of the slab.
      if (z_hi - z_lo < options.min_slab * height)
        throw AlgorithmError("build_polycube: " + where.str() + ", and the slab is too thin for another plane");
      const double z = place_plane(heights, 0.5 * (z_lo + z_hi), z_lo, z_hi, 0.25 * (z_hi - z_lo));
      inserted.push_back(z);
      result.repairs.push_back(where.str() + "; inserted a plane at z = " + std::to_string(z));
    }
    result.seconds_checks += seconds_since(t);
    check_work("in " + std::to_string(round) + " rounds of repairs");
    if (failing == 0) break;
    if (round >= options.max_rounds)
      throw RepairRoundsExhausted("build_polycube: " + std::to_string(failing) + " slabs still fail after " +
                                      std::to_string(round) + " rounds; first: " + first_problem,
                                  failing);
    if (!inserted.empty()) {
      t = Clock::now();
      result.planes_inserted += static_cast<int>(inserted.size());
      if (result.planes_inserted > options.max_inserted_planes)
        throw AlgorithmError("build_polycube: more than " + std::to_string(options.max_inserted_planes) +
                             " planes inserted; still failing: " + first_problem);
      std::vector<double> planes = sliced.planes;
      planes.insert(planes.end(), inserted.begin(), inserted.end());
      sliced = slice_mesh(surface, planes);
      for (const Piece& piece : sliced.pieces)
        if (piece.genus != 0) throw AlgorithmError("build_polycube: re-slicing made a piece of positive genus");
      result.seconds_checks += seconds_since(t);
    }
  }

  for (const auto& [z, state] : states) {
    if (!std::binary_search(sliced.planes.begin(), sliced.planes.end(), z)) continue;
    result.accuracy_splits += state.quadtree.accuracy_splits;
    result.section_splits += state.quadtree.topology_splits;
    result.section_relabels += state.quadtree.topology_relabels;
  }

  // Simplification: merge sibling leaves back where the repairs made finer cells than d_a, the
  // sections' topology and both slabs need, then let each Q_i follow its neighbours where that
  // removes corners — every change checked like the repairs' (fewer corners, same guarantee).
  auto t = Clock::now();
  const int n = static_cast<int>(sliced.planes.size());
  std::vector<std::vector<QuadLeaf>> final_leaves;
  for (const auto* l : leaves) final_leaves.push_back(*l);
  const std::vector<std::vector<QuadLeaf>> refined_leaves =
      options.simplify ? final_leaves : std::vector<std::vector<QuadLeaf>>{};
  if (options.simplify) {
    // No merged cell wider than the widest gap between planes: Q's boundary moves horizontally
    // by about as much as the extrusions already stand off vertically.
    double widest_gap = z_max - z_min;
    if (n > 1) {
      widest_gap = 0;
      for (int i = 0; i + 1 < n; ++i) widest_gap = std::max(widest_gap, sliced.planes[i + 1] - sliced.planes[i]);
    }
    const int coarsest_level =
        std::clamp(static_cast<int>(std::ceil(std::log2(frame.scale / widest_gap) - 1e-9)), 0, kQuadGridBits);
    std::vector<std::vector<std::vector<int>>> model_pieces(n + 1);
    for (size_t p = 0; p < sliced.pieces.size(); ++p)
      model_pieces[sliced.pieces[p].plane_below + 1].push_back(sections.piece_contours[p]);
    // Plane i's two slabs with `trial` as Q_i.
    auto slabs_pass = [&](int i) {
      return [&, i](const std::vector<QuadLeaf>& trial, std::vector<char>& implicated) {
        const SlabCheck below = check_slab(sections, i > 0 ? SlabSide{i - 1, &final_leaves[i - 1]} : SlabSide{},
                                           SlabSide{i, &trial}, model_pieces[i]);
        const SlabCheck above = check_slab(sections, SlabSide{i, &trial},
                                           i + 1 < n ? SlabSide{i + 1, &final_leaves[i + 1]} : SlabSide{},
                                           model_pieces[i + 1]);
        for (int l : below.hi_refine) implicated[l] = 1;
        for (int l : above.lo_refine) implicated[l] = 1;
        return below.ok() && above.ok();
      };
    };
    auto neighbour = [&](int j) {
      return j >= 0 && j < n ? SnapNeighbour{&sections.planes[j], &final_leaves[j]} : SnapNeighbour{};
    };
    for (int i = 0; i < n; ++i) {
      CoarsenedSection coarsened =
          coarsen_section(sections.planes[i], final_leaves[i], options.da, coarsest_level, slabs_pass(i));
      result.coarsening_merges += coarsened.merges;
      final_leaves[i] = std::move(coarsened.leaves);
      check_work("while simplifying");
    }
    // Upwards, each plane following the one below; then downwards, following the one above.
    for (int pass = 0; pass < 2; ++pass)
      for (int k = 1; k < n; ++k) {
        const int i = pass == 0 ? k : n - 1 - k;
        CoarsenedSection snapped = snap_section(sections.planes[i], final_leaves[i], options.da, coarsest_level,
                                                neighbour(i - 1), neighbour(i + 1), pass == 0, slabs_pass(i));
        result.snapped_cells += snapped.merges;
        final_leaves[i] = std::move(snapped.leaves);
        check_work("while simplifying");
      }
  }
  result.seconds_simplify = seconds_since(t);

  // The surface and its triangulation, and the guarantee, on the mesh. Should the simplified
  // quadtrees fail the final check (the slab checks are combinatorial, the final one is not),
  // P is built again from the quadtrees as the repairs left them.
  PolycubeSurfaceOptions surface_options;
  surface_options.target_vertices =
      options.target_vertices > 0 ? options.target_vertices : std::max(model.num_vertices(), options.min_vertices);
  surface_options.avoid_z = sliced.planes;
  PolycubeVerification verification;
  const std::vector<std::vector<QuadLeaf>>* attempts[2] = {&final_leaves, &refined_leaves};
  const std::vector<std::vector<QuadLeaf>>* used = nullptr;
  for (const auto* attempt : attempts) {
    if (attempt->empty()) continue;
    used = attempt;
    const bool simplified = options.simplify && attempt == &final_leaves;
    std::string problem;
    try {
      t = Clock::now();
      result.polycube = build_polycube_surface(sections, *attempt, z_min, z_max, surface_options);
      result.seconds_surface += seconds_since(t);
      t = Clock::now();
      verification = verify_polycube(result.polycube, sections, sliced, topology.genus);
      result.seconds_verify += seconds_since(t);
      if (verification.ok() || !simplified) break;
      problem = verification.problems.front();
    } catch (const AlgorithmError& e) {
      if (!simplified) throw;
      problem = e.what();
    }
    result.repairs.push_back("simplified quadtrees fail the final check (" + problem +
                             "): rebuilt without simplification");
    result.coarsening_merges = result.snapped_cells = 0;
  }
  for (int i = 0; i < n; ++i) {
    for (const QuadLeaf& leaf : (*used)[i]) result.deepest_level = std::max(result.deepest_level, leaf.cell.level);
    for (double e : region_errors(sections.planes[i], (*used)[i]))
      result.max_region_error = std::max(result.max_region_error, e);
  }
  if (!verification.ok()) {
    std::string text;
    for (const std::string& p : verification.problems) text += (text.empty() ? "" : "; ") + p;
    throw AlgorithmError("build_polycube: the polycube fails its final check: " + text);
  }
  result.polycube_sliced = std::move(verification.sliced);
  result.polycube_piece_contours = std::move(verification.piece_contours);
  result.piece_match = std::move(verification.piece_match);
  result.planes_z = sliced.planes;
  result.model_sliced = std::move(sliced);
  result.model_sections = std::move(sections);
  result.rasterized_cells = rasterized_cells() - work_start;
  result.seconds_total = seconds_since(start);
  return result;
}

bool same_polycube(const PolycubeResult& a, const PolycubeResult& b) {
  const Polycube &p = a.polycube, &q = b.polycube;
  const auto same_sections = [](const std::vector<std::vector<SectionPolygon>>& x, const std::vector<std::vector<SectionPolygon>>& y) {
    if (x.size() != y.size()) return false;
    for (size_t i = 0; i < x.size(); ++i) {
      if (x[i].size() != y[i].size()) return false;
      for (size_t k = 0; k < x[i].size(); ++k)
        if (x[i][k].contour != y[i][k].contour || x[i][k].points != y[i][k].points) return false;
    }
    return true;
  };
  const auto same_edges = [](const std::vector<PolycubeEdge>& x, const std::vector<PolycubeEdge>& y) {
    if (x.size() != y.size()) return false;
    for (size_t i = 0; i < x.size(); ++i)
      if (x[i].vertices != y[i].vertices || x[i].axis != y[i].axis || x[i].faces[0] != y[i].faces[0] || x[i].faces[1] != y[i].faces[1])
        return false;
    return true;
  };
  return a.planes_z == b.planes_z && a.piece_match == b.piece_match && a.polycube_piece_contours == b.polycube_piece_contours &&
         p.corners == q.corners && p.vertices == q.vertices && p.levels == q.levels && p.spacing == q.spacing &&
         p.mesh.V.rows() == q.mesh.V.rows() && p.mesh.F.rows() == q.mesh.F.rows() && p.mesh.V == q.mesh.V && p.mesh.F == q.mesh.F &&
         p.face_axis.size() == q.face_axis.size() && p.face_axis == q.face_axis && p.face_patch.size() == q.face_patch.size() &&
         p.face_patch == q.face_patch && same_edges(p.edges, q.edges) && same_sections(p.sections, q.sections);
}

}  // namespace polycube
