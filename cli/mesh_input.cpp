#include "cli/mesh_input.h"

#include "formats/mesh_io.h"
#include "polycube/errors.h"

#include <iomanip>
#include <sstream>

namespace polycube::cli {

void add_mesh_input_options(CLI::App& command, MeshInput& input) {
  command.add_option("FILE", input.path, "Input mesh (.obj .off .ply .stl)")->required();
  command.add_flag("--fill-holes", input.prepare.fill_holes, "Close boundary loops (CGAL hole filling)");
  command.add_flag("--largest-component", input.prepare.largest_component, "Keep only the largest component");
  command.add_flag_callback(
      "--no-self-intersections", [&input] { input.prepare.check_self_intersections = false; },
      "Skip the self-intersection check");
}

PreparedMesh load_mesh(const MeshInput& input, const Progress& progress) {
  progress.stage("read", input.path);
  const PolygonSoup soup = read_polygon_soup(input.path);
  progress.stage("validate", std::to_string(soup.points.size()) + " vertices, " +
                                 std::to_string(soup.polygons.size()) + " faces");
  PreparedMesh prepared = prepare_mesh(soup, input.prepare);
  for (const std::string& repair : prepared.repairs) progress.warning(repair);
  for (const std::string& warning : prepared.diagnosis.warnings) progress.warning(warning);
  return prepared;
}

std::optional<Separation> separated_for_stages(const PreparedMesh& prepared, const Progress& progress, nlohmann::json& report) {
  if (prepared.diagnosis.self_intersections <= 0) return std::nullopt;
  progress.stage("separate", "the model intersects itself: smoothing round the crossings, on a copy the planes cut");
  Separation s;
  try {
    s = separate_self_intersections(prepared.mesh);
  } catch (const AlgorithmError& e) {
    progress.warning(std::string(e.what()) + ": no separated copy; the model as read is used");
    report["separation"] = {{"failed", e.what()}};
    return std::nullopt;
  }
  progress.stage("separate", std::to_string(s.pairs_before) + " face pairs apart after " + std::to_string(s.rounds) + " rounds; " +
                                 std::to_string(s.moved_vertices) + " vertices moved, by up to " +
                                 std::to_string(100 * s.max_shift) + " % of the diagonal");
  report["separation"] = {{"pairs_before", s.pairs_before},
                          {"rounds", s.rounds},
                          {"moved_vertices", s.moved_vertices},
                          {"max_shift", s.max_shift},
                          {"seconds", s.seconds}};
  return s;
}

void say_equalised_copy(const EqualisedCopy& equalised, const Progress& progress, nlohmann::json& report) {
  const Eigen::Vector3d& d = equalised.deviations;
  const Eigen::Vector3d& s = equalised.scales;
  std::ostringstream said;
  said << std::setprecision(3) << "principal deviations " << d(0) << ", " << d(1) << ", " << d(2)
       << ": first on a copy with its axes scaled by " << s(0) << ", " << s(1) << ", " << s(2);
  progress.stage("equalise", said.str());
  report["deviations"] = {d(0), d(1), d(2)};
  report["scales"] = {s(0), s(1), s(2)};
}

Eigen::MatrixX3d placed_as_input(const PreparedMesh& prepared, Eigen::MatrixX3d V) {
  if (!prepared.offset.isZero(0)) V.rowwise() += prepared.offset.transpose();
  return V;
}

TriMesh placed_as_input(const PreparedMesh& prepared, TriMesh mesh) {
  mesh.V = placed_as_input(prepared, std::move(mesh.V));
  return mesh;
}

Eigen::Vector3d placed_as_input(const PreparedMesh& prepared, const Eigen::Vector3d& x) { return x + prepared.offset; }

nlohmann::json diagnosis_json(const PreparedMesh& prepared) {
  const MeshDiagnosis& d = prepared.diagnosis;
  nlohmann::json j;
  j["input_vertices"] = d.input_vertices;
  j["input_faces"] = d.input_polygons;
  j["vertices"] = d.vertices;
  j["faces"] = d.faces;
  j["edges"] = d.edges;
  j["components"] = d.components;
  j["boundary_loops"] = d.boundary_loops;
  j["boundary_edges"] = d.boundary_edges;
  j["nonmanifold_edges"] = d.nonmanifold_edges;
  j["nonmanifold_vertices"] = d.nonmanifold_vertices;
  j["manifold"] = d.manifold();
  j["orientable"] = d.orientable;
  j["closed"] = d.closed();
  j["degenerate_faces"] = d.degenerate_faces;
  j["self_intersections"] = d.self_intersections >= 0 ? nlohmann::json(d.self_intersections) : nlohmann::json();
  j["euler"] = d.euler;
  j["genus"] = d.genus ? nlohmann::json(*d.genus) : nlohmann::json();
  if (d.vertices > 0) {
    j["bounding_box"] = {{"min", {d.bbox.min.x(), d.bbox.min.y(), d.bbox.min.z()}},
                         {"max", {d.bbox.max.x(), d.bbox.max.y(), d.bbox.max.z()}},
                         {"diagonal", d.bbox.diagonal()}};
  }
  j["repairs"] = prepared.repairs;
  j["problems"] = d.problems;
  j["warnings"] = d.warnings;
  j["valid"] = d.valid();
  return j;
}

}  // namespace polycube::cli
