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
#include <array>
#include <vector>

namespace polycube {

// Corners within this fraction of the target's bounding-box diagonal of a face lie in it.
inline constexpr double kInFaceTolerance = 1e-9;

// The face among fm, fa, fb, fc (the faces closest to the centroid and to a, b, c) whose
// triangle holds all three corners to within `tolerance`, or -1. corners(f, k): corner k of
// target face f.
template <class Corners>
int face_holding(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, int fm, int fa, int fb, int fc,
                 const Corners& corners, double tolerance) {
  for (const int f : {fm, fa, fb, fc}) {
    if (f < 0) continue;
    const Eigen::Vector3d p = corners(f, 0), q = corners(f, 1), r = corners(f, 2);
    bool holds = true;
    for (const Eigen::Vector3d* x : {&a, &b, &c}) holds = holds && (closest_on_triangle(*x, p, q, r).point - *x).norm() <= tolerance;
    if (holds) return f;
  }
  return -1;
}

// closest(p, seed) -> the target face closest to p (seed: a face near p, or -1; only a hint).
// area_vectors[f]: twice the area times the outward unit normal of target face f.
// fa, fb, fc: the faces closest to a, b, c. corners(f, k): corner k of target face f; in_face:
// kInFaceTolerance × the target's bounding-box diagonal (face_holding).
template <class ClosestFace, class Corners>
bool image_triangle_flipped(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, int fa, int fb, int fc,
                            const std::vector<Eigen::Vector3d>& area_vectors, const ClosestFace& closest, const Corners& corners,
                            double in_face) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  constexpr int kOrder = 4;
  // The centroid, the corners, then the grid's points off the corners: at most 4 + 12 faces
  // (a fixed array: this runs for every triangle the smoothing's guard judges).
  std::array<int, 16> faces{};
  int count = 0;
  faces[count++] = closest((a + b + c) / 3, fa);
  faces[count++] = fa;
  faces[count++] = fb;
  faces[count++] = fc;
  // Inside one of those faces: that face alone decides.
  const int holder = face_holding(a, b, c, faces[0], fa, fb, fc, corners, in_face);
  if (holder >= 0) return n.dot(area_vectors[holder]) <= 0;
  auto faces_away = [&]() {
    std::sort(faces.begin(), faces.begin() + count);
    count = static_cast<int>(std::unique(faces.begin(), faces.begin() + count) - faces.begin());
    Eigen::Vector3d nearby = Eigen::Vector3d::Zero();
    for (int k = 0; k < count; ++k) nearby += area_vectors[faces[k]];
    return n.dot(nearby) <= 0;
  };
  if (!faces_away()) return false;
  for (int i = 0; i <= kOrder; ++i)
    for (int j = 0; i + j <= kOrder; ++j) {
      const int k = kOrder - i - j;
      if (i == kOrder || j == kOrder || k == kOrder) continue;  // the corners: already there
      faces[count++] = closest((i * a + j * b + k * c) / kOrder, i >= j && i >= k ? fa : (j >= k ? fb : fc));
    }
  return faces_away();
}

}  // namespace polycube
