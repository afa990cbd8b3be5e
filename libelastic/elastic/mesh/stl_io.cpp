// STL, ASCII and binary. STL stores unconnected triangles; reading welds corners with bit-identical
// coordinates (after turning -0 into +0) into shared vertices, in order of first appearance.
// Nothing closer than identical is merged: welding by distance would be a guess.

#include <Eigen/Geometry>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <unordered_map>

#include "elastic/mesh/detail/io_common.h"

namespace elastic::detail {

namespace {

struct PositionKey {
  std::uint64_t x, y, z;
  bool operator==(const PositionKey&) const = default;
};

struct PositionHash {
  size_t operator()(const PositionKey& k) const {
    // Mix the three bit patterns (64-bit variant of boost::hash_combine's constant).
    size_t h = k.x;
    h ^= k.y + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    h ^= k.z + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    return h;
  }
};

class Welder {
 public:
  explicit Welder(PolygonMesh& mesh) : mesh_(mesh) {}
  int vertex(const Eigen::Vector3d& p) {
    // +0.0 folds -0.0 into 0.0 so that the two zeros, which compare equal, weld.
    const PositionKey key{std::bit_cast<std::uint64_t>(p.x() + 0.0),
                          std::bit_cast<std::uint64_t>(p.y() + 0.0),
                          std::bit_cast<std::uint64_t>(p.z() + 0.0)};
    const auto [it, inserted] = index_.try_emplace(key, mesh_.num_vertices());
    if (inserted) {
      mesh_.positions.push_back(p);
    }
    return it->second;
  }

 private:
  PolygonMesh& mesh_;
  std::unordered_map<PositionKey, int, PositionHash> index_;
};

/// Whether every coordinate is within float's range (what an STL file can hold).
bool fits_float(const Eigen::Vector3d& p) {
  return p.cwiseAbs().maxCoeff() <= static_cast<double>(std::numeric_limits<float>::max());
}

std::uint32_t read_u32_le(const char* p) {
  unsigned char b[4];
  std::memcpy(b, p, 4);
  return static_cast<std::uint32_t>(b[0]) | (static_cast<std::uint32_t>(b[1]) << 8) |
         (static_cast<std::uint32_t>(b[2]) << 16) | (static_cast<std::uint32_t>(b[3]) << 24);
}

float read_f32_le(const char* p) {
  return std::bit_cast<float>(read_u32_le(p));
}

MeshReadResult read_binary_stl(const std::string& bytes, const std::filesystem::path& path) {
  MeshReadResult result;
  PolygonMesh& mesh = result.mesh;
  const std::uint32_t n = read_u32_le(bytes.data() + 80);
  const std::uint64_t expected = 84 + 50ULL * n;
  if (bytes.size() < expected) {
    throw InvalidInputError(
        path.string(), "truncated file: the header announces " + std::to_string(n) +
                           " triangles (" + std::to_string(expected) + " bytes) but the file has " +
                           std::to_string(bytes.size()) + " bytes");
  }
  if (bytes.size() > expected) {
    result.warnings.push_back(path.string() + ": " + std::to_string(bytes.size() - expected) +
                              " bytes after the last triangle ignored");
  }
  Welder welder(mesh);
  mesh.face_offsets.reserve(n + 1);
  mesh.face_offsets.push_back(0);
  for (std::uint32_t t = 0; t < n; ++t) {
    const char* record = bytes.data() + 84 + 50ULL * t;
    for (int corner = 0; corner < 3; ++corner) {
      Eigen::Vector3d p;
      for (int k = 0; k < 3; ++k) {
        p[k] = static_cast<double>(read_f32_le(record + 12 + 12 * corner + 4 * k));
      }
      if (!p.allFinite()) {
        throw InvalidInputError(
            path.string(), "triangle " + std::to_string(t) + " has a NaN or infinite coordinate");
      }
      mesh.face_vertices.push_back(welder.vertex(p));
    }
    mesh.face_offsets.push_back(static_cast<int>(mesh.face_vertices.size()));
  }
  if (mesh.face_offsets.size() == 1) {
    mesh.face_offsets.clear();
  }
  return result;
}

MeshReadResult read_ascii_stl(const std::string& text, const std::filesystem::path& path) {
  MeshReadResult result;
  PolygonMesh& mesh = result.mesh;
  LineScanner scanner(text, path);
  Welder welder(mesh);
  mesh.face_offsets.push_back(0);
  std::vector<int> loop;
  bool in_loop = false;
  bool ended = false;
  std::string_view line;
  while (scanner.next(line)) {
    std::string_view rest = line;
    const std::string_view keyword = next_token(rest);
    if (keyword.empty()) {
      continue;
    }
    if (keyword == "vertex") {
      if (!in_loop) {
        scanner.fail("vertex outside 'outer loop'");
      }
      Eigen::Vector3d p;
      for (int k = 0; k < 3; ++k) {
        p[k] = expect_double(rest, scanner, "vertex coordinate");
      }
      if (!p.allFinite()) {
        scanner.fail("vertex has a NaN or infinite coordinate");
      }
      if (!fits_float(p)) {
        // STL stores 32-bit floats: such a vertex has no binary STL form and would be written
        // as an infinity that does not read back.
        scanner.fail("vertex coordinate beyond the range of float (about 3.4e38)");
      }
      loop.push_back(welder.vertex(p));
    } else if (keyword == "outer") {
      if (in_loop) {
        scanner.fail("'outer loop' inside a loop: the facet before it has no 'endloop'");
      }
      in_loop = true;
      loop.clear();
    } else if (in_loop && (keyword == "endfacet" || keyword == "facet" || keyword == "endsolid")) {
      // Built by appending: GCC 12 reports a false -Wrestrict on the operator+ chain here.
      std::string message = "'";
      message.append(keyword);
      message.append("' inside a loop: the facet has no 'endloop'");
      scanner.fail(message);
    } else if (keyword == "endloop") {
      if (!in_loop) {
        scanner.fail("'endloop' without 'outer loop'");
      }
      if (loop.size() < 3) {
        scanner.fail("facet with " + std::to_string(loop.size()) + " vertices (at least 3)");
      }
      mesh.face_vertices.insert(mesh.face_vertices.end(), loop.begin(), loop.end());
      mesh.face_offsets.push_back(static_cast<int>(mesh.face_vertices.size()));
      in_loop = false;
    } else if (keyword == "endsolid") {
      ended = true;
    }
    // solid, facet (its normal is recomputed from the corners when needed), endfacet: nothing to
    // keep.
  }
  if (in_loop || !ended) {
    throw InvalidInputError(path.string(), "truncated file: it ends before 'endsolid'");
  }
  if (mesh.face_offsets.size() == 1) {
    mesh.face_offsets.clear();
  }
  return result;
}

/// Unit normal of a triangle, or zero when it has no area.
Eigen::Vector3d triangle_normal(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double length = n.norm();
  return length > 0.0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
}

}  // namespace

MeshReadResult read_stl(const std::string& text, const std::filesystem::path& path) {
  // Binary when the size matches the triangle count in the header, whatever the first bytes say
  // (some binary writers start their header with "solid"); ASCII when it starts with "solid".
  if (text.size() >= 84) {
    const std::uint64_t n = read_u32_le(text.data() + 80);
    if (84 + 50 * n == text.size()) {
      return read_binary_stl(text, path);
    }
  }
  std::string_view head(text.data(), std::min<size_t>(text.size(), 512));
  size_t i = 0;
  while (i < head.size() && is_space(head[i])) {
    ++i;
  }
  if (head.substr(i).starts_with("solid") && head.find("facet") != std::string_view::npos) {
    return read_ascii_stl(text, path);
  }
  if (head.substr(i).starts_with("solid") && text.size() < 84) {
    return read_ascii_stl(text, path);
  }
  if (text.size() < 84) {
    throw InvalidInputError(path.string(), "truncated file: " + std::to_string(text.size()) +
                                               " bytes, shorter than a binary STL header (84)");
  }
  return read_binary_stl(text, path);
}

void check_stl_writable(const PolygonMesh& mesh, const std::filesystem::path& path) {
  std::size_t triangles = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    triangles += static_cast<size_t>(mesh.face_size(f) - 2);
    for (const int v : mesh.face(f)) {
      if (!fits_float(mesh.positions[static_cast<size_t>(v)])) {
        throw InvalidInputError(path.string(), "vertex " + std::to_string(v) +
                                                   " is beyond the range of float (about 3.4e38), "
                                                   "which STL stores");
      }
    }
  }
  if (triangles > 0xffffffffULL) {
    throw InvalidInputError(path.string(), "too many triangles for STL (" +
                                               std::to_string(triangles) + ", at most 2^32 - 1)");
  }
}

std::string write_stl(const PolygonMesh& mesh, const MeshWriteOptions& options) {
  // Polygons are split into a fan of triangles around their first corner.
  std::size_t triangles = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    triangles += static_cast<size_t>(mesh.face_size(f) - 2);
  }
  std::string out;
  auto for_each_triangle = [&](auto&& emit) {
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const auto face = mesh.face(f);
      for (size_t k = 1; k + 1 < face.size(); ++k) {
        emit(mesh.positions[static_cast<size_t>(face[0])],
             mesh.positions[static_cast<size_t>(face[k])],
             mesh.positions[static_cast<size_t>(face[k + 1])]);
      }
    }
  };
  if (options.binary) {
    out.reserve(84 + 50 * triangles);
    std::string header = "binary STL written by libelastic";
    header.resize(80, ' ');
    out += header;
    auto u32 = [&](std::uint32_t v) {
      for (int k = 0; k < 4; ++k) {
        out += static_cast<char>((v >> (8 * k)) & 0xffu);
      }
    };
    auto f32 = [&](double v) { u32(std::bit_cast<std::uint32_t>(static_cast<float>(v))); };
    u32(static_cast<std::uint32_t>(triangles));
    for_each_triangle(
        [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
          const Eigen::Vector3d n = triangle_normal(a, b, c);
          for (const Eigen::Vector3d* p : {&n, &a, &b, &c}) {
            for (int k = 0; k < 3; ++k) {
              f32((*p)[k]);
            }
          }
          out += '\0';
          out += '\0';
        });
  } else {
    out = "solid libelastic\n";
    auto vec = [&](const Eigen::Vector3d& v) {
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        append_number(out, v[k]);
      }
      out += '\n';
    };
    for_each_triangle(
        [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
          out += "facet normal";
          vec(triangle_normal(a, b, c));
          out += "outer loop\n";
          for (const Eigen::Vector3d* p : {&a, &b, &c}) {
            out += "vertex";
            vec(*p);
          }
          out += "endloop\nendfacet\n";
        });
    out += "endsolid libelastic\n";
  }
  return out;
}

}  // namespace elastic::detail
