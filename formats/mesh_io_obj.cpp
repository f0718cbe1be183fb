// Wavefront OBJ: a strict reader for the polygonal subset (v, f) and a writer.
#include <algorithm>
#include <cmath>

#include "formats/mesh_io_internal.h"

namespace polycube::mesh_io_detail {

namespace {

// Statements of the OBJ specification (and common extensions) that carry nothing we use. They are
// skipped silently; anything else counts as unrecognised.
bool is_ignored_statement(std::string_view key) {
  // Common ones, then display attributes, then free-form geometry (curves and surfaces).
  static constexpr std::string_view ignored[] = {
      "vt",     "vn",     "vp",     "g",     "o",        "s",        "usemtl",     "mtllib",    "l",     "p",
      "usemap", "maplib", "lod",    "bevel", "c_interp", "d_interp", "shadow_obj", "trace_obj", "ctech", "stech",
      "call",   "csh",    "cstype", "deg",   "bmat",     "step",     "curv",       "curv2",     "surf",  "parm",
      "trim",   "hole",   "scrv",   "sp",    "end",      "con",      "mg"};
  for (std::string_view name : ignored)
    if (key == name) return true;
  return false;
}

// The vertex index of one face corner "v", "v/vt", "v//vn" or "v/vt/vn" (texture and normal
// indices are ignored).
bool parse_corner(std::string_view token, int& index) { return parse_int(token.substr(0, token.find('/')), index); }

class ObjReader {
 public:
  ObjReader(const std::string& path, std::string_view text) : path_(path), text_(text) {}

  PolygonSoup read() {
    if (is_blank(text_)) fail(path_, "file is empty");
    LineCursor lines(text_);
    std::string_view line;
    while (lines.next(line)) {
      split_tokens(strip_comment(line), tokens_);
      if (tokens_.empty()) continue;
      ++statements_;
      const std::string_view key = tokens_[0];
      if (key == "v")
        read_vertex(lines.line_number());
      else if (key == "f" || key == "fo")  // "fo" is the old name of "f"
        read_face(lines.line_number());
      else if (!is_ignored_statement(key))
        note_unrecognised(lines.line_number(), key);
    }
    finish();
    return std::move(soup_);
  }

 private:
  void read_vertex(long line) {
    const std::size_t count = tokens_.size() - 1;
    if (count < 3) fail_at(path_, line, "expected 3 coordinates, got " + std::to_string(count));
    Eigen::Vector3d p;
    // Values after x y z (a weight w, or the r g b colour extension) are checked but not used.
    for (std::size_t i = 1; i < tokens_.size(); ++i) {
      double value = 0.0;
      if (!parse_double(tokens_[i], value)) fail_at(path_, line, quote(tokens_[i]) + " is not a number");
      if (i > 3) continue;
      if (!std::isfinite(value))
        fail_at(path_, line,
                "vertex " + std::to_string(soup_.points.size() + 1) + " has a non-finite coordinate (" +
                    std::string(tokens_[i]) + ")");
      p[static_cast<Eigen::Index>(i - 1)] = value;
    }
    soup_.points.push_back(p);
  }

  void read_face(long line) {
    const std::size_t count = tokens_.size() - 1;
    if (count < 3) fail_at(path_, line, "face has " + std::to_string(count) + " vertices, at least 3 needed");
    const int defined = static_cast<int>(soup_.points.size());
    std::vector<int> polygon(count);
    bool refers_ahead = false;
    for (std::size_t i = 0; i < count; ++i) {
      const std::string_view token = tokens_[i + 1];
      int index = 0;
      if (!parse_corner(token, index)) fail_at(path_, line, quote(token) + " is not a vertex reference");
      if (index == 0) fail_at(path_, line, "vertex index 0 is invalid (OBJ indices start at 1)");
      if (index < 0) {
        // Negative indices count back from the last vertex defined so far.
        if (-index > defined)
          fail_at(path_, line,
                  "relative index " + std::to_string(index) + " reaches before the first vertex (" +
                      std::to_string(defined) + " vertices defined so far)");
        polygon[i] = defined + index;
      } else {
        polygon[i] = index - 1;
        refers_ahead = refers_ahead || index > defined;
      }
    }
    // Vertices may legally be defined after the faces using them: check those at the end.
    if (refers_ahead) forward_references_.push_back({soup_.polygons.size(), line});
    soup_.polygons.push_back(std::move(polygon));
  }

  void note_unrecognised(long line, std::string_view key) {
    if (unrecognised_ == 0) {
      first_unrecognised_line_ = line;
      first_unrecognised_ = quote(key);
    }
    ++unrecognised_;
  }

  void finish() {
    // An unknown statement here and there is tolerated (exporters add their own), but a file that
    // is mostly not OBJ is rejected rather than read as whatever few lines happen to match.
    if (2 * unrecognised_ > statements_)
      fail(path_, "not an OBJ file: " + std::to_string(unrecognised_) + " of " + std::to_string(statements_) +
                      " non-empty lines are not OBJ statements (first at line " +
                      std::to_string(first_unrecognised_line_) + ": " + first_unrecognised_ + ")");
    if (soup_.points.empty()) fail(path_, "no vertices ('v' lines)");
    if (soup_.polygons.empty()) fail(path_, "no faces ('f' lines)");
    const int num_vertices = static_cast<int>(soup_.points.size());
    for (const ForwardReference& ref : forward_references_)
      for (int index : soup_.polygons[ref.polygon])
        if (index >= num_vertices)
          fail_at(path_, ref.line,
                  "face refers to vertex " + std::to_string(index + 1) + ", but the file has " +
                      std::to_string(num_vertices) + " vertices");
  }

  struct ForwardReference {
    std::size_t polygon;
    long line;
  };

  const std::string& path_;
  std::string_view text_;
  PolygonSoup soup_;
  std::vector<std::string_view> tokens_;
  std::vector<ForwardReference> forward_references_;
  long statements_ = 0;
  long unrecognised_ = 0;
  long first_unrecognised_line_ = 0;
  std::string first_unrecognised_;
};

}  // namespace

PolygonSoup read_obj(const std::string& path, const std::string& text) { return ObjReader(path, text).read(); }

void write_obj(std::string& out, const Eigen::MatrixX3d& V, const std::vector<std::vector<int>>& polygons,
               const MeshColors& colors) {
  out += "# written by polycube\n";
  const bool vertex_colors = colors.vertex_rgb.rows() > 0;
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    out += 'v';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_number(out, V(v, k));
    }
    if (vertex_colors) {
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        const double c = colors.vertex_rgb(v, k);
        append_number(out, std::isfinite(c) ? std::clamp(c, 0.0, 1.0) : 0.0);
      }
    }
    out += '\n';
  }
  for (const std::vector<int>& polygon : polygons) {
    out += 'f';
    for (int index : polygon) {
      out += ' ';
      append_int(out, index + 1);
    }
    out += '\n';
  }
}

}  // namespace polycube::mesh_io_detail
