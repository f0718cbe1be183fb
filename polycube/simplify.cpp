#include "polycube/simplify.h"

#include "polycube/cgal_bridge.h"

#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_placement.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_cost.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_placement.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include <stdexcept>
#include <string>

namespace polycube {

TriMesh simplified_mesh(const TriMesh& mesh, int target_faces) {
  if (target_faces < 4) throw std::invalid_argument("simplified_mesh: target_faces must be >= 4, got " + std::to_string(target_faces));
  if (mesh.num_faces() <= target_faces) return mesh;
  namespace SMS = CGAL::Surface_mesh_simplification;
  cgal::SurfaceMesh sm = cgal::to_surface_mesh(mesh);
  // A closed triangle mesh has 3/2 edges per face.
  const SMS::Count_stop_predicate<cgal::SurfaceMesh> stop(static_cast<std::size_t>(1.5 * target_faces));
  const SMS::LindstromTurk_cost<cgal::SurfaceMesh> cost;
  const SMS::Bounded_normal_change_placement<SMS::LindstromTurk_placement<cgal::SurfaceMesh>> placement;
  SMS::edge_collapse(sm, stop, CGAL::parameters::get_cost(cost).get_placement(placement));
  return cgal::to_tri_mesh(sm);
}

}  // namespace polycube
