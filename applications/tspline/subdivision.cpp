#include "applications/tspline/subdivision.h"

#include "polycube/errors.h"

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>

namespace polycube {

namespace {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

// OpenSubdiv's largest uniform refinement level.
constexpr int kMaxLevels = 10;

// A vertex as OpenSubdiv's PrimvarRefiner interpolates it: Clear() then weighted sums.
struct Point {
  double x[3];
  void Clear() { x[0] = x[1] = x[2] = 0; }
  void AddWithWeight(const Point& source, double weight) {
    for (int d = 0; d < 3; ++d) x[d] += weight * source.x[d];
  }
};

// OpenSubdiv reports errors through a process-wide callback (printf by default); library code
// must not print, so messages are kept here and put into our exception instead.
std::string& last_osd_error() {
  static thread_local std::string message;
  return message;
}

void record_osd_error(Far::ErrorType, const char* message) { last_osd_error() = message ? message : ""; }

void record_osd_warning(const char*) {}

}  // namespace

PolyMesh subdivide_catmull_clark(const PolyMesh& control, int levels, bool limit_positions) {
  if (levels < 0 || levels > kMaxLevels)
    throw std::invalid_argument("subdivide_catmull_clark: levels must be in 0.." + std::to_string(kMaxLevels) +
                                ", got " + std::to_string(levels));
  // Limit masks need the topology around each vertex that only refined levels guarantee
  // (all faces quads).
  if (limit_positions && levels == 0)
    throw std::invalid_argument("subdivide_catmull_clark: limit positions need levels >= 1");
  const int nv = control.num_vertices();
  std::vector<int> face_sizes;
  std::vector<Far::Index> face_indices;
  face_sizes.reserve(control.faces.size());
  for (size_t f = 0; f < control.faces.size(); ++f) {
    const auto& face = control.faces[f];
    if (face.size() < 3)
      throw MeshError("subdivide_catmull_clark: face " + std::to_string(f) + " has " + std::to_string(face.size()) +
                      " vertices, need at least 3");
    for (int v : face) {
      if (v < 0 || v >= nv)
        throw MeshError("subdivide_catmull_clark: face " + std::to_string(f) + " uses vertex " + std::to_string(v) +
                        ", valid are 0.." + std::to_string(nv - 1));
      face_indices.push_back(v);
    }
    face_sizes.push_back(static_cast<int>(face.size()));
  }
  if (control.faces.empty()) throw MeshError("subdivide_catmull_clark: control mesh has no faces");
  if (levels == 0) return control;

  Far::TopologyDescriptor descriptor;
  descriptor.numVertices = nv;
  descriptor.numFaces = control.num_faces();
  descriptor.numVertsPerFace = face_sizes.data();
  descriptor.vertIndicesPerFace = face_indices.data();

  Sdc::Options sdc_options;
  sdc_options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  Far::SetErrorCallback(record_osd_error);
  Far::SetWarningCallback(record_osd_warning);
  last_osd_error().clear();
  std::unique_ptr<Far::TopologyRefiner> refiner(
      Factory::Create(descriptor, Factory::Options(Sdc::SCHEME_CATMARK, sdc_options)));
  if (!refiner)
    throw MeshError("subdivide_catmull_clark: OpenSubdiv rejected the control mesh: " +
                    (last_osd_error().empty() ? std::string("invalid topology") : last_osd_error()));
  Far::TopologyRefiner::UniformOptions uniform(levels);
  uniform.fullTopologyInLastLevel = limit_positions;  // limit masks walk the last level's topology
  refiner->RefineUniform(uniform);

  // Positions level by level: level 0 is the control mesh, vertices of level l+1 follow level l.
  std::vector<Point> points(static_cast<size_t>(refiner->GetNumVerticesTotal()));
  for (int v = 0; v < nv; ++v)
    for (int d = 0; d < 3; ++d) points[v].x[d] = control.V(v, d);
  Far::PrimvarRefinerReal<double> primvar(*refiner);
  Point* source = points.data();
  for (int level = 1; level <= levels; ++level) {
    Point* destination = source + refiner->GetLevel(level - 1).GetNumVertices();
    primvar.Interpolate(level, source, destination);
    source = destination;
  }

  const Far::TopologyLevel& last = refiner->GetLevel(levels);
  if (limit_positions) {
    std::vector<Point> limit(static_cast<size_t>(last.GetNumVertices()));
    Point* limit_points = limit.data();
    primvar.Limit(source, limit_points);
    std::copy(limit.begin(), limit.end(), source);
  }
  PolyMesh refined;
  refined.V.resize(last.GetNumVertices(), 3);
  for (int v = 0; v < last.GetNumVertices(); ++v)
    for (int d = 0; d < 3; ++d) refined.V(v, d) = source[v].x[d];
  refined.faces.resize(static_cast<size_t>(last.GetNumFaces()));
  for (int f = 0; f < last.GetNumFaces(); ++f) {
    const Far::ConstIndexArray face = last.GetFaceVertices(f);
    refined.faces[f].assign(face.begin(), face.end());
  }
  return refined;
}

}  // namespace polycube
