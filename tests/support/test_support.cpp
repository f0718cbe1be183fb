#include "support/test_support.h"

#include "formats/mesh_io.h"
#include "polycube/topology.h"
#include "polycube/validate.h"
#include "support/generated_meshes.h"

#include <sys/wait.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <random>
#include <sstream>
#include <vector>

namespace polycube::test {

std::string data_path(const std::string& name) { return std::string(POLYCUBE_TEST_DATA_DIR) + "/" + name; }

const std::map<std::string, int>& closed_test_meshes() {
  static const std::map<std::string, int> meshes = {
      {"sphere.off", 0}, {"torus_quad.off", 1}, {"rotor.off", 1},  {"elk.off", 1},
      {"knot.off", 1},   {"joint.off", 2},      {"eight.off", 2},  {"double-torus-example.off", 2},
      {"helmet.off", 3}, {"anchor.off", 4},     {"couplingdown.off", 9}};
  return meshes;
}

TriMesh load_test_mesh(const std::string& name) { return load_mesh_file(data_path(name)); }

const MappedModel& mapped_model(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<MappedModel>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<MappedModel>& slot = cache[name];
  if (!slot) {
    auto built = std::make_unique<MappedModel>();
    if (name == "generated-genus-5") built->model = make_genus_surface(5, 40);
    else if (name == "rocker-arm.obj") built->model = load_mesh_file(example_path(name));
    else built->model = load_test_mesh(name);
    built->polycube = build_polycube(built->model, analyse_topology(built->model));
    built->map = build_polycube_map(built->model, built->polycube);
    slot = std::move(built);
  }
  return *slot;
}

std::string test_name_of_file(const std::string& file) {
  std::string name = file.substr(0, file.find('.'));
  for (char& c : name)
    if (c == '-') c = '_';
  return name;
}

TriMesh load_mesh_file(const std::string& path) {
  PrepareOptions options;
  options.check_self_intersections = false;
  PreparedMesh prepared = prepare_mesh(read_polygon_soup(path), options);
  require_mappable(prepared.diagnosis);
  return std::move(prepared.mesh);
}

std::string example_path(const std::string& name) { return std::string(POLYCUBE_EXAMPLES_DIR) + "/" + name; }

std::string binary_path() { return POLYCUBE_BINARY; }

namespace {

// The directories temp_dir made, removed when the test process exits normally (each ctest test is
// its own process), unless POLYCUBE_KEEP_TEST_FILES is set. A crashed test leaves its own.
class TempDirs {
 public:
  ~TempDirs() {
    if (std::getenv("POLYCUBE_KEEP_TEST_FILES")) return;
    for (const std::filesystem::path& dir : dirs_) {
      std::error_code ignored;  // a test that took its own directory's permissions away keeps it
      std::filesystem::remove_all(dir, ignored);
    }
  }
  void add(const std::filesystem::path& dir) {
    const std::lock_guard<std::mutex> lock(mutex_);
    dirs_.push_back(dir);
  }

 private:
  std::mutex mutex_;
  std::vector<std::filesystem::path> dirs_;
};

}  // namespace

std::string temp_dir(const std::string& tag) {
  static std::atomic<int> counter{0};
  static TempDirs made;
  std::random_device rd;
  const auto dir = std::filesystem::temp_directory_path() /
                   ("polycube-test-" + tag + "-" + std::to_string(rd()) + "-" + std::to_string(counter++));
  std::filesystem::create_directories(dir);
  made.add(dir);
  return dir.string();
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string write_file(const std::string& path, const std::string& contents) {
  std::ofstream out(path, std::ios::binary);
  out << contents;
  return path;
}

int run_command(const std::string& command, std::string* out, std::string* err) {
  const std::string dir = temp_dir("cmd");
  const std::string out_path = dir + "/stdout", err_path = dir + "/stderr";
  const std::string full = command + " > '" + out_path + "' 2> '" + err_path + "' < /dev/null";
  const int status = std::system(full.c_str());
  if (out) *out = read_file(out_path);
  if (err) *err = read_file(err_path);
  std::filesystem::remove_all(dir);
  if (status == -1) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

CliRun polycube_cli(const std::string& arguments) {
  CliRun run;
  run.code = run_command(quoted(binary_path()) + " " + arguments, &run.out, &run.err);
  return run;
}

int line_count(const std::string& text) { return static_cast<int>(std::count(text.begin(), text.end(), '\n')); }

}  // namespace polycube::test
