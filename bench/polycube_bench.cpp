// Benchmark of the polycube stage (issue 4): for every mesh given, the topology stage and
// build_polycube with default parameters, then the two-sided Hausdorff distance between P and
// the model. Prints one Markdown table row per mesh (see bench/polycube.md). Each mesh runs in
// its own child process, so that its peak resident memory (taken when build_polycube returns,
// before the distance is measured) is its own.
//
// Not part of the CMake build; compile against a Release build tree B (e.g. build), one line:
//   g++ -O2 -std=c++17 -I. -I/usr/include/eigen3 bench/polycube_bench.cpp -o /tmp/polycube_bench
//       B/libpolycube_formats.a B/libpolycube_engine.a -lgmpxx -lgmp -lmpfr -lpthread
//   /tmp/polycube_bench /work/shared/data/dev/*.off /work/shared/data/paper/*.obj
#include "formats/mesh_io.h"
#include "polycube/errors.h"
#include "polycube/polycube_build.h"
#include "polycube/polycube_distance.h"
#include "polycube/topology.h"
#include "polycube/validate.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

using namespace polycube;

namespace {

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // kilobytes on Linux
}

// One table row for the mesh at `path`; returns the process exit code.
int bench(const std::string& path) {
  const std::string name = path.substr(path.find_last_of('/') + 1);
  const auto start = std::chrono::steady_clock::now();
  try {
    PrepareOptions prepare;
    prepare.check_self_intersections = false;
    const PreparedMesh prepared = prepare_mesh(read_polygon_soup(path), prepare);
    require_mappable(prepared.diagnosis);
    const TriMesh& mesh = prepared.mesh;
    const auto t0 = std::chrono::steady_clock::now();
    const TopologyResult topology = analyse_topology(mesh);
    const auto t1 = std::chrono::steady_clock::now();
    const PolycubeResult result = build_polycube(mesh, topology);
    const auto t2 = std::chrono::steady_clock::now();
    const double rss = peak_rss_mb();
    const HausdorffDistance distance = hausdorff_distance(mesh, result.polycube.mesh);
    const double percent = 100 * distance.hausdorff / bounding_box(mesh.V).diagonal();
    std::printf("| %s | %d | %d | %zu (%d) | %zu | %zu | %zu | %d | %zu (%d / %d / %d) | %d / %d | %.2f | %.2f + %.2f | %.0f | ok |\n",
                name.c_str(), mesh.num_vertices(), result.genus, result.planes_z.size(), result.planes_inserted,
                result.model_sliced.pieces.size(), result.polycube.corners.size(), result.polycube.faces.size(),
                result.polycube.mesh.num_vertices(), result.repairs.size(), result.planes_inserted,
                result.relabelled_cells, result.stacking_splits, result.coarsening_merges, result.snapped_cells, percent,
                std::chrono::duration<double>(t1 - t0).count(), std::chrono::duration<double>(t2 - t1).count(), rss);
    return 0;
  } catch (const std::exception& e) {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("| %s | | | | | | | | | | | %.2f | %.0f | failed: %s |\n", name.c_str(), seconds, peak_rss_mb(), e.what());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::printf("| mesh | model V | genus | planes (inserted) | pieces | corners | faces | P vertices | repairs "
              "(planes / relabelled / split cells) | simplified (merged / snapped) | Hausdorff %% diag | seconds "
              "(topology + polycube) | peak RSS MB | result |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::fflush(stdout);
  int failed = 0;
  for (int a = 1; a < argc; ++a) {
    const pid_t child = fork();
    if (child == 0) {
      const int code = bench(argv[a]);
      std::fflush(stdout);
      _exit(code);
    }
    int status = 0;
    if (child < 0 || waitpid(child, &status, 0) < 0 || !WIFEXITED(status)) {
      const std::string path = argv[a];
      std::printf("| %s | | | | | | | | | | | | | crashed (%s) |\n", path.substr(path.find_last_of('/') + 1).c_str(),
                  child < 0 ? "no process" : WIFSIGNALED(status) ? strsignal(WTERMSIG(status)) : "unknown");
      std::fflush(stdout);
      ++failed;
    } else if (WEXITSTATUS(status) != 0) {
      ++failed;
    }
  }
  return failed == 0 ? 0 : 1;
}
