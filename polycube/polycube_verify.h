// The guarantee, checked on the final triangle mesh rather than assumed: P is a closed, oriented,
// connected 2-manifold of the model's genus whose triangles are all flat on axis-aligned faces,
// and P cut by the model's planes falls into pieces matching the model's pieces one to one,
// with the same boundary loops and genus 0 (§3 step iii, Appendix).
#pragma once

#include "polycube/contour_sections.h"
#include "polycube/polycube_surface.h"
#include "polycube/slice.h"

#include <string>
#include <vector>

namespace polycube {

// What the check found.
//   sliced           P cut by the model's planes (the pieces P_j)
//   piece_contours   per piece of P: the model contour (CrossSections id) of each of its loops
//   piece_match      per model piece: the piece of P with the same loops, -1 if none
//   genus            of P
//   problems         one line per violated property, empty when P is valid
struct PolycubeVerification {
  SlicedMesh sliced;
  std::vector<std::vector<int>> piece_contours;
  std::vector<int> piece_match;
  int genus = -1;
  std::vector<std::string> problems;

  bool ok() const { return problems.empty(); }
};

// Checks P against the model: the mesh properties (every edge with two faces in opposite
// directions, manifold vertices, one component, genus, positive volume, every triangle of
// positive area with a normal exactly along its face_axis), then slices P by the planes of
// model_sliced and matches every loop of P to a model contour through the polygons of Q_i
// (Polycube::sections) and every piece of P to the model piece with the same loop set.
PolycubeVerification verify_polycube(const Polycube& polycube, const CrossSections& model_sections,
                                     const SlicedMesh& model_sliced, int model_genus);

}  // namespace polycube
