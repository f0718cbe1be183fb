// Internal: conversion between our TriMesh and CGAL's Surface_mesh. Include only from .cpp files
// of the engine; public headers never show CGAL types.
#pragma once

#include "polycube/mesh.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

namespace polycube::cgal {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;

// Builds a Surface_mesh from an edge- and vertex-manifold, consistently oriented TriMesh.
// Vertex i of the result is vertex i of the input; face f is face f.
SurfaceMesh to_surface_mesh(const TriMesh& mesh);

// Converts back, compacting away removed elements.
TriMesh to_tri_mesh(const SurfaceMesh& sm);

}  // namespace polycube::cgal
