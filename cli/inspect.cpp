// `polycube inspect FILE [--json]`: what the mesh is and whether it can be mapped.
#include "cli/commands.h"
#include "cli/mesh_input.h"
#include "cli/stage_json.h"

#include "polycube/topology.h"

#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>

namespace polycube::cli {

namespace {

struct InspectOptions {
  MeshInput input;
  bool json = false;
  bool topology = false;
};

void print_text(const std::string& path, const PreparedMesh& prepared) {
  const MeshDiagnosis& d = prepared.diagnosis;
  auto row = [](const std::string& key) -> std::ostream& { return std::cout << std::left << std::setw(20) << key; };
  row("file") << path << "\n";
  row("vertices") << d.vertices << "\n";
  row("faces") << d.faces << " triangles\n";
  row("edges") << d.edges << "\n";
  row("components") << d.components << "\n";
  row("boundary loops") << d.boundary_loops << " (" << d.boundary_edges << " edges)\n";
  row("euler") << d.euler << "\n";
  row("genus");
  if (d.genus) std::cout << *d.genus << "\n"; else std::cout << "undefined (not a manifold)\n";
  row("manifold") << (d.manifold() ? "yes" : "no") << " (" << d.nonmanifold_edges << " non-manifold edges, "
                  << d.nonmanifold_vertices << " non-manifold vertices)\n";
  row("orientable") << (d.orientable ? "yes" : "no") << "\n";
  row("zero-area faces") << d.degenerate_faces << "\n";
  row("self-intersections");
  if (d.self_intersections >= 0) std::cout << d.self_intersections << " face pairs\n"; else std::cout << "not checked\n";
  if (d.vertices > 0) {
    row("bounding box") << std::setprecision(6) << "[" << d.bbox.min.x() << ", " << d.bbox.min.y() << ", "
                        << d.bbox.min.z() << "] to [" << d.bbox.max.x() << ", " << d.bbox.max.y() << ", "
                        << d.bbox.max.z() << "], diagonal " << d.bbox.diagonal() << "\n";
  }
  for (const std::string& repair : prepared.repairs) row("repaired") << repair << "\n";
  row("verdict") << (d.valid() ? "valid: closed, connected, 2-manifold, oriented; ready to map" : "not mappable") << "\n";
  for (const std::string& problem : d.problems) row("  problem") << problem << "\n";
  for (const std::string& warning : d.warnings) row("  warning") << warning << "\n";
}

void print_topology(const TopologyResult& topology) {
  auto row = [](const std::string& key) -> std::ostream& { return std::cout << std::left << std::setw(20) << key; };
  const CriticalPoints& c = topology.critical;
  row("critical points") << c.minima.size() << " minima, " << c.maxima.size() << " maxima, " << c.saddle_count()
                         << " saddles\n";
  row("cutting planes") << topology.planes_z.size() << " (" << topology.planes_added_for_genus
                        << " added to make every piece genus 0)\n";
  int max_genus = 0;
  for (const Piece& piece : topology.sliced.pieces) max_genus = std::max(max_genus, piece.genus);
  row("pieces") << topology.sliced.pieces.size() << ", largest genus " << max_genus << "\n";
  row("topology time") << std::setprecision(3) << topology.seconds_total << " s\n";
}

}  // namespace

void add_inspect_command(CLI::App& app, const GlobalOptions& global, CommandRunner& runner) {
  auto options = std::make_shared<InspectOptions>();
  CLI::App* command = app.add_subcommand("inspect", "Report a mesh's size, topology and whether it can be mapped");
  add_mesh_input_options(*command, options->input);
  command->add_flag("--json", options->json, "Print one JSON object on stdout");
  command->add_flag("--topology", options->topology,
                    "Also run the topology stage: critical points, cutting planes, genus-0 pieces");
  command->callback([options, &global, &runner] {
    runner = [options, &global] {
      const Progress progress(global);
      const PreparedMesh prepared = load_mesh(options->input, progress);
      std::optional<TopologyResult> topology;
      if (options->topology && prepared.diagnosis.valid()) {
        progress.stage("topology", "harmonic function, critical points, cutting planes, slicing");
        topology = analyse_topology(prepared.mesh);
      }
      if (options->json) {
        nlohmann::json j = diagnosis_json(prepared);
        j["file"] = options->input.path;
        if (topology) j.update(topology_json(*topology));
        std::cout << j.dump(2) << std::endl;
      } else {
        print_text(options->input.path, prepared);
        if (topology) print_topology(*topology);
      }
      require_mappable(prepared.diagnosis);  // one-line error and exit code 4 when not mappable
      return static_cast<int>(kSuccess);
    };
  });
}

}  // namespace polycube::cli
