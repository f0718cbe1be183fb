// Meshes generated in code for tests: clean closed surfaces of known genus with decent triangle
// quality (for Laplacians, Ricci flow, tetrahedralization), and small broken fixtures whose only
// purpose is to carry one named defect for validation tests.
#pragma once

#include "polycube/mesh.h"

namespace polycube::test {

// ---- clean closed surfaces: 2-manifold, one component, outward-oriented ------------------------

// Parametric torus around the z axis (genus 1), centred at the origin.
//   R   distance from the z axis to the tube centre, R > r > 0
//   r   tube radius
//   nu  segments around the z axis (>= 3), nv segments around the tube (>= 3)
// Returns nu*nv vertices and 2*nu*nv triangles (each grid quad split along the same diagonal).
// Throws std::invalid_argument on bad parameters.
TriMesh make_torus(double R, double r, int nu, int nv);

// Closed smooth-ish surface of the given genus (>= 0), polygonised from an implicit function
// with marching tetrahedra, then improved by Delaunay edge flips and tangential smoothing with
// projection back onto the implicit surface.
//   genus 0: ellipsoid with semi-axes (1.2, 0.9, 0.7)
//   genus g: tube of radius 0.3 around a planar grid graph of g square cells of side 1.2 in the
//            plane z = 0 (one row for g <= 3, two rows otherwise), junctions blended smoothly
//   resolution  grid cells along the longest side of the bounding box (>= 16); the triangle
//               count grows with resolution^2: about 5k-12k triangles at 24, 20k-50k at 48
//               (fewest for long shapes such as genus 3, most for genus 1)
// Measured quality for genus 0..10, resolution 16..96: smallest angle > 10 degrees (> 13 up to
// resolution 48), smallest / mean triangle area > 0.005.
// Deterministic: the same arguments give the same mesh. Throws std::invalid_argument on bad
// parameters.
TriMesh make_genus_surface(int genus, int resolution = 48);

// Unit icosphere centred at the origin: the icosahedron with every triangle split in four
// `subdivisions` times (>= 0), vertices projected onto the sphere.
// Returns 10*4^s + 2 vertices and 20*4^s triangles.
TriMesh make_sphere(int subdivisions);

// The cube [-1, 1]^3 as 12 outward triangles (two per face): a polycube with 8 corners.
TriMesh make_cube();

// Open tube around the z axis: n vertices around, rows + 1 rings from z = 0 to z = height,
// quads split along alternating diagonals, outward-oriented; two boundary loops (genus 0).
TriMesh make_tube(double radius, double height, int n, int rows);

// A closed thin-walled pipe along z from 0 to length (genus 1): n vertices round each ring,
// rows + 1 rings on the outer wall (radius outer) and on the inner wall (radius inner), quads
// split along one diagonal, each end an annulus one quad wide; outward-oriented.
TriMesh make_pipe(double outer, double inner, double length, int n, int rows);

// A closed rod along z from 0 to length: n vertices round each end circle, one quad (two
// triangles) per side along the whole length, the ends closed by fans round a centre vertex (as
// CAD models are meshed: slivers when the rod is thin).
TriMesh make_rod(double radius, double length, int n);

// ---- broken fixtures: each has exactly the defect its name says --------------------------------

// Open tube (radius 1, height 2, 8 segments around, 2 rings of quads) without caps: one
// component, edge- and vertex-manifold, oriented, two boundary loops of 8 edges (genus 0).
TriMesh open_cylinder();

// Two disjoint closed outward-oriented tetrahedra: two connected components.
TriMesh two_tetrahedra();

// Triangular bipyramid (apexes above and below) plus the equatorial triangle as an inner
// membrane: no boundary edges, and each of the 3 membrane edges has exactly three faces (all
// other edges two). A single edge with three faces cannot occur in a surface without boundary
// (around each vertex the number of odd edges is even), so three is the fewest.
TriMesh nonmanifold_edge();

// Two closed outward-oriented tetrahedra sharing exactly one vertex (index 0): every edge has
// two faces, one vertex is non-manifold, one connected component (components join at vertices).
TriMesh nonmanifold_vertex();

// Closed tetrahedron with one face (row 3) listed in reverse order: every edge has two faces but
// the three edges of that face are traversed in the same direction by both their faces.
TriMesh flipped_face_tetrahedron();

}  // namespace polycube::test
