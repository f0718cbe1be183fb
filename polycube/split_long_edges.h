// Finer triangulation of the same surface: long edges split at their midpoints. A coarse model
// (a CAD tetrahedron of 4 triangles, a cube of 12) gives the map's harmonic disk maps almost no
// interior vertices, so the map P → M shears whatever is carried through it (the quads'
// angles); the same surface with short edges does not. Not tried: CGAL's
// Polygon_mesh_processing::split_long_edges (documented for splitting constrained edges before
// an isotropic remeshing; how it triangulates the faces round the new vertices decides the
// triangles' shapes, which the disk maps' clamped cotangent weights need) and its isotropic
// remeshing (moves vertices: the surface changes at creases unless they are found and protected).
// Red splits keep a well-shaped triangle's pieces similar to it.
#pragma once

#include "polycube/mesh.h"

namespace polycube {

// What split_long_edges did.
//   mesh    the finer mesh: the input's vertices first, in order, then the midpoints; every new
//           triangle lies in an input triangle (the surface is the same point set)
//   rounds  rounds of splitting (each halves every edge still longer than max_length)
//   capped  stopped before every edge was short enough, at the round that would pass max_faces
struct SplitLongEdges {
  TriMesh mesh;
  int rounds = 0;
  bool capped = false;
};

// Splits every edge longer than max_length at its midpoint, round after round, until none is:
// a triangle with all three edges split becomes four similar ones (red), one with one edge split
// becomes two (green: the median to the split edge, no longer than the triangle's other edges);
// a triangle with two edges to split gets its third split too (so a green split never halves a
// triangle twice and its slivers compound). Edge lengths halve every round, so it ends after
// about log2(longest / max_length) rounds. A round that would make more than max_faces
// triangles is not made (capped). Triangles sharing an edge (any number of them) get the same
// midpoint. Throws std::invalid_argument for max_length <= 0 or max_faces < 1.
SplitLongEdges split_long_edges(const TriMesh& mesh, double max_length, long long max_faces);

// The share of the surface area (0..1) in triangles whose longest edge is more than `aspect` times
// their height onto it. The splits above keep a sliver's shape (a red split makes four similar
// triangles), so a model made of slivers gains nothing from them but more slivers. 0 for a mesh
// without area. Throws std::invalid_argument for aspect <= 0.
double sliver_area_share(const TriMesh& mesh, double aspect);

}  // namespace polycube
