// `polycube map FILE -o DIR`: the pipeline, stage by stage, with a report of each.
#include "cli/commands.h"
#include "cli/mesh_input.h"
#include "cli/stage_json.h"

#include "applications/preview/render.h"
#include "formats/atomic_file.h"
#include "formats/image_io.h"
#include "formats/mesh_io.h"
#include "polycube/errors.h"
#include "polycube/topology.h"

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <memory>

namespace polycube::cli {

namespace {

// The stages `map` can stop after, in pipeline order. The default is the last one built.
const std::vector<std::string> kStages = {"topology"};

struct MapOptions {
  MeshInput input;
  std::string output_dir;
  std::string stage = kStages.back();
  TopologyOptions topology;
  double da = 0.3;
};

// A distinct, light colour per index (golden-ratio hue steps), RGB in [0,1].
Eigen::Vector3d index_colour(int index) {
  const double hue = std::fmod(index * 0.6180339887498949, 1.0) * 6.0;
  const double s = 0.55, v = 0.95;
  const int sector = static_cast<int>(hue) % 6;
  const double f = hue - std::floor(hue);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  switch (sector) {
    case 0: return {v, t, p};
    case 1: return {q, v, p};
    case 2: return {p, v, t};
    case 3: return {p, q, v};
    case 4: return {t, p, v};
    default: return {v, p, q};
  }
}

Eigen::MatrixX3d piece_colours(const SlicedMesh& sliced) {
  Eigen::MatrixX3d rgb(sliced.mesh.num_faces(), 3);
  for (int f = 0; f < sliced.mesh.num_faces(); ++f) rgb.row(f) = index_colour(sliced.face_piece[f]);
  return rgb;
}

// The sliced model with each face coloured by its piece, for viewing in MeshLab or Blender.
void write_pieces(const std::string& path, const SlicedMesh& sliced) {
  MeshColors colours;
  colours.face_rgb = piece_colours(sliced);
  std::vector<std::vector<int>> faces(sliced.mesh.num_faces());
  for (int f = 0; f < sliced.mesh.num_faces(); ++f) faces[f] = {sliced.mesh.F(f, 0), sliced.mesh.F(f, 1), sliced.mesh.F(f, 2)};
  write_polygon_mesh(path, sliced.mesh.V, faces, &colours);
}

// A picture of the pieces: the model from a 3/4 view in front and from behind.
void write_pieces_preview(const std::string& path, const SlicedMesh& sliced) {
  const Eigen::MatrixX3d rgb = piece_colours(sliced);
  RenderItem item;
  item.mesh = &sliced.mesh;
  item.face_rgb = &rgb;
  RenderItem back = item;
  back.view_direction = {-item.view_direction.x(), -item.view_direction.y(), item.view_direction.z()};
  const Image image = render_tiles({item, back});
  write_image(path, image);
}

int run_map(const MapOptions& options, const GlobalOptions& global) {
  const Progress progress(global);
  const PreparedMesh prepared = load_mesh(options.input, progress);
  require_mappable(prepared.diagnosis);

  const std::filesystem::path dir(options.output_dir);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw OutputError("cannot create output directory " + options.output_dir + (ec ? ": " + ec.message() : ""));

  nlohmann::json report;
  report["input"] = diagnosis_json(prepared);
  report["input"]["file"] = options.input.path;
  report["parameters"] = {{"dz", options.topology.dz}, {"da", options.da}, {"stage", options.stage}};
  std::vector<std::string> outputs;

  progress.stage("topology", "harmonic function, critical points, cutting planes, slicing");
  const TopologyResult topology = analyse_topology(prepared.mesh, options.topology);
  report["topology"] = topology_json(topology);
  progress.stage("topology", std::to_string(topology.critical.saddle_count()) + " saddles, " +
                                 std::to_string(topology.planes_z.size()) + " planes, " +
                                 std::to_string(topology.sliced.pieces.size()) + " genus-0 pieces");
  const std::string pieces_path = (dir / "pieces.ply").string();
  write_pieces(pieces_path, topology.sliced);
  outputs.push_back(pieces_path);
  const std::string preview_path = (dir / "preview.png").string();
  write_pieces_preview(preview_path, topology.sliced);
  outputs.push_back(preview_path);

  report["seconds"] = {{"topology", topology.seconds_total}, {"total", progress.elapsed_seconds()}};
  const std::string report_path = (dir / "report.json").string();
  report["outputs"] = outputs;
  write_text_atomically(report_path, [&](std::ostream& out) { out << report.dump(2) << "\n"; });
  outputs.push_back(report_path);
  progress.stage("done", "wrote " + std::to_string(outputs.size()) + " files in " + options.output_dir);
  return kSuccess;
}

}  // namespace

void add_map_command(CLI::App& app, const GlobalOptions& global, CommandRunner& runner) {
  auto options = std::make_shared<MapOptions>();
  CLI::App* command = app.add_subcommand("map", "Build the polycube and the map for a closed mesh");
  add_mesh_input_options(*command, options->input);
  command->add_option("-o,--output", options->output_dir, "Output directory (created if missing)")->required();
  command->add_option("--dz", options->topology.dz, "Largest gap between cutting planes, unit-cube units (paper's d_z)")
      ->capture_default_str()
      ->check(CLI::Range(1e-3, 1.0));
  command->add_option("--da", options->da, "Area tolerance of the axis-aligned contours (paper's d_a)")
      ->capture_default_str()
      ->check(CLI::Range(1e-3, 1.0));
  command->add_option("--stage", options->stage, "Stop after this stage")
      ->capture_default_str()
      ->check(CLI::IsMember(kStages));
  command->callback([options, &global, &runner] { runner = [options, &global] { return run_map(*options, global); }; });
}

}  // namespace polycube::cli
