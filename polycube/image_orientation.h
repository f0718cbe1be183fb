// The audit's orientation test of one image triangle (map_audit.h), shared by the audit and by
// the stages that must judge triangles exactly as it does (map_smoothing, map_refinement).
//
// An image triangle (a, b, c) is a chord of the target surface: only its corners lie on it. It
// is flipped when its normal faces away from the target's outward normal nearby, which is
// estimated from the distinct target faces closest to points of the chord, area-weighted:
//   1. the centroid and the three corners; if the chord faces along their sum, it is good;
//   2. otherwise a second, finer look: the faces closest to the 15 points of the barycentric grid
//      of order 4 (corners and edge points included) and the centroid; flipped only if the
//      chord faces away from their sum too.
// "The faces closest to a point" are every face through its closest point on the target, to
// within the in-face tolerance: a corner on an edge of the target brings both faces there, a
// corner on a vertex every face round it (TargetSurface::tied_faces). One face picked among tied ones would depend on how a search
// tree breaks ties, and so on the frame the meshes are given in: the audit of the files a user
// reads (in the input frame) must be the audit the stages ran (in the frame they chose).
// The first look alone misjudges chords whose corners lie on opposite faces of P — across a thin
// part, or a staircase P makes of a sloped model face (rotor: a chamfer triangle whose image runs
// from one end cap of a rod of P to the other, its normal within 10° of the model triangle's, and
// the faces nearest its corners summing to nearly zero): the sign is then the residue of a
// cancellation. The grid sees the faces the chord passes over. A chord reversed on one face, or
// folded wrongly across an edge, faces away from every face near it and stays flipped.
//
// An image triangle that lies in one target face (its corners within a tolerance of that face's
// triangle) is no chord: the target under it is that face, and it is judged by that face's
// normal alone (face_holding). Neighbouring faces' normals would misjudge it next to a sharp
// edge or a saddle vertex of a coarse target: an exact image of the overlay (map_overlay.h) in a
// small face beside a large one at a dihedral angle under 90° faces away from their sum.
#pragma once

#include "polycube/closest_point.h"

#include <Eigen/Core>

#include <algorithm>
#include <vector>

namespace polycube {

// Corners within this fraction of the target's bounding-box diagonal of a face lie in it.
inline constexpr double kInFaceTolerance = 1e-9;

// The first of `faces` whose triangle holds all three corners to within `tolerance`, or -1.
// corners(f, k): corner k of target face f. (Two faces can only both hold a non-degenerate
// triangle when they are coplanar, and then their normals agree.)
template <class Corners>
int face_holding(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const std::vector<int>& faces,
                 const Corners& corners, double tolerance) {
  for (const int f : faces) {
    const Eigen::Vector3d p = corners(f, 0), q = corners(f, 1), r = corners(f, 2);
    bool holds = true;
    for (const Eigen::Vector3d* x : {&a, &b, &c}) holds = holds && (closest_on_triangle(*x, p, q, r).point - *x).norm() <= tolerance;
    if (holds) return f;
  }
  return -1;
}

// closest(p, seed) -> a target face closest to p (seed: a face near p, or -1; only a hint).
// tied(p, f, faces): appends to `faces` every other target face through p's closest point on f,
// to within in_face (when that point lies on an edge or a vertex of f).
// area_vectors[f]: twice the area times the outward unit normal of target face f.
// fa, fb, fc: faces closest to a, b, c. corners(f, k): corner k of target face f; in_face:
// kInFaceTolerance × the target's bounding-box diagonal (face_holding, ties).
template <class ClosestFace, class TiedFaces, class Corners>
bool image_triangle_flipped(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, int fa, int fb, int fc,
                            const std::vector<Eigen::Vector3d>& area_vectors, const ClosestFace& closest, const TiedFaces& tied,
                            const Corners& corners, double in_face) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  constexpr int kOrder = 4;
  // The faces closest to the centroid and the corners, then to the grid's points off the corners.
  thread_local std::vector<int> faces;
  faces.clear();
  auto add = [&](const Eigen::Vector3d& p, int f) {
    if (f < 0) return;
    faces.push_back(f);
    tied(p, f, faces);
  };
  const Eigen::Vector3d centroid = (a + b + c) / 3;
  add(centroid, closest(centroid, fa));
  add(a, fa);
  add(b, fb);
  add(c, fc);
  auto distinct = [&]() {
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  };
  distinct();
  // Inside one of those faces: that face alone decides.
  const int holder = face_holding(a, b, c, faces, corners, in_face);
  if (holder >= 0) return n.dot(area_vectors[holder]) <= 0;
  auto faces_away = [&]() {
    distinct();
    Eigen::Vector3d nearby = Eigen::Vector3d::Zero();
    for (const int f : faces) nearby += area_vectors[f];
    return n.dot(nearby) <= 0;
  };
  if (!faces_away()) return false;
  for (int i = 0; i <= kOrder; ++i)
    for (int j = 0; i + j <= kOrder; ++j) {
      const int k = kOrder - i - j;
      if (i == kOrder || j == kOrder || k == kOrder) continue;  // the corners: already there
      const Eigen::Vector3d p = (i * a + j * b + k * c) / kOrder;
      add(p, closest(p, i >= j && i >= k ? fa : (j >= k ? fb : fc)));
    }
  return faces_away();
}

}  // namespace polycube
