#include "polycube/piece_mesh.h"

#include "polycube/errors.h"

#include <stdexcept>
#include <string>
#include <unordered_map>

namespace polycube {

PieceMesh extract_piece(const SlicedMesh& sliced, int piece) {
  if (piece < 0 || piece >= static_cast<int>(sliced.pieces.size()))
    throw std::out_of_range("extract_piece: piece " + std::to_string(piece) + " of " +
                            std::to_string(sliced.pieces.size()));
  const Piece& p = sliced.pieces[piece];
  const TriMesh& M = sliced.mesh;
  PieceMesh out;
  std::unordered_map<int, int> local;
  local.reserve(p.faces.size());
  out.mesh.F.resize(static_cast<Eigen::Index>(p.faces.size()), 3);
  out.face_to_global = p.faces;
  for (size_t k = 0; k < p.faces.size(); ++k)
    for (int i = 0; i < 3; ++i) {
      const int g = M.F(p.faces[k], i);
      auto [it, inserted] = local.emplace(g, static_cast<int>(out.vertex_to_global.size()));
      if (inserted) out.vertex_to_global.push_back(g);
      out.mesh.F(static_cast<Eigen::Index>(k), i) = it->second;
    }
  out.mesh.V.resize(static_cast<Eigen::Index>(out.vertex_to_global.size()), 3);
  for (size_t v = 0; v < out.vertex_to_global.size(); ++v)
    out.mesh.V.row(static_cast<Eigen::Index>(v)) = M.V.row(out.vertex_to_global[v]);
  out.loops.reserve(p.boundary_loops.size());
  for (const std::vector<int>& loop : p.boundary_loops) {
    std::vector<int> l;
    l.reserve(loop.size());
    for (int g : loop) {
      const auto it = local.find(g);
      if (it == local.end())
        throw MeshError("extract_piece: loop vertex " + std::to_string(g) + " is not on piece " +
                        std::to_string(piece));
      l.push_back(it->second);
    }
    out.loops.push_back(std::move(l));
  }
  out.loop_plane = p.loop_plane;
  return out;
}

}  // namespace polycube
