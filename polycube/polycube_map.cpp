#include "polycube/polycube_map.h"

#include "polycube/polycube_map_data.h"

#include "polycube/barycentric.h"
#include "polycube/circle_domain.h"
#include "polycube/contour_map.h"
#include "polycube/disk_locator.h"
#include "polycube/errors.h"
#include "polycube/flat_metric.h"
#include "polycube/parallel.h"
#include "polycube/piece_disk.h"
#include "polycube/piece_mesh.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <string>

namespace polycube {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

constexpr double kTwoPi = 6.283185307179586;

// Splits the inner edges of a side's work mesh (slits need room), keeping the face parents.
void refine(SideDisk& side) {
  std::vector<int> parent;
  side.work = split_inner_edges(side.work, parent);
  for (int& p : parent) p = side.work_face_parent[p];
  side.work_face_parent = std::move(parent);
}

constexpr int kMaxRefinements = 3;

// A segment of a disk boundary: an arc of a loop from a slit end (or, without slits, from u = 0)
// or one side of a slit.
struct SegmentKey {
  bool slit = false;
  int id = -1;        // contour (loop arc) or slit index
  double start = 0;   // loop arc: u of its first point; slit: +1 forward, -1 backward
  bool operator==(const SegmentKey& o) const { return slit == o.slit && id == o.id && std::abs(start - o.start) < 1e-12; }
};

// The boundary walk of one side: segments in order and each boundary vertex's place.
struct BoundaryWalk {
  std::vector<SegmentKey> segments;
  std::vector<double> length;        // per segment, 3D length on this side
  std::vector<int> direction;        // per segment: loop arcs +1 / -1 against the contour's u
  std::vector<double> span;          // per segment: loop arcs the u they cover (1 for slits)
  std::vector<int> segment_of;       // per boundary vertex
  std::vector<double> param_of;      // per boundary vertex, in [0, 1)
};

}  // namespace


namespace {

// Of the candidate faces of `mesh`, the one containing x best, with x's barycentric coordinates.
int best_face(const TriMesh& mesh, const std::vector<int>& candidates, const Eigen::Vector3d& x, Eigen::Vector3d& bary) {
  int best = -1;
  double best_min = -INFINITY;
  for (int f : candidates) {
    const Eigen::Vector3d w = barycentric3(mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)), mesh.V.row(mesh.F(f, 2)), x);
    if (w.minCoeff() > best_min) {
      best_min = w.minCoeff();
      best = f;
      bary = w;
    }
  }
  bary = clamp_bary(bary);
  return best;
}

Eigen::Vector3d disk_point(const DiskEmbedding& disk, int f, const Eigen::Vector3d& w, bool uv) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    if (uv) p.head<2>() += w[i] * disk.uv.row(disk.mesh.F(f, i)).transpose();
    else p += w[i] * disk.mesh.V.row(disk.mesh.F(f, i)).transpose();
  }
  return p;
}

// Per face of a disk: the share of the other side's area its image covers (through the other
// disk, as a chord triangle) over its own share of its side's area. The areas that do not move
// with the disk's uv are computed once.
class ImageAreaRatio {
 public:
  ImageAreaRatio(const DiskEmbedding& disk, const DiskEmbedding& other, const DiskLocator& other_locator)
      : other_(other), locator_(other_locator), share_(face_areas(disk.mesh)) {
    const Eigen::VectorXd other_faces = face_areas(other.mesh);
    double own_area = 0;  // sums in face order
    for (double a : share_) own_area += a;
    for (double a : other_faces) other_area_ += a;
    for (double& a : share_) a /= own_area;
  }

  std::vector<double> operator()(const DiskEmbedding& disk) const {
    std::vector<Eigen::Vector3d> image(disk.mesh.num_vertices());
    for (int v = 0; v < disk.mesh.num_vertices(); ++v) {
      Eigen::Vector3d w;
      const int f = locator_.locate(disk.uv.row(v).transpose(), w);
      image[v] = disk_point(other_, f, w, false);
    }
    std::vector<double> ratio(disk.mesh.num_faces(), 1.0);
    for (int f = 0; f < disk.mesh.num_faces(); ++f) {
      const Eigen::Vector3d& a = image[disk.mesh.F(f, 0)];
      const double image_share = 0.5 * (image[disk.mesh.F(f, 1)] - a).cross(image[disk.mesh.F(f, 2)] - a).norm() / other_area_;
      if (share_[f] > 0) ratio[f] = image_share / share_[f];
    }
    return ratio;
  }

 private:
  const DiskEmbedding& other_;
  const DiskLocator& locator_;
  Eigen::VectorXd share_;
  double other_area_ = 0;
};

}  // namespace

SurfacePoint PolycubeMapData::carry(bool from_polycube, int input_face, const Eigen::Vector3d& x) const {
  const auto& sliced_of = from_polycube ? polycube_sliced_faces_of : model_sliced_faces_of;
  const auto& face_local = from_polycube ? polycube_face_local : model_face_local;
  // The pieces are cut from the sliced meshes, whose faces keep positions: find the piece face.
  int best_pair = -1, best_local = -1;
  double best_min = -INFINITY;
  for (int sf : sliced_of[input_face]) {
    const auto [pair, local] = face_local[sf];
    const SideDisk& side = from_polycube ? pairs[pair].polycube : pairs[pair].model;
    const TriMesh& m = side.piece.mesh;
    const Eigen::Vector3d w = barycentric3(m.V.row(m.F(local, 0)), m.V.row(m.F(local, 1)), m.V.row(m.F(local, 2)), x);
    if (w.minCoeff() > best_min) {
      best_min = w.minCoeff();
      best_pair = pair;
      best_local = local;
    }
  }
  const PiecePair& pp = pairs[best_pair];
  const SideDisk& from = from_polycube ? pp.polycube : pp.model;
  const SideDisk& to = from_polycube ? pp.model : pp.polycube;
  Eigen::Vector3d w;
  const int df = best_face(from.disk.mesh, from.faces_of[best_local], x, w);
  const Eigen::Vector2d q = disk_point(from.disk, df, w, true).head<2>();
  Eigen::Vector3d v;
  const int tf = to.locator->locate(q, v);
  const Eigen::Vector3d y = disk_point(to.disk, tf, v, false);
  const int sliced_face = to.piece.face_to_global[to.work_face_parent[to.disk.face_origin[tf]]];
  const TriMesh& target = from_polycube ? model : polycube;
  const int face = (from_polycube ? model_face_origin : polycube_face_origin)[sliced_face];
  SurfacePoint out;
  out.face = face;
  out.bary = clamp_bary(barycentric3(target.V.row(target.F(face, 0)), target.V.row(target.F(face, 1)), target.V.row(target.F(face, 2)), y));
  return out;
}

Eigen::Vector3d surface_position(const TriMesh& mesh, const SurfacePoint& p) {
  return p.bary[0] * mesh.V.row(mesh.F(p.face, 0)).transpose() + p.bary[1] * mesh.V.row(mesh.F(p.face, 1)).transpose() +
         p.bary[2] * mesh.V.row(mesh.F(p.face, 2)).transpose();
}

SurfacePoint PolycubeMap::to_model(const SurfacePoint& on_polycube) const {
  return data->carry(true, on_polycube.face, surface_position(data->polycube, on_polycube));
}

SurfacePoint PolycubeMap::to_polycube(const SurfacePoint& on_model) const {
  return data->carry(false, on_model.face, surface_position(data->model, on_model));
}

namespace {

// Per side: loop of each vertex, its contour parameter, the direction of each loop relative to
// its contour map, slit edges, slit parameters.
struct SideInfo {
  std::vector<int> loop_of;
  std::vector<double> u;
  std::vector<int> direction;  // per loop: +1 if the piece's loop runs counter-clockwise
  std::map<std::pair<int, int>, std::pair<int, int>> slit_edge;  // (a, b) directed -> (slit, +1/-1)
  std::vector<std::map<int, double>> slit_t;                      // per slit: vertex -> t
  std::vector<double> slit_length;
};

SideInfo side_info(const SideDisk& side, const std::vector<ContourMap>& contours, bool polycube) {
  SideInfo info;
  const int n = side.work.num_vertices();
  info.loop_of.assign(n, -1);
  info.u.assign(n, NAN);
  for (size_t l = 0; l < side.piece.loops.size(); ++l) {
    const ContourMap& cm = contours[side.loop_contour[l]];
    const std::vector<int>& ids = polycube ? cm.polycube_vertices : cm.model_vertices;
    const std::vector<double>& us = polycube ? cm.polycube_u : cm.model_u;
    std::map<int, int> index;
    for (size_t i = 0; i < ids.size(); ++i) index[ids[i]] = static_cast<int>(i);
    const std::vector<int>& loop = side.piece.loops[l];
    for (int v : loop) {
      auto it = index.find(side.piece.vertex_to_global[v]);
      if (it == index.end()) throw AlgorithmError("a piece loop is not on its contour");
      info.loop_of[v] = static_cast<int>(l);
      info.u[v] = us[it->second];
    }
    const int i0 = index.at(side.piece.vertex_to_global[loop[0]]);
    const int next = ids[(i0 + 1) % ids.size()];
    info.direction.push_back(next == side.piece.vertex_to_global[loop[1]] ? 1 : -1);
  }
  const TriMesh& m = side.work;
  for (size_t s = 0; s < side.slits.size(); ++s) {
    const std::vector<int>& path = side.slits[s].path;
    std::vector<double> cumulative(path.size(), 0.0);
    for (size_t k = 1; k < path.size(); ++k) cumulative[k] = cumulative[k - 1] + (m.V.row(path[k]) - m.V.row(path[k - 1])).norm();
    const double total = cumulative.back();
    std::map<int, double> t;
    for (size_t k = 0; k < path.size(); ++k) t[path[k]] = total > 0 ? cumulative[k] / total : static_cast<double>(k) / (path.size() - 1);
    info.slit_t.push_back(std::move(t));
    info.slit_length.push_back(total);
    for (size_t k = 0; k + 1 < path.size(); ++k) {
      info.slit_edge[{path[k], path[k + 1]}] = {static_cast<int>(s), 1};
      info.slit_edge[{path[k + 1], path[k]}] = {static_cast<int>(s), -1};
    }
  }
  return info;
}

double wrap01(double x) {
  x -= std::floor(x);
  return x >= 1 ? 0 : x;
}

BoundaryWalk walk_boundary(const SideDisk& side, const CutDisk& cut, const SideInfo& info) {
  const int nb = static_cast<int>(cut.boundary.size());
  const TriMesh& m = side.work;
  auto origin = [&](int k) { return cut.vertex_origin[cut.boundary[((k % nb) + nb) % nb]]; };
  // Kind of the boundary edge leaving boundary vertex k.
  auto edge_key = [&](int k) {
    SegmentKey key;
    auto it = info.slit_edge.find({origin(k), origin(k + 1)});
    if (it != info.slit_edge.end()) {
      key.slit = true;
      key.id = it->second.first;
      key.start = it->second.second;
    } else {
      const int l = info.loop_of[origin(k)];
      if (l < 0 || info.loop_of[origin(k + 1)] != l) throw AlgorithmError("a cut piece's boundary edge is neither on a loop nor on a slit");
      key.id = side.loop_contour[l];
    }
    return key;
  };
  auto same_kind = [](const SegmentKey& a, const SegmentKey& b) { return a.slit == b.slit && a.id == b.id && (!a.slit || a.start == b.start); };
  int first = -1;
  for (int k = 0; k < nb && first < 0; ++k)
    if (!same_kind(edge_key(k - 1), edge_key(k))) first = k;
  BoundaryWalk walk;
  walk.segment_of.assign(nb, -1);
  walk.param_of.assign(nb, 0);
  if (first < 0) {
    // One loop, no slit: a single arc from u = 0.
    const int l = info.loop_of[origin(0)];
    SegmentKey key = edge_key(0);
    key.start = 0;
    walk.segments.push_back(key);
    double length = 0;
    for (int k = 0; k < nb; ++k) {
      walk.segment_of[k] = 0;
      walk.param_of[k] = wrap01(info.direction[l] * info.u[origin(k)]);
      length += (m.V.row(origin(k + 1)) - m.V.row(origin(k))).norm();
    }
    walk.length.push_back(length);
    walk.direction.push_back(info.direction[l]);
    walk.span.push_back(1);
    return walk;
  }
  // Segments from `first` on; each boundary vertex belongs to the segment of its outgoing edge.
  int k = first;
  for (int done = 0; done < nb;) {
    SegmentKey key = edge_key(k);
    const int seg = static_cast<int>(walk.segments.size());
    int end = k;  // last vertex of the segment's run (exclusive end vertex is end + 1)
    int count = 0;
    while (count == 0 || (done + count < nb && same_kind(edge_key(end), key))) {
      ++count;
      ++end;
    }
    // Vertices k .. k + count - 1 belong to this segment; vertex k + count starts the next one.
    double length = 0;
    int direction = 1;
    double span = 1;
    for (int j = 0; j < count; ++j) length += (m.V.row(origin(k + j + 1)) - m.V.row(origin(k + j))).norm();
    if (key.slit) {
      const std::map<int, double>& t = info.slit_t[key.id];
      for (int j = 0; j < count; ++j) {
        const double tv = t.at(origin(k + j));
        walk.param_of[(k + j) % nb] = key.start > 0 ? tv : 1 - tv;
        walk.segment_of[(k + j) % nb] = seg;
      }
    } else {
      const int l = info.loop_of[origin(k)];
      const int d = info.direction[l];
      const double u0 = info.u[origin(k)];
      const double u1 = info.u[origin(k + count)];
      direction = d;
      span = wrap01(d * (u1 - u0));
      if (span == 0) span = 1;
      key.start = u0;
      for (int j = 0; j < count; ++j) {
        walk.param_of[(k + j) % nb] = wrap01(d * (info.u[origin(k + j)] - u0)) / span;
        walk.segment_of[(k + j) % nb] = seg;
      }
    }
    walk.segments.push_back(key);
    walk.length.push_back(length);
    walk.direction.push_back(direction);
    walk.span.push_back(span);
    done += count;
    k += count;
  }
  return walk;
}

// The parameters of a segment's points on either side: for a loop arc the contour's union u's
// inside the arc, for a slit both sides' t's.
std::vector<double> segment_points(const SegmentKey& key, int direction, double span, const std::vector<ContourMap>& contours,
                                   const SideInfo& model, const SideInfo& polycube) {
  std::vector<double> params;
  if (key.slit) {
    for (const SideInfo* info : {&model, &polycube})
      for (const auto& [v, t] : info->slit_t[key.id]) {
        const double p = key.start > 0 ? t : 1 - t;
        if (p < 1) params.push_back(p);
      }
  } else {
    for (double u : contours[key.id].u) {
      const double p = wrap01(direction * (u - key.start));
      if (p < span) params.push_back(p / span);
    }
  }
  std::sort(params.begin(), params.end());
  params.erase(std::unique(params.begin(), params.end()), params.end());
  return params;
}

// Index of the parameter of `values` (ascending) equal to x up to rounding.
int find_param(const std::vector<double>& values, double x) {
  auto it = std::lower_bound(values.begin(), values.end(), x - 1e-12);
  if (it == values.end() || std::abs(*it - x) > 1e-9) return -1;
  return static_cast<int>(it - values.begin());
}

}  // namespace

PolycubeMap build_polycube_map(const TriMesh& model, const PolycubeResult& result, const PolycubeMapOptions& options) {
  const auto start = Clock::now();
  const SlicedMesh& ms = result.model_sliced;
  const SlicedMesh& ps = result.polycube_sliced;
  const CrossSections& sections = result.model_sections;
  const int n_pairs = static_cast<int>(ms.pieces.size());
  if (static_cast<int>(result.piece_match.size()) != n_pairs) throw std::invalid_argument("build_polycube_map: piece_match does not match the model's pieces");

  for (int f = 0; f < ms.mesh.num_faces(); ++f)
    if (ms.face_origin[f] < 0 || ms.face_origin[f] >= model.num_faces())
      throw AlgorithmError("the topology stage split a degenerate saddle (the model moved there); the map does not support this yet");
  auto data = std::make_shared<PolycubeMapData>();
  data->model = model;
  data->polycube = result.polycube.mesh;
  data->polycube_sliced_vertices = ps.mesh.num_vertices();
  data->model_face_origin = ms.face_origin;
  data->polycube_face_origin = ps.face_origin;
  data->pairs.resize(n_pairs);
  PolycubeMap out;
  out.pieces.resize(n_pairs);

  std::vector<int> order(n_pairs);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return ms.pieces[a].faces.size() > ms.pieces[b].faces.size(); });

  // Phase 1: pieces, the model's flat metric and its slits.
  parallel_for_each(order, options.threads, "piece", [&](int j) {
    const auto t0 = Clock::now();
    PiecePair& pair = data->pairs[j];
    PieceMapStats& stats = out.pieces[j];
    stats.model_piece = j;
    stats.polycube_piece = result.piece_match[j];
    pair.model.piece = extract_piece(ms, j);
    pair.polycube.piece = extract_piece(ps, result.piece_match[j]);
    pair.model.loop_contour = sections.piece_contours[j];
    pair.polycube.loop_contour = result.polycube_piece_contours[result.piece_match[j]];
    const PieceMesh& piece = pair.model.piece;
    for (SideDisk* side : {&pair.model, &pair.polycube}) {
      side->work = side->piece.mesh;
      side->work_face_parent.resize(side->work.num_faces());
      std::iota(side->work_face_parent.begin(), side->work_face_parent.end(), 0);
    }
    stats.loops = static_cast<int>(piece.loops.size());
    if (piece.loops.size() < 2) {
      stats.seconds = seconds_since(t0);
      return;
    }
    // Slits by the flat metric of §3.3 (straight lines of the circle domain); 3D lengths if the
    // metric cannot be computed.
    int root = 0;
    double longest = -1;
    for (size_t l = 0; l < piece.loops.size(); ++l) {
      double length = 0;
      const auto& loop = piece.loops[l];
      for (size_t i = 0; i < loop.size(); ++i) length += (piece.mesh.V.row(loop[(i + 1) % loop.size()]) - piece.mesh.V.row(loop[i])).norm();
      if (length > longest) {
        longest = length;
        root = static_cast<int>(l);
      }
    }
    EdgeLength length = [&piece](int a, int b) { return (piece.mesh.V.row(a) - piece.mesh.V.row(b)).norm(); };
    CircleDomain domain;
    try {
      const FlatMetric metric = flat_metric(piece.mesh, piece.loops);
      domain = circle_domain(piece.mesh, metric);
      stats.ricci_iterations = metric.iterations;
      stats.ricci_residual = metric.residual;
      stats.flat_slits = true;
      root = domain.outer_loop;
      length = [&domain, &piece](int a, int b) {
        return (domain.uv.row(a) - domain.uv.row(b)).norm() + 1e-9 * (piece.mesh.V.row(a) - piece.mesh.V.row(b)).norm();
      };
    } catch (const Error&) {
      stats.flat_slits = false;
    }
    for (int refinement = 0;; ++refinement) {
      try {
        pair.model.slits = find_slits(pair.model.work, piece.loops, root, length);
        break;
      } catch (const AlgorithmError&) {
        if (refinement == kMaxRefinements) throw;
      }
      refine(pair.model);
      stats.flat_slits = false;
      const TriMesh& work = pair.model.work;
      length = [&work](int a, int b) { return (work.V.row(a) - work.V.row(b)).norm(); };
    }
    stats.slits = static_cast<int>(pair.model.slits.size());
    stats.seconds = seconds_since(t0);
  });

  // Phase 2: one boundary map per contour, pinned at the slit ends of both pieces.
  const int n_contours = static_cast<int>(sections.contours.size());
  std::vector<int> polycube_loop_piece(n_contours, -1), polycube_loop_index(n_contours, -1);
  for (size_t p = 0; p < ps.pieces.size(); ++p)
    for (size_t l = 0; l < ps.pieces[p].boundary_loops.size(); ++l) {
      const int c = result.polycube_piece_contours[p][l];
      if (polycube_loop_piece[c] < 0) {
        polycube_loop_piece[c] = static_cast<int>(p);
        polycube_loop_index[c] = static_cast<int>(l);
      }
    }
  std::vector<ContourMap> contours(n_contours);
  std::vector<int> contour_order(n_contours);
  std::iota(contour_order.begin(), contour_order.end(), 0);
  parallel_for_each(contour_order, options.threads, "contour", [&](int c) {
    if (polycube_loop_piece[c] < 0) throw AlgorithmError("no polygon of the polycube for this contour");
    contours[c] = start_contour_map(sections.contours[c].vertices, ms.mesh.V, ps.pieces[polycube_loop_piece[c]].boundary_loops[polycube_loop_index[c]],
                                    ps.mesh.V);
  });
  std::vector<std::map<int, int>> model_index(n_contours);
  for (int c = 0; c < n_contours; ++c)
    for (size_t i = 0; i < contours[c].model_vertices.size(); ++i) model_index[c][contours[c].model_vertices[i]] = static_cast<int>(i);
  for (int j = 0; j < n_pairs; ++j) {
    const SideDisk& side = data->pairs[j].model;
    for (const Slit& s : side.slits)
      for (int v : {s.path.front(), s.path.back()}) {
        const int g = side.piece.vertex_to_global[v];
        const int c = sections.vertex_contour[g];
        add_anchor(contours[c], model_index[c].at(g));
      }
  }
  parallel_for_each(contour_order, options.threads, "contour", [&](int c) { finish_contour_map(contours[c], ms.mesh.V, ps.mesh.V); });
  // Per pair and slit: the polycube ends (sliced ids) of the model's slit ends.
  std::vector<std::vector<std::pair<int, int>>> polycube_ends(n_pairs);
  for (int j = 0; j < n_pairs; ++j) {
    const SideDisk& side = data->pairs[j].model;
    for (const Slit& s : side.slits) {
      int ends[2];
      for (int e = 0; e < 2; ++e) {
        const int g = side.piece.vertex_to_global[e == 0 ? s.path.front() : s.path.back()];
        const int c = sections.vertex_contour[g];
        ends[e] = contours[c].polycube_vertices[anchor_of(contours[c], model_index[c].at(g))];
      }
      polycube_ends[j].emplace_back(ends[0], ends[1]);
    }
  }
  out.contours = n_contours;

  // Phase 3: per pair, the polycube's slits, both disks and their locators.
  parallel_for_each(order, options.threads, "piece", [&](int j) {
    const auto t0 = Clock::now();
    PiecePair& pair = data->pairs[j];
    PieceMapStats& stats = out.pieces[j];
    SideDisk& M = pair.model;
    SideDisk& P = pair.polycube;
    // The polycube's slits join the same loops in the same order, between the pinned ends.
    std::map<int, int> local;
    for (size_t v = 0; v < P.piece.vertex_to_global.size(); ++v) local[P.piece.vertex_to_global[v]] = static_cast<int>(v);
    std::vector<int> loop_of_contour(n_contours, -1);
    for (size_t l = 0; l < P.piece.loops.size(); ++l) loop_of_contour[P.loop_contour[l]] = static_cast<int>(l);
    for (int refinement = 0;; ++refinement) {
      const TriMesh& pm = P.work;
      std::vector<char> blocked(pm.num_vertices(), 0);
      for (const auto& loop : P.piece.loops)
        for (int v : loop) blocked[v] = 1;
      const EdgeLength length = [&pm](int a, int b) { return (pm.V.row(a) - pm.V.row(b)).norm(); };
      P.slits.clear();
      for (size_t s = 0; s < M.slits.size(); ++s) {
        Slit slit;
        slit.from = loop_of_contour[M.loop_contour[M.slits[s].from]];
        slit.to = loop_of_contour[M.loop_contour[M.slits[s].to]];
        slit.path = shortest_path(pm, local.at(polycube_ends[j][s].first), local.at(polycube_ends[j][s].second), blocked, length);
        if (slit.path.empty()) break;
        for (int v : slit.path) blocked[v] = 1;
        P.slits.push_back(std::move(slit));
      }
      if (P.slits.size() == M.slits.size()) break;
      if (refinement == kMaxRefinements)
        throw AlgorithmError("no room for the slits of polycube piece " + std::to_string(stats.polycube_piece) + " after " +
                             std::to_string(kMaxRefinements) + " refinements");
      refine(P);
    }
    const CutDisk cut_m = cut_open(M.work, M.slits);
    const CutDisk cut_p = cut_open(P.work, P.slits);
    const SideInfo info_m = side_info(M, contours, false);
    const SideInfo info_p = side_info(P, contours, true);
    const BoundaryWalk walk_m = walk_boundary(M, cut_m, info_m);
    BoundaryWalk walk_p = walk_boundary(P, cut_p, info_p);
    // Align P's segment order with M's.
    const int ns = static_cast<int>(walk_m.segments.size());
    if (static_cast<int>(walk_p.segments.size()) != ns) throw AlgorithmError("the cut pieces' boundaries have different segment counts");
    int shift = -1;
    for (int r = 0; r < ns && shift < 0; ++r) {
      bool same = true;
      for (int i = 0; i < ns && same; ++i) same = walk_p.segments[(i + r) % ns] == walk_m.segments[i];
      if (same) shift = r;
    }
    if (shift < 0) throw AlgorithmError("the cut pieces' boundaries do not correspond (slit order differs)");
    for (int& s : walk_p.segment_of) s = ((s - shift) % ns + ns) % ns;
    std::rotate(walk_p.length.begin(), walk_p.length.begin() + shift, walk_p.length.end());
    std::rotate(walk_p.span.begin(), walk_p.span.begin() + shift, walk_p.span.end());
    std::rotate(walk_p.direction.begin(), walk_p.direction.begin() + shift, walk_p.direction.end());

    // Common boundary points and their angles.
    const double total_m = std::accumulate(walk_m.length.begin(), walk_m.length.end(), 0.0);
    const double total_p = std::accumulate(walk_p.length.begin(), walk_p.length.end(), 0.0);
    std::vector<double> weight(ns), theta0(ns + 1, 0.0);
    for (int s = 0; s < ns; ++s) weight[s] = std::max(0.5 * (walk_m.length[s] / total_m + walk_p.length[s] / total_p), 1e-3 / ns);
    const double weight_sum = std::accumulate(weight.begin(), weight.end(), 0.0);
    for (int s = 0; s < ns; ++s) theta0[s + 1] = theta0[s] + kTwoPi * weight[s] / weight_sum;
    std::vector<std::vector<double>> points(ns);
    for (int s = 0; s < ns; ++s) {
      const SegmentKey& key = walk_m.segments[s];
      points[s] = segment_points(key, walk_m.direction[s], walk_m.span[s], contours, info_m, info_p);
    }
    auto embed = [&](const CutDisk& cut, const BoundaryWalk& walk) {
      const int nb = static_cast<int>(cut.boundary.size());
      // Global index of each boundary vertex among all points: segment offset + index.
      std::vector<int> offset(ns + 1, 0);
      for (int s = 0; s < ns; ++s) offset[s + 1] = offset[s] + static_cast<int>(points[s].size());
      const int total = offset[ns];
      auto angle = [&](int g) {
        const int s = static_cast<int>(std::upper_bound(offset.begin(), offset.end(), g) - offset.begin()) - 1;
        return theta0[s] + (theta0[s + 1] - theta0[s]) * points[s][g - offset[s]];
      };
      std::vector<int> global(nb);
      for (int k = 0; k < nb; ++k) {
        const int i = find_param(points[walk.segment_of[k]], walk.param_of[k]);
        if (i < 0) throw AlgorithmError("a boundary vertex of a cut piece has no common boundary point");
        global[k] = offset[walk.segment_of[k]] + i;
      }
      std::vector<double> angle_of(nb);
      std::vector<std::vector<std::pair<double, double>>> extra(nb);
      for (int k = 0; k < nb; ++k) {
        angle_of[k] = angle(global[k]);
        const int g0 = global[k], g1 = global[(k + 1) % nb];
        const int steps = ((g1 - g0) % total + total) % total;
        if (steps <= 1) continue;
        // Positions along the edge by the points' global parameter (segment + param).
        auto position = [&](int g) {
          g = ((g % total) + total) % total;
          const int s = static_cast<int>(std::upper_bound(offset.begin(), offset.end(), g) - offset.begin()) - 1;
          return s + points[s][g - offset[s]];
        };
        const double p0 = position(g0);
        double p1 = position(g1);
        if (p1 <= p0) p1 += ns;
        for (int step = 1; step < steps; ++step) {
          double p = position(g0 + step);
          if (p < p0) p += ns;
          extra[k].emplace_back(angle((g0 + step) % total), (p - p0) / (p1 - p0));
        }
      }
      return embed_disk(cut, angle_of, extra);
    };
    M.disk = embed(cut_m, walk_m);
    P.disk = embed(cut_p, walk_p);
    P.locator = std::make_unique<DiskLocator>(P.disk.uv, P.disk.mesh.F);
    // Parts of M_j that its disk squeezes and P_j's does not (pockets, fingers between the planes).
    const DecrowdResult decrowd = decrowd_disk(M.disk, ImageAreaRatio(M.disk, P.disk, *P.locator));
    stats.decrowd_iterations = decrowd.iterations;
    stats.min_area_ratio_before = decrowd.min_ratio_before;
    stats.min_area_ratio = decrowd.min_ratio_after;
    M.locator = std::make_unique<DiskLocator>(M.disk.uv, M.disk.mesh.F);  // after the re-weighting moved M's uv
    for (SideDisk* side : {&M, &P}) {
      side->vertex_copy.assign(side->work.num_vertices(), -1);
      for (size_t v = 0; v < side->disk.vertex_origin.size(); ++v) {
        const int o = side->disk.vertex_origin[v];
        if (o >= 0 && side->vertex_copy[o] < 0) side->vertex_copy[o] = static_cast<int>(v);
      }
      side->faces_of.assign(side->piece.mesh.num_faces(), {});
      for (size_t f = 0; f < side->disk.face_origin.size(); ++f)
        side->faces_of[side->work_face_parent[side->disk.face_origin[f]]].push_back(static_cast<int>(f));
    }
    stats.disk_boundary = static_cast<int>(std::accumulate(points.begin(), points.end(), size_t{0}, [](size_t a, const auto& p) { return a + p.size(); }));
    stats.model_disk_vertices = M.disk.mesh.num_vertices();
    stats.polycube_disk_vertices = P.disk.mesh.num_vertices();
    stats.flipped_model_disk = M.disk.flipped;
    stats.flipped_polycube_disk = P.disk.flipped;
    stats.min_disk_area = std::min(M.disk.min_area, P.disk.min_area);
    stats.seconds += seconds_since(t0);
  });

  // Indices from sliced faces to pieces and from input faces to sliced faces.
  data->model_face_local.assign(ms.mesh.num_faces(), {-1, -1});
  data->polycube_face_local.assign(ps.mesh.num_faces(), {-1, -1});
  for (int j = 0; j < n_pairs; ++j) {
    const PiecePair& pair = data->pairs[j];
    for (size_t f = 0; f < pair.model.piece.face_to_global.size(); ++f) data->model_face_local[pair.model.piece.face_to_global[f]] = {j, static_cast<int>(f)};
    for (size_t f = 0; f < pair.polycube.piece.face_to_global.size(); ++f)
      data->polycube_face_local[pair.polycube.piece.face_to_global[f]] = {j, static_cast<int>(f)};
  }
  for (int f = 0; f < ps.mesh.num_faces(); ++f)
    if (data->polycube_face_local[f].first < 0) throw AlgorithmError("a piece of the polycube matches no piece of the model");
  data->model_sliced_faces_of.assign(model.num_faces(), {});
  data->polycube_sliced_faces_of.assign(result.polycube.mesh.num_faces(), {});
  for (int f = 0; f < ms.mesh.num_faces(); ++f) data->model_sliced_faces_of[ms.face_origin[f]].push_back(f);
  for (int f = 0; f < ps.mesh.num_faces(); ++f) data->polycube_sliced_faces_of[ps.face_origin[f]].push_back(f);

  // Phase 4: the map at the vertices of both meshes (input vertices keep their ids when sliced).
  out.data = data;
  auto evaluate = [&](bool from_polycube) {
    const TriMesh& source = from_polycube ? result.polycube.mesh : model;
    std::vector<int> a_face(source.num_vertices(), -1);
    Eigen::VectorXi corner(source.num_vertices());
    for (int f = 0; f < source.num_faces(); ++f)
      for (int i = 0; i < 3; ++i) {
        a_face[source.F(f, i)] = f;
        corner[source.F(f, i)] = i;
      }
    std::vector<SurfacePoint> images(source.num_vertices());
    std::vector<int> vertices(source.num_vertices());
    std::iota(vertices.begin(), vertices.end(), 0);
    parallel_for_each(std::vector<int>{0, 1}, options.threads, "vertex block", [&](int block) {
      for (int v = block; v < source.num_vertices(); v += 2) {
        SurfacePoint p;
        p.face = a_face[v];
        p.bary = Eigen::Vector3d::Zero();
        p.bary[corner[v]] = 1;
        images[v] = from_polycube ? out.to_model(p) : out.to_polycube(p);
      }
    });
    return images;
  };
  out.polycube_on_model = evaluate(true);
  out.model_on_polycube = evaluate(false);
  out.polycube_on_model_xyz.resize(out.polycube_on_model.size(), 3);
  for (size_t v = 0; v < out.polycube_on_model.size(); ++v) out.polycube_on_model_xyz.row(v) = surface_position(model, out.polycube_on_model[v]);
  out.model_on_polycube_xyz.resize(out.model_on_polycube.size(), 3);
  for (size_t v = 0; v < out.model_on_polycube.size(); ++v)
    out.model_on_polycube_xyz.row(v) = surface_position(result.polycube.mesh, out.model_on_polycube[v]);
  out.seconds = seconds_since(start);
  return out;
}

}  // namespace polycube
