#include "formats/mesh_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <vector>

#include "polycube/errors.h"
#include "support/test_support.h"

namespace polycube {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> entries(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  return names;
}

// Expects soup to hold `points` points, point `at` equal to `point`, and exactly `polygons`.
void expect_soup(const PolygonSoup& soup, std::size_t points, int at, const Eigen::Vector3d& point,
                 const std::vector<std::vector<int>>& polygons, const std::string& what = "") {
  ASSERT_EQ(soup.points.size(), points) << what;
  EXPECT_EQ(soup.points[at], point) << what;
  EXPECT_EQ(soup.polygons, polygons) << what;
}

// Expects reading path to throw an InputError naming the file and containing `expected`.
void expect_input_error(const std::string& path, const std::string& expected) {
  try {
    const PolygonSoup soup = read_polygon_soup(path);
    ADD_FAILURE() << path << ": read " << soup.points.size() << " points, expected an error with '" << expected << "'";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(fs::path(path).filename().string()), std::string::npos) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << "expected '" << expected << "' in: " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
  }
}

// Values chosen to catch any loss of precision: not representable in short decimals, tiny,
// huge, subnormal, negative zero.
Eigen::MatrixX3d awkward_vertices() {
  Eigen::MatrixX3d V(8, 3);
  V << 0.1, 1.0 / 3.0, -2.0 / 7.0,                                    //
      1e-300, -1e300, 5e-324,                                         //
      -0.0, 123456789.123456789, std::nextafter(1.0, 2.0),            //
      3.141592653589793, -2.718281828459045, 1.7976931348623157e308,  //
      0.5, 0.25, 0.125,                                               //
      -1.0, 2.0, -3.0,                                                //
      std::numeric_limits<double>::min(), 6.02214076e23, -1.602e-19,  //
      42.0, -42.0, 1e-5;
  return V;
}

// Triangles, quads, a pentagon and a hexagon.
std::vector<std::vector<int>> mixed_polygons() {
  return {{0, 1, 2}, {0, 2, 3, 4}, {4, 5, 6, 7, 0}, {1, 3, 5, 7, 2, 6}, {7, 6, 5}, {3, 2, 1, 0}};
}

void expect_same(const PolygonSoup& soup, const Eigen::MatrixX3d& V, const std::vector<std::vector<int>>& polygons) {
  ASSERT_EQ(soup.points.size(), static_cast<std::size_t>(V.rows()));
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(soup.points[v][k], V(v, k)) << "vertex " << v << " coordinate " << k;
  EXPECT_EQ(soup.polygons, polygons);
}

// ---- round trips ---------------------------------------------------------------------------

class MeshRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(MeshRoundTrip, PolygonsAndCoordinatesSurviveExactly) {
  const std::string path = test::temp_dir("roundtrip") + "/mesh" + GetParam();
  write_polygon_mesh(path, awkward_vertices(), mixed_polygons());
  expect_same(read_polygon_soup(path), awkward_vertices(), mixed_polygons());
}

TEST_P(MeshRoundTrip, TriangleMeshSurvives) {
  const std::string path = test::temp_dir("roundtrip") + "/tri" + GetParam();
  TriMesh mesh;
  mesh.V = awkward_vertices();
  mesh.F.resize(3, 3);
  mesh.F << 0, 1, 2, 2, 3, 4, 7, 6, 5;
  write_mesh(path, mesh);
  expect_same(read_polygon_soup(path), mesh.V, {{0, 1, 2}, {2, 3, 4}, {7, 6, 5}});
}

TEST_P(MeshRoundTrip, ColouredMeshReadsBackItsGeometry) {
  const std::string path = test::temp_dir("roundtrip") + "/coloured" + GetParam();
  MeshColors colors;
  colors.vertex_rgb = Eigen::MatrixX3d::Random(8, 3).cwiseAbs();
  colors.vertex_rgb(0, 0) = std::nan("");  // written as 0, must not break the file
  colors.vertex_rgb(1, 1) = 7.0;           // clamped
  colors.face_rgb = Eigen::MatrixX3d::Random(6, 3).cwiseAbs();
  write_polygon_mesh(path, awkward_vertices(), mixed_polygons(), &colors);
  expect_same(read_polygon_soup(path), awkward_vertices(), mixed_polygons());
  const std::string contents = test::read_file(path);
  if (GetParam() == ".ply") {
    EXPECT_NE(contents.find("element vertex 8\nproperty double x\nproperty double y\nproperty double z\n"
                            "property uchar red\nproperty uchar green\nproperty uchar blue\n"),
              std::string::npos);
    EXPECT_NE(contents.find("property list uchar int vertex_indices\nproperty uchar red\n"), std::string::npos);
  } else if (GetParam() == ".off") {
    EXPECT_EQ(contents.rfind("COFF\n", 0), 0u);
  }
}

TEST_P(MeshRoundTrip, LargePolygonsSurvive) {
  // More than 255 corners: PLY needs a wider list length type than uchar.
  const int n = 300;
  Eigen::MatrixX3d V(n, 3);
  std::vector<int> polygon(n);
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * std::acos(-1.0) * i / n;
    V.row(i) << std::cos(angle), std::sin(angle), 0.0;
    polygon[i] = i;
  }
  const std::string path = test::temp_dir("roundtrip") + "/disk" + GetParam();
  write_polygon_mesh(path, V, {polygon});
  expect_same(read_polygon_soup(path), V, {polygon});
}

INSTANTIATE_TEST_SUITE_P(Formats, MeshRoundTrip, ::testing::Values(".obj", ".off", ".ply", ".PLY"));

TEST(MeshWrite, PlyIsBinaryLittleEndianWithDoubles) {
  const std::string path = test::temp_dir("write") + "/mesh.ply";
  Eigen::MatrixX3d V(3, 3);
  V << 1, 2, 3, 4, 5, 6, 7, 8, 9.5;
  write_polygon_mesh(path, V, {{0, 1, 2}});
  const std::string contents = test::read_file(path);
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment written by polycube\nelement vertex 3\n"
      "property double x\nproperty double y\nproperty double z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  ASSERT_EQ(contents.substr(0, header.size()), header);
  ASSERT_EQ(contents.size(), header.size() + 9 * 8 + 1 + 3 * 4);
  const unsigned char last_double[8] = {0, 0, 0, 0, 0, 0, 0x23, 0x40};  // 9.5, least significant byte first
  EXPECT_EQ(std::memcmp(contents.data() + header.size() + 8 * 8, last_double, 8), 0);
}

TEST(MeshWrite, UnsupportedExtensionWritesNothing) {
  const std::string dir = test::temp_dir("write");
  EXPECT_THROW(write_polygon_mesh(dir + "/mesh.stl", awkward_vertices(), mixed_polygons()), OutputError);
  EXPECT_THROW(write_polygon_mesh(dir + "/mesh", awkward_vertices(), mixed_polygons()), OutputError);
  EXPECT_TRUE(entries(dir).empty());
}

TEST(MeshWrite, InconsistentInputIsAnOutputErrorAndWritesNothing) {
  const std::string dir = test::temp_dir("write");
  const std::string path = dir + "/mesh.ply";
  EXPECT_THROW(write_polygon_mesh(path, awkward_vertices(), {{0, 1, 8}}), OutputError);
  EXPECT_THROW(write_polygon_mesh(path, awkward_vertices(), {{0, -1, 2}}), OutputError);
  EXPECT_THROW(write_polygon_mesh(path, awkward_vertices(), {{0, 1}}), OutputError);
  MeshColors colors;
  colors.face_rgb = Eigen::MatrixX3d::Zero(5, 3);
  EXPECT_THROW(write_polygon_mesh(path, awkward_vertices(), mixed_polygons(), &colors), OutputError);
  colors.face_rgb.resize(0, 3);
  colors.vertex_rgb = Eigen::MatrixX3d::Zero(3, 3);
  EXPECT_THROW(write_polygon_mesh(path, awkward_vertices(), mixed_polygons(), &colors), OutputError);
  EXPECT_TRUE(entries(dir).empty());
}

TEST(MeshWrite, MissingDirectoryIsAnOutputError) {
  const std::string path = test::temp_dir("write") + "/missing/mesh.obj";
  try {
    write_polygon_mesh(path, awkward_vertices(), mixed_polygons());
    ADD_FAILURE() << "no error";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

// ---- PLY and STL written by other tools ----------------------------------------------------

TEST(PlyRead, AsciiWithColoursAndExtraProperties) {
  const std::string path = test::write_file(test::temp_dir("ply") + "/ascii.ply",
                               "ply\n"
                               "format ascii 1.0\n"
                               "comment written by hand\n"
                               "obj_info nothing\n"
                               "element vertex 4\n"
                               "property float x\n"
                               "property float y\n"
                               "property double z\n"
                               "property float nx\n"
                               "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                               "element face 2\n"
                               "property list uchar int vertex_indices\n"
                               "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                               "element edge 1\n"
                               "property int vertex1\nproperty int vertex2\n"
                               "end_header\n"
                               "0 0 0 1 255 0 0\n"
                               "1 0 0 1 0 255 0\n"
                               "0 1 0 1 0 0 255\n"
                               "1.5 1 -0.25 1 10 20 30\n"
                               "3 0 1 2 255 255 255\n"
                               "4 0 1 3 2 0 0 0\n"
                               "0 1\n");
  expect_soup(read_polygon_soup(path), 4, 3, Eigen::Vector3d(1.5, 1, -0.25), {{0, 1, 2}, {0, 1, 3, 2}});
}

// Appends value's bytes, most significant first.
template <typename T>
void append_big_endian(std::string& out, T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  const std::uint16_t probe = 1;
  const bool little_host = *reinterpret_cast<const unsigned char*>(&probe) == 1;
  for (std::size_t i = 0; i < sizeof(T); ++i) out += static_cast<char>(bytes[little_host ? sizeof(T) - 1 - i : i]);
}

TEST(PlyRead, BinaryBigEndianWithVertexIndex) {
  std::string contents =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar uint vertex_index\nend_header\n";
  for (float value : {1.5f, -2.0f, 3.25f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f}) append_big_endian(contents, value);
  contents += static_cast<char>(3);
  for (std::uint32_t index : {2u, 0u, 1u}) append_big_endian(contents, index);
  expect_soup(read_polygon_soup(test::write_file(test::temp_dir("ply") + "/big.ply", contents)), 3, 0, Eigen::Vector3d(1.5, -2.0, 3.25),
              {{2, 0, 1}});
}

// A binary STL of the given triangles (9 floats each), with the given text at the start of its
// 80-byte header.
std::string binary_stl(const std::vector<std::array<float, 9>>& triangles,
                       const std::string& header_text = "binary STL written by a test") {
  std::string out = header_text;
  out.resize(80, ' ');
  const auto append_le = [&out](auto value) {
    unsigned char bytes[sizeof value];
    std::memcpy(bytes, &value, sizeof value);
    const std::uint16_t probe = 1;
    const bool little_host = *reinterpret_cast<const unsigned char*>(&probe) == 1;
    for (std::size_t i = 0; i < sizeof value; ++i)
      out += static_cast<char>(bytes[little_host ? i : sizeof value - 1 - i]);
  };
  append_le(static_cast<std::uint32_t>(triangles.size()));
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) append_le(0.0f);  // normal, unused
    for (float value : t) append_le(value);
    append_le(std::uint16_t{0});
  }
  return out;
}

// A tetrahedron as STL stores it: 12 corners, 4 distinct positions.
std::vector<std::array<float, 9>> tetrahedron_triangles() {
  return {{0, 0, 0, 0, 1, 0, 1, 0, 0},
          {0, 0, 0, 1, 0, 0, 0, 0, 1},
          {0, 0, 0, 0, 0, 1, 0, 1, 0},
          {1, 0, 0, 0, 1, 0, 0, 0, 1}};
}

void expect_indexed_tetrahedron(const PolygonSoup& soup) {
  ASSERT_EQ(soup.points.size(), 4u) << "corners at equal positions must be merged";
  ASSERT_EQ(soup.polygons.size(), 4u);
  const auto triangles = tetrahedron_triangles();
  for (std::size_t f = 0; f < 4; ++f)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(soup.points[soup.polygons[f][c]][k], triangles[f][3 * c + k]) << "face " << f << " corner " << c;
}

TEST(StlRead, BinaryIsIndexed) {
  const std::string dir = test::temp_dir("stl");
  expect_indexed_tetrahedron(read_polygon_soup(test::write_file(dir + "/tetra.stl", binary_stl(tetrahedron_triangles()))));
}

TEST(StlRead, BinaryWhoseHeaderStartsWithSolid) {
  // Some CAD exporters write "solid" into the binary header; the file size tells it apart.
  const std::string dir = test::temp_dir("stl");
  expect_indexed_tetrahedron(
      read_polygon_soup(test::write_file(dir + "/tetra.STL", binary_stl(tetrahedron_triangles(), "solid exported by CAD"))));
}

TEST(StlRead, AsciiIsIndexed) {
  std::string text = "solid tetra\n";
  for (const auto& t : tetrahedron_triangles()) {
    text += "  facet normal 0 0 0\n    outer loop\n";
    for (int c = 0; c < 3; ++c)
      text += "      vertex " + std::to_string(t[3 * c]) + " " + std::to_string(t[3 * c + 1]) + " " +
              std::to_string(t[3 * c + 2]) + "\r\n";
    text += "    endloop\n  endfacet\n";
  }
  text += "endsolid tetra\n";
  expect_indexed_tetrahedron(read_polygon_soup(test::write_file(test::temp_dir("stl") + "/tetra.stl", text)));
}

// The ASCII tetrahedron with `after_solid` between "solid" and its name.
std::string ascii_tetrahedron(const std::string& after_solid) {
  std::string text = "solid" + after_solid + "tetra\n";
  for (const auto& t : tetrahedron_triangles()) {
    text += "  facet normal 0 0 0\n    outer loop\n";
    for (int c = 0; c < 3; ++c)
      text += "      vertex " + std::to_string(t[3 * c]) + " " + std::to_string(t[3 * c + 1]) + " " + std::to_string(t[3 * c + 2]) + "\n";
    text += "    endloop\n  endfacet\n";
  }
  return text + "endsolid tetra\n";
}

// "solid" then a tab (assimp's sphereWithHole.stl): text, not a binary file announcing
// 1 953 654 134 triangles (the bytes "vert" read as a count).
TEST(StlRead, AsciiWithATabAfterSolid) {
  const std::string dir = test::temp_dir("stl");
  expect_indexed_tetrahedron(read_polygon_soup(test::write_file(dir + "/tab.stl", ascii_tetrahedron("\t"))));
  expect_indexed_tetrahedron(read_polygon_soup(test::write_file(dir + "/tabs.stl", "\t" + ascii_tetrahedron("\t\t"))));
}

TEST(StlRead, AsciiErrorsHaveLineNumbers) {
  const std::string dir = test::temp_dir("stl");
  const std::string head = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n";
  expect_input_error(test::write_file(dir + "/a.stl", head + "vertex 0 1\nendloop\nendfacet\nendsolid\n"),
                     "line 6: expected 3 coordinates, got 2");
  expect_input_error(test::write_file(dir + "/b.stl", head + "vertex 0 nan 0\nendloop\nendfacet\nendsolid\n"),
                     "line 6: non-finite coordinate (nan)");
  expect_input_error(test::write_file(dir + "/c.stl", head + "vertex 0 1 0\nvertex 1 1 0\nendloop\nendfacet\nendsolid\n"),
                     "line 9: facet has 4 vertices");
  expect_input_error(test::write_file(dir + "/d.stl", head + "vertex 0 1 0\nendloop\nendfacet\n"), "truncated");
}

TEST(StlRead, NonFiniteBinaryCoordinateIsAnError) {
  auto triangles = tetrahedron_triangles();
  triangles[2][4] = std::numeric_limits<float>::quiet_NaN();
  expect_input_error(test::write_file(test::temp_dir("stl") + "/nan.stl", binary_stl(triangles)), "triangle 2 has a non-finite");
}

// ---- truncated and corrupt binary files ----------------------------------------------------

TEST(BinaryRead, TruncatedPlyIsAnInputError) {
  const std::string dir = test::temp_dir("truncated");
  const std::string path = dir + "/mesh.ply";
  write_polygon_mesh(path, awkward_vertices(), mixed_polygons());
  const std::string whole = test::read_file(path);
  const std::size_t header = whole.find("end_header\n") + 11;
  for (std::size_t cut : {std::size_t{1}, std::size_t{5}, whole.size() - header - 8 * 24, whole.size() - header})
    expect_input_error(test::write_file(dir + "/cut.ply", whole.substr(0, whole.size() - cut)), "truncated: header announces");
  expect_input_error(test::write_file(dir + "/cut.ply", whole.substr(0, whole.size() - 1)),
                     "header announces 8 vertices and 6 faces, file ends after 8 vertices and 5 faces");
  expect_input_error(test::write_file(dir + "/cut.ply", whole.substr(0, header - 5)), "no end_header");
}

TEST(BinaryRead, TruncatedStlIsAnInputError) {
  const std::string dir = test::temp_dir("truncated");
  const std::string whole = binary_stl(tetrahedron_triangles());
  expect_input_error(test::write_file(dir + "/cut.stl", whole.substr(0, whole.size() - 1)),
                     "truncated: header announces 4 triangles (284 bytes), file has 283 bytes");
  expect_input_error(test::write_file(dir + "/cut.stl", whole.substr(0, 60)), "truncated");
}

TEST(BinaryRead, CorruptPlyBodyIsAnInputError) {
  // A list length of 0xFFFFFFFF must be reported, not allocated.
  std::string contents =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";
  contents += std::string(36, '\0');
  contents += std::string(4, '\xFF') + std::string(12, '\0');
  expect_input_error(test::write_file(test::temp_dir("corrupt") + "/huge.ply", contents), "truncated");
}

TEST(BinaryRead, UnsupportedPlyHeadersAreInputErrors) {
  const std::string dir = test::temp_dir("corrupt");
  const std::string vertex = "ply\nformat ascii 1.0\nelement vertex 3\n";
  const std::string face =
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n0 0 1\n0 1 0\n3 0 1 2\n";
  // CGAL's reader would dereference a null pointer on integer coordinates.
  expect_input_error(test::write_file(dir + "/int.ply", vertex + "property int x\nproperty int y\nproperty int z\n" + face),
                     "vertex property 'x' has type 'int'");
  expect_input_error(test::write_file(dir + "/early.ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n"),
                     "line 3: property before any element");
  expect_input_error(test::write_file(dir + "/noz.ply", vertex + "property float x\nproperty float y\n" + face), "no property 'z'");
  expect_input_error(test::write_file(dir + "/type.ply", vertex + "property float x\nproperty float y\nproperty real z\n" + face),
                     "line 6: unknown property type 'real'");
  expect_input_error(test::write_file(dir + "/short.ply", vertex + "property float x\nproperty float y\nproperty float z\n" +
                                                 "element face 1\nproperty list uchar short vertex_indices\n"
                                                 "end_header\n0 0 0\n0 0 1\n0 1 0\n3 0 1 2\n"),
                     "supported: int, uint");
  expect_input_error(test::write_file(dir + "/empty-element.ply", "ply\nformat ascii 1.0\nelement junk 999999999999\nend_header\n"),
                     "no properties");
  expect_input_error(test::write_file(dir + "/notply.ply", "PLY\n"), "not a PLY file");
  expect_input_error(test::write_file(dir + "/points.ply", vertex + "property float x\nproperty float y\nproperty float z\n"
                                                       "end_header\n0 0 0\n0 0 1\n0 1 0\n"),
                     "no face element");
}

// Header lines the format does not define are free text, as for CGAL's reader: Blender 2.4x
// wrote "Created by Blender3D ..." without a comment keyword (assimp's Wuson.ply).
TEST(PlyRead, UndefinedHeaderLinesAreFreeText) {
  const std::string path = test::write_file(test::temp_dir("ply") + "/blender.ply",
                                            "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org, source file: \n"
                                            "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                            "element face 1\nproperty list uchar uint vertex_indices\nend_header\n"
                                            "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  expect_soup(read_polygon_soup(path), 3, 1, Eigen::Vector3d(1, 0, 0), {{0, 1, 2}});
}

// A UTF-8 byte-order mark before a text format is dropped (Windows editors write one); UTF-16
// text is refused by name, not as "not an OBJ file" with garbled characters.
TEST(TextRead, ByteOrderMarks) {
  const std::string dir = test::temp_dir("bom");
  const std::string bom = "\xEF\xBB\xBF";
  const std::string off = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                          "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"a.off", off}, {"a.obj", obj}, {"a.ply", ply}}) {
    expect_soup(read_polygon_soup(test::write_file(dir + "/" + name, bom + text)), 3, 2, Eigen::Vector3d(0, 1, 0), {{0, 1, 2}}, name);
  }
  // "OFF\n" in UTF-16, little- and big-endian.
  expect_input_error(test::write_file(dir + "/le.off", std::string("\xFF\xFEO\0F\0F\0\n\0", 10)), "UTF-16 text (byte-order mark FF FE)");
  expect_input_error(test::write_file(dir + "/be.obj", std::string("\xFE\xFF\0v\0 \0" "0", 8)), "UTF-16 text (byte-order mark FE FF)");
  expect_input_error(test::write_file(dir + "/only.off", bom), "file is empty");
}

TEST(BinaryRead, AsciiPlyErrorsHaveLineNumbers) {
  const std::string dir = test::temp_dir("corrupt");
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  expect_input_error(test::write_file(dir + "/nan.ply", header + "0 0 0\n0 nan 1\n0 1 0\n3 0 1 2\n"),
                     "line 11: vertex 1 has a non-finite value (nan)");
  expect_input_error(test::write_file(dir + "/word.ply", header + "0 0 0\n0 0 1\n0 x 0\n3 0 1 2\n"),
                     "line 12: vertex 2: 'x' is not");
  expect_input_error(test::write_file(dir + "/float-index.ply", header + "0 0 0\n0 0 1\n0 1 0\n3 0 1.5 2\n"),
                     "line 13: face 0: property 'vertex_indices' needs an integer of type int, got '1.5'");
  expect_input_error(test::write_file(dir + "/long-list.ply", header + "0 0 0\n0 0 1\n0 1 0\n300 0 1 2\n"),
                     "needs an integer of type uchar, got '300'");
  expect_input_error(test::write_file(dir + "/short.ply", header + "0 0 0\n0 0 1\n0 1 0\n3 0 1\n"),
                     "truncated: header announces 3 vertices and 1 faces, file ends after 3 vertices and 0 faces");
  expect_input_error(test::write_file(dir + "/index.ply", header + "0 0 0\n0 0 1\n0 1 0\n3 0 1 3\n"),
                     "face 0 refers to vertex 3, but the file has 3 vertices");
  expect_input_error(test::write_file(dir + "/negative.ply", header + "0 0 0\n0 0 1\n0 1 0\n3 0 -1 2\n"), "refers to vertex -1");
}

// Every prefix and many random corruptions of a valid file either read or throw InputError:
// nothing crashes, hangs or throws anything else.
TEST(BinaryRead, PrefixesAndCorruptionsNeverCrash) {
  const std::string dir = test::temp_dir("fuzz");
  std::vector<std::pair<std::string, std::string>> files;  // extension, contents
  for (const char* extension : {".obj", ".off", ".ply"}) {
    write_polygon_mesh(dir + "/mesh" + extension, awkward_vertices(), mixed_polygons());
    files.emplace_back(extension, test::read_file(dir + "/mesh" + extension));
  }
  files.emplace_back(".stl", binary_stl(tetrahedron_triangles()));
  std::mt19937 random(12345);
  for (const auto& [extension, whole] : files) {
    const std::string path = dir + "/fuzz" + extension;
    std::vector<std::string> variants;
    for (std::size_t length = 0; length < whole.size(); length += 3) variants.push_back(whole.substr(0, length));
    for (int i = 0; i < 300; ++i) {
      std::string corrupt = whole;
      for (int flips = 0; flips < 1 + i % 4; ++flips)
        corrupt[random() % corrupt.size()] = static_cast<char>(random() % 256);
      variants.push_back(corrupt);
    }
    for (const std::string& contents : variants) {
      test::write_file(path, contents);
      try {
        read_polygon_soup(path);
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      }
    }
  }
}

// ---- OBJ -----------------------------------------------------------------------------------

TEST(ObjRead, StatementsAndIndexForms) {
  const std::string path = test::write_file(test::temp_dir("obj") + "/forms.obj",
                               "# exported\n"
                               "mtllib forms.mtl\n"
                               "o thing\n"
                               "v 0 0 0\n"
                               "v +1 0 0 1.0\n"        // weight
                               "v 1 1 0 0.5 0.25 1\n"  // colour extension
                               "v 0 1 0\t# trailing comment\r\n"
                               "vt 0 0\n"
                               "vn 0 0 1\n"
                               "g group\n"
                               "usemtl red\n"
                               "s off\n"
                               "f 1/1/1 2/1/1 3/1/1 4/1/1\n"
                               "f -4//1 -3//1 -1//1\n"  // relative
                               "f 1/1 3/1 4/1\n"
                               "l 1 2\n"
                               "vendor_statement 1 2 3\n"  // unknown: tolerated
                               "f 5 6 7\n"                 // vertices defined below
                               "v 2 0 0\nv 2 1 0\nv 2 1 1\n");
  const PolygonSoup soup = read_polygon_soup(path);
  ASSERT_EQ(soup.points.size(), 7u);
  EXPECT_EQ(soup.points[1], Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(soup.points[2], Eigen::Vector3d(1, 1, 0));
  EXPECT_EQ(soup.polygons, (std::vector<std::vector<int>>{{0, 1, 2, 3}, {0, 1, 3}, {0, 2, 3}, {4, 5, 6}}));
}

TEST(ObjRead, ErrorsNameTheLineAndTheProblem) {
  const std::string dir = test::temp_dir("obj");
  const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"v 1 2\nf 1 2 3\n", "line 1: expected 3 coordinates, got 2"},
      {"v 1 2 x\n", "line 1: 'x' is not a number"},
      {"v 0 0 0\nv nan 0 0\n", "line 2: vertex 2 has a non-finite coordinate (nan)"},
      {"v 0 0 1e999\n", "line 1: vertex 1 has a non-finite coordinate (1e999)"},
      {triangle + "f 1 2 7\n", "line 4: face refers to vertex 7, but the file has 3 vertices"},
      {triangle + "f 1 2\n", "line 4: face has 2 vertices, at least 3 needed"},
      {triangle + "f 0 1 2\n", "line 4: vertex index 0 is invalid"},
      {triangle + "f -1 -2 -4\n", "line 4: relative index -4 reaches before the first vertex"},
      {triangle + "f 1/2 x/1 3\n", "line 4: 'x/1' is not a vertex reference"},
      {"# nothing but a comment\n", "no vertices"},
      {triangle, "no faces"},
      {" \n\t\n", "file is empty"},
      {"hello world\nfoo\n" + triangle + "f 1 2 3\nbar\nbaz\nqux\nquux\nx\n", "not an OBJ file: 7 of 11"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i)
    expect_input_error(test::write_file(dir + "/case" + std::to_string(i) + ".obj", cases[i].first), cases[i].second);
}

TEST(ObjRead, RockerArm) {
  const PolygonSoup soup = read_polygon_soup(test::example_path("rocker-arm.obj"));
  EXPECT_EQ(soup.points.size(), 10044u);
  EXPECT_EQ(soup.polygons.size(), 20088u);
  for (const auto& polygon : soup.polygons) ASSERT_EQ(polygon.size(), 3u);
}

// ---- OFF -----------------------------------------------------------------------------------

TEST(OffRead, VariantsCommentsAndColours) {
  const std::string dir = test::temp_dir("off");
  const std::vector<std::vector<int>> triangle = {{0, 1, 2}};
  // Counts on the header line, colours on vertices and faces, comments, CRLF, blank lines.
  PolygonSoup soup = read_polygon_soup(test::write_file(dir + "/coff.off",
                                           "# leading comment\r\n"
                                           "COFF 3 1 0  # counts here\r\n"
                                           "\r\n"
                                           "0 0 0 255 0 0 255\r\n"
                                           "1 0 0 0 255 0 255\r\n"
                                           "# a comment between vertices\n"
                                           "0 1 0.5 0 0 255 255\r\n"
                                           "3 0 1 2 10 20 30\r\n"));
  ASSERT_EQ(soup.points.size(), 3u);
  EXPECT_EQ(soup.points[2], Eigen::Vector3d(0, 1, 0.5));
  EXPECT_EQ(soup.polygons, triangle);
  soup = read_polygon_soup(test::write_file(dir + "/noff.OFF", "NOFF\n3 1\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n"));
  EXPECT_EQ(soup.polygons, triangle);
}

TEST(OffRead, ErrorsNameTheLineAndTheProblem) {
  const std::string dir = test::temp_dir("off");
  const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"OFF\n3 1 0\n0 0 0\n1 0 0\n", "truncated: header announces 3 vertices and 1 faces, file ends after 2 vertices"},
      {"OFF\n3 1 0\n" + vertices, "file ends after 3 vertices and 0 faces"},
      {"OFF\n3 1 0\n0 0\n", "line 3: expected 3 coordinates, got 2"},
      {"OFF\n3 1 0\n0 0 inf\n", "line 3: vertex 0 has a non-finite coordinate (inf)"},
      {"OFF\n3 1 0\n0 0 zero\n", "line 3: 'zero' is not a number"},
      {"OFF\n3 1 0\n" + vertices + "3 0 1 3\n", "line 6: face 0 refers to vertex 3, but the file has 3 vertices"},
      {"OFF\n3 1 0\n" + vertices + "3 0 -1 2\n", "face 0 refers to vertex -1"},
      {"OFF\n3 1 0\n" + vertices + "2 0 1\n", "line 6: face 0 has 2 vertices, at least 3 needed"},
      {"OFF\n3 1 0\n" + vertices + "4 0 1 2\n", "face 0 announces 4 vertices, but the line has 3 values"},
      {"OFF\nthree 1 0\n", "line 2: expected the counts"},
      {"OFF\n", "truncated: no vertex and face counts"},
      {"ply\n3 1 0\n", "line 1: expected the header 'OFF', got 'ply'"},
      {"4OFF\n3 1 0\n", "unsupported OFF variant '4OFF'"},
      {"OFF BINARY\n", "binary OFF is not supported"},
      {"# only comments\n", "no 'OFF' header (only comments)"},
      {"\n  \n", "file is empty"},
      {"OFF\n0 0 0\n", "no vertices"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i)
    expect_input_error(test::write_file(dir + "/case" + std::to_string(i) + ".off", cases[i].first), cases[i].second);
}

// ---- the test data -------------------------------------------------------------------------

TEST(DataFiles, UnparsableBadFilesAreInputErrors) {
  expect_input_error(test::data_path("bad/empty.obj"), "file is empty");
  expect_input_error(test::data_path("bad/garbage.obj"), "not an OBJ file");
  expect_input_error(test::data_path("bad/truncated.off"),
                     "truncated: header announces 3 vertices and 1 faces, file ends after 2 vertices");
  expect_input_error(test::data_path("bad/nan-and-bad-index.off"),
                     "line 6: vertex 3 has a non-finite coordinate (nan)");
  // With the NaN fixed, the bad index is reported.
  std::string fixed = test::read_file(test::data_path("bad/nan-and-bad-index.off"));
  fixed.replace(fixed.find("nan"), 3, "0");
  expect_input_error(test::write_file(test::temp_dir("data") + "/bad-index.off", fixed),
                     "line 8: face 1 refers to vertex 7, but the file has 4 vertices");
}

TEST(DataFiles, MeshLevelProblemsStillRead) {
  // These are parsable; their problems (holes, non-manifold parts, components) are for validation.
  for (const char* name : {"bad/degenerate-open.off", "bad/many-components-bones.off", "bad/nonmanifold-beetle.obj",
                           "bad/open-cube.off", "bad/tetra-plus-triangle.off"}) {
    SCOPED_TRACE(name);
    const PolygonSoup soup = read_polygon_soup(test::data_path(name));
    EXPECT_GT(soup.points.size(), 0u);
    EXPECT_GT(soup.polygons.size(), 0u);
  }
}

TEST(DataFiles, AllTestMeshesRead) {
  int files = 0;
  for (const auto& entry : fs::directory_iterator(test::data_path(""))) {
    if (entry.path().extension() != ".off") continue;
    SCOPED_TRACE(entry.path().string());
    const PolygonSoup soup = read_polygon_soup(entry.path().string());
    EXPECT_GT(soup.polygons.size(), 0u);
    ++files;
  }
  EXPECT_GE(files, 10);
  for (const char* name : {"torus_quad.off", "double-torus-example.off"}) {
    const PolygonSoup soup = read_polygon_soup(test::data_path(name));
    std::size_t largest = 0;
    for (const auto& polygon : soup.polygons) largest = std::max(largest, polygon.size());
    EXPECT_GT(largest, 3u) << name << " has polygons, which must stay polygons";
  }
}

TEST(DataFiles, MissingDirectoryAndUnsupported) {
  expect_input_error(test::data_path("no-such-mesh.obj"), "no such file");
  const std::string dir = test::temp_dir("data");
  fs::create_directory(dir + "/folder.off");
  expect_input_error(dir + "/folder.off", "is a directory");
  expect_input_error(test::write_file(dir + "/points.xyz", "0 0 0\n"), "unsupported format '.xyz' (supported: .obj .off .ply .stl)");
  expect_input_error(test::write_file(dir + "/noextension", "OFF\n"), "unsupported format ''");
  expect_input_error(test::write_file(dir + "/empty.stl", ""), "file is empty");
  expect_input_error(test::write_file(dir + "/empty.ply", ""), "file is empty");
}

TEST(DataFiles, ExtensionIsCaseInsensitive) {
  const std::string dir = test::temp_dir("data");
  fs::copy_file(test::data_path("sphere.off"), dir + "/Sphere.OFF");
  EXPECT_EQ(read_polygon_soup(dir + "/Sphere.OFF").polygons, read_polygon_soup(test::data_path("sphere.off")).polygons);
}

// ---- speed ---------------------------------------------------------------------------------

TEST(Speed, HundredThousandTrianglesReadWellUnderASecond) {
  // A 230 x 230 grid: 53361 vertices, 105800 triangles, with non-trivial coordinates.
  const int n = 230;
  Eigen::MatrixX3d V((n + 1) * (n + 1), 3);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) V.row(i * (n + 1) + j) << i / 7.0, j / 3.0, std::sin(i * 0.1) * std::cos(j * 0.1);
  std::vector<std::vector<int>> triangles;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j, b = a + 1, c = a + n + 1, d = c + 1;
      triangles.push_back({a, b, d});
      triangles.push_back({a, d, c});
    }
  const std::string dir = test::temp_dir("speed");
  for (const char* extension : {".obj", ".off", ".ply"}) {
    const std::string path = dir + "/grid" + extension;
    write_polygon_mesh(path, V, triangles);
    const auto start = std::chrono::steady_clock::now();
    const PolygonSoup soup = read_polygon_soup(path);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(soup.polygons.size(), triangles.size());
    EXPECT_LT(seconds, 0.5) << extension;
    RecordProperty(std::string("read_seconds") + extension, std::to_string(seconds));
  }
}

}  // namespace
}  // namespace polycube
