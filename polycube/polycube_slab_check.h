// The correspondence check of one slab of the stacked polycube (§3.2 stacking, §3 step iii):
// between planes i-1 and i the polycube P is Q_{i-1} extruded up to the middle height m, then
// Q_i above it, joined by the horizontal faces Q_{i-1} Δ Q_i at m. This checks, combinatorially
// on the common grid of the two quadtrees, that P is a 2-manifold there and that its pieces in
// the slab have exactly the loops of the model's pieces, each with genus 0.
#pragma once

#include "polycube/contour_sections.h"
#include "polycube/quadtree_section.h"

#include <array>
#include <string>
#include <vector>

namespace polycube {

// One side of a slab: a plane and its quadtree, or nothing (below the first / above the last
// plane: the empty set).
struct SlabSide {
  int plane = -1;                             // index into CrossSections::planes, -1 for none
  const std::vector<QuadLeaf>* leaves = nullptr;  // ignored when plane < 0
};

// What the check found.
//   nonmanifold_vertices  grid vertices at height m (the slab's middle) where P would not be a
//                         2-manifold (e.g. a cell of Q_{i-1} \ Q_i and one of Q_i \ Q_{i-1}
//                         sharing an edge, or boxes touching at a corner only)
//   nonmanifold    per such vertex: the leaves around it of lo (first 4) and hi (last 4), in
//                  the order SW, SE, NW, NE; -1 outside the unit square
//   pieces         P's pieces in the slab as the contour ids (CrossSections) of their loops
//   piece_genus    per piece
//   model_match    per model piece given: the P piece with exactly its loops and genus 0, or -1
//   lo_refine, hi_refine  leaves (indices into the sides' leaf lists) whose subdivision may
//                  repair what failed: mixed cells around non-manifold vertices and along the
//                  contours of unmatched pieces
//   problem        first failure, empty if none
struct SlabCheck {
  int nonmanifold_vertices = 0;
  std::vector<std::array<int, 8>> nonmanifold;
  std::vector<std::vector<int>> pieces;
  std::vector<int> piece_genus;
  std::vector<int> model_match;
  std::vector<int> lo_refine;
  std::vector<int> hi_refine;
  std::string problem;

  bool ok() const { return problem.empty(); }
};

// Checks the slab between `lo` and `hi` against the model's pieces in it, given as the contour
// ids of their loops (CrossSections::piece_contours). Both quadtrees must be valid
// (QuadtreeSection::valid), so that every contour has exactly one loop of Q.
//
// P in the slab deformation-retracts onto X = closure(Q_lo Δ Q_hi) ∪ ∂Q_lo ∪ ∂Q_hi at height m
// (the walls retract onto their top or bottom curves), so P's pieces are the components of the
// planar complex X, and a piece with b loops has genus (1 + h - b) / 2 where h is the number of
// bounded components of the plane minus that component (Alexander duality: χ = 1 - h).
SlabCheck check_slab(const CrossSections& sections, const SlabSide& lo, const SlabSide& hi,
                     const std::vector<std::vector<int>>& model_pieces);

// Whether P is a 2-manifold at a grid vertex, from the occupancy of its 8 octants: bit
// dx + 2 dy + 4 dz is set when the octant on side (dx, dy, dz) (0: negative) is inside.
// True when the vertex is not on the surface (all inside or all outside).
bool octants_manifold(int occupancy);

}  // namespace polycube
