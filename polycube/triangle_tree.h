// Internal (CGAL; include only from engine .cpp files): the AABB tree types over a mesh's
// triangles that the distance measures and the audit use for closest points.
#pragma once

#include "polycube/mesh.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <vector>

namespace polycube::triangle_tree {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

inline Point point(const TriMesh& mesh, int v) { return Point(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)); }

// One CGAL triangle per face, in face order (a tree built on them reports face ids as iterator
// offsets).
inline std::vector<Triangle> triangles_of(const TriMesh& mesh) {
  std::vector<Triangle> triangles;
  triangles.reserve(mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) triangles.emplace_back(point(mesh, mesh.F(f, 0)), point(mesh, mesh.F(f, 1)), point(mesh, mesh.F(f, 2)));
  return triangles;
}

}  // namespace polycube::triangle_tree
