#include "polycube/polycube_verify.h"

#include "polycube/errors.h"
#include "polycube/mesh_topology.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <map>
#include <set>
#include <sstream>

namespace polycube {

namespace {

// The polygon of Q_i (its model contour) whose boundary passes through p, -1 if none.
int contour_at(const std::vector<SectionPolygon>& polygons, const Eigen::Vector2d& p) {
  for (const SectionPolygon& polygon : polygons) {
    const size_t n = polygon.points.size();
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d& a = polygon.points[i];
      const Eigen::Vector2d& b = polygon.points[(i + 1) % n];
      if (a.x() == b.x() && p.x() == a.x() && p.y() >= std::min(a.y(), b.y()) && p.y() <= std::max(a.y(), b.y()))
        return polygon.contour;
      if (a.y() == b.y() && p.y() == a.y() && p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()))
        return polygon.contour;
    }
  }
  return -1;
}

// What identifies a piece across M and P: its slab and the contours of its loops. The contours
// alone do not: with a single plane (a thin plate sliced through its thickness once) the piece
// below and the piece above both have every contour of that plane.
std::vector<int> piece_key(int plane_below, std::vector<int> contours) {
  std::sort(contours.begin(), contours.end());
  contours.insert(contours.begin(), plane_below);
  return contours;
}

}  // namespace

PolycubeVerification verify_polycube(const Polycube& polycube, const CrossSections& model_sections,
                                     const SlicedMesh& model_sliced, int model_genus) {
  PolycubeVerification result;
  auto problem = [&](const std::string& text) { result.problems.push_back(text); };
  const TriMesh& mesh = polycube.mesh;
  const int nv = mesh.num_vertices(), nf = mesh.num_faces();
  if (nv == 0 || nf == 0 || polycube.face_axis.size() != nf) {
    problem("empty mesh or face_axis of the wrong size");
    return result;
  }
  if (!mesh.V.allFinite()) problem("non-finite vertex coordinates");
  if (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= nv) {
    problem("face indices out of range");
    return result;
  }

  // Every triangle flat on its axis-aligned face, with positive area and outward normal.
  int tilted = 0, degenerate = 0;
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const int axis = std::abs(polycube.face_axis[f]) - 1, sign = polycube.face_axis[f] > 0 ? 1 : -1;
    if (axis < 0 || axis > 2) {
      ++tilted;
      continue;
    }
    if (n[axis] == 0) ++degenerate;
    else if (n[(axis + 1) % 3] != 0 || n[(axis + 2) % 3] != 0 || (n[axis] > 0 ? 1 : -1) != sign) ++tilted;
  }
  if (degenerate) problem(std::to_string(degenerate) + " degenerate triangles");
  if (tilted) problem(std::to_string(tilted) + " triangles whose normal is not exactly their face's axis direction");

  // Closed, oriented, manifold, connected, of the model's genus, enclosing positive volume.
  const EdgeDefects defects = edge_defects(mesh.F, build_edge_map(mesh.F));
  if (defects.boundary) problem(std::to_string(defects.boundary) + " boundary edges");
  if (defects.nonmanifold) problem(std::to_string(defects.nonmanifold) + " edges with more than two triangles");
  if (defects.misoriented)
    problem(std::to_string(defects.misoriented) + " edges whose triangles disagree in orientation");
  if (!result.problems.empty()) return result;
  const int bad_vertices = count_nonmanifold_vertices(mesh.F, nv);
  if (bad_vertices) problem(std::to_string(bad_vertices) + " non-manifold vertices");
  const int unused = count_unreferenced_vertices(mesh.F, nv);
  if (unused) problem(std::to_string(unused) + " unused vertices");
  const int components = connected_components(mesh.F, nv);
  if (components != 1) problem(std::to_string(components) + " connected components");
  result.genus = genus(mesh.F, nv);
  if (result.genus != model_genus)
    problem("genus " + std::to_string(result.genus) + ", the model has genus " + std::to_string(model_genus));
  const double volume = signed_volume(mesh);
  if (!(volume > 0)) problem("signed volume " + std::to_string(volume) + " is not positive");
  if (!result.problems.empty()) return result;

  // Pieces: slice by the same planes, which must stay where they are (no vertex on a plane).
  result.sliced = slice_mesh(mesh, model_sliced.planes);
  if (result.sliced.planes != model_sliced.planes || result.sliced.nudged_planes != 0) {
    problem("the model's planes cannot slice the polycube unchanged (a vertex lies on a plane)");
    return result;
  }
  const int num_contours = static_cast<int>(model_sections.contours.size());
  std::vector<int> below(num_contours, 0), above(num_contours, 0);
  std::map<std::vector<int>, int> polycube_piece_of;
  result.piece_contours.resize(result.sliced.pieces.size());
  int unmatched_loops = 0, positive_genus = 0;
  for (size_t p = 0; p < result.sliced.pieces.size(); ++p) {
    const Piece& piece = result.sliced.pieces[p];
    if (piece.genus != 0) ++positive_genus;
    for (size_t l = 0; l < piece.boundary_loops.size(); ++l) {
      const std::vector<int>& loop = piece.boundary_loops[l];
      const int plane = piece.loop_plane[l];
      const Eigen::Vector3d mid = 0.5 * (result.sliced.mesh.V.row(loop[0]) + result.sliced.mesh.V.row(loop[1]));
      const int c = contour_at(polycube.sections[plane], mid.head<2>());
      if (c < 0 || model_sections.contours[c].plane != plane) {
        ++unmatched_loops;
        continue;
      }
      (plane == piece.plane_above ? below : above)[c]++;
      result.piece_contours[p].push_back(c);
    }
    polycube_piece_of[piece_key(piece.plane_below, result.piece_contours[p])] = static_cast<int>(p);
  }
  if (positive_genus) problem(std::to_string(positive_genus) + " polycube pieces of positive genus");
  if (unmatched_loops) problem(std::to_string(unmatched_loops) + " polycube loops on no polygon of Q");
  int missing = 0;
  for (int c = 0; c < num_contours; ++c) missing += below[c] != 1 || above[c] != 1;
  if (missing) problem(std::to_string(missing) + " model contours without exactly one polycube loop on each side");

  result.piece_match.assign(model_sliced.pieces.size(), -1);
  int unmatched_pieces = 0;
  std::set<int> used;
  for (size_t m = 0; m < model_sliced.pieces.size(); ++m) {
    const auto it = polycube_piece_of.find(piece_key(model_sliced.pieces[m].plane_below, model_sections.piece_contours[m]));
    if (it == polycube_piece_of.end() || !used.insert(it->second).second) {
      ++unmatched_pieces;
      continue;
    }
    result.piece_match[m] = it->second;
  }
  if (unmatched_pieces) problem(std::to_string(unmatched_pieces) + " model pieces without a polycube piece with the same loops");
  if (result.sliced.pieces.size() != model_sliced.pieces.size())
    problem("the polycube has " + std::to_string(result.sliced.pieces.size()) + " pieces, the model " +
            std::to_string(model_sliced.pieces.size()));
  return result;
}

}  // namespace polycube
