// Reading and preparing the input mesh, shared by every subcommand that takes one.
#pragma once

#include "cli/commands.h"
#include "polycube/align.h"
#include "polycube/separate.h"
#include "polycube/validate.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace polycube::cli {

struct MeshInput {
  std::string path;
  PrepareOptions prepare;
};

// Adds FILE and the repair flags (--fill-holes, --largest-component, --no-self-intersections).
void add_mesh_input_options(CLI::App& command, MeshInput& input);

// Reads and prepares the mesh; reports each repair as a warning. Throws InputError.
PreparedMesh load_mesh(const MeshInput& input, const Progress& progress);

// When the model intersects itself: its separated copy (separate.h; same vertices and faces) for
// the stages that cut it by planes, said on stderr and in `report` ("separation"); nothing
// otherwise, and nothing when the smoothing leaves crossings after its rounds (a warning, and
// `separation.failed` in `report`: the caller works on the model as read; before the thirty-ninth
// session that ended the command with exit 6). Results on the copy go back to the model with
// to_original_surface.
std::optional<Separation> separated_for_stages(const PreparedMesh& prepared, const Progress& progress, nlohmann::json& report);

// A long model's scaled copy (equalised_copy), said on stderr and in `report` (its deviations and
// scales), before the search on it (`map`, `quad`).
void say_equalised_copy(const EqualisedCopy& equalised, const Progress& progress, nlohmann::json& report);

// Positions of the prepared mesh's frame in the input's: plus PreparedMesh::offset (a model far
// from the origin is moved there by prepare_mesh; every file and coordinate written goes back).
Eigen::MatrixX3d placed_as_input(const PreparedMesh& prepared, Eigen::MatrixX3d V);
TriMesh placed_as_input(const PreparedMesh& prepared, TriMesh mesh);
Eigen::Vector3d placed_as_input(const PreparedMesh& prepared, const Eigen::Vector3d& x);

// The diagnosis as a JSON object (keys documented in README.md).
nlohmann::json diagnosis_json(const PreparedMesh& prepared);

}  // namespace polycube::cli
