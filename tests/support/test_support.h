// Helpers shared by the test executables: where the test meshes and the built CLI live, and
// meshes generated in code for the edge cases no file covers.
#pragma once

#include "polycube/mesh.h"
#include "polycube/polycube_build.h"
#include "polycube/polycube_map.h"

#include <map>
#include <string>
#include <vector>

namespace polycube::test {

// A model with its stages up to the map (default options, the model's own orientation), built
// once per name and kept for the test executable's life: "generated-genus-5"
// (make_genus_surface(5, 40)), a mesh of examples/ ("rocker-arm.obj") or of tests/data.
struct MappedModel {
  TriMesh model;
  PolycubeResult polycube;
  PolycubeMap map;
};
const MappedModel& mapped_model(const std::string& name);

// Absolute path of a file in tests/data/.
std::string data_path(const std::string& name);

// The closed meshes in tests/data with their genus (from the CGAL data documentation).
const std::map<std::string, int>& closed_test_meshes();

// A mesh of tests/data read and prepared (polygons triangulated, oriented outward), without the
// self-intersection search. Throws MeshError if it is not mappable.
TriMesh load_test_mesh(const std::string& name);

// A GoogleTest parameter name for a mesh file name: "double-torus-example.off" ->
// "double_torus_example".
std::string test_name_of_file(const std::string& file);

// Any mesh file read and prepared like load_test_mesh.
TriMesh load_mesh_file(const std::string& path);

// Absolute path of a file in examples/.
std::string example_path(const std::string& name);

// Absolute path of the built `polycube` binary.
std::string binary_path();

// A fresh empty directory under the system temp dir, removed with everything in it when the test
// process exits (kept when the environment variable POLYCUBE_KEEP_TEST_FILES is set).
std::string temp_dir(const std::string& tag);

// Whole contents of a file (binary); empty when it cannot be read.
std::string read_file(const std::string& path);

// Writes contents to path (binary), replacing it; returns path.
std::string write_file(const std::string& path, const std::string& contents);

// Runs a shell command; returns its exit code and fills stdout/stderr when given.
int run_command(const std::string& command, std::string* out = nullptr, std::string* err = nullptr);

// A run of the built `polycube` binary.
struct CliRun {
  int code = -1;
  std::string out, err;
};

// Runs `polycube <arguments>` (arguments are passed to the shell as written).
CliRun polycube_cli(const std::string& arguments);

// s in single quotes for the shell.
std::string quoted(const std::string& s);

// Number of newline characters in text.
int line_count(const std::string& text);

}  // namespace polycube::test
