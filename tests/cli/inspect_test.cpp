// End-to-end: the real `polycube` binary, its output, errors and exit codes.
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <algorithm>
#include <map>

namespace polycube {
namespace {

using test::CliRun;
using test::line_count;
using test::polycube_cli;
using test::quoted;

TEST(InspectCli, JsonGenusOnEveryClosedTestMesh) {
  for (const auto& [name, genus] : test::closed_test_meshes()) {
    SCOPED_TRACE(name);
    const CliRun run = polycube_cli("inspect --json --quiet " + quoted(test::data_path(name)));
    EXPECT_EQ(run.code, 0) << run.err;
    EXPECT_EQ(run.err, "") << "--quiet prints nothing on stderr";
    const auto j = nlohmann::json::parse(run.out);
    EXPECT_EQ(j.at("genus").get<int>(), genus);
    EXPECT_EQ(j.at("euler").get<int>(), 2 - 2 * genus);
    EXPECT_EQ(j.at("components").get<int>(), 1);
    EXPECT_EQ(j.at("boundary_loops").get<int>(), 0);
    EXPECT_TRUE(j.at("valid").get<bool>());
    EXPECT_GT(j.at("vertices").get<int>(), 0);
    EXPECT_GT(j.at("faces").get<int>(), 0);
  }
}

TEST(InspectCli, ExampleMeshTextReport) {
  const CliRun run = polycube_cli("inspect " + quoted(test::example_path("rocker-arm.obj")));
  EXPECT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("genus               1"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("valid"), std::string::npos);
  EXPECT_NE(run.err.find("read"), std::string::npos) << "progress on stderr without --quiet";
}

TEST(InspectCli, EveryBadInputEndsInOneLineErrorAndItsExitCode) {
  // Expected exit code per class: 3 unreadable, 4 not mappable.
  const std::map<std::string, int> bad = {{"empty.obj", 3},           {"garbage.obj", 3},
                                          {"truncated.off", 3},       {"nan-and-bad-index.off", 3},
                                          {"open-cube.off", 4},       {"degenerate-open.off", 4},
                                          {"nonmanifold-beetle.obj", 4}, {"many-components-bones.off", 4},
                                          {"tetra-plus-triangle.off", 4}};
  size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(test::data_path("bad"))) {
    ++files;
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    ASSERT_TRUE(bad.count(name)) << "new bad file without an expected exit code";
    for (const std::string& flags : {std::string("--quiet"), std::string("--json --quiet")}) {
      const CliRun run = polycube_cli("inspect " + flags + " " + quoted(entry.path().string()));
      EXPECT_EQ(run.code, bad.at(name)) << run.err;
      EXPECT_EQ(line_count(run.err), 1) << run.err;
      EXPECT_EQ(run.err.rfind("polycube: error: ", 0), 0u) << run.err;
    }
  }
  EXPECT_EQ(files, bad.size());
}

TEST(InspectCli, InvalidMeshStillGetsAFullJsonReport) {
  const CliRun run = polycube_cli("inspect --json --quiet " + quoted(test::data_path("bad/many-components-bones.off")));
  EXPECT_EQ(run.code, 4);
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j.at("components").get<int>(), 26);
  EXPECT_FALSE(j.at("valid").get<bool>());
  EXPECT_NE(run.err.find("26 connected components"), std::string::npos) << run.err;
}

TEST(InspectCli, RepairFlagsMakeBadInputsMappable) {
  CliRun run = polycube_cli("inspect --json --quiet --fill-holes " + quoted(test::data_path("bad/open-cube.off")));
  EXPECT_EQ(run.code, 0) << run.err;
  EXPECT_EQ(nlohmann::json::parse(run.out).at("genus").get<int>(), 0);

  run = polycube_cli("inspect --json --quiet --largest-component " +
                     quoted(test::data_path("bad/many-components-bones.off")));
  EXPECT_EQ(run.code, 0) << run.err;
  EXPECT_EQ(nlohmann::json::parse(run.out).at("components").get<int>(), 1);
}

TEST(InspectCli, TopologyReportsCriticalPointsPlanesAndGenusZeroPieces) {
  const std::map<std::string, int> meshes = {{"sphere.off", 0}, {"rotor.off", 1}, {"eight.off", 2}, {"anchor.off", 4}};
  for (const auto& [name, genus] : meshes) {
    SCOPED_TRACE(name);
    const CliRun run = polycube_cli("inspect --json --quiet --topology " + quoted(test::data_path(name)));
    ASSERT_EQ(run.code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    EXPECT_EQ(j.at("critical_points").at("minima").get<int>(), 1);
    EXPECT_EQ(j.at("critical_points").at("maxima").get<int>(), 1);
    EXPECT_EQ(j.at("critical_points").at("saddles").get<int>(), 2 * genus);
    const auto& planes = j.at("cutting_planes");
    EXPECT_FALSE(planes.empty());
    EXPECT_TRUE(std::is_sorted(planes.begin(), planes.end()));
    const double zmin = j.at("bounding_box").at("min")[2], zmax = j.at("bounding_box").at("max")[2];
    for (const auto& z : planes) {
      EXPECT_GT(z.get<double>(), zmin) << "planes are in the input's coordinates";
      EXPECT_LT(z.get<double>(), zmax);
    }
    int euler_sum = 0;
    for (const auto& piece : j.at("pieces")) {
      EXPECT_EQ(piece.at("genus").get<int>(), 0);
      EXPECT_GE(piece.at("boundaries").get<int>(), 1);
      euler_sum += piece.at("euler").get<int>();
      const int below = piece.at("plane_below"), above = piece.at("plane_above");
      EXPECT_TRUE(below == -1 || above == -1 || above == below + 1) << "a piece lies between adjacent planes";
    }
    EXPECT_EQ(euler_sum, 2 - 2 * genus);
  }
}

TEST(InspectCli, UsageAndMissingFileErrors) {
  CliRun run = polycube_cli("inspect");
  EXPECT_EQ(run.code, 2);
  EXPECT_EQ(line_count(run.err), 1) << run.err;
  run = polycube_cli("inspect --no-such-option " + quoted(test::data_path("sphere.off")));
  EXPECT_EQ(run.code, 2);
  run = polycube_cli("frobnicate");
  EXPECT_EQ(run.code, 2);
  run = polycube_cli("inspect --quiet /nonexistent/mesh.obj");
  EXPECT_EQ(run.code, 3);
  EXPECT_EQ(line_count(run.err), 1) << run.err;
  run = polycube_cli("inspect /nonexistent/mesh.obj");  // progress lines, then the error last
  EXPECT_EQ(run.code, 3);
  EXPECT_NE(run.err.find("\npolycube: error: /nonexistent/mesh.obj"), std::string::npos) << run.err;
  run = polycube_cli("--help");
  EXPECT_EQ(run.code, 0);
  EXPECT_NE(run.out.find("inspect"), std::string::npos);
}

}  // namespace
}  // namespace polycube
