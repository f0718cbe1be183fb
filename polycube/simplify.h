// A coarser copy of a closed mesh with the same topology, for work where the full resolution only
// costs time (scoring orientations of a large scan).
#pragma once

#include "polycube/mesh.h"

namespace polycube {

// The mesh simplified by edge collapses (CGAL's Lindstrom–Turk cost and placement, placements
// that would turn a face's normal by more than about 90° refused) until it has at most about
// target_faces faces. Collapses respect the link condition, so a closed 2-manifold keeps its
// genus and stays one component. A mesh already that small is returned unchanged.
// Throws MeshError when the mesh is not a manifold CGAL can take, std::invalid_argument for
// target_faces < 4.
TriMesh simplified_mesh(const TriMesh& mesh, int target_faces);

}  // namespace polycube
