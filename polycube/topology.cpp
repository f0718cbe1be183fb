#include "polycube/topology.h"

#include "polycube/disjoint_sets.h"

#include "polycube/errors.h"
#include "polycube/intrinsic_delaunay.h"
#include "polycube/mesh_topology.h"
#include "polycube/plane_placement.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>
#include <sstream>
#include <string>

namespace polycube {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Closed, connected, 2-manifold, oriented, finite, with height; throws MeshError otherwise.
// Returns the Euler characteristic.
int require_closed_surface(const TriMesh& mesh) {
  const int nv = mesh.num_vertices(), nf = mesh.num_faces();
  if (nv == 0 || nf == 0) throw MeshError("analyse_topology: empty mesh");
  if (!mesh.V.allFinite()) throw MeshError("analyse_topology: non-finite vertex coordinates");
  for (int f = 0; f < nf; ++f) {
    for (int i = 0; i < 3; ++i)
      if (mesh.F(f, i) < 0 || mesh.F(f, i) >= nv)
        throw MeshError("analyse_topology: face " + std::to_string(f) + " refers to vertex " +
                        std::to_string(mesh.F(f, i)) + " of " + std::to_string(nv));
    if (mesh.F(f, 0) == mesh.F(f, 1) || mesh.F(f, 1) == mesh.F(f, 2) || mesh.F(f, 2) == mesh.F(f, 0))
      throw MeshError("analyse_topology: face " + std::to_string(f) + " repeats a vertex");
  }
  const EdgeMap edges = build_edge_map(mesh.F);
  const EdgeDefects defects = edge_defects(mesh.F, edges);
  const int open = defects.boundary, nonmanifold = defects.nonmanifold, misoriented = defects.misoriented;
  const int nonmanifold_vertices = nonmanifold == 0 ? count_nonmanifold_vertices(mesh.F, nv) : 0;
  const int unused = count_unreferenced_vertices(mesh.F, nv);
  const int components = connected_components(mesh.F, nv);
  if (open || nonmanifold || misoriented || nonmanifold_vertices || unused || components != 1) {
    std::ostringstream message;
    message << "analyse_topology: mesh must be a closed, connected, oriented 2-manifold, got " << open
            << " boundary edges, " << nonmanifold << " non-manifold edges, " << nonmanifold_vertices
            << " non-manifold vertices, " << misoriented << " inconsistently oriented edges, " << unused
            << " unused vertices, " << components << " components";
    throw MeshError(message.str());
  }
  const BoundingBox box = bounding_box(mesh.V);
  if (!(box.max.z() > box.min.z())) throw MeshError("analyse_topology: mesh has no height (all z equal)");
  return nv - edges.num_edges() + nf;
}

// A piece as a small indexed mesh, for trying cuts at candidate heights without slicing.
class PieceCut {
 public:
  PieceCut(const SlicedMesh& sliced, const Piece& piece) {
    const Eigen::MatrixX3i& F = sliced.mesh.F;
    std::vector<int> local_of(sliced.mesh.V.rows(), -1);
    for (int f : piece.faces)
      for (int i = 0; i < 3; ++i)
        if (local_of[F(f, i)] < 0) {
          local_of[F(f, i)] = static_cast<int>(z_.size());
          z_.push_back(sliced.mesh.V(F(f, i), 2));
        }
    faces_.resize(piece.faces.size());
    for (size_t k = 0; k < piece.faces.size(); ++k)
      for (int i = 0; i < 3; ++i) faces_[k][i] = local_of[F(piece.faces[k], i)];
    // Local edges with their (one or two) faces.
    Eigen::MatrixX3i local_F(faces_.size(), 3);
    for (size_t k = 0; k < faces_.size(); ++k) local_F.row(k) << faces_[k][0], faces_[k][1], faces_[k][2];
    const EdgeMap edges = build_edge_map(local_F);
    edge_ends_.resize(edges.num_edges());
    edge_faces_.resize(edges.num_edges());
    for (int e = 0; e < edges.num_edges(); ++e) {
      edge_ends_[e] = {edges.E(e, 0), edges.E(e, 1)};
      edge_faces_[e] = {edges.EF(e, 0), edges.EF(e, 1)};
    }
    for (const auto& loop : piece.boundary_loops) loop_vertex_.push_back(local_of[loop.front()]);
  }

  // Total genus of the parts of the piece below and above height c (c strictly inside the slab,
  // vertices at exactly c count as above).
  int genus_after_cut(double c) {
    const int nv = static_cast<int>(z_.size()), ne = static_cast<int>(edge_ends_.size());
    auto below = [&](int v) { return z_[v] < c; };
    vertex_sets_.reset(nv);
    edge_sets_.reset(ne);
    for (int e = 0; e < ne; ++e)
      if (below(edge_ends_[e][0]) == below(edge_ends_[e][1])) vertex_sets_.unite(edge_ends_[e][0], edge_ends_[e][1]);
    // Level loops at c: crossing edges joined through the faces they cross.
    face_crossing_.assign(faces_.size(), -1);
    for (int e = 0; e < ne; ++e) {
      if (below(edge_ends_[e][0]) == below(edge_ends_[e][1])) continue;
      for (int f : edge_faces_[e]) {
        if (f < 0) continue;
        if (face_crossing_[f] < 0)
          face_crossing_[f] = e;
        else
          edge_sets_.unite(face_crossing_[f], e);
      }
    }
    // Per component (root vertex): chi and boundary loop count.
    chi_.assign(nv, 0);
    loops_.assign(nv, 0);
    used_.assign(nv, 0);
    for (int v = 0; v < nv; ++v) {
      ++chi_[vertex_sets_.find(v)];
      used_[vertex_sets_.find(v)] = 1;
    }
    for (int e = 0; e < ne; ++e)
      if (below(edge_ends_[e][0]) == below(edge_ends_[e][1])) --chi_[vertex_sets_.find(edge_ends_[e][0])];
    for (const auto& face : faces_)
      if (below(face[0]) == below(face[1]) && below(face[1]) == below(face[2])) ++chi_[vertex_sets_.find(face[0])];
    for (int v : loop_vertex_) ++loops_[vertex_sets_.find(v)];
    for (int e = 0; e < ne; ++e) {
      if (below(edge_ends_[e][0]) == below(edge_ends_[e][1]) || edge_sets_.find(e) != e) continue;
      // One new loop, bounding a component on each side.
      ++loops_[vertex_sets_.find(edge_ends_[e][0])];
      ++loops_[vertex_sets_.find(edge_ends_[e][1])];
    }
    int total = 0;
    for (int v = 0; v < nv; ++v)
      if (used_[v] && vertex_sets_.find(v) == v) total += (2 - chi_[v] - loops_[v]) / 2;
    return total;
  }

 private:
  std::vector<double> z_;
  std::vector<std::array<int, 3>> faces_;
  std::vector<std::array<int, 2>> edge_ends_, edge_faces_;
  std::vector<int> loop_vertex_;
  DisjointSets vertex_sets_, edge_sets_;
  std::vector<int> face_crossing_, chi_, loops_;
  std::vector<char> used_;
};

// Critical points of the height function z on a mesh's own triangulation (simulation of
// simplicity for equal z), without cancellation: every one of them is genuine.
// Per vertex: 0 regular, -1 extremum, m > 0 saddle of multiplicity m.
std::vector<int> height_critical_points(const TriMesh& mesh) {
  IntrinsicDelaunayOptions no_flips;
  no_flips.max_flips_per_edge = 0;
  const IntrinsicTriangulation input = intrinsic_delaunay(mesh, no_flips);
  const CriticalPoints zc = critical_points(input, mesh.V.col(2));
  std::vector<int> kind(mesh.num_vertices(), 0);
  for (const auto* list : {&zc.minima, &zc.maxima})
    for (int v : *list) kind[v] = -1;
  for (size_t k = 0; k < zc.saddles.size(); ++k) kind[zc.saddles[k]] = zc.saddle_multiplicity[k];
  return kind;
}

// What to do about a piece of positive genus.
struct Refinement {
  double plane = 0;        // a new plane, or
  int split_vertex = -1;   // a degenerate saddle to split first
};

// The plane to add for a piece of positive genus: between two consecutive distinct heights of
// the z-critical vertices inside it, the gap whose cut leaves the least genus, then the widest.
// When all of them lie at one height, the handle sits in a degenerate saddle (a monkey saddle
// of z): ask for it to be split.
Refinement refine_piece(const SlicedMesh& sliced, const Piece& piece, const std::vector<int>& z_critical,
                        const std::vector<double>& sorted_heights, int piece_index) {
  std::vector<double> levels;
  std::vector<int> critical;
  for (int f : piece.faces)
    for (int i = 0; i < 3; ++i) {
      const int v = sliced.mesh.F(f, i);
      if (v < sliced.input_vertices && z_critical[v] != 0) {
        levels.push_back(sliced.mesh.V(v, 2));
        critical.push_back(v);
      }
    }
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  std::sort(critical.begin(), critical.end());
  critical.erase(std::unique(critical.begin(), critical.end()), critical.end());
  Refinement refinement;
  if (levels.size() < 2) {
    for (int v : critical)
      if (z_critical[v] >= 2 && (refinement.split_vertex < 0 || z_critical[v] > z_critical[refinement.split_vertex]))
        refinement.split_vertex = v;
    if (refinement.split_vertex >= 0) return refinement;
    std::ostringstream message;
    message << "analyse_topology: piece " << piece_index << " has genus " << piece.genus
            << " but its critical points of z lie at " << levels.size() << " height(s) (vertices";
    for (int v : critical) message << " " << v << (z_critical[v] > 0 ? "/saddle" : "/extremum");
    message << "); no horizontal plane can cut its handle";
    throw AlgorithmError(message.str());
  }
  // Try at most ~256 gaps, evenly spread.
  const int gaps = static_cast<int>(levels.size()) - 1;
  const int stride = std::max(1, gaps / 256);
  PieceCut cut(sliced, piece);
  int best = -1, best_genus = 0;
  double best_width = 0;
  for (int k = 0; k < gaps; k += stride) {
    const int genus = cut.genus_after_cut(0.5 * (levels[k] + levels[k + 1]));
    const double width = levels[k + 1] - levels[k];
    if (best < 0 || genus < best_genus || (genus == best_genus && width > best_width)) {
      best = k;
      best_genus = genus;
      best_width = width;
    }
  }
  const double lo = levels[best], hi = levels[best + 1];
  refinement.plane = place_plane(sorted_heights, 0.5 * (lo + hi), lo, hi, 0.25 * (hi - lo));
  return refinement;
}

// Splits the saddle of z at v (multiplicity m >= 2: 2(m+1) alternating arcs of higher and
// lower neighbours around it) into two saddles at different heights, by a vertex split: a new
// vertex w takes over one arc of v's link together with the two neighbours (wings) beside it,
// and is placed a third of the way from v towards the wings' midpoint, so that it sits on the
// wings' side of v's height. v keeps multiplicity m - 1, w gets a simple saddle, and a plane can
// then pass between them. This moves the surface locally (within the star of v); it is needed
// only where the handle of a piece is concentrated in one PL monkey saddle, which no
// horizontal plane can cut. Among the arcs, takes the valid split (no folded or degenerate
// triangle, v's multiplicity drops, no new degenerate saddle) with the best triangles.
// Returns false when no arc gives a valid split.
bool split_degenerate_saddle(TriMesh& mesh, int v, const std::vector<int>& z_critical) {
  const Eigen::MatrixX3d& V = mesh.V;
  // Faces around v in counter-clockwise order: face k is (v, link[k], link[k+1]).
  std::vector<int> around, link;
  {
    std::vector<std::array<int, 3>> star;  // (face, next link vertex a, b) with face = (v, a, b)
    for (int f = 0; f < mesh.num_faces(); ++f)
      for (int c = 0; c < 3; ++c)
        if (mesh.F(f, c) == v) star.push_back({f, mesh.F(f, (c + 1) % 3), mesh.F(f, (c + 2) % 3)});
    if (star.size() < 3) return false;
    int a = star[0][1];
    for (size_t k = 0; k < star.size(); ++k) {
      auto it = std::find_if(star.begin(), star.end(), [&](const std::array<int, 3>& s) { return s[1] == a; });
      if (it == star.end()) return false;
      around.push_back((*it)[0]);
      link.push_back(a);
      a = (*it)[2];
    }
    if (a != link.front()) return false;
  }
  const int d = static_cast<int>(link.size());
  auto above = [&](int u, int w) { return V(u, 2) > V(w, 2) || (V(u, 2) == V(w, 2) && u > w); };
  std::vector<char> up(d);
  for (int k = 0; k < d; ++k) up[k] = above(link[k], v);
  auto normal = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    return Eigen::Vector3d((b - a).cross(c - a));
  };
  auto quality = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const double s = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
    return s > 0 ? 2 * std::sqrt(3.0) * (b - a).cross(c - a).norm() / s : 0.0;
  };
  const int m = z_critical[v];
  int degenerate_before = 0;
  for (int kind : z_critical) degenerate_before += kind >= 2;

  // The mesh after moving faces a .. b-1 around v to a new vertex at pw; worst gets the worst
  // quality of the changed faces, 0 if one of them folds over.
  auto split = [&](int a, int b, const Eigen::Vector3d& pw, double& worst) {
    const Eigen::Vector3d pv = V.row(v), pa = V.row(link[a]), pb = V.row(link[b]);
    TriMesh candidate = mesh;
    const int w = mesh.num_vertices(), nf = mesh.num_faces();
    candidate.V.conservativeResize(w + 1, 3);
    candidate.V.row(w) = pw.transpose();
    candidate.F.conservativeResize(nf + 2, 3);
    bool valid = true;
    worst = 1;
    for (int k = a; k != b; k = (k + 1) % d) {
      const Eigen::Vector3d p1 = V.row(link[k]), p2 = V.row(link[(k + 1) % d]);
      valid = valid && normal(pv, p1, p2).dot(normal(pw, p1, p2)) > 0;
      worst = std::min(worst, quality(pw, p1, p2));
      candidate.F.row(around[k]) << w, link[k], link[(k + 1) % d];
    }
    // The two new faces beside the new edge v-w, against the faces they border.
    const Eigen::Vector3d na = normal(pv, V.row(link[(a + d - 1) % d]), pa) + normal(pv, pa, V.row(link[(a + 1) % d]));
    const Eigen::Vector3d nb = normal(pv, V.row(link[(b + d - 1) % d]), pb) + normal(pv, pb, V.row(link[(b + 1) % d]));
    valid = valid && normal(pv, pa, pw).dot(na) > 0 && normal(pw, pb, pv).dot(nb) > 0;
    worst = valid ? std::min({worst, quality(pv, pa, pw), quality(pw, pb, pv)}) : 0.0;
    candidate.F.row(nf) << v, link[a], w;
    candidate.F.row(nf + 1) << w, link[b], v;
    return candidate;
  };

  TriMesh best_mesh;
  double best_quality = 0;
  for (int start = 0; start < d; ++start) {
    // Arcs start where the sign changes; the arc [start, end] is the excursion, a = start - 1
    // and b = end + 1 its wings.
    if (up[start] == up[(start + d - 1) % d]) continue;
    int end = start;
    while (up[(end + 1) % d] == up[start]) end = (end + 1) % d;
    const int a = (start + d - 1) % d, b = (end + 1) % d;
    const Eigen::Vector3d pv = V.row(v), pa = V.row(link[a]), pb = V.row(link[b]);
    const Eigen::Vector3d mid = 0.5 * (pa + pb);
    // w stays strictly between v and the nearer wing in height.
    const double wing_gap = up[a] ? std::min(pa.z(), pb.z()) - pv.z() : pv.z() - std::max(pa.z(), pb.z());
    const double mid_gap = std::abs(mid.z() - pv.z());
    if (!(wing_gap > 0) || !(mid_gap > 0)) continue;
    // The largest step towards the wings that gives valid triangles.
    for (double shrink : {1.0, 0.5, 0.25}) {
      const double t = shrink * std::min(1.0 / 3.0, 0.5 * wing_gap / mid_gap);
      double worst = 0;
      TriMesh candidate = split(a, b, pv + t * (mid - pv), worst);
      if (!(worst > 0)) continue;
      if (worst > best_quality) {
        const std::vector<int> kind = height_critical_points(candidate);
        int degenerate_after = 0;
        for (int k : kind) degenerate_after += k >= 2;
        if (kind[v] < m && kind.back() < m && degenerate_after <= degenerate_before) {
          best_mesh = std::move(candidate);
          best_quality = worst;
        }
      }
      break;
    }
  }
  if (best_quality <= 0) return false;
  mesh = std::move(best_mesh);
  return true;
}

}  // namespace

TopologyResult analyse_topology(const TriMesh& mesh, const TopologyOptions& options, const HarmonicSolver* harmonic) {
  const auto start = Clock::now();
  TopologyResult result;
  result.euler = require_closed_surface(mesh);
  result.genus = (2 - result.euler) / 2;

  // §3.1: harmonic function and its critical points on the same (intrinsic) triangulation.
  auto t = Clock::now();
  result.harmonic = harmonic ? harmonic->solve(mesh) : harmonic_function(mesh, options.harmonic);
  result.seconds_harmonic = seconds_since(t);
  t = Clock::now();
  CriticalPointOptions cp;
  cp.cancel_extra_extrema = true;
  cp.keep_minimum = result.harmonic.source;
  cp.keep_maximum = result.harmonic.sink;
  const Eigen::VectorXd heights_of_vertices = mesh.V.col(2);
  cp.tie_break = &heights_of_vertices;
  const IntrinsicTriangulation& T = result.harmonic.intrinsic;
  result.critical = critical_points(T, result.harmonic.f, cp);
  result.seconds_critical = seconds_since(t);

  // §3.2: planes between critical levels, at most dz apart.
  t = Clock::now();
  CuttingPlaneOptions planes_options;
  planes_options.dz = options.dz;
  planes_options.level_merge = options.level_merge;
  planes_options.split_end_gaps = options.split_end_gaps;
  planes_options.length_scales = options.length_scales;
  result.initial_planes = cutting_planes(mesh, result.critical, planes_options);
  std::vector<double> planes = result.initial_planes.z;
  result.seconds_planes = seconds_since(t);

  // Genus refinement (and, rarely, splits of degenerate saddles of z) on a working copy.
  TriMesh surface = mesh;
  std::vector<double> heights;
  std::vector<int> z_critical;  // computed when first needed
  auto update_heights = [&] {
    heights.assign(surface.V.col(2).data(), surface.V.col(2).data() + surface.V.rows());
    std::sort(heights.begin(), heights.end());
  };
  update_heights();
  long long planes_before = -1;  // planes of the previous pass when it added some
  while (true) {
    t = Clock::now();
    result.sliced = slice_mesh(surface, planes);
    result.seconds_slicing += seconds_since(t);
    t = Clock::now();
    planes = result.sliced.planes;
    if (planes_before >= 0 && static_cast<long long>(planes.size()) <= planes_before)
      throw AlgorithmError("analyse_topology: the planes added for genus coincide with existing ones after moving "
                           "them off vertex heights (" + std::to_string(planes.size()) + " planes)");
    planes_before = -1;
    std::vector<double> added;
    std::vector<int> splits;
    for (size_t p = 0; p < result.sliced.pieces.size(); ++p) {
      const Piece& piece = result.sliced.pieces[p];
      if (piece.genus <= 0) continue;
      if (z_critical.empty()) z_critical = height_critical_points(surface);
      const Refinement refinement = refine_piece(result.sliced, piece, z_critical, heights, static_cast<int>(p));
      if (refinement.split_vertex >= 0)
        splits.push_back(refinement.split_vertex);
      else
        added.push_back(refinement.plane);
    }
    if (!splits.empty()) {
      std::sort(splits.begin(), splits.end());
      splits.erase(std::unique(splits.begin(), splits.end()), splits.end());
      for (int v : splits) {
        if (z_critical[v] < 2) continue;  // changed by an earlier split
        if (!split_degenerate_saddle(surface, v, z_critical))
          throw AlgorithmError("analyse_topology: the handle of a piece lies in the degenerate saddle of z at vertex " +
                               std::to_string(v) + " (multiplicity " + std::to_string(z_critical[v]) +
                               "), which could not be split");
        z_critical = height_critical_points(surface);
        ++result.split_saddles;
      }
      update_heights();
      result.seconds_planes += seconds_since(t);
      ++result.refinement_rounds;
      if (result.split_saddles > options.max_planes)
        throw AlgorithmError("analyse_topology: more than " + std::to_string(options.max_planes) +
                             " degenerate saddles split");
      continue;
    }
    result.seconds_planes += seconds_since(t);
    if (added.empty()) break;
    std::sort(added.begin(), added.end());
    added.erase(std::unique(added.begin(), added.end()), added.end());
    result.planes_added_for_genus += static_cast<int>(added.size());
    ++result.refinement_rounds;
    planes_before = static_cast<long long>(planes.size());
    planes.insert(planes.end(), added.begin(), added.end());
    if (static_cast<int>(planes.size()) > options.max_planes) {
      int worst = 0;
      for (const Piece& piece : result.sliced.pieces) worst = std::max(worst, piece.genus);
      throw AlgorithmError("analyse_topology: more than " + std::to_string(options.max_planes) +
                           " planes needed (" + std::to_string(planes.size()) + " after " +
                           std::to_string(result.refinement_rounds) + " refinement rounds, a piece of genus " +
                           std::to_string(worst) + " left)");
    }
  }

  // Consistency of the result: pieces add up to the surface.
  int euler_sum = 0;
  for (const Piece& piece : result.sliced.pieces) euler_sum += piece.euler;
  if (euler_sum != result.euler)
    throw AlgorithmError("analyse_topology: Euler characteristics of the pieces sum to " + std::to_string(euler_sum) +
                         ", the mesh has " + std::to_string(result.euler));

  result.planes_z = result.sliced.planes;
  const BoundingBox box = bounding_box(mesh.V);
  const double extent = box.extent().maxCoeff();
  for (double z : result.planes_z) result.planes_normalised.push_back((z - box.min.z()) / extent);
  result.seconds_total = seconds_since(start);
  return result;
}

}  // namespace polycube
