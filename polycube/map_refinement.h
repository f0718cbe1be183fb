// Refining P's triangulation where the map φ: P → M, sampled at P's vertices, is a poor chord of
// the continuous map (issue 5).
//
// Stage 4's φ (build_polycube_map) is a bijection in the continuum — per piece the composition of
// two embedded disk maps — and is piecewise linear on the common refinement of P's and M's disk
// triangulations. The files sample it at P's vertices only, and P's triangles are often large
// next to M's (a coarse P on a curved or coarse M): the chord through a triangle's three images
// can then point against M (a flipped triangle) and chords across M's edges lose area. Sampling
// φ at more points of P removes both: on the common refinement the sampled map is φ itself.
//
// Method. P's triangles are bisected where the sampled map is bad, and φ is evaluated at every
// new vertex with PolycubeMap::to_model (each new vertex is a point of a face of the unrefined P):
//   - a triangle is bad when its image is flipped or degenerate, by exactly the audit's test
//     (map_audit.h: the image's normal against the area-weighted normals of the distinct model
//     faces closest to its centroid and corners);
//   - while the total image area is off M's area by more than the tolerance, the triangles whose
//     split into four (at φ of their edge midpoints) would gain the most chord area are refined,
//     as many as the missing area needs;
//   - a marked triangle is refined by Rivara's longest-edge bisection (each step bisects the
//     terminal edge of the longest-edge propagation path, splitting both triangles on it), so the
//     triangulation stays conforming (no T-junctions) and its angles stay bounded below by half
//     of the unrefined ones.
// New vertices lie on P's edges — at their midpoints, or exactly on a cutting plane where an edge
// crosses one (not too near its ends): φ is glued there from two pieces' maps, its strongest
// kink, which chords straddling it never resolve at any scale. So the refined P, unlike the
// built one (PolycubeSurfaceOptions::avoid_z), may have vertices on the cutting planes; it is not
// sliced again. Every triangle stays in its polycube face, every normal exactly axis-aligned,
// P's corners and polycube vertices unchanged, and the surface the same. A refinement step (one
// marked triangle with its propagation path) is undone unless the triangles it split end with
// fewer bad ones (the triangle was bad) or no more (it was marked for area): φ as
// build_polycube_map evaluates it is not orientation-preserving at every point at fine scales
// (sampled on a 16 × 16 grid of each of torus_quad's P faces, 766 of 140 800 tiny triangles come
// out reversed, 279 of them with all corners in one model face), so blind bisection of bad
// triangles multiplies them. Rounds repeat until no triangle is bad and the area is within
// tolerance, or the vertex budget, round or level limit is reached, or no step is kept; the best
// round (fewest bad triangles, then area nearest the tolerance) is the attempt's result. When it
// turns M → P triangles bad (see model_to_polycube_before/after below), the attempt is repeated
// with the P faces near them frozen; the best admissible attempt is returned, and when none is
// better than the unrefined sampling, the unrefined P and map are returned unchanged, so the
// refinement never makes the P → M direction worse. The M → P samples keep their positions;
// only their faces are re-expressed in the refined triangles.
#pragma once

#include "polycube/map_audit.h"
#include "polycube/mesh.h"
#include "polycube/polycube_build.h"
#include "polycube/polycube_map.h"
#include "polycube/polycube_surface.h"

#include <Eigen/Core>

#include <vector>

namespace polycube {

struct MapRefinementOptions {
  // The image area to reach: |Σ image triangle areas / M's area − 1| <= this. The audit accepts
  // 0.02; the margin leaves room for the smoothing that runs on the refined sampling afterwards.
  double area_tolerance = 0.01;
  // Most vertices of the refined P: max(max_vertex_factor × #V(P), #V(P) + min_vertex_budget).
  double max_vertex_factor = 3;
  int min_vertex_budget = 5000;
  // Most refinement rounds (each refines every triangle marked in it once).
  int max_rounds = 40;
  // Most bisections below a triangle of the unrefined P: a bad triangle this deep is left as it
  // is (deeper images would be degenerate by the audit's area threshold long before anyway).
  int max_level = 30;
  // Worker threads for φ's evaluations and the audit's test; 0: one per hardware thread. The
  // result does not depend on it.
  int threads = 0;
};

// The refined sampling and what it took.
//   polycube          P with its triangle mesh refined: new vertices appended after the unrefined
//                     ones (same ids for those), face_axis / face_patch per refined triangle,
//                     every PolycubeEdge's vertex list with the new vertices on it, spacing
//                     recomputed; faces, corners, vertices, sections, levels unchanged
//   map               the vertex samples over the refined P: polycube_on_model(_xyz) per refined
//                     vertex, model_on_polycube as points of the refined triangles with the input's
//                     positions (model_on_polycube_xyz unchanged), pieces / contours / seconds
//                     copied. Its `data` is empty: to_model / to_polycube take points of the
//                     UNREFINED P, so call them on the input map (see polycube_origin)
//   polycube_origin   per refined vertex: the same point as a point of the unrefined P
//   face_origin       per refined triangle: the unrefined triangle it lies in
//   refined           false when the input sampling is returned unchanged (already within the
//                     targets, or no round improved on it)
//   converged         the returned sampling has no bad P → M triangle and its area is within
//                     area_tolerance
//   rounds            refinement rounds run (over all attempts)
//   bisections        edges bisected (in the returned sampling)
//   vertices_before/after, triangles_before/after  of P's mesh
//   before, after     the P → M direction judged exactly as audit_map_direction judges it
//                     (flipped, degenerate, max_distance, area_ratio, ok) for the input and the
//                     returned sampling
//   model_to_polycube_before/after  audit_map_direction of the M → P samples against the input's
//                     and the refined P (left default when no attempt improved on the input). The samples do
//                     not move, but the audit weighs the normals of the closest P triangles by
//                     their areas, so the count can change with P's triangulation. A refinement is
//                     kept only if P → M has no more bad (flipped or degenerate) triangles and
//                     either M → P has no more or both directions together have fewer.
//                     Before that rule, where M → P triangles turned bad, the input faces closest
//                     to them and their neighbours are frozen (never split) and the refinement
//                     runs again, at most 3 more times
//   model_to_polycube_rejected  a refinement better for P → M was dropped by that rule
//   frozen_faces      input faces frozen that way
//   seconds           wall time
struct MapRefinementResult {
  Polycube polycube;
  PolycubeMap map;
  std::vector<SurfacePoint> polycube_origin;
  Eigen::VectorXi face_origin;
  bool refined = false;
  bool converged = false;
  int rounds = 0;
  int bisections = 0;
  int vertices_before = 0, vertices_after = 0;
  int triangles_before = 0, triangles_after = 0;
  MapDirectionAudit before, after;
  MapDirectionAudit model_to_polycube_before, model_to_polycube_after;
  bool model_to_polycube_rejected = false;
  int frozen_faces = 0;
  double seconds = 0;
};

// Refines P's sampling of φ.
//   model     the mesh build_polycube_map was given (closed, outward)
//   polycube  build_polycube's result for it (the mesh that `map` was built on; edges crossing
//             its planes_z are split on them)
//   map       build_polycube_map(model, polycube): φ is evaluated at new vertices by to_model
// Throws std::invalid_argument when the map does not belong to the meshes (sample counts, face
// indices, no map data) or an option is out of range.
MapRefinementResult refine_map_sampling(const TriMesh& model, const PolycubeResult& polycube, const PolycubeMap& map,
                                        const MapRefinementOptions& options = {});

// The same refinement for a map known only at P's vertices (smooth_map's result): the map inside
// a triangle is read as its chord projected to the closest point of the model, the reading
// `polycube quad` makes of the written files. Used after the smoothing, which moves images off
// the places the first refinement put them (chords across the model's edges lose area again).
// Where those bisections leave the image area short by more than area_tolerance, the refinement
// is run again with a second kind of split, and the better result kept (fewer bad triangles of
// both directions, then of P → M, then the area): a P edge whose images lie in two model faces
// round a common model vertex is split where the straight line between them, over those faces
// unfolded about the vertex, crosses the edge it leaves the first face by, its new image exactly
// on that model edge. Halves that still cross are split again in later rounds, so chords come to
// lie in one closed model face each, where they lose nothing: on a CAD part's sharp edges the
// midpoint bisections gain area only in proportion to their count (a tetrahedron's smoothed map:
// 0.85 → 0.87 with 10 000 more vertices; with the edge splits 0.99 with 224, in the input frame).
//   polycube  the P the samples belong to (e.g. refine_map_sampling's refined P)
//   planes_z  heights new vertices are put on where edges cross them (PolycubeResult::planes_z)
//   samples   polycube_on_model(_xyz), model_on_polycube(_xyz) at that P's vertices
// Throws std::invalid_argument as refine_map_sampling does.
MapRefinementResult refine_vertex_map_sampling(const TriMesh& model, const Polycube& polycube, const std::vector<double>& planes_z,
                                               const PolycubeMap& samples, const MapRefinementOptions& options = {});

}  // namespace polycube
