// End-to-end: `polycube map` through the real binary: outputs, report, and clean failures.
#include "formats/image_io.h"
#include "formats/mesh_io.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace polycube {
namespace {

using test::CliRun;
using test::polycube_cli;
using test::quoted;

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(MapCli, TopologyStageWritesReportAndPieces) {
  const std::string dir = test::temp_dir("map") + "/out";  // created by the command
  const CliRun run = polycube_cli("map " + quoted(test::data_path("eight.off")) + " -o " + quoted(dir) +
                                  " --stage topology");
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.err.find("topology"), std::string::npos) << "stage progress on stderr";

  const auto report = read_json(dir + "/report.json");
  EXPECT_EQ(report.at("input").at("genus").get<int>(), 2);
  EXPECT_EQ(report.at("parameters").at("stage").get<std::string>(), "topology");
  const auto& topology = report.at("topology");
  EXPECT_EQ(topology.at("critical_points").at("saddles").get<int>(), 4);
  EXPECT_EQ(topology.at("max_piece_genus").get<int>(), 0);

  // pieces.ply is the sliced model: same genus and one face colour per piece.
  const PolygonSoup pieces = read_polygon_soup(dir + "/pieces.ply");
  int triangles = 0;
  for (const auto& piece : topology.at("pieces")) triangles += piece.at("triangles").get<int>();
  EXPECT_EQ(static_cast<int>(pieces.polygons.size()), triangles);
  EXPECT_GE(pieces.polygons.size(), report.at("input").at("faces").get<size_t>());

  const Image preview = read_image(dir + "/preview.png");
  EXPECT_GT(preview.width, preview.height) << "views side by side";
  EXPECT_GE(preview.height, 256);

  for (const auto& entry : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << "no temporary left behind";
}

TEST(MapCli, QuietRunPrintsNothing) {
  const std::string dir = test::temp_dir("map-quiet");
  const CliRun run = polycube_cli("map --quiet " + quoted(test::data_path("sphere.off")) + " -o " + quoted(dir));
  EXPECT_EQ(run.code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  EXPECT_EQ(run.out, "");
}

TEST(MapCli, BadInputFailsCleanlyAndWritesNothing) {
  const std::string dir = test::temp_dir("map-bad") + "/out";
  CliRun run = polycube_cli("map --quiet " + quoted(test::data_path("bad/open-cube.off")) + " -o " + quoted(dir));
  EXPECT_EQ(run.code, 4);
  EXPECT_EQ(test::line_count(run.err), 1) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir)) << "nothing is written for an unmappable mesh";

  run = polycube_cli("map --quiet " + quoted(test::data_path("sphere.off")) + " -o /proc/polycube-cannot-write");
  EXPECT_EQ(run.code, 5) << run.err;
  EXPECT_EQ(test::line_count(run.err), 1) << run.err;

  run = polycube_cli("map --quiet " + quoted(test::data_path("sphere.off")) + " -o " + quoted(dir) + " --dz 0");
  EXPECT_EQ(run.code, 2) << run.err;
  run = polycube_cli("map --quiet " + quoted(test::data_path("sphere.off")));
  EXPECT_EQ(run.code, 2) << "-o is required";
}

}  // namespace
}  // namespace polycube
