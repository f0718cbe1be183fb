// One piece M_i of a sliced mesh (§3 step iii) as a small triangle mesh of its own, so that the
// per-piece stages (uniform flat metric §3.3, piecewise map §3.4) work on compact local indices.
#pragma once

#include "polycube/mesh.h"
#include "polycube/slice.h"

#include <vector>

namespace polycube {

// A piece with local vertex ids.
//   mesh              the piece's faces (same order as Piece::faces) on its own vertices; the
//                     vertices are numbered in order of first use by those faces
//   vertex_to_global  #V(mesh): the vertex of SlicedMesh::mesh each local vertex is
//   face_to_global    #F(mesh): the face of SlicedMesh::mesh each local face is
//   loops             Piece::boundary_loops in local ids (same order, same orientation: the
//                     piece on the left)
//   loop_plane        Piece::loop_plane (index into SlicedMesh::planes per loop)
struct PieceMesh {
  TriMesh mesh;
  std::vector<int> vertex_to_global;
  std::vector<int> face_to_global;
  std::vector<std::vector<int>> loops;
  std::vector<int> loop_plane;
};

// Copies piece `piece` of `sliced` into its own mesh. Throws std::out_of_range if piece is not a
// valid index, MeshError if a loop vertex is not a vertex of the piece's faces.
PieceMesh extract_piece(const SlicedMesh& sliced, int piece);

}  // namespace polycube
