// PLY (Stanford): read through CGAL's reader, written by hand (binary little-endian).
//
// CGAL's reader trusts its input: a property before any element, an integer-typed x, or a
// corrupt list length (resized to billions of entries) crash it or exhaust memory, and a
// truncated file gives only `false`. So the header is parsed and the body walked here first;
// once both are known to be well-formed, CGAL reads the values.
#include <CGAL/IO/PLY.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>

#include "formats/mesh_io_internal.h"

namespace polycube::mesh_io_detail {

namespace {

enum class PlyEncoding { ascii, binary_little_endian, binary_big_endian };

struct PlyType {
  int size = 0;  // bytes in binary encodings
  bool is_integer = false;
  bool is_signed = false;
};

// PLY scalar type names (the classic ones and the sized aliases); size 0 if unknown.
PlyType ply_type(std::string_view name) {
  if (name == "char" || name == "int8") return {1, true, true};
  if (name == "uchar" || name == "uint8") return {1, true, false};
  if (name == "short" || name == "int16") return {2, true, true};
  if (name == "ushort" || name == "uint16") return {2, true, false};
  if (name == "int" || name == "int32") return {4, true, true};
  if (name == "uint" || name == "uint32") return {4, true, false};
  if (name == "float" || name == "float32") return {4, false, true};
  if (name == "double" || name == "float64") return {8, false, true};
  return {};
}

// Whether an integer value fits in an integer PLY type (at most 32 bits).
bool fits(const PlyType& type, std::int64_t value) {
  const int bits = 8 * type.size;
  if (type.is_signed) return value >= -(std::int64_t{1} << (bits - 1)) && value < (std::int64_t{1} << (bits - 1));
  return value >= 0 && value < (std::int64_t{1} << bits);
}

// The classic name of an integer PLY type, for messages.
std::string type_name(const PlyType& type) {
  const std::string base = type.size == 1 ? "char" : type.size == 2 ? "short" : "int";
  return type.is_signed ? base : "u" + base;
}

struct PlyProperty {
  std::string name;
  std::string type_name;  // value type (of the entries, for a list)
  PlyType type;
  bool is_list = false;
  PlyType count_type;  // lists only
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;

  const PlyProperty* property(std::string_view property_name) const {
    for (const PlyProperty& p : properties)
      if (p.name == property_name) return &p;
    return nullptr;
  }
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::ascii;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;  // first byte after the end_header line
  long lines = 0;               // header lines, so ASCII data starts on line lines + 1
};

// CGAL's names for the two elements it turns into points and polygons.
bool is_vertex_element(const std::string& name) { return name == "vertex" || name == "vertices"; }
bool is_face_element(const std::string& name) { return name == "face" || name == "faces"; }

std::string plural(const PlyElement& element) {
  return element.name == "vertex" ? "vertices" : element.name.back() == 's' ? element.name : element.name + "s";
}

PlyHeader parse_header(const std::string& path, const std::string& bytes) {
  PlyHeader header;
  LineCursor lines(bytes);
  std::string_view line;
  std::vector<std::string_view> tokens;
  bool ended = false;
  while (!ended && lines.next(line)) {
    const long number = lines.line_number();
    split_tokens(line, tokens);
    if (number == 1) {
      if (tokens.size() != 1 || tokens[0] != "ply") fail(path, "not a PLY file (the first line is not 'ply')");
      // Said upfront: a header cut short would otherwise be reported as an odd keyword.
      if (bytes.find("end_header") == std::string::npos) fail(path, "truncated: the header has no end_header line");
      continue;
    }
    if (number == 2) {
      if (tokens.size() != 3 || tokens[0] != "format") fail_at(path, number, "expected 'format <encoding> 1.0'");
      if (tokens[1] == "ascii")
        header.encoding = PlyEncoding::ascii;
      else if (tokens[1] == "binary_little_endian")
        header.encoding = PlyEncoding::binary_little_endian;
      else if (tokens[1] == "binary_big_endian")
        header.encoding = PlyEncoding::binary_big_endian;
      else
        fail_at(path, number, "unknown PLY encoding " + quote(tokens[1]));
      continue;
    }
    if (tokens.empty()) fail_at(path, number, "empty line in the header");
    const std::string_view keyword = tokens[0];
    if (keyword == "element") {
      std::int64_t count = -1;
      bool parsed = false;
      // Element counts may exceed int in principle; parse them as 64-bit.
      if (tokens.size() == 3) {
        const auto result = std::from_chars(tokens[2].data(), tokens[2].data() + tokens[2].size(), count);
        parsed = result.ptr == tokens[2].data() + tokens[2].size() && result.ec == std::errc();
      }
      if (!parsed || count < 0) fail_at(path, number, "expected 'element <name> <count>'");
      header.elements.push_back({std::string(tokens[1]), static_cast<std::uint64_t>(count), {}});
    } else if (keyword == "property") {
      if (header.elements.empty()) fail_at(path, number, "property before any element");
      PlyProperty property;
      if (tokens.size() == 5 && tokens[1] == "list") {
        property.is_list = true;
        property.count_type = ply_type(tokens[2]);
        property.type_name = tokens[3];
        property.name = tokens[4];
        if (property.count_type.size == 0 || !property.count_type.is_integer)
          fail_at(path, number, "list length type " + quote(tokens[2]) + " is not an integer type");
      } else if (tokens.size() == 3) {
        property.type_name = tokens[1];
        property.name = tokens[2];
      } else {
        fail_at(path, number, "expected 'property <type> <name>' or 'property list <type> <type> <name>'");
      }
      property.type = ply_type(property.type_name);
      if (property.type.size == 0) fail_at(path, number, "unknown property type " + quote(property.type_name));
      header.elements.back().properties.push_back(std::move(property));
    } else if (keyword == "end_header") {
      ended = true;
      // Readers loop over the items of an element even when there is nothing to read in them: a
      // huge count would make them spin for hours.
      for (const PlyElement& element : header.elements)
        if (element.properties.empty() && element.count > 0)
          fail(path,
               "element '" + element.name + "' has " + std::to_string(element.count) + " items but no properties");
    }
    // Any other line is free text, as CGAL's reader takes it: comment and obj_info, and lines
    // the format does not define, such as the "Created by Blender3D ..." line Blender 2.4x wrote
    // without a comment keyword. Such a line cannot declare an element or property of its own.
  }
  if (!ended) fail(path, "truncated: the header has no end_header line");
  header.lines = lines.line_number();
  header.data_offset = lines.offset();
  return header;
}

// Checks that the properties CGAL relies on have the types it expects; otherwise CGAL ignores the
// element, or (for x, y, z and the halfedge element) dereferences a null cast in release builds.
void check_supported(const std::string& path, const PlyHeader& header) {
  bool has_vertices = false, has_faces = false;
  for (const PlyElement& element : header.elements) {
    if (is_vertex_element(element.name)) {
      has_vertices = true;
      for (const char* axis : {"x", "y", "z"}) {
        const PlyProperty* p = element.property(axis);
        if (!p) fail(path, "the " + element.name + " element has no property '" + axis + "'");
        if (p->is_list || p->type.is_integer)
          fail(path,
               std::string("vertex property '") + axis + "' has type '" + p->type_name + "'; supported: float, double");
      }
    } else if (is_face_element(element.name)) {
      has_faces = true;
      const PlyProperty* p = element.property("vertex_indices");
      if (!p) p = element.property("vertex_index");
      if (!p || !p->is_list) fail(path, "the " + element.name + " element has no list property 'vertex_indices'");
      if (!p->type.is_integer || p->type.size != 4)
        fail(path, "face property '" + p->name + "' has entries of type '" + p->type_name + "'; supported: int, uint");
    } else if (element.name == "halfedge") {
      for (const char* name : {"source", "target"}) {
        const PlyProperty* p = element.property(name);
        if (p && (p->is_list || (p->type_name != "uint" && p->type_name != "uint32")))
          fail(path, std::string("halfedge property '") + name + "' must have type uint");
      }
    }
  }
  if (!has_vertices) fail(path, "no vertex element");
  if (!has_faces) fail(path, "no face element");
}

std::string announced(const PlyHeader& header) {
  std::string out;
  for (std::size_t i = 0; i < header.elements.size(); ++i) {
    if (i > 0) out += i + 1 == header.elements.size() ? " and " : ", ";
    out += std::to_string(header.elements[i].count) + " " + plural(header.elements[i]);
  }
  return out;
}

// Throws "truncated: header announces ..., file ends after ..." for data ending in item `item` of
// element `element`.
[[noreturn]] void fail_truncated(const std::string& path, const PlyHeader& header, std::size_t element,
                                 std::uint64_t item) {
  std::string read;
  for (std::size_t i = 0; i <= element; ++i) {
    if (i > 0) read += i == element ? " and " : ", ";
    read += std::to_string(i == element ? item : header.elements[i].count) + " " + plural(header.elements[i]);
  }
  fail(path, "truncated: header announces " + announced(header) + ", file ends after " + read);
}

// Reads an unsigned or signed binary integer of `type` at p.
std::int64_t read_binary_integer(const unsigned char* p, const PlyType& type, bool big_endian) {
  std::uint64_t bits = 0;
  for (int i = 0; i < type.size; ++i) {
    const int byte = big_endian ? i : type.size - 1 - i;
    bits = (bits << 8) | p[byte];
  }
  if (type.is_signed && type.size < 8 && (bits >> (8 * type.size - 1)) != 0)
    return static_cast<std::int64_t>(bits) - (std::int64_t{1} << (8 * type.size));
  return static_cast<std::int64_t>(bits);
}

// Walks the binary body item by item, checking that every item is complete and every list length
// is non-negative and fits in the remaining data.
void check_binary_body(const std::string& path, const PlyHeader& header, const std::string& bytes) {
  const bool big_endian = header.encoding == PlyEncoding::binary_big_endian;
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  std::size_t pos = header.data_offset;
  const std::size_t end = bytes.size();
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    bool fixed_size = true;
    std::size_t item_size = 0;
    for (const PlyProperty& p : element.properties) {
      fixed_size = fixed_size && !p.is_list;
      item_size += static_cast<std::size_t>(p.type.size);
    }
    if (fixed_size) {
      // Common case (vertices): check the whole block at once.
      const std::uint64_t available = item_size == 0 ? element.count : (end - pos) / item_size;
      if (available < element.count) fail_truncated(path, header, e, available);
      pos += static_cast<std::size_t>(element.count) * item_size;
      continue;
    }
    for (std::uint64_t item = 0; item < element.count; ++item) {
      for (const PlyProperty& p : element.properties) {
        if (p.is_list) {
          if (end - pos < static_cast<std::size_t>(p.count_type.size)) fail_truncated(path, header, e, item);
          const std::int64_t length = read_binary_integer(data + pos, p.count_type, big_endian);
          pos += static_cast<std::size_t>(p.count_type.size);
          if (length < 0)
            fail(path, element.name + " " + std::to_string(item) + ": negative list length " + std::to_string(length));
          if (static_cast<std::uint64_t>(length) > (end - pos) / static_cast<std::size_t>(p.type.size))
            fail_truncated(path, header, e, item);
          pos += static_cast<std::size_t>(length) * static_cast<std::size_t>(p.type.size);
        } else {
          if (end - pos < static_cast<std::size_t>(p.type.size)) fail_truncated(path, header, e, item);
          pos += static_cast<std::size_t>(p.type.size);
        }
      }
    }
  }
}

// Walks the ASCII body token by token (CGAL ignores line breaks too), checking that every value
// is a number (an integer where the type says so), every item complete, every list length sane.
void check_ascii_body(const std::string& path, const PlyHeader& header, const std::string& bytes) {
  LineCursor lines(std::string_view(bytes).substr(header.data_offset));
  std::vector<std::string_view> tokens;
  std::size_t next = 0;  // next unread entry of tokens
  // The next token, or false at the end of the file.
  const auto next_token = [&](std::string_view& token) {
    while (next == tokens.size()) {
      std::string_view line;
      if (!lines.next(line)) return false;
      split_tokens(line, tokens);
      next = 0;
    }
    token = tokens[next++];
    return true;
  };
  const auto line_number = [&] { return header.lines + lines.line_number(); };
  std::string_view token;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    for (std::uint64_t item = 0; item < element.count; ++item) {
      const auto where = [&] { return element.name + " " + std::to_string(item); };
      // Checks the next value; returns it for integer types (list lengths), 0 otherwise.
      const auto read_value = [&](const PlyProperty& p, const PlyType& type) -> std::int64_t {
        if (!next_token(token)) fail_truncated(path, header, e, item);
        if (type.is_integer) {
          // CGAL reads integers with operator>>, which would stop at a '.' and shift every
          // following value: insist on plain integers within the type's range.
          std::int64_t value = 0;
          std::string_view digits = token.substr(!token.empty() && token.front() == '+' ? 1 : 0);
          const auto result = std::from_chars(digits.data(), digits.data() + digits.size(), value);
          if (digits.empty() || result.ptr != digits.data() + digits.size() || result.ec != std::errc() ||
              !fits(type, value))
            fail_at(path, line_number(),
                    where() + ": property '" + p.name + "' needs an integer of type " + type_name(type) + ", got " +
                        quote(token));
          return value;
        }
        double value = 0.0;
        if (!parse_double(token, value))
          fail_at(path, line_number(), where() + ": " + quote(token) + " is not a number");
        if (!std::isfinite(value))
          fail_at(path, line_number(), where() + " has a non-finite value (" + std::string(token) + ")");
        return 0;
      };
      for (const PlyProperty& p : element.properties) {
        if (!p.is_list) {
          read_value(p, p.type);
          continue;
        }
        const std::int64_t length = read_value(p, p.count_type);
        if (length < 0) fail_at(path, line_number(), where() + ": negative list length " + std::to_string(length));
        for (std::int64_t i = 0; i < length; ++i) read_value(p, p.type);
      }
    }
  }
}

}  // namespace

PolygonSoup read_ply(const std::string& path, const std::string& bytes) {
  const PlyHeader header = parse_header(path, bytes);
  check_supported(path, header);
  if (header.encoding == PlyEncoding::ascii)
    check_ascii_body(path, header, bytes);
  else
    check_binary_body(path, header, bytes);

  using Point = CGAL::Simple_cartesian<double>::Point_3;
  std::vector<Point> points;
  // size_t, as CGAL converts every index type to it: negative int indices become huge and are
  // caught by the range check below rather than wrapping to valid ones.
  std::vector<std::vector<std::size_t>> polygons;
  std::istringstream in(bytes, std::ios::in | std::ios::binary);
  if (!CGAL::IO::read_PLY(in, points, polygons, CGAL::parameters::verbose(false)))
    fail(path, "malformed PLY data (CGAL's reader failed after the structure checks passed)");

  PolygonSoup soup;
  soup.points.reserve(points.size());
  for (const Point& p : points) soup.points.emplace_back(p.x(), p.y(), p.z());
  soup.polygons.reserve(polygons.size());
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    std::vector<int> polygon(polygons[f].size());
    for (std::size_t i = 0; i < polygon.size(); ++i) {
      if (polygons[f][i] >= points.size())
        fail(path, "face " + std::to_string(f) + " refers to vertex " +
                       // Shown as the file stored it: int -1 arrives as SIZE_MAX.
                       std::to_string(static_cast<std::int64_t>(polygons[f][i])) + ", but the file has " +
                       std::to_string(points.size()) + " vertices");
      polygon[i] = static_cast<int>(polygons[f][i]);
    }
    soup.polygons.push_back(std::move(polygon));
  }
  return soup;
}

namespace {

// Appends value's bytes least significant first, whatever the host byte order.
template <typename Unsigned>
void append_little_endian(std::string& out, Unsigned bits) {
  for (std::size_t i = 0; i < sizeof(Unsigned); ++i) out += static_cast<char>((bits >> (8 * i)) & 0xFF);
}

void append_double_le(std::string& out, double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  append_little_endian(out, bits);
}

}  // namespace

void write_ply(std::string& out, const Eigen::MatrixX3d& V, const std::vector<std::vector<int>>& polygons,
               const MeshColors& colors) {
  const bool vertex_colors = colors.vertex_rgb.rows() > 0;
  const bool face_colors = colors.face_rgb.rows() > 0;
  std::size_t largest = 0;
  for (const std::vector<int>& polygon : polygons) largest = std::max(largest, polygon.size());
  // uchar lengths are what every reader expects; only huge polygons need a wider type.
  const bool wide_lengths = largest > std::numeric_limits<std::uint8_t>::max();

  out += "ply\nformat binary_little_endian 1.0\ncomment written by polycube\n";
  out += "element vertex " + std::to_string(V.rows()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  if (vertex_colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "element face " + std::to_string(polygons.size()) + "\n";
  out += wide_lengths ? "property list uint int vertex_indices\n" : "property list uchar int vertex_indices\n";
  if (face_colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "end_header\n";

  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    for (int k = 0; k < 3; ++k) append_double_le(out, V(v, k));
    if (vertex_colors)
      for (int k = 0; k < 3; ++k) out += static_cast<char>(color_byte(colors.vertex_rgb(v, k)));
  }
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const std::vector<int>& polygon = polygons[f];
    if (wide_lengths)
      append_little_endian(out, static_cast<std::uint32_t>(polygon.size()));
    else
      out += static_cast<char>(polygon.size());
    for (int index : polygon) append_little_endian(out, static_cast<std::uint32_t>(index));
    if (face_colors)
      for (int k = 0; k < 3; ++k)
        out += static_cast<char>(color_byte(colors.face_rgb(static_cast<Eigen::Index>(f), k)));
  }
}

}  // namespace polycube::mesh_io_detail
