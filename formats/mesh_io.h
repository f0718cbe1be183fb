// Reading and writing surface meshes. The format is chosen by the file extension (any case):
// read .obj .off .ply (ASCII and binary) .stl (ASCII and binary); write .obj .off .ply.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "polycube/mesh.h"

namespace polycube {

// Optional per-face and per-vertex colours for writers. Components lie in [0,1] (values outside
// are clamped, non-finite ones written as 0).
struct MeshColors {
  Eigen::MatrixX3d face_rgb;    // #F by 3 RGB per polygon, or empty for none
  Eigen::MatrixX3d vertex_rgb;  // #V by 3 RGB per vertex, or empty for none
};

// Reads the points and polygons of a mesh file, keeping polygons as they are (quads stay quads).
// STL stores every triangle corner separately; corners at exactly the same position are merged
// so that the result is indexed. Colours, normals and texture coordinates are ignored.
//   path  .obj, .off, .ply or .stl file
// Guarantees: at least one point and one polygon; every coordinate is finite; every polygon has
// at least 3 corners, all indices in 0..#points-1. (Repeated corners, unreferenced vertices and
// other mesh-level problems are left to validation.)
// Throws InputError with one line "<path>: [line <n>: ]<problem>" for a missing, unreadable, empty,
// truncated or malformed file, an unsupported extension, or data violating the guarantees.
PolygonSoup read_polygon_soup(const std::string& path);

// Writes a triangle mesh; see write_polygon_mesh.
void write_mesh(const std::string& path, const TriMesh& mesh);

// Writes a polygon mesh, atomically (see formats/atomic_file.h), in the format of path's extension:
//   .obj  ASCII; vertex colours as the common `v x y z r g b` extension, face colours dropped
//         (OBJ needs a material file for them)
//   .off  ASCII; COFF with vertex colours, face colours after each face's indices (0..255)
//   .ply  binary little-endian, double coordinates; colours as uchar red/green/blue properties
// Coordinates are written with the shortest decimal form that reads back to the same double, so
// every format round-trips V exactly.
//   V         #V by 3 vertex positions
//   polygons  #F polygons, each at least 3 vertex indices in 0..#V-1, in order around the face
//   colors    optional; each matrix empty or with #F (face_rgb) / #V (vertex_rgb) rows
// Throws OutputError for an unsupported extension, inconsistent input (bad index, colour row
// count) or when the file cannot be written.
void write_polygon_mesh(const std::string& path, const Eigen::MatrixX3d& V,
                        const std::vector<std::vector<int>>& polygons, const MeshColors* colors = nullptr);

}  // namespace polycube
