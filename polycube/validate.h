// The engine's entry gate: turns what a file held (a polygon soup) into the closed, connected,
// 2-manifold, outward-oriented triangle mesh every later stage assumes, repairing what can be
// repaired without changing the shape and reporting everything else with numbers.
#pragma once

#include "polycube/mesh.h"

#include <optional>
#include <string>
#include <vector>

namespace polycube {

// The model's size the stages compute with: squared areas (about diagonal^4) stay normal doubles.
inline constexpr double kSmallestDiagonal = 1e-50, kLargestDiagonal = 1e50;
// A boundary vertex within this times the bounding-box diagonal of the inside of another face's
// boundary edge is a T-junction, and that face is split there (prepare_mesh).
inline constexpr double kTJunctionTolerance = 1e-5;
// A face whose smallest altitude is at most this fraction of the bounding-box diagonal has no
// area the stages can use (its cotangents and flat metric are rounding noise): it counts as a
// zero-area face, as an exactly collinear one does.
inline constexpr double kZeroAltitude = 1e-12;

struct PrepareOptions {
  // Close every boundary loop with CGAL's hole filling (triangulate and refine, no fairing).
  bool fill_holes = false;
  // Keep only the component with the most faces.
  bool largest_component = false;
  // Search for pairs of intersecting faces (CGAL, about a second per million faces).
  bool check_self_intersections = true;
  // A model whose bounding box's centre is farther from the origin than this many diagonals is
  // moved there (PreparedMesh::offset): at 1e7 from the origin, a sphere 0.5 in radius built no
  // polycube (a contour's shoelace area of absolute coordinates came out negative). 0: never.
  double centre_beyond_diagonals = 1000;
};

// What the prepared mesh is, counted after the repairs of prepare_mesh.
struct MeshDiagnosis {
  int input_vertices = 0;
  int input_polygons = 0;
  int vertices = 0;
  int faces = 0;
  int edges = 0;
  int components = 0;
  int boundary_edges = 0;
  int boundary_loops = 0;
  int nonmanifold_edges = 0;     // edges with more than two faces
  int nonmanifold_vertices = 0;  // vertices whose faces form more than one fan
  bool orientable = true;        // false: no consistent orientation exists
  int degenerate_faces = 0;      // zero-area faces (collinear, or kZeroAltitude) that could not be removed
  int self_intersections = -1;   // intersecting face pairs; -1 when not checked
  int euler = 0;                 // V - E + F
  std::optional<int> genus;      // set for 2-manifold, orientable meshes
  BoundingBox bbox;
  // One line per reason the mesh cannot be mapped; empty when it can.
  std::vector<std::string> problems;
  // One line per property the method tolerates but the user should know about. Self-
  // intersections are one: every stage works on the surface's intrinsic metric and per-triangle
  // maps, so an embedding that touches itself still maps, but contours there may be coarser.
  std::vector<std::string> warnings;

  bool closed() const { return boundary_edges == 0; }
  bool manifold() const { return nonmanifold_edges == 0 && nonmanifold_vertices == 0; }
  bool valid() const { return problems.empty(); }
};

struct PreparedMesh {
  TriMesh mesh;
  MeshDiagnosis diagnosis;
  // One line per change made to the input (triangulation, removals, reorientation, repairs).
  std::vector<std::string> repairs;
  // The input's positions are mesh's plus this: zero unless the model was moved to the origin
  // (PrepareOptions::centre_beyond_diagonals). The diagnosis' bounding box stays the input's.
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};

// Triangulates polygons, removes repeated-vertex and duplicate faces and unreferenced vertices,
// closes seams where the mesh has a boundary (boundary vertices at exactly one position merged,
// faces split at T-junctions; each kept only when it leaves fewer boundary edges and no more
// non-manifold edges or vertices), orients faces consistently and outward, applies the optional repairs, removes zero-area faces
// where that keeps the mesh valid, and diagnoses the result. Never throws for mesh problems
// (they go to diagnosis.problems); throws InputError for non-finite coordinates or bad indices.
PreparedMesh prepare_mesh(const PolygonSoup& soup, const PrepareOptions& options = {});

// Throws MeshError with a one-line summary of diagnosis.problems unless the mesh is valid.
void require_mappable(const MeshDiagnosis& diagnosis);

}  // namespace polycube
