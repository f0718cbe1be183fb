// Geomview OFF: a strict, line-based reader (one vertex or face per line, as every exporter
// writes them) and a writer.
#include <algorithm>
#include <cmath>

#include "formats/mesh_io_internal.h"

namespace polycube::mesh_io_detail {

namespace {

// "OFF" with optional ST (texture), C (colour) and N (normal) prefixes, which only add values
// after the coordinates. 4OFF (homogeneous) and nOFF (other dimensions) change the vertex layout
// and are reported as unsupported.
enum class OffKeyword { plain, unsupported, not_off };

OffKeyword classify_keyword(std::string_view token) {
  if (token.size() < 3 || token.substr(token.size() - 3) != "OFF") return OffKeyword::not_off;
  std::string_view prefix = token.substr(0, token.size() - 3);
  if (prefix.substr(0, 2) == "ST") prefix.remove_prefix(2);
  for (char c : prefix) {
    if (c == '4' || c == 'n') return OffKeyword::unsupported;
    if (c != 'C' && c != 'N') return OffKeyword::not_off;
  }
  return OffKeyword::plain;
}

class OffReader {
 public:
  OffReader(const std::string& path, std::string_view text) : path_(path), text_(text), lines_(text) {}

  PolygonSoup read() {
    read_header();
    // Do not trust the counts for the reservation: a corrupt header must not allocate gigabytes.
    const std::size_t plausible = text_.size() / 4 + 1;
    soup_.points.reserve(std::min<std::size_t>(num_vertices_, plausible));
    soup_.polygons.reserve(std::min<std::size_t>(num_faces_, plausible));
    for (int v = 0; v < num_vertices_; ++v) read_vertex(v);
    for (int f = 0; f < num_faces_; ++f) read_face(f);
    // Anything after the announced faces (edges, trailing comments) is ignored, as in Geomview.
    return std::move(soup_);
  }

 private:
  // Next line holding something other than whitespace and comments, split into tokens_.
  bool next_tokens() {
    std::string_view line;
    while (lines_.next(line)) {
      split_tokens(strip_comment(line), tokens_);
      if (!tokens_.empty()) return true;
    }
    return false;
  }

  void read_header() {
    if (!next_tokens()) fail(path_, is_blank(text_) ? "file is empty" : "no 'OFF' header (only comments)");
    const long line = lines_.line_number();
    switch (classify_keyword(tokens_[0])) {
      case OffKeyword::not_off:
        fail_at(path_, line, "expected the header 'OFF', got " + quote(tokens_[0]));
      case OffKeyword::unsupported:
        fail_at(path_, line, "unsupported OFF variant " + quote(tokens_[0]) + " (only 3D OFF is read)");
      case OffKeyword::plain:
        break;
    }
    if (tokens_.size() > 1 && tokens_[1] == "BINARY") fail_at(path_, line, "binary OFF is not supported");
    // The counts may follow the keyword on the same line.
    std::vector<std::string_view> counts(tokens_.begin() + 1, tokens_.end());
    if (counts.empty()) {
      if (!next_tokens()) fail(path_, "truncated: no vertex and face counts after the header");
      counts = tokens_;
    }
    int edges = 0;  // unused by OFF readers, but must be a number when present
    if (counts.size() < 2 || counts.size() > 3 || !parse_int(counts[0], num_vertices_) ||
        !parse_int(counts[1], num_faces_) || (counts.size() == 3 && !parse_int(counts[2], edges)) ||
        num_vertices_ < 0 || num_faces_ < 0)
      fail_at(path_, lines_.line_number(), "expected the counts '#vertices #faces [#edges]'");
  }

  void read_vertex(int v) {
    if (!next_tokens()) truncated(v, 0);
    const long line = lines_.line_number();
    if (tokens_.size() < 3) fail_at(path_, line, "expected 3 coordinates, got " + std::to_string(tokens_.size()));
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) {
      if (!parse_double(tokens_[k], p[k])) fail_at(path_, line, quote(tokens_[k]) + " is not a number");
      if (!std::isfinite(p[k]))
        fail_at(path_, line,
                "vertex " + std::to_string(v) + " has a non-finite coordinate (" + std::string(tokens_[k]) + ")");
    }
    // Further values (normal, colour, texture coordinates) are ignored.
    soup_.points.push_back(p);
  }

  void read_face(int f) {
    if (!next_tokens()) truncated(num_vertices_, f);
    const long line = lines_.line_number();
    int count = 0;
    if (!parse_int(tokens_[0], count)) fail_at(path_, line, "expected a vertex count, got " + quote(tokens_[0]));
    if (count < 3)
      fail_at(path_, line,
              "face " + std::to_string(f) + " has " + std::to_string(count) + " vertices, at least 3 needed");
    if (tokens_.size() - 1 < static_cast<std::size_t>(count))
      fail_at(path_, line,
              "face " + std::to_string(f) + " announces " + std::to_string(count) + " vertices, but the line has " +
                  std::to_string(tokens_.size() - 1) + " values");
    std::vector<int> polygon(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) {
      const std::string_view token = tokens_[static_cast<std::size_t>(i) + 1];
      int& index = polygon[static_cast<std::size_t>(i)];
      if (!parse_int(token, index)) fail_at(path_, line, quote(token) + " is not a vertex index");
      if (index < 0 || index >= num_vertices_)
        fail_at(path_, line,
                "face " + std::to_string(f) + " refers to vertex " + std::to_string(index) + ", but the file has " +
                    std::to_string(num_vertices_) + " vertices");
    }
    // Values after the indices are a face colour: ignored.
    soup_.polygons.push_back(std::move(polygon));
  }

  [[noreturn]] void truncated(int vertices_read, int faces_read) const {
    std::string problem = "truncated: header announces " + std::to_string(num_vertices_) + " vertices and " +
                          std::to_string(num_faces_) + " faces, file ends after " + std::to_string(vertices_read) +
                          " vertices";
    if (vertices_read == num_vertices_) problem += " and " + std::to_string(faces_read) + " faces";
    fail(path_, problem);
  }

  const std::string& path_;
  std::string_view text_;
  LineCursor lines_;
  PolygonSoup soup_;
  std::vector<std::string_view> tokens_;
  int num_vertices_ = 0;
  int num_faces_ = 0;
};

}  // namespace

PolygonSoup read_off(const std::string& path, const std::string& text) { return OffReader(path, text).read(); }

void write_off(std::string& out, const Eigen::MatrixX3d& V, const std::vector<std::vector<int>>& polygons,
               const MeshColors& colors) {
  const bool vertex_colors = colors.vertex_rgb.rows() > 0;
  const bool face_colors = colors.face_rgb.rows() > 0;
  // Colours as bytes 0..255 with an opaque alpha: the convention MeshLab reads and writes.
  const auto append_color = [&out](const Eigen::MatrixX3d& rgb, Eigen::Index row) {
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_int(out, color_byte(rgb(row, k)));
    }
    out += " 255";
  };
  out += vertex_colors ? "COFF\n" : "OFF\n";
  append_int(out, V.rows());
  out += ' ';
  append_int(out, static_cast<long long>(polygons.size()));
  out += " 0\n";
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    for (int k = 0; k < 3; ++k) {
      if (k > 0) out += ' ';
      append_number(out, V(v, k));
    }
    if (vertex_colors) append_color(colors.vertex_rgb, v);
    out += '\n';
  }
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    append_int(out, static_cast<long long>(polygons[f].size()));
    for (int index : polygons[f]) {
      out += ' ';
      append_int(out, index);
    }
    if (face_colors) append_color(colors.face_rgb, static_cast<Eigen::Index>(f));
    out += '\n';
  }
}

}  // namespace polycube::mesh_io_detail
