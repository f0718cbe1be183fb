// Text helpers shared by the mesh readers and writers.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <system_error>

#include "formats/mesh_io_internal.h"
#include "polycube/errors.h"

namespace polycube::mesh_io_detail {

void fail(const std::string& path, const std::string& problem) { throw InputError(path + ": " + problem); }

void fail_at(const std::string& path, long line, const std::string& problem) {
  throw InputError(path + ": line " + std::to_string(line) + ": " + problem);
}

bool LineCursor::next(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  const char* begin = text_.data() + pos_;
  // memchr is much faster than a char loop on large files.
  const void* newline = std::memchr(begin, '\n', text_.size() - pos_);
  const std::size_t length =
      newline ? static_cast<std::size_t>(static_cast<const char*>(newline) - begin) : text_.size() - pos_;
  line = std::string_view(begin, length);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ += length + 1;
  ++line_number_;
  return true;
}

std::string_view strip_comment(std::string_view line) {
  const std::size_t hash = line.find('#');
  return hash == std::string_view::npos ? line : line.substr(0, hash);
}

namespace {
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

// from_chars does not take the leading '+' that some exporters write: drop it (but not "+-").
bool skip_plus(std::string_view& token) {
  if (token.empty() || token.front() != '+') return true;
  token.remove_prefix(1);
  return token.empty() || token.front() != '-';
}
}  // namespace

void split_tokens(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (i < n) {
    while (i < n && is_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < n && !is_space(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
}

bool is_blank(std::string_view text) {
  return std::all_of(text.begin(), text.end(), [](char c) { return is_space(c); });
}

bool parse_double(std::string_view token, double& value) {
  if (!skip_plus(token)) return false;
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, value);
  if (stop != end) return false;
  if (error == std::errc::result_out_of_range) {
    // from_chars refuses overflow and (in libstdc++) subnormals; strtod gives +-inf or the
    // subnormal, so that huge values are reported as non-finite and tiny ones are kept.
    value = std::strtod(std::string(token).c_str(), nullptr);
    return true;
  }
  return error == std::errc();
}

bool parse_int(std::string_view token, int& value) {
  if (!skip_plus(token)) return false;
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, value);
  return !token.empty() && stop == end && error == std::errc();
}

std::string quote(std::string_view token) {
  constexpr std::size_t max_length = 24;
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < max_length; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    out += std::isprint(c) ? static_cast<char>(c) : '?';
  }
  if (token.size() > max_length) out += "...";
  return out + "'";
}

void append_number(std::string& out, double value) {
  char buffer[32];
  // to_chars without a precision gives the shortest round-trip representation.
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}

void append_int(std::string& out, long long value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}

unsigned char color_byte(double component) {
  if (!(component > 0.0)) return 0;  // also NaN
  if (component >= 1.0) return 255;
  return static_cast<unsigned char>(std::lround(component * 255.0));
}

}  // namespace polycube::mesh_io_detail
