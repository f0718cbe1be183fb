// Carrying the grid on P to the model M: each grid vertex, a point of P, goes through a map
// P → M. The quad application needs nothing else from the polycube map, so the map can be the
// one in memory (PolycubeMap::to_model) or one read back from a `polycube map` directory (its
// values at P's vertices, interpolated and placed on M).
#pragma once

#include "applications/quad/polycube_grid.h"
#include "applications/quad/quad_mesh.h"
#include "applications/quad/surface_projector.h"
#include "polycube/mesh.h"
#include "polycube/polycube_map.h"

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <vector>

namespace polycube {

struct CarryOptions {
  // Threads evaluating the map; 1: the calling thread only (for maps that are not thread-safe);
  // 0: one per hardware thread.
  int threads = 1;
};

// The grid's quads with every vertex moved to map(on_polycube[v]) (SurfaceMap: polycube_grid.h;
// it must be callable from several threads at once when threads != 1). Connectivity is the
// grid's.
// Throws AlgorithmError if the map returns a non-finite point.
QuadMesh carry_grid(const PolycubeGrid& grid, const SurfaceMap& map, const CarryOptions& options = {});

// A map known at P's vertices only, linear inside each triangle.
//   polycube  P's triangle mesh (the faces SurfacePoint::face refers to)
//   images    #V(P) by 3: the image of each vertex of P
// Copies what it needs. Throws std::invalid_argument if the row counts differ.
SurfaceMap vertex_image_map(const TriMesh& polycube, const Eigen::MatrixX3d& images);

// map followed by the closest point on the projector's surface (so that images interpolated
// between points of M land on M). Keeps the projector alive.
SurfaceMap projected_map(SurfaceMap map, std::shared_ptr<const SurfaceProjector> surface);

// Per vertex of grid `to`, the vertex of grid `from` at the same point (positions on P equal to
// 1e-9 of P's bounding-box diagonal), -1 for none: a refined grid keeps the lines of the grid it
// refines, so their crossings are the same vertices.
std::vector<int> same_grid_vertices(const PolycubeGrid& from, const PolycubeGrid& to);

// A refined grid carried as its refinement round starts: the vertices it shares with the grid it
// refines (same_grid_vertices) where that grid's finished quads have them (`quads`: carried,
// relaxed and fitted; same connectivity as `from`); each added one at its image under the map
// (so it reaches what the old quads cut across), shifted as the vertices of `from` round it
// were shifted from their images (barycentric in from's quads on P, as triangulate_quads splits
// them), then placed on `model` by closest point. An empty map: each added vertex where from's
// quads are on M at its place (the same barycentric interpolation of their positions), then on
// `model` by closest point (the quads split as they are, without the map). Throws
// std::invalid_argument when quads do not have from's connectivity; what carry_grid throws.
//   mesh  the carried grid
//   same  same_grid_vertices(from, grid)
struct RefinedCarry {
  QuadMesh mesh;
  std::vector<int> same;
};
RefinedCarry carry_refined_grid(const PolycubeGrid& grid, const SurfaceMap& map, const PolycubeGrid& from, const QuadMesh& quads,
                                const SurfaceProjector& model, const CarryOptions& options = {});

}  // namespace polycube
