#include "polycube/slice.h"

#include "polycube/disjoint_sets.h"

#include "polycube/errors.h"
#include "polycube/mesh_topology.h"
#include "polycube/plane_placement.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

namespace polycube {

namespace {

// Sorted, unique planes strictly inside (z_min, z_max), none at (or within 1e-9 of the height
// from) a vertex height: such planes move to the clearest height nearby (place_plane).
std::vector<double> usable_planes(const std::vector<double>& requested, const std::vector<double>& heights,
                                  int& nudged) {
  nudged = 0;
  const double z_min = heights.front(), z_max = heights.back();
  const double tolerance = 1e-9 * (z_max - z_min);
  std::vector<double> planes;
  for (double p : requested)
    if (std::isfinite(p) && p > z_min && p < z_max) planes.push_back(p);
  std::sort(planes.begin(), planes.end());
  planes.erase(std::unique(planes.begin(), planes.end()), planes.end());
  auto clearance = [&](double p) {
    auto it = std::lower_bound(heights.begin(), heights.end(), p);
    double d = std::numeric_limits<double>::infinity();
    if (it != heights.end()) d = *it - p;
    if (it != heights.begin()) d = std::min(d, p - *(it - 1));
    return d;
  };
  for (size_t k = 0; k < planes.size(); ++k) {
    if (clearance(planes[k]) > tolerance) continue;
    const double lo = k > 0 ? planes[k - 1] : z_min, hi = k + 1 < planes.size() ? planes[k + 1] : z_max;
    planes[k] = place_plane(heights, planes[k], lo, hi, 0.25 * std::min(planes[k] - lo, hi - planes[k]));
    ++nudged;
  }
  planes.erase(std::remove_if(planes.begin(), planes.end(), [&](double p) { return !(clearance(p) > 0); }),
               planes.end());
  planes.erase(std::unique(planes.begin(), planes.end()), planes.end());
  return planes;
}

// Shape quality of a triangle: 4 sqrt(3) area / (sum of squared edge lengths), 1 for equilateral.
double quality(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double denominator = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  if (!(denominator > 0)) return 0;
  return 2 * std::sqrt(3.0) * (b - a).cross(c - a).norm() / denominator;
}

}  // namespace

SlicedMesh slice_mesh(const TriMesh& mesh, const std::vector<double>& planes_z) {
  const int nv = mesh.num_vertices(), nf = mesh.num_faces();
  SlicedMesh result;
  result.input_vertices = nv;
  if (nv == 0 || nf == 0) throw MeshError("slice_mesh: empty mesh");
  const Eigen::MatrixX3d& V = mesh.V;
  const Eigen::MatrixX3i& F = mesh.F;

  std::vector<double> heights(V.col(2).data(), V.col(2).data() + nv);
  std::sort(heights.begin(), heights.end());
  const std::vector<double> planes = usable_planes(planes_z, heights, result.nudged_planes);
  result.planes = planes;
  const int np = static_cast<int>(planes.size());
  // Slab of a height that is not a plane: the number of planes below it.
  auto slab_of = [&](double z) {
    return static_cast<int>(std::upper_bound(planes.begin(), planes.end(), z) - planes.begin());
  };

  // New vertices on crossed edges, ascending in z along each edge.
  const EdgeMap edges = build_edge_map(F);
  for (int e = 0; e < edges.num_edges(); ++e)
    if (edges.face_count[e] != 2)
      throw MeshError("slice_mesh: edge (" + std::to_string(edges.E(e, 0)) + ", " + std::to_string(edges.E(e, 1)) +
                      ") has " + std::to_string(edges.face_count[e]) + " faces, expected 2");
  const int ne = edges.num_edges();
  std::vector<int> edge_first(ne, -1), edge_count(ne, 0);
  std::vector<Eigen::Vector3d> new_points;
  std::vector<int> vertex_plane(nv, -1);  // plane index of each created vertex (-1: input vertex)
  for (int e = 0; e < ne; ++e) {
    int a = edges.E(e, 0), b = edges.E(e, 1);
    if (V(a, 2) == V(b, 2)) continue;
    if (V(a, 2) > V(b, 2)) std::swap(a, b);
    const int first = slab_of(V(a, 2)), last = slab_of(V(b, 2));  // planes first..last-1 cross
    if (first == last) continue;
    edge_first[e] = nv + static_cast<int>(new_points.size());
    edge_count[e] = last - first;
    const Eigen::Vector3d pa = V.row(a).transpose(), pb = V.row(b).transpose();
    for (int k = first; k < last; ++k) {
      const double t = (planes[k] - pa.z()) / (pb.z() - pa.z());
      Eigen::Vector3d p = pa + t * (pb - pa);
      p.z() = planes[k];
      new_points.push_back(p);
      vertex_plane.push_back(k);
    }
  }
  const int total_vertices = nv + static_cast<int>(new_points.size());
  result.mesh.V.resize(total_vertices, 3);
  result.mesh.V.topRows(nv) = V;
  for (size_t k = 0; k < new_points.size(); ++k) result.mesh.V.row(nv + k) = new_points[k].transpose();
  const Eigen::MatrixX3d& RV = result.mesh.V;

  // Split faces.
  std::vector<std::array<int, 3>> faces;
  std::vector<int> face_origin, face_slab;
  faces.reserve(nf + 4 * new_points.size());
  std::vector<int> ring, polygon;
  for (int f = 0; f < nf; ++f) {
    int lowest = slab_of(V(F(f, 0), 2)), highest = lowest;
    for (int i = 1; i < 3; ++i) {
      const int s = slab_of(V(F(f, i), 2));
      lowest = std::min(lowest, s);
      highest = std::max(highest, s);
    }
    if (lowest == highest) {
      faces.push_back({F(f, 0), F(f, 1), F(f, 2)});
      face_origin.push_back(f);
      face_slab.push_back(lowest);
      continue;
    }
    // Boundary of the face with the created vertices, counter-clockwise.
    ring.clear();
    for (int i = 0; i < 3; ++i) {
      const int a = F(f, i), b = F(f, (i + 1) % 3), e = edges.FE(f, i);
      ring.push_back(a);
      if (edge_count[e] == 0) continue;
      if (V(a, 2) < V(b, 2))
        for (int k = 0; k < edge_count[e]; ++k) ring.push_back(edge_first[e] + k);
      else
        for (int k = edge_count[e] - 1; k >= 0; --k) ring.push_back(edge_first[e] + k);
    }
    // The part of the face in slab s is the convex polygon of ring points in that slab or on its
    // bounding planes s-1 and s.
    for (int s = lowest; s <= highest; ++s) {
      polygon.clear();
      for (int v : ring) {
        const bool in_slab =
            v < nv ? slab_of(V(v, 2)) == s : (vertex_plane[v] == s - 1 || vertex_plane[v] == s);
        if (in_slab) polygon.push_back(v);
      }
      const int n = static_cast<int>(polygon.size());
      if (n < 3) continue;
      // Fan from the apex whose worst triangle is best.
      int best_apex = 0;
      double best_quality = -1;
      for (int apex = 0; apex < (n == 3 ? 1 : n); ++apex) {
        double worst = 1;
        for (int k = 1; k + 1 < n; ++k)
          worst = std::min(worst, quality(RV.row(polygon[apex]), RV.row(polygon[(apex + k) % n]),
                                          RV.row(polygon[(apex + k + 1) % n])));
        if (worst > best_quality) {
          best_quality = worst;
          best_apex = apex;
        }
      }
      for (int k = 1; k + 1 < n; ++k) {
        faces.push_back({polygon[best_apex], polygon[(best_apex + k) % n], polygon[(best_apex + k + 1) % n]});
        face_origin.push_back(f);
        face_slab.push_back(s);
      }
    }
  }
  const int rf = static_cast<int>(faces.size());
  result.mesh.F.resize(rf, 3);
  result.face_origin.resize(rf);
  for (int f = 0; f < rf; ++f) {
    result.mesh.F.row(f) << faces[f][0], faces[f][1], faces[f][2];
    result.face_origin[f] = face_origin[f];
  }

  // Pieces: faces of one slab joined across edges.
  const EdgeMap refined = build_edge_map(result.mesh.F);
  DisjointSets sets(rf);
  for (int e = 0; e < refined.num_edges(); ++e) {
    if (refined.face_count[e] != 2)
      throw AlgorithmError("slice_mesh: refined edge (" + std::to_string(refined.E(e, 0)) + ", " +
                           std::to_string(refined.E(e, 1)) + ") has " + std::to_string(refined.face_count[e]) +
                           " faces");
    const int f0 = refined.EF(e, 0), f1 = refined.EF(e, 1);
    if (face_slab[f0] == face_slab[f1]) sets.unite(f0, f1);
  }
  // Number pieces by (slab, first face).
  std::vector<int> first_face(rf, -1);
  std::vector<std::pair<int, int>> keys;  // (slab, first face) per root
  for (int f = 0; f < rf; ++f) {
    const int r = sets.find(f);
    if (first_face[r] < 0) {
      first_face[r] = f;
      keys.push_back({face_slab[f], f});
    }
  }
  std::sort(keys.begin(), keys.end());
  std::vector<int> root_piece(rf, -1);
  for (size_t p = 0; p < keys.size(); ++p) root_piece[sets.find(keys[p].second)] = static_cast<int>(p);
  result.face_piece.resize(rf);
  result.pieces.resize(keys.size());
  for (int f = 0; f < rf; ++f) {
    const int p = root_piece[sets.find(f)];
    result.face_piece[f] = p;
    result.pieces[p].faces.push_back(f);
  }

  // Euler characteristic and boundary loops per piece.
  std::vector<int> vertex_stamp(total_vertices, -1), edge_stamp(refined.num_edges(), -1);
  std::vector<int> next_on_boundary(total_vertices, -1);
  for (size_t p = 0; p < result.pieces.size(); ++p) {
    Piece& piece = result.pieces[p];
    const int pid = static_cast<int>(p);
    const int s = face_slab[piece.faces.front()];
    piece.plane_below = s > 0 ? s - 1 : -1;
    piece.plane_above = s < np ? s : -1;
    int vertices = 0, edge_count_piece = 0;
    std::vector<int> boundary_starts;
    for (int f : piece.faces)
      for (int i = 0; i < 3; ++i) {
        const int v = result.mesh.F(f, i);
        if (vertex_stamp[v] != pid) {
          vertex_stamp[v] = pid;
          ++vertices;
        }
        const int e = refined.FE(f, i);
        if (edge_stamp[e] != pid) {
          edge_stamp[e] = pid;
          ++edge_count_piece;
        }
        const int other = refined.EF(e, 0) == f ? refined.EF(e, 1) : refined.EF(e, 0);
        if (result.face_piece[other] != pid) {
          next_on_boundary[v] = result.mesh.F(f, (i + 1) % 3);
          boundary_starts.push_back(v);
        }
      }
    piece.euler = vertices - edge_count_piece + static_cast<int>(piece.faces.size());
    for (int start : boundary_starts) {
      if (next_on_boundary[start] < 0) continue;  // already in a loop
      std::vector<int> loop;
      int v = start;
      while (v >= 0 && next_on_boundary[v] >= 0) {
        loop.push_back(v);
        const int w = next_on_boundary[v];
        next_on_boundary[v] = -1;
        v = w;
      }
      if (v != start)
        throw AlgorithmError("slice_mesh: boundary of piece " + std::to_string(p) + " does not close at vertex " +
                             std::to_string(start));
      const int plane = vertex_plane[loop.front()];
      if (plane < 0 || (plane != piece.plane_below && plane != piece.plane_above))
        throw AlgorithmError("slice_mesh: boundary loop of piece " + std::to_string(p) + " is not on its planes");
      piece.boundary_loops.push_back(std::move(loop));
      piece.loop_plane.push_back(plane);
    }
    piece.genus = (2 - piece.euler - static_cast<int>(piece.boundary_loops.size())) / 2;
  }
  return result;
}

}  // namespace polycube
