// Geomview OFF: [ST][C][N]OFF headers, `#` comments, counts on the header line or the next one,
// CRLF.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "elastic/mesh/detail/io_common.h"

namespace elastic::detail {

namespace {

/// The line up to a '#' comment.
std::string_view strip_comment(std::string_view line) {
  const size_t hash = line.find('#');
  return hash == std::string_view::npos ? line : line.substr(0, hash);
}

/// Next line holding something other than blanks and comments; false at the end of the file.
bool next_content_line(LineScanner& scanner, std::string_view& content) {
  std::string_view line;
  while (scanner.next(line)) {
    content = trim(strip_comment(line));
    if (!content.empty()) {
      return true;
    }
  }
  return false;
}

bool looks_integer(std::string_view token) {
  return token.find_first_of(".eE") == std::string_view::npos;
}

/// What the header says: the attributes of every vertex line and the counts.
struct OffHeader {
  bool has_uv = false;
  bool has_color = false;
  bool has_normal = false;
  long long nv = 0;
  long long nf = 0;
};

/// The [ST][C][N]OFF keyword line and the counts (on it or on the next content line).
OffHeader read_header(LineScanner& scanner, const std::filesystem::path& path) {
  std::string_view content;
  if (!next_content_line(scanner, content)) {
    throw InvalidInputError(path.string(), "no OFF header (only comments or blanks)");
  }
  std::string_view rest = content;
  std::string_view keyword = next_token(rest);
  if (!keyword.ends_with("OFF")) {
    scanner.fail("expected an OFF header, found '" + std::string(keyword) + "'");
  }
  std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  OffHeader header;
  if (prefix.starts_with("ST")) {
    header.has_uv = true;
    prefix.remove_prefix(2);
  }
  if (prefix.starts_with("C")) {
    header.has_color = true;
    prefix.remove_prefix(1);
  }
  if (prefix.starts_with("N")) {
    header.has_normal = true;
    prefix.remove_prefix(1);
  }
  if (!prefix.empty()) {
    scanner.fail("unsupported OFF variant '" + std::string(keyword) +
                 "' (4OFF / nOFF are not read)");
  }
  if (trim(rest) == "BINARY") {
    scanner.fail("binary OFF is not supported");
  }
  if (trim(rest).empty()) {
    if (!next_content_line(scanner, content)) {
      throw InvalidInputError(path.string(),
                              "truncated file: no vertex/face counts after the header");
    }
    rest = content;
  }
  header.nv = expect_int(rest, scanner, "vertex count");
  header.nf = expect_int(rest, scanner, "face count");
  if (header.nv < 0 || header.nf < 0 || header.nv > 2147483647LL || header.nf > 2147483647LL) {
    scanner.fail("invalid counts");
  }
  return header;
}

/// After a vertex's position and normal: its colour (3 or 4 values, integers 0..255 or reals
/// 0..1), then s t when ST.
void read_vertex_extras(std::string_view rest, const OffHeader& header, LineScanner& scanner,
                        std::vector<double>& values, PolygonMesh& mesh) {
  std::vector<std::string_view> tokens;
  for (std::string_view t = next_token(rest); !t.empty(); t = next_token(rest)) {
    tokens.push_back(t);
  }
  values.resize(tokens.size());
  for (size_t i = 0; i < tokens.size(); ++i) {
    if (!parse_double(tokens[i], values[i])) {
      scanner.fail("cannot parse vertex value '" + std::string(tokens[i]) + "'");
    }
  }
  size_t uv_at = tokens.size();
  if (header.has_uv) {
    if (tokens.size() < 2) {
      scanner.fail("missing texture coordinates");
    }
    uv_at = tokens.size() - 2;
    const Eigen::Vector2d uv(values[uv_at], values[uv_at + 1]);
    if (!uv.allFinite()) {
      scanner.fail("vertex has a NaN or infinite texture coordinate");
    }
    mesh.texcoords.push_back(uv);
  }
  if (header.has_color) {
    if (uv_at < 3) {
      scanner.fail("missing vertex colour");
    }
    const bool bytes =
        looks_integer(tokens[0]) && looks_integer(tokens[1]) && looks_integer(tokens[2]);
    const double scale = bytes ? 1.0 / 255.0 : 1.0;
    for (int k = 0; k < 3; ++k) {
      // Stored as float: a colour must be finite there.
      if (!(std::fabs(values[k] * scale) <=
            static_cast<double>(std::numeric_limits<float>::max()))) {
        scanner.fail("vertex colour '" + std::string(tokens[static_cast<size_t>(k)]) +
                     "' is NaN, infinite or beyond float range");
      }
    }
    mesh.vertex_colors.emplace_back(static_cast<float>(values[0] * scale),
                                    static_cast<float>(values[1] * scale),
                                    static_cast<float>(values[2] * scale));
  }
}

/// The vertex lines: position, normal when N, then read_vertex_extras.
void read_vertices(const OffHeader& header, LineScanner& scanner, const std::filesystem::path& path,
                   PolygonMesh& mesh) {
  std::string_view content;
  std::vector<double> values;
  for (long long v = 0; v < header.nv; ++v) {
    if (!next_content_line(scanner, content)) {
      throw InvalidInputError(path.string(), "truncated file: it ends after " + std::to_string(v) +
                                                 " of " + std::to_string(header.nv) + " vertices");
    }
    std::string_view rest = content;
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) {
      p[k] = expect_double(rest, scanner, "vertex coordinate");
    }
    if (!p.allFinite()) {
      scanner.fail("vertex has a NaN or infinite coordinate");
    }
    mesh.positions.push_back(p);
    if (header.has_normal) {
      Eigen::Vector3d n;
      for (int k = 0; k < 3; ++k) {
        n[k] = expect_double(rest, scanner, "normal coordinate");
      }
      if (!n.allFinite()) {
        scanner.fail("vertex has a NaN or infinite normal");
      }
      mesh.normals.push_back(n);
    }
    read_vertex_extras(rest, header, scanner, values, mesh);
  }
}

/// The face lines: a size, that many vertex indices, and an unused colour.
void read_faces(const OffHeader& header, LineScanner& scanner, const std::filesystem::path& path,
                PolygonMesh& mesh) {
  std::string_view content;
  for (long long f = 0; f < header.nf; ++f) {
    if (!next_content_line(scanner, content)) {
      throw InvalidInputError(path.string(), "truncated file: it ends after " + std::to_string(f) +
                                                 " of " + std::to_string(header.nf) + " faces");
    }
    std::string_view rest = content;
    const long long n = expect_int(rest, scanner, "face size");
    if (n < 3) {
      scanner.fail("face with " + std::to_string(n) + " corners (at least 3)");
    }
    for (long long k = 0; k < n; ++k) {
      const long long i = expect_int(rest, scanner, "face vertex index");
      if (i < 0 || i >= header.nv) {
        scanner.fail("vertex index " + std::to_string(i) + " out of range (" +
                     std::to_string(header.nv) + " vertices)");
      }
      mesh.face_vertices.push_back(static_cast<int>(i));
    }
    // Anything after the indices is a face colour: not used.
    mesh.face_offsets.push_back(static_cast<int>(mesh.face_vertices.size()));
  }
}

}  // namespace

MeshReadResult read_off(const std::string& text, const std::filesystem::path& path) {
  MeshReadResult result;
  PolygonMesh& mesh = result.mesh;
  LineScanner scanner(text, path);
  const OffHeader header = read_header(scanner, path);
  // Counts come from the file: a vertex line holds at least "0 0 0\n" (6 bytes) and a face line
  // "3 0 1 2\n" (8 bytes), so nothing is reserved beyond what the remaining bytes can hold. The
  // loops read at least one line per vertex or face and report a short file with the counts.
  const auto remaining = static_cast<long long>(text.size() - scanner.position());
  mesh.positions.reserve(static_cast<size_t>(std::min(header.nv, remaining / 6 + 1)));
  if (header.has_color) {
    mesh.vertex_colors.reserve(static_cast<size_t>(std::min(header.nv, remaining / 6 + 1)));
  }
  read_vertices(header, scanner, path, mesh);
  mesh.face_offsets.reserve(static_cast<size_t>(std::min(header.nf, remaining / 8 + 1)) + 1);
  mesh.face_offsets.push_back(0);
  read_faces(header, scanner, path, mesh);
  if (mesh.face_offsets.size() == 1) {
    mesh.face_offsets.clear();
  }
  // Per-vertex attributes become per-corner ones indexing a per-vertex pool.
  if (header.has_uv) {
    mesh.corner_texcoords = mesh.face_vertices;
  }
  if (header.has_normal) {
    mesh.corner_normals = mesh.face_vertices;
  }
  return result;
}

std::string write_off(const PolygonMesh& mesh, const MeshWriteOptions& options) {
  const bool colors = options.vertex_colors && mesh.has_vertex_colors();
  std::string out = colors ? "COFF\n" : "OFF\n";
  append_number(out, mesh.num_vertices());
  out += ' ';
  append_number(out, mesh.num_faces());
  out += " 0\n";
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    for (int k = 0; k < 3; ++k) {
      if (k) {
        out += ' ';
      }
      append_number(out, mesh.positions[v][k]);
    }
    if (colors) {
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        append_number(out, to_byte(mesh.vertex_colors[v][k]));
      }
      out += " 255";
    }
    out += '\n';
  }
  for (int f = 0; f < mesh.num_faces(); ++f) {
    append_number(out, mesh.face_size(f));
    for (int v : mesh.face(f)) {
      out += ' ';
      append_number(out, v);
    }
    out += '\n';
  }
  return out;
}

}  // namespace elastic::detail
