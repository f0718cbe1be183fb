#include "polycube/cgal_bridge.h"

#include "polycube/errors.h"

#include <vector>

namespace polycube::cgal {

SurfaceMesh to_surface_mesh(const TriMesh& mesh) {
  SurfaceMesh sm;
  std::vector<SurfaceMesh::Vertex_index> vertices;
  vertices.reserve(mesh.num_vertices());
  for (int v = 0; v < mesh.num_vertices(); ++v)
    vertices.push_back(sm.add_vertex(Point(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2))));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto face = sm.add_face(vertices[mesh.F(f, 0)], vertices[mesh.F(f, 1)], vertices[mesh.F(f, 2)]);
    if (face == SurfaceMesh::null_face())
      throw MeshError("to_surface_mesh: face " + std::to_string(f) + " cannot be added (mesh is not manifold or not oriented)");
  }
  return sm;
}

TriMesh to_tri_mesh(const SurfaceMesh& input) {
  SurfaceMesh sm = input;
  if (sm.has_garbage()) sm.collect_garbage();
  TriMesh mesh;
  mesh.V.resize(sm.number_of_vertices(), 3);
  for (auto v : sm.vertices()) {
    const Point& p = sm.point(v);
    mesh.V.row(v.idx()) << p.x(), p.y(), p.z();
  }
  mesh.F.resize(sm.number_of_faces(), 3);
  int row = 0;
  for (auto f : sm.faces()) {
    int corner = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) {
      if (corner == 3) throw MeshError("to_tri_mesh: face with more than 3 vertices");
      mesh.F(row, corner++) = static_cast<int>(v.idx());
    }
    ++row;
  }
  return mesh;
}

}  // namespace polycube::cgal
