// read_polygon_soup and the writers: dispatch on the extension, file access, checks shared by
// every format. The formats themselves are in mesh_io_<format>.cpp.
#include "formats/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "formats/atomic_file.h"
#include "formats/mesh_io_internal.h"
#include "polycube/errors.h"

namespace polycube {

using namespace mesh_io_detail;

namespace {

namespace fs = std::filesystem;

std::string lowercase_extension(const std::string& path) {
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// The whole file as bytes. Reading it in one go keeps the parsers simple and fast.
std::string load_file(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) fail(path, "no such file");
  if (fs::is_directory(status)) fail(path, "is a directory, not a file");
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) fail(path, std::string("cannot open: ") + std::strerror(errno));
  std::string bytes;
  char buffer[1 << 16];
  std::size_t count = 0;
  while ((count = std::fread(buffer, 1, sizeof buffer, file.get())) > 0) bytes.append(buffer, count);
  if (std::ferror(file.get())) fail(path, std::string("read error: ") + std::strerror(errno));
  if (bytes.empty()) fail(path, "file is empty");
  return bytes;
}

// The guarantees of read_polygon_soup, for every format (the text readers already report most of
// these with line numbers; PLY and STL come through CGAL).
void validate(const std::string& path, const PolygonSoup& soup) {
  if (soup.points.empty()) fail(path, "no vertices");
  if (soup.polygons.empty()) fail(path, "no faces");
  for (std::size_t v = 0; v < soup.points.size(); ++v)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(soup.points[v][k]))
        fail(path, "vertex " + std::to_string(v) + " has a non-finite coordinate (" +
                       std::to_string(soup.points[v][k]) + ")");
  const long long num_vertices = static_cast<long long>(soup.points.size());
  for (std::size_t f = 0; f < soup.polygons.size(); ++f) {
    const std::vector<int>& polygon = soup.polygons[f];
    if (polygon.size() < 3)
      fail(path,
           "face " + std::to_string(f) + " has " + std::to_string(polygon.size()) + " vertices, at least 3 needed");
    for (int index : polygon)
      if (index < 0 || index >= num_vertices)
        fail(path, "face " + std::to_string(f) + " refers to vertex " + std::to_string(index) + ", but the file has " +
                       std::to_string(num_vertices) + " vertices");
  }
}

// Caller errors are reported as OutputError: the requested file cannot be written from them.
void check_writable_mesh(const std::string& path, const Eigen::MatrixX3d& V,
                         const std::vector<std::vector<int>>& polygons, const MeshColors& colors) {
  const auto reject = [&path](const std::string& problem) {
    throw OutputError("cannot write " + path + ": " + problem);
  };
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    if (polygons[f].size() < 3)
      reject("polygon " + std::to_string(f) + " has " + std::to_string(polygons[f].size()) +
             " vertices, at least 3 needed");
    for (int index : polygons[f])
      if (index < 0 || index >= V.rows())
        reject("polygon " + std::to_string(f) + " refers to vertex " + std::to_string(index) + ", but the mesh has " +
               std::to_string(V.rows()) + " vertices");
  }
  const auto faces = static_cast<Eigen::Index>(polygons.size());
  if (colors.face_rgb.rows() != 0 && colors.face_rgb.rows() != faces)
    reject("face_rgb has " + std::to_string(colors.face_rgb.rows()) + " rows for " + std::to_string(faces) + " faces");
  if (colors.vertex_rgb.rows() != 0 && colors.vertex_rgb.rows() != V.rows())
    reject("vertex_rgb has " + std::to_string(colors.vertex_rgb.rows()) + " rows for " + std::to_string(V.rows()) +
           " vertices");
}

}  // namespace

PolygonSoup read_polygon_soup(const std::string& path) {
  const std::string extension = lowercase_extension(path);
  using Reader = PolygonSoup (*)(const std::string&, const std::string&);
  Reader reader = nullptr;
  if (extension == ".obj")
    reader = &read_obj;
  else if (extension == ".off")
    reader = &read_off;
  else if (extension == ".ply")
    reader = &read_ply;
  else if (extension == ".stl")
    reader = &read_stl;
  else
    fail(path, "unsupported format '" + extension + "' (supported: .obj .off .ply .stl)");

  std::string bytes = load_file(path);
  // A byte-order mark at the start of a text format: UTF-8's is dropped (Windows editors write
  // it), UTF-16 text is refused by name. (A binary STL's header is free-form: its bytes are left.)
  if (extension != ".stl") {
    if (bytes.rfind("\xFF\xFE", 0) == 0 || bytes.rfind("\xFE\xFF", 0) == 0)
      fail(path, "UTF-16 text (byte-order mark " + std::string(bytes[0] == '\xFF' ? "FF FE" : "FE FF") +
                     "): save the file as ASCII or UTF-8");
    if (bytes.rfind("\xEF\xBB\xBF", 0) == 0) bytes.erase(0, 3);
  }
  PolygonSoup soup = reader(path, bytes);
  validate(path, soup);
  return soup;
}

void write_mesh(const std::string& path, const TriMesh& mesh) {
  std::vector<std::vector<int>> polygons(static_cast<std::size_t>(mesh.F.rows()));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    polygons[static_cast<std::size_t>(f)] = {mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)};
  write_polygon_mesh(path, mesh.V, polygons);
}

void write_polygon_mesh(const std::string& path, const Eigen::MatrixX3d& V,
                        const std::vector<std::vector<int>>& polygons, const MeshColors* colors) {
  const MeshColors no_colors;
  const MeshColors& used = colors ? *colors : no_colors;
  const std::string extension = lowercase_extension(path);
  using Writer =
      void (*)(std::string&, const Eigen::MatrixX3d&, const std::vector<std::vector<int>>&, const MeshColors&);
  Writer writer = nullptr;
  if (extension == ".obj")
    writer = &write_obj;
  else if (extension == ".off")
    writer = &write_off;
  else if (extension == ".ply")
    writer = &write_ply;
  else
    throw OutputError("cannot write " + path + ": unsupported format '" + extension + "' (supported: .obj .off .ply)");
  check_writable_mesh(path, V, polygons, used);

  // The file is built in memory and written in one call: much faster than formatted stream output.
  std::string contents;
  writer(contents, V, polygons, used);
  write_text_atomically(path, [&contents](std::ostream& out) {
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
  });
}

}  // namespace polycube
