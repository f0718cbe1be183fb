#include "applications/hex/tetrahedralize.h"

#include "polycube/errors.h"
#include "polycube/mesh_topology.h"

#include <tetgen.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace polycube {

namespace {

// Meaning of the codes TetGen 1.5 throws through terminatetetgen().
std::string tetgen_reason(int code) {
  switch (code) {
    case 1: return "out of memory";
    case 2: return "internal error";
    case 3: return "the surface intersects itself";
    case 4: return "a very small input feature size was detected";
    case 5: return "two very close input facets were detected";
    case 10: return "invalid input";
    default: return "unknown error";
  }
}

// Faces whose corners are collinear up to rounding, and vertices at the same position: TetGen
// may fail on both.
void check_geometry(const TriMesh& surface) {
  for (int f = 0; f < surface.num_faces(); ++f) {
    const Eigen::Vector3d a = surface.V.row(surface.F(f, 0)), b = surface.V.row(surface.F(f, 1)),
                          c = surface.V.row(surface.F(f, 2));
    const double longest = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    // Twice the area relative to the squared longest edge: about the sine of the largest angle.
    if ((b - a).cross(c - a).norm() <= 1e-12 * longest)
      throw MeshError("tetrahedralize: face " + std::to_string(f) + " has zero area (collinear corners)");
  }
  std::vector<int> order(surface.num_vertices());
  for (int v = 0; v < surface.num_vertices(); ++v) order[v] = v;
  auto position = [&](int v) { return std::array<double, 3>{surface.V(v, 0), surface.V(v, 1), surface.V(v, 2)}; };
  std::sort(order.begin(), order.end(), [&](int x, int y) { return position(x) < position(y); });
  for (size_t k = 1; k < order.size(); ++k)
    if (position(order[k]) == position(order[k - 1]))
      throw MeshError("tetrahedralize: vertices " + std::to_string(std::min(order[k], order[k - 1])) + " and " +
                      std::to_string(std::max(order[k], order[k - 1])) + " are at the same position");
}

void check_surface(const TriMesh& surface) {
  if (surface.num_faces() == 0 || surface.num_vertices() < 4)
    throw MeshError("tetrahedralize: surface is empty (" + std::to_string(surface.num_vertices()) + " vertices, " +
                    std::to_string(surface.num_faces()) + " faces)");
  if (surface.F.minCoeff() < 0 || surface.F.maxCoeff() >= surface.num_vertices())
    throw MeshError("tetrahedralize: face indices outside 0.." + std::to_string(surface.num_vertices() - 1));
  if (!surface.V.allFinite()) throw MeshError("tetrahedralize: surface has non-finite coordinates");
  const EdgeMap edges = build_edge_map(surface.F);
  const long open = (edges.face_count.array() != 2).count();
  if (open > 0)
    throw MeshError("tetrahedralize: surface is not closed and edge-manifold: " + std::to_string(open) + " of " +
                    std::to_string(edges.num_edges()) + " edges do not have exactly two faces");
  check_geometry(surface);
}

// Fills a tetgenio with the surface as a piecewise linear complex of triangles.
// tetgenio frees these arrays with delete[] in its destructor.
void fill_input(const TriMesh& surface, tetgenio& in) {
  in.firstnumber = 0;
  in.numberofpoints = surface.num_vertices();
  in.pointlist = new REAL[3 * in.numberofpoints];
  for (int v = 0; v < surface.num_vertices(); ++v)
    for (int d = 0; d < 3; ++d) in.pointlist[3 * v + d] = surface.V(v, d);
  in.numberoffacets = surface.num_faces();
  in.facetlist = new tetgenio::facet[in.numberoffacets];
  for (int f = 0; f < surface.num_faces(); ++f) {
    tetgenio::facet& facet = in.facetlist[f];
    tetgenio::init(&facet);
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&facet.polygonlist[0]);
    facet.polygonlist[0].numberofvertices = 3;
    facet.polygonlist[0].vertexlist = new int[3];
    for (int c = 0; c < 3; ++c) facet.polygonlist[0].vertexlist[c] = surface.F(f, c);
  }
}

// Runs TetGen with the given switches; its error codes become AlgorithmError.
void run_tetgen(const std::string& switches, tetgenio& in, tetgenio& out) {
  std::string text = switches;
  try {
    ::tetrahedralize(text.data(), &in, &out);
  } catch (int code) {
    throw AlgorithmError("tetrahedralize: TetGen failed (code " + std::to_string(code) + "): " + tetgen_reason(code));
  }
}

// TetGen 1.5 frees its memory twice when it stops with an error (terminatetetgen() frees, then
// the destructor of its stack mesh frees again), which crashes the process before the error
// code can be caught. Its commonest error, a self-intersecting surface, is therefore looked for
// first with TetGen's own detector (switch d), which reports instead of stopping.
void check_self_intersections(const TriMesh& surface) {
  tetgenio in, out;
  fill_input(surface, in);
  run_tetgen("pdzQ", in, out);
  if (out.numberoftrifaces <= 0) return;
  // The intersecting faces come back as vertex triples: name the input faces.
  std::map<std::array<int, 3>, int> face_of;
  for (int f = 0; f < surface.num_faces(); ++f) {
    std::array<int, 3> key = {surface.F(f, 0), surface.F(f, 1), surface.F(f, 2)};
    std::sort(key.begin(), key.end());
    face_of.emplace(key, f);
  }
  std::string examples;
  for (int t = 0; t < std::min(out.numberoftrifaces, 4); ++t) {
    std::array<int, 3> key = {out.trifacelist[3 * t], out.trifacelist[3 * t + 1], out.trifacelist[3 * t + 2]};
    std::sort(key.begin(), key.end());
    const auto it = face_of.find(key);
    if (it != face_of.end()) examples += (examples.empty() ? "" : ", ") + std::to_string(it->second);
  }
  throw AlgorithmError("tetrahedralize: the surface intersects itself: " + std::to_string(out.numberoftrifaces) +
                       " faces involved" + (examples.empty() ? "" : " (faces " + examples + ", ...)"));
}

}  // namespace

TetMesh tetrahedralize(const TriMesh& surface, const TetrahedralizeOptions& options) {
  if (!(options.max_volume >= 0))
    throw std::invalid_argument("tetrahedralize: max_volume must be >= 0, got " + std::to_string(options.max_volume));
  if (!(options.min_ratio == 0 || options.min_ratio >= 1))
    throw std::invalid_argument("tetrahedralize: min_ratio must be 0 or >= 1, got " +
                                std::to_string(options.min_ratio));
  check_surface(surface);

  // p: piecewise linear complex input, Y: no Steiner points on the boundary, z: 0-based indices,
  // q: radius-edge bound, a: volume bound, Q: quiet.
  std::ostringstream switches;
  switches.precision(17);
  switches << "pYz";
  if (options.min_ratio > 0) switches << "q" << options.min_ratio;
  if (options.max_volume > 0) switches << "a" << options.max_volume;
  if (options.quiet) switches << "Q";

  check_self_intersections(surface);
  tetgenio in, out;
  fill_input(surface, in);
  run_tetgen(switches.str(), in, out);
  if (out.numberoftetrahedra <= 0 || out.numberofpoints < surface.num_vertices())
    throw AlgorithmError("tetrahedralize: TetGen produced " + std::to_string(out.numberoftetrahedra) +
                         " tetrahedra on " + std::to_string(out.numberofpoints) + " points");

  TetMesh result;
  result.V.resize(out.numberofpoints, 3);
  for (int v = 0; v < out.numberofpoints; ++v)
    for (int d = 0; d < 3; ++d) result.V(v, d) = out.pointlist[3 * v + d];
  // Surface vertices are kept bit for bit (TetGen copies them; restore in case of any rounding).
  result.V.topRows(surface.num_vertices()) = surface.V;
  result.T.resize(out.numberoftetrahedra, 4);
  for (int t = 0; t < out.numberoftetrahedra; ++t) {
    for (int c = 0; c < 4; ++c) result.T(t, c) = out.tetrahedronlist[out.numberofcorners * t + c];
    const Eigen::Vector3d a = result.V.row(result.T(t, 0)), b = result.V.row(result.T(t, 1)),
                          c = result.V.row(result.T(t, 2)), d = result.V.row(result.T(t, 3));
    if ((b - a).cross(c - a).dot(d - a) < 0) std::swap(result.T(t, 2), result.T(t, 3));
  }
  return result;
}

}  // namespace polycube
