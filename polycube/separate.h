// A copy of a self-intersecting model whose surface no longer meets itself, for the stages that
// cut it by planes. The map is intrinsic, but the polycube is built from the model's
// cross-sections: where the surface passes through itself (a tail through a flank, fingers
// through each other), a cutting plane's contours cross, the quadtree cannot give them the
// section's topology, and the orientations that cut there fail (CGAL's man.off failed in every
// one). The copy has the same vertices and faces; only the vertices round the crossings move, by
// implicit smoothing (mean curvature flow, local): thin parts that pass through each other shrink
// towards their middles and come apart. Every stage can then run on the copy, and its results are
// carried back to the model by the faces and barycentric coordinates the two share
// (to_original_surface).
#pragma once

#include "polycube/mesh.h"

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace polycube {

// Pairs of faces that intersect other than along a shared vertex or edge (CGAL's
// self_intersections), by face index.
std::vector<std::pair<int, int>> self_intersecting_faces(const TriMesh& mesh);

// One round: the vertices of the intersecting faces and `rings` rings round them (one ring more
// each round) take one implicit smoothing step, (M - t L) x' = M x with the rest of the mesh
// held, where L is the model's cotangent Laplacian (negative weights clamped to 0, so the system
// is positive definite), M its lumped vertex areas now, and t = step × diagonal² (the step is
// scale-free). Rounds go on until no face pair intersects.
struct SeparationOptions {
  double step = 1e-4;
  int rings = 2;
  int max_rounds = 20;
};

//   mesh            the copy: same faces, vertices round the crossings moved
//   pairs_before    intersecting face pairs of the model
//   rounds          smoothing rounds run
//   moved_vertices  vertices the copy moved
//   max_shift       largest vertex move, as a fraction of the bounding-box diagonal
struct Separation {
  TriMesh mesh;
  int pairs_before = 0;
  int rounds = 0;
  int moved_vertices = 0;
  double max_shift = 0;
  double seconds = 0;
};

// The model itself (pairs_before 0, no round) when it does not intersect itself.
// Throws AlgorithmError when face pairs still intersect after max_rounds.
Separation separate_self_intersections(const TriMesh& model, const SeparationOptions& options = {});

// Points on the surface of `copy` (a mesh with the same faces as `original`: the separated copy)
// moved to the same place of the original: each point's closest point on the copy, its face and
// barycentric coordinates there, evaluated on the original's face.
Eigen::MatrixX3d to_original_surface(const TriMesh& copy, const TriMesh& original, const Eigen::MatrixX3d& points);

// One point x of the copy's face f (up to rounding) at the same place of the original: f's
// barycentric coordinates of x (clamped to the face) evaluated on the original's face f. The two
// meshes must have the same faces (not checked here).
Eigen::Vector3d to_original_point(const TriMesh& copy, const TriMesh& original, int f, const Eigen::Vector3d& x);

}  // namespace polycube
