// STL (ASCII and binary): read through CGAL's reader, after checks of our own.
//
// CGAL's reader merges corners at exactly equal positions (so the soup comes out indexed) but on
// bad input only returns false, and it guesses the encoding from the first word: binary files
// whose free-form header starts with "solid" (as some CAD exporters write) are first parsed as
// text. So the encoding is decided here from the file size, truncation and non-finite values are
// reported with numbers, and only then does CGAL read.
#include <CGAL/IO/STL.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>

#include "formats/mesh_io_internal.h"

namespace polycube::mesh_io_detail {

namespace {

constexpr std::size_t binary_header_size = 80 + 4;  // free-form header, triangle count
constexpr std::size_t binary_triangle_size = 50;    // normal, 3 corners (floats), attribute bytes

std::uint32_t read_u32_le(const std::string& bytes, std::size_t offset) {
  std::uint32_t value = 0;
  for (int i = 3; i >= 0; --i)
    value = (value << 8) | static_cast<unsigned char>(bytes[offset + static_cast<std::size_t>(i)]);
  return value;
}

float read_float_le(const std::string& bytes, std::size_t offset) {
  const std::uint32_t bits = read_u32_le(bytes, offset);
  float value = 0.0f;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

constexpr const char* kWhitespace = " \t\r\n\v\f";

// Where "solid" followed by whitespace (or the end) starts after leading whitespace: the start of
// an ASCII file (npos: none). CGAL takes only ' ', '\n' and '\r' after it for ASCII at once;
// "solid\t..." it parses as binary first (read_stl gives it a space instead).
std::size_t solid_at(const std::string& bytes) {
  const std::size_t first = bytes.find_first_not_of(kWhitespace);
  if (first == std::string::npos || bytes.compare(first, 5, "solid") != 0) return std::string::npos;
  const std::size_t after = first + 5;
  return after == bytes.size() || std::strchr(kWhitespace, bytes[after]) ? first : std::string::npos;
}

void check_binary(const std::string& path, const std::string& bytes) {
  if (bytes.size() < binary_header_size)
    fail(path, "truncated: a binary STL has at least " + std::to_string(binary_header_size) + " bytes, the file has " +
                   std::to_string(bytes.size()));
  const std::uint64_t triangles = read_u32_le(bytes, 80);
  const std::uint64_t needed = binary_header_size + triangles * binary_triangle_size;
  if (bytes.size() < needed)
    fail(path, "truncated: header announces " + std::to_string(triangles) + " triangles (" + std::to_string(needed) +
                   " bytes), file has " + std::to_string(bytes.size()) + " bytes");
  // Checked here, by triangle, because CGAL's corner merging (a std::map on coordinates) is not
  // well-defined for NaN: such a corner could merge with an arbitrary point and go unnoticed.
  for (std::uint64_t t = 0; t < triangles; ++t) {
    const std::size_t corners = binary_header_size + static_cast<std::size_t>(t) * binary_triangle_size + 12;
    for (std::size_t k = 0; k < 9; ++k) {
      const float value = read_float_le(bytes, corners + 4 * k);
      if (!std::isfinite(value))
        fail(path, "triangle " + std::to_string(t) + " has a non-finite coordinate (" + std::to_string(value) + ")");
    }
  }
}

// The structure CGAL's ASCII parser expects, checked with line numbers: "vertex" followed by
// three finite numbers, three vertices per facet, and a closing "endsolid".
void check_ascii(const std::string& path, const std::string& bytes) {
  LineCursor lines(bytes);
  std::string_view line;
  std::vector<std::string_view> tokens;
  int corners = 0;
  bool in_facet = false, closed = false;
  long facet_line = 0;
  while (lines.next(line)) {
    split_tokens(line, tokens);
    if (tokens.empty()) continue;
    const long number = lines.line_number();
    const std::string_view key = tokens[0];
    if (key == "facet") {
      if (in_facet) fail_at(path, number, "'facet' inside the facet opened on line " + std::to_string(facet_line));
      in_facet = true;
      facet_line = number;
      corners = 0;
    } else if (key == "vertex") {
      if (!in_facet) fail_at(path, number, "'vertex' outside a facet");
      if (tokens.size() != 4) fail_at(path, number, "expected 3 coordinates, got " + std::to_string(tokens.size() - 1));
      for (std::size_t k = 1; k < 4; ++k) {
        double value = 0.0;
        if (!parse_double(tokens[k], value)) fail_at(path, number, quote(tokens[k]) + " is not a number");
        if (!std::isfinite(value)) fail_at(path, number, "non-finite coordinate (" + std::string(tokens[k]) + ")");
      }
      ++corners;
    } else if (key == "endfacet") {
      if (corners != 3)
        fail_at(path, number, "facet has " + std::to_string(corners) + " vertices; STL facets are triangles");
      in_facet = false;
    } else if (key == "endsolid") {
      closed = true;
    } else if (key == "solid") {
      closed = false;
    }
  }
  if (in_facet) fail(path, "truncated: the facet opened on line " + std::to_string(facet_line) + " is not closed");
  if (!closed) fail(path, "truncated: no 'endsolid' at the end");
}

}  // namespace

PolygonSoup read_stl(const std::string& path, const std::string& bytes) {
  if (is_blank(bytes)) fail(path, "file is empty");
  // A binary file has exactly the size its triangle count announces; only files that do not,
  // and start with "solid", are ASCII.
  const std::size_t solid = solid_at(bytes);
  bool binary = solid == std::string::npos;
  if (bytes.size() >= binary_header_size &&
      bytes.size() == binary_header_size + std::uint64_t{read_u32_le(bytes, 80)} * binary_triangle_size)
    binary = true;

  std::string data;
  if (binary) {
    check_binary(path, bytes);
    // The header is free-form and unused: blank it so that CGAL never mistakes it for "solid".
    data = bytes;
    std::fill(data.begin(), data.begin() + 80, '\0');
  } else {
    check_ascii(path, bytes);
    // "solid" then a tab (or another whitespace CGAL does not take): a space instead, so that
    // CGAL parses the text as text.
    const std::size_t after = solid + 5;
    if (after < bytes.size() && bytes[after] != ' ' && bytes[after] != '\n' && bytes[after] != '\r') {
      data = bytes;
      data[after] = ' ';
    }
  }

  std::vector<std::array<double, 3>> points;
  std::vector<std::array<int, 3>> triangles;
  std::istringstream in(data.empty() ? bytes : data, std::ios::in | std::ios::binary);
  if (!CGAL::IO::read_STL(in, points, triangles, CGAL::parameters::verbose(false)))
    fail(path, std::string("malformed ") + (binary ? "binary" : "ASCII") + " STL (CGAL's reader failed)");

  PolygonSoup soup;
  soup.points.reserve(points.size());
  for (const std::array<double, 3>& p : points) soup.points.emplace_back(p[0], p[1], p[2]);
  soup.polygons.reserve(triangles.size());
  for (const std::array<int, 3>& t : triangles) soup.polygons.push_back({t[0], t[1], t[2]});
  return soup;
}

}  // namespace polycube::mesh_io_detail
