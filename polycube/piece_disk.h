// §3.4 steps (i)–(ii) for one piece: slits that join its boundary loops into one, the piece cut
// open along them into a topological disk, and that disk embedded in the unit disk by a harmonic
// map with positive edge weights (an embedding by Tutte's / Floater's theorem, since the boundary
// goes to a convex polygon).
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

#include <functional>
#include <vector>

namespace polycube {

// A slit: a simple path of mesh edges from a vertex of loop `from` to a vertex of loop `to`, its
// inner vertices off every loop.
struct Slit {
  int from = -1;
  int to = -1;
  std::vector<int> path;
};

// Joins the loops of a genus-0 piece by slits into a tree rooted at loop `root`: repeatedly the
// shortest path (by `edge_length(a, b)`) from the loops joined so far to another loop, through
// vertices on no loop and no earlier slit, not starting or ending at an earlier slit's end.
//   loops   boundary loops (vertex cycles); #loops - 1 slits are returned, in the order found
// Throws AlgorithmError if some loop cannot be reached.
using EdgeLength = std::function<double(int, int)>;
std::vector<Slit> find_slits(const TriMesh& piece, const std::vector<std::vector<int>>& loops, int root, const EdgeLength& edge_length);

// The shortest path from vertex a to vertex b through vertices not `blocked` (a and b may be).
// Empty if there is none.
std::vector<int> shortest_path(const TriMesh& piece, int a, int b, const std::vector<char>& blocked, const EdgeLength& edge_length);

// Splits every edge with two faces (every edge not on a boundary loop) at its midpoint: faces
// become 4, 3 or 2 faces in the same plane, boundary loops keep their vertices and the surface
// does not move. Gives slits room where a piece is one triangle wide. New vertices are appended.
//   face_parent  per face of the result: the face of `mesh` it lies in
TriMesh split_inner_edges(const TriMesh& mesh, std::vector<int>& face_parent);

// The piece cut open along the slits.
//   mesh          the cut mesh: a vertex per wedge of faces between cut edges around each vertex
//   vertex_origin per cut vertex: the piece vertex it copies
//   boundary      the single boundary loop of the cut mesh, oriented with the faces
struct CutDisk {
  TriMesh mesh;
  std::vector<int> vertex_origin;
  std::vector<int> boundary;
};

// Cuts along the slit edges. Throws AlgorithmError if the result is not a disk (one boundary
// loop, Euler characteristic 1).
CutDisk cut_open(const TriMesh& piece, const std::vector<Slit>& slits);

// The cut disk with extra vertices on its boundary edges and its embedding.
//   mesh          3D positions (extra vertices on the edges they split) and faces: the cut
//                 mesh's faces, those on split boundary edges fanned from their opposite vertex
//   face_origin   per face: the face of the cut mesh (= of the piece) it lies in
//   vertex_origin per vertex: the piece vertex it copies, -1 for extra boundary vertices
//   uv            positions in the unit disk: boundary on the unit circle at the angles given,
//                 inside by the harmonic map
//   flipped       faces with signed area <= 0 in uv; min_area the smallest signed area
//   fixed         per vertex: on the unit circle (Dirichlet)
//   edges, edge_weight  the edges with a free end (a < b) and their harmonic-map weights
struct DiskEmbedding {
  TriMesh mesh;
  std::vector<int> face_origin;
  std::vector<int> vertex_origin;
  Eigen::MatrixX2d uv;
  int flipped = 0;
  double min_area = 0;
  std::vector<char> fixed;
  std::vector<std::pair<int, int>> edges;
  std::vector<double> edge_weight;
};

// Inserts the boundary points and embeds.
//   cut          the cut disk
//   angle_of     per vertex of cut.boundary (same order): its angle on the unit circle; angles
//                increase strictly (mod 2π) along the boundary, one turn in total
//   extra        per boundary edge k (from boundary[k] to boundary[k+1]): the points to insert on
//                it, as (angle, fraction of the way along the edge), ascending
// Edge weights: cotangent weights of the 3D triangles clamped to [1e-3, 1e3] (positive, so the
// map is an embedding whatever the mesh), Dirichlet boundary, sparse Cholesky.
DiskEmbedding embed_disk(const CutDisk& cut, const std::vector<double>& angle_of,
                         const std::vector<std::vector<std::pair<double, double>>>& extra);

// Signed area of face f in the disk.
double uv_area(const DiskEmbedding& disk, int f);

// Crowding. A harmonic map squeezes a part of the piece behind a narrow neck exponentially in
// the neck's length over its girth: a blind pocket or a thin finger lying between two cutting
// planes (femur: a canal of about 100 vertices whose disk triangles have 1e-25 of their share of the
// area). The other side's disk has no such part, so the map sends it to a point of the other
// surface (degenerate images), and the other side's triangles never reach it (lost area).
// decrowd_disk re-solves the disk with the weights of the edges of crowded faces lowered
// (log weight += step × mean over the edge's faces of min(log(ratio / target), 0)), repeatedly:
// lower weights let a region spread, the weights stay positive, so every iterate is still an
// embedding on the same convex boundary (Tutte / Floater), and faces at or above `target` keep
// their weights (uncrowded parts barely move).
//   area_ratio  per face of disk.mesh: its image's share of the area over its own share (the
//               caller's measure of crowding, e.g. through the other side's disk)
//   trigger     nothing is done unless some face's ratio is below it
//   stop        iterations end when every ratio is at or above it
// The iterate with the largest smallest ratio is kept (the input when none is better); an
// iterate with a flipped face (rounding in extreme weights) ends the iterations.
// Defaults measured on the shipped meshes (bench/map.md, bench/quad.md; this step alone, before the
// audit's second look changed the orientations kept): 1e-6 / 1e-3 / 1e-5 fixed only femur's canal;
// these also give cow's hooves and elephant's trunk tip more of P (quad Hausdorff femur 3.6 → 2.5 %,
// cow 11.6 → 8.9 %, elephant 0.62 → 0.45 %; the map's ε_angle lower on all three) and leave the
// paper models exactly as they were.
struct DecrowdOptions {
  double trigger = 1e-2;
  double target = 1e-1;
  double stop = 5e-2;
  double step = 1;
  int max_iterations = 12;
};
struct DecrowdResult {
  int iterations = 0;
  double min_ratio_before = 1;
  double min_ratio_after = 1;
};
using AreaRatio = std::function<std::vector<double>(const DiskEmbedding&)>;
DecrowdResult decrowd_disk(DiskEmbedding& disk, const AreaRatio& area_ratio, const DecrowdOptions& options = {});

}  // namespace polycube
