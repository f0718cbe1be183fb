// Benchmark of the polycube stage (issue 4): for every mesh given, the topology stage and
// build_polycube with default parameters, then the two-sided Hausdorff distance between P and
// the model. Prints one Markdown table row per mesh (see bench/polycube.md).
//
// Not part of the CMake build; compile against a Release build tree, e.g.
//   g++ -O2 -std=c++17 -I. -I/usr/include/eigen3 bench/polycube_bench.cpp -o /tmp/polycube_bench
//       build-cube/libpolycube_formats.a build-cube/libpolycube_engine.a
//       -lOpenImageIO -lOpenImageIO_Util -lgmpxx -lgmp -lmpfr -lpthread
// (one command line).
//   /tmp/polycube_bench /work/shared/data/dev/*.off /work/shared/data/paper/*.obj
#include "formats/mesh_io.h"
#include "polycube/errors.h"
#include "polycube/polycube_build.h"
#include "polycube/polycube_distance.h"
#include "polycube/topology.h"
#include "polycube/validate.h"

#include <chrono>
#include <cstdio>
#include <exception>
#include <string>

using namespace polycube;

int main(int argc, char** argv) {
  std::printf("| mesh | model V | genus | planes (inserted) | pieces | corners | faces | P vertices | repairs "
              "(planes / relabelled / split cells) | Hausdorff %% diag | seconds (topology + polycube) | result |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int a = 1; a < argc; ++a) {
    const std::string path = argv[a];
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
      const HausdorffDistance distance = hausdorff_distance(mesh, result.polycube.mesh);
      const double percent = 100 * distance.hausdorff / bounding_box(mesh.V).diagonal();
      std::printf("| %s | %d | %d | %zu (%d) | %zu | %zu | %zu | %d | %zu (%d / %d / %d) | %.2f | %.2f + %.2f | ok |\n",
                  name.c_str(), mesh.num_vertices(), result.genus, result.planes_z.size(), result.planes_inserted,
                  result.model_sliced.pieces.size(), result.polycube.corners.size(), result.polycube.faces.size(),
                  result.polycube.mesh.num_vertices(), result.repairs.size(), result.planes_inserted,
                  result.relabelled_cells, result.stacking_splits, percent,
                  std::chrono::duration<double>(t1 - t0).count(), std::chrono::duration<double>(t2 - t1).count());
    } catch (const std::exception& e) {
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::printf("| %s | | | | | | | | | | %.2f | failed: %s |\n", name.c_str(), seconds, e.what());
    }
    std::fflush(stdout);
  }
  return 0;
}
