#pragma once
// Private to the mesh readers and writers (not installed): whole-file reading, a line/token scanner
// with error positions, number parsing and formatting, and the per-format entry points.

#include <charconv>
#include <cmath>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"

namespace elastic::detail {

/// The whole file as bytes. \throws IoError when it cannot be opened or read; InvalidInputError
/// when empty.
std::string read_whole_file(const std::filesystem::path& path);

/// Walks a text buffer line by line (LF or CRLF), tracking the 1-based line number for messages.
class LineScanner {
 public:
  LineScanner(std::string_view text, const std::filesystem::path& path)
      : text_(text), path_(path) {}

  /// The next line without its line end; false at the end of the text.
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) {
      return false;
    }
    const size_t end = text_.find('\n', pos_);
    const size_t stop = end == std::string_view::npos ? text_.size() : end;
    line = text_.substr(pos_, stop - pos_);
    if (!line.empty() && line.back() == '\r') {
      line.remove_suffix(1);
    }
    pos_ = end == std::string_view::npos ? text_.size() : end + 1;
    ++line_;
    return true;
  }
  int line_number() const { return line_; }
  /// Byte offset of the next unread line.
  size_t position() const { return pos_; }
  const std::filesystem::path& path() const { return path_; }

  /// Throws InvalidInputError "<path>: line N: <problem>".
  [[noreturn]] void fail(const std::string& problem) const {
    throw InvalidInputError(path_.string(), "line " + std::to_string(line_) + ": " + problem);
  }

 private:
  std::string_view text_;
  const std::filesystem::path& path_;
  size_t pos_ = 0;
  int line_ = 0;
};

inline bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

/// Removes and returns the next whitespace-separated token of `rest` (empty when none is left).
inline std::string_view next_token(std::string_view& rest) {
  size_t i = 0;
  while (i < rest.size() && is_space(rest[i])) {
    ++i;
  }
  size_t j = i;
  while (j < rest.size() && !is_space(rest[j])) {
    ++j;
  }
  const std::string_view token = rest.substr(i, j - i);
  rest.remove_prefix(j);
  return token;
}

/// `rest` without leading and trailing whitespace.
inline std::string_view trim(std::string_view rest) {
  while (!rest.empty() && is_space(rest.front())) {
    rest.remove_prefix(1);
  }
  while (!rest.empty() && is_space(rest.back())) {
    rest.remove_suffix(1);
  }
  return rest;
}

/// Parses a whole token as a double (a leading '+' allowed, as C's strtod does); false if it is not
/// one.
inline bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') {
    token.remove_prefix(1);
  }
  if (token.empty()) {
    return false;
  }
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

/// Parses a whole token as an int; false if it is not one or out of range.
inline bool parse_int(std::string_view token, long long& value) {
  if (!token.empty() && token.front() == '+') {
    token.remove_prefix(1);
  }
  if (token.empty()) {
    return false;
  }
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

/// Next token as a double, failing with the line number when missing or malformed.
inline double expect_double(std::string_view& rest, const LineScanner& scanner, const char* what) {
  const std::string_view token = next_token(rest);
  double value = 0.0;
  if (token.empty()) {
    scanner.fail(std::string("missing ") + what);
  }
  if (!parse_double(token, value)) {
    scanner.fail("cannot parse " + std::string(what) + " '" + std::string(token) + "'");
  }
  return value;
}

inline long long expect_int(std::string_view& rest, const LineScanner& scanner, const char* what) {
  const std::string_view token = next_token(rest);
  long long value = 0;
  if (token.empty()) {
    scanner.fail(std::string("missing ") + what);
  }
  if (!parse_int(token, value)) {
    scanner.fail("cannot parse " + std::string(what) + " '" + std::string(token) + "'");
  }
  return value;
}

/// Appends the shortest decimal text that reads back as exactly `value` (std::to_chars without a
/// precision round-trips, like printing max_digits10 digits, but without trailing noise digits).
inline void append_number(std::string& out, double value) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, end);
}

inline void append_number(std::string& out, long long value) {
  char buffer[24];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, end);
}

inline void append_number(std::string& out, int value) {
  append_number(out, static_cast<long long>(value));
}

/// Lower-cased file extension with the dot (".obj").
std::string lower_extension(const std::filesystem::path& path);

/// Checks a mesh before writing: offsets, indices, attribute sizes, and that every number to be
/// written (positions, texture coordinates, normals, colours, sharpness values) is finite.
/// \throws InvalidInputError naming `path`.
void check_writable(const PolygonMesh& mesh, const std::filesystem::path& path);

/// Checks what only STL limits: every written vertex within float range (STL stores 32-bit
/// floats), at most 2^32 - 1 triangles. \throws InvalidInputError naming `path`.
void check_stl_writable(const PolygonMesh& mesh, const std::filesystem::path& path);

/// A colour channel in [0,1] as an 8-bit value (rounded, clamped).
inline int to_byte(float c) {
  const float clamped = c < 0.0f ? 0.0f : (c > 1.0f ? 1.0f : c);
  return static_cast<int>(std::lround(clamped * 255.0f));
}

// Per-format readers (the text is the whole file) and writers (return the file's bytes).
MeshReadResult read_obj(const std::string& text, const std::filesystem::path& path,
                        const MeshReadOptions& options);
MeshReadResult read_off(const std::string& text, const std::filesystem::path& path);
MeshReadResult read_ply(const std::string& text, const std::filesystem::path& path);
MeshReadResult read_stl(const std::string& text, const std::filesystem::path& path);

/// Reads an .mtl file into `materials` (appending); returns false when the file does not exist.
bool read_mtl(const std::filesystem::path& path, std::vector<Material>& materials);

std::string write_obj(const PolygonMesh& mesh, const MeshWriteOptions& options,
                      const std::string& mtl_file_name);
std::string write_mtl(const PolygonMesh& mesh, const std::filesystem::path& mtl_path);
std::string write_off(const PolygonMesh& mesh, const MeshWriteOptions& options);
std::string write_ply(const PolygonMesh& mesh, const MeshWriteOptions& options);
std::string write_stl(const PolygonMesh& mesh, const MeshWriteOptions& options);

}  // namespace elastic::detail
