// A conforming quad grid on a polycube P: the integer-grid quads that φ: P → M carries onto the
// model as an all-quad remesh whose only irregular vertices are P's corners (issue 7).
//
// 1. Levels: per axis, the coordinates of P's face planes; they hold every polycube edge and
//    vertex. Lines at all levels cut each face into coarse cells, and since every face uses the
//    same lines, they meet across polycube edges: a conforming quad layout of P (no T-junctions),
//    every cell an axis-aligned rectangle, valence 4 except at P's cone points.
// 2. Free loops: a level line that closes into a loop through regular vertices only and runs
//    along no polycube edge is needed by no feature (it only exists because some other part of P
//    has a face at that height). Removing such loops merges the cells on both sides and leaves a
//    conforming rectangle layout, so lines end up only where P's corners and edges need them.
// 3. Chords: in a conforming layout the cells crossed by a chord (a strip through opposite sides)
//    all have the same width across it. Every chord is split into max(1, round(width / h))
//    equal parts, the same along its whole length, so each cell becomes a grid of near-square
//    quads whose lines continue into its neighbours: still no T-junctions, and a vertex has 4
//    quads except where P's total angle is not 2π — its corners.
// 4. Refinement (optional): a chord's parts need not be equal. Halving one part adds a line along
//    the whole chord at the same fraction of its width in every cell, so the layout stays
//    conforming; the quad application uses it where the carried quads miss the model
//    (refine_quads_to_model, quad_remesh.h).
#pragma once

#include "applications/quad/quad_mesh.h"
#include "polycube/mesh.h"
#include "polycube/polycube_map.h"

#include <Eigen/Core>

#include <array>
#include <functional>
#include <vector>

namespace polycube {

// A map from the polycube's surface to space: a point of P (a triangle of P's mesh and
// barycentric coordinates) to its image (φ: P → M).
using SurfaceMap = std::function<Eigen::Vector3d(const SurfacePoint&)>;

// A place where the grid should be finer (PolycubeGridOptions::refine_rounds).
struct GridRefinement {
  SurfacePoint point;
  int halvings = 1;
};

struct PolycubeGridOptions {
  // Quad size h in input units (on M when the grid is sized through a map); 0: chosen from
  // target_quads.
  double cell_size = 0;
  // About how many quads to make when cell_size is 0: h is the size whose uniform rounding gives
  // the count closest to this, then single chords get one part more (widest steps first) while
  // that brings the count closer. P's layout sets a minimum: one quad per layout cell.
  int target_quads = 10000;
  // Remove free loops (step 2). false keeps every level line across the whole polycube (the
  // plain global grid; many more, thinner quads on polycubes with many levels).
  bool remove_free_loops = true;
  // Plane coordinates closer than this times P's bounding-box diagonal are one level.
  double merge_tolerance = 1e-9;
  // More quads than this is an error (a cell size far too small for the shape).
  long long max_quads = 20'000'000;
  // Local refinement, in rounds (step 4 above): each point of a round is a point of P (a triangle
  // of the given mesh and barycentric coordinates); the part containing it of each of the two
  // chords through its cell is halved, `halvings` times (each time the half holding the point).
  // A part next to a cut another point of the same round made is not halved again in that round.
  // A halved part is a new grid line along the whole chord, so the grid stays conforming and no
  // vertex becomes irregular; quads there become rectangles on P. Empty: the uniform split.
  std::vector<std::vector<GridRefinement>> refine_rounds;
  // More quads than this (0: no limit) stops the refinement before the point that would exceed
  // it; the points are taken in order, so put the most important first.
  long long refine_max_quads = 0;
  // Threads for locating points on P and sizing chords through the map (0: one per hardware
  // thread; the map must then be callable from several threads at once); the grid does not
  // depend on it.
  int threads = 0;
};

// The grid on P.
//   mesh          all-quad mesh on P, positions on P, counter-clockwise seen from outside
//   on_polycube   #V: each vertex as a point of P (a triangle of the input mesh and barycentric
//                 coordinates)
//   quad_axis     #Q: +-1, +-2, +-3 for an outward normal along +-x, +-y, +-z
//   quad_cell     #Q: the layout cell each quad subdivides
//   quad_refined_by  #Q: a point of the last refinement round (index into
//                 options.refine_rounds.back()) that cut a line bounding the quad; -1: none
//   layout        the coarse layout on P after removing free loops (rectangles, conforming)
//   cell_parts    #layout quads by 2: parts of the cell's sides 0 and 2 (column 0) and 1 and 3
//                 (column 1)
//   frame         P's axes as rows, in the coordinates of the given mesh: the identity for an
//                 axis-aligned P; for a P written turned (`polycube map` writes P back in the
//                 input's frame after gridding the model in its principal axes) the directions of
//                 its face normals. Levels and quad_axis refer to these axes; positions are in
//                 the given mesh's coordinates.
//   levels        per axis: the distinct face-plane coordinates of P, ascending
//   corners       grid vertices at P's cone points (vertices of P whose total angle differs from
//                 2π: every polycube corner, also saddles where edges of only two directions
//                 meet), ascending
//   corner_polycube_vertex  per corner: the vertex of P it sits on
//   cell_size     h: the given one, or the one chosen for target_quads
//   level_cells   cells between consecutive levels (before removing free loops)
//   free_loops    loops removed
//   chords        of the layout
//   refined_parts chord parts halved by options.refine_rounds
//   sized_through_map  chord widths were measured on the map's images
//   seconds       wall time
struct PolycubeGrid {
  QuadMesh mesh;
  std::vector<SurfacePoint> on_polycube;
  Eigen::VectorXi quad_axis;
  Eigen::VectorXi quad_cell;
  Eigen::VectorXi quad_refined_by;
  QuadMesh layout;
  Eigen::MatrixX2i cell_parts;
  Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();
  std::array<std::vector<double>, 3> levels;
  std::vector<int> corners;
  std::vector<int> corner_polycube_vertex;
  double cell_size = 0;
  long long level_cells = 0;
  int free_loops = 0;
  int chords = 0;
  int refined_parts = 0;
  bool sized_through_map = false;
  double seconds = 0;
};

// Builds the grid from P's triangle mesh alone (so it works on a polycube.obj read from disk).
//   polycube  closed, outward-oriented, embedded triangle mesh, every triangle's normal along
//             one of three orthogonal directions (+-x, +-y, +-z, or turned: see frame)
//   size_map  optional φ: chord widths are then the longest image under φ of the chord's layout
//             edges (polylines through 8 samples, fewer on huge layouts), so quads come out near
//             h wide on M where φ stretches or shrinks P, instead of on P
// Throws MeshError when a triangle is degenerate or not axis-aligned (normal more than 1e-6 off
// P's axes), std::invalid_argument for bad options, AlgorithmError when the grid exceeds
// max_quads, or when P is not a polycube the grid can follow (opposite faces overlapping on one
// plane, a face boundary off the other faces' planes): the result is checked to be a closed
// oriented 2-manifold before it is returned.
PolycubeGrid build_polycube_grid(const TriMesh& polycube, const PolycubeGridOptions& options = {},
                                 const SurfaceMap& size_map = {});

// Vertices of a closed triangle mesh whose total angle differs from 2π by more than tolerance
// (radians): P's corners, where a quad grid must be irregular. Ascending.
std::vector<int> cone_vertices(const TriMesh& mesh, double tolerance = 1e-6);

}  // namespace polycube
