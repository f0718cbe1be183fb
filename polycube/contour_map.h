// The boundary map ψ of §3.4 (eq. 6, Fig. 6) between one contour of the model and the polygon of
// the polycube on the same cutting plane. Built once per contour and used by both pieces that meet
// there, so the piecewise map is continuous across the cut.
//
// Both curves get one common parameter u in [0, 1): on P's polygon u is the normalised arc length
// from a start vertex; on the model's contour u comes from the monotone correspondence F between
// the two arc lengths that minimises eq. 6, ∫ |ψ(v) − v|², plus a small penalty on stretching
// (dynamic programming over uniform samples of both curves, started at the best rotation, then
// smoothed), pinned piecewise linearly so that chosen pairs of vertices ("anchors": where the slits
// of §3.4 end) have exactly the same u. ψ maps the point of P at u to the point of the model at u.
// Following the nearest points rather than plain arc length keeps the correspondence of
// consecutive contours aligned, so pieces between them are not twisted.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace polycube {

// A point of a closed vertex loop: vertex `index` moved `fraction` of the way (in u) to the next
// vertex of the loop.
struct LoopPosition {
  int index = 0;
  double fraction = 0;
};

// One contour and its polygon.
//   model_vertices, polycube_vertices  vertex ids (of the sliced model and the sliced polycube),
//                counter-clockwise seen from +z
//   model_u, polycube_u  the common parameter of each vertex
//   offset       the eq. 6 rotation of the model's arc length against P's (start of F)
//   psi_p, psi_m F as a table: P arc length psi_p (0 .. 1, increasing) to model arc length psi_m
//                (offset .. offset + 1, strictly increasing)
//   rms_distance sqrt of the mean of |ψ(v) − v|² over P's polygon, input units (after pinning)
//   anchors      pairs (index into model_vertices, index into polycube_vertices) with equal u
//   u            the union of both curves' vertex parameters, ascending, each once (a model vertex
//                within 1e-10 of a polycube vertex shares its u)
//   model_at, polycube_at  where each u lies on either curve
struct ContourMap {
  std::vector<int> model_vertices;
  std::vector<int> polycube_vertices;
  std::vector<double> model_u;
  std::vector<double> polycube_u;
  double offset = 0;
  std::vector<double> psi_p, psi_m;
  double rms_distance = 0;
  std::vector<std::pair<int, int>> anchors;
  std::vector<double> u;
  std::vector<LoopPosition> model_at;
  std::vector<LoopPosition> polycube_at;
};

// Starts the map of a contour: orients both loops counter-clockwise, measures arc lengths and
// finds the eq. 6 offset. Anchors and parameters come later (add_anchor, finish_contour_map).
//   model_loop, polycube_loop  closed vertex cycles (either orientation) on the same plane
//   model_V, polycube_V        positions of those vertex ids
// Throws std::invalid_argument for loops with fewer than 3 vertices.
ContourMap start_contour_map(const std::vector<int>& model_loop, const Eigen::MatrixX3d& model_V,
                             const std::vector<int>& polycube_loop, const Eigen::MatrixX3d& polycube_V);

// Asks for model vertex `model_index` (into model_vertices) to be pinned to a polycube vertex
// (a slit ends there). Asking twice for the same vertex is one anchor.
void add_anchor(ContourMap& map, int model_index);

// Pins every anchor to a polycube vertex: in the same cyclic order as on the model, the first
// to the vertex closest (in arc length) to ψ's preimage of its model vertex, each later one to
// the closest among those that keep the order, arc lengths measured forwards from the first
// one's vertex (so a vertex just behind it is a whole turn away); then computes model_u,
// polycube_u, u, model_at, polycube_at and rms_distance. Throws AlgorithmError if the polygon
// has too few vertices for the anchors.
void finish_contour_map(ContourMap& map, const Eigen::MatrixX3d& model_V, const Eigen::MatrixX3d& polycube_V);

// After finish_contour_map: the polycube vertex (index into polycube_vertices) pinned to model
// vertex `model_index`. Throws std::out_of_range if it is not an anchor.
int anchor_of(const ContourMap& map, int model_index);

}  // namespace polycube
