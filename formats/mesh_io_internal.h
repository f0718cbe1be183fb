// Private to formats/mesh_io_*.cpp: the per-format readers and writers behind formats/mesh_io.h,
// and the small text helpers they share.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "formats/mesh_io.h"

namespace polycube::mesh_io_detail {

// Throws InputError "<path>: <problem>".
[[noreturn]] void fail(const std::string& path, const std::string& problem);

// Throws InputError "<path>: line <line>: <problem>".
[[noreturn]] void fail_at(const std::string& path, long line, const std::string& problem);

// Iterates over the lines of a text, counting them from 1. Handles \n and \r\n endings.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text) : text_(text) {}

  // Sets line to the next line (without its ending) and returns true, or returns false at the end.
  bool next(std::string_view& line);

  // Number of the line last returned by next().
  long line_number() const { return line_number_; }

  // Offset in the text of the first byte after the line last returned and its ending.
  std::size_t offset() const { return pos_ < text_.size() ? pos_ : text_.size(); }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  long line_number_ = 0;
};

// The part of line before a '#' comment.
std::string_view strip_comment(std::string_view line);

// Splits line at whitespace into tokens (cleared first; views into line).
void split_tokens(std::string_view line, std::vector<std::string_view>& tokens);

// True if text holds nothing but whitespace.
bool is_blank(std::string_view text);

// Parses a whole token as a decimal number (a leading '+' allowed; nan and inf are accepted and
// left for the caller to reject). Magnitudes beyond double range give +-inf, tiny ones 0 or a
// subnormal. False if the token is not exactly one number.
bool parse_double(std::string_view token, double& value);

// Parses a whole token as a base-10 int; false if it is not one or does not fit.
bool parse_int(std::string_view token, int& value);

// A token for an error message: quoted, non-printable bytes replaced, long ones shortened.
std::string quote(std::string_view token);

// Per-format readers; text/bytes is the whole file. They check what they can report precisely
// (with line numbers); read_polygon_soup validates every result again.
PolygonSoup read_obj(const std::string& path, const std::string& text);
PolygonSoup read_off(const std::string& path, const std::string& text);
PolygonSoup read_ply(const std::string& path, const std::string& bytes);
PolygonSoup read_stl(const std::string& path, const std::string& bytes);

// Appends the shortest decimal form of value that parses back to the same double.
void append_number(std::string& out, double value);

// Appends a decimal integer.
void append_int(std::string& out, long long value);

// A colour component in [0,1] as a byte 0..255 (clamped; non-finite gives 0).
unsigned char color_byte(double component);

// Per-format writers: append the whole file to out. Inputs are already checked for consistency.
void write_obj(std::string& out, const Eigen::MatrixX3d& V, const std::vector<std::vector<int>>& polygons,
               const MeshColors& colors);
void write_off(std::string& out, const Eigen::MatrixX3d& V, const std::vector<std::vector<int>>& polygons,
               const MeshColors& colors);
void write_ply(std::string& out, const Eigen::MatrixX3d& V, const std::vector<std::vector<int>>& polygons,
               const MeshColors& colors);

}  // namespace polycube::mesh_io_detail
