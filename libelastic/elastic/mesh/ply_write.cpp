// Stanford PLY writing (ascii or binary_little_endian): positions, per-vertex normals, colours and
// texture coordinates where every corner of a vertex agrees, else MeshLab's per-corner `texcoord`
// list; face colours. Reading is ply_read.cpp.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "elastic/mesh/detail/io_common.h"

namespace elastic::detail {

namespace {

/// The per-vertex values of a per-corner attribute, when every corner of a vertex has the same
/// value.
template <class T>
bool per_vertex_values(const PolygonMesh& mesh, const std::vector<T>& pool,
                       const std::vector<int>& corners, std::vector<T>& out) {
  out.assign(mesh.positions.size(), T::Zero());
  std::vector<char> set(mesh.positions.size(), 0);
  for (size_t c = 0; c < corners.size(); ++c) {
    const auto v = static_cast<size_t>(mesh.face_vertices[c]);
    const T& value = pool[static_cast<size_t>(corners[c])];
    if (!set[v]) {
      set[v] = 1;
      out[v] = value;
    } else if (out[v] != value) {
      return false;
    }
  }
  return true;
}

/// Output in either encoding: numbers as text separated by spaces, or little-endian binary.
class PlyWriter {
 public:
  explicit PlyWriter(bool binary) : binary_(binary) {}
  void real(double value) {
    if (binary_) {
      raw(value);
    } else {
      separate();
      append_number(out, value);
    }
  }
  void integer(int value) {
    if (binary_) {
      raw(static_cast<std::int32_t>(value));
    } else {
      separate();
      append_number(out, value);
    }
  }
  void byte(int value) {
    if (binary_) {
      out += static_cast<char>(static_cast<unsigned char>(value));
    } else {
      separate();
      append_number(out, value);
    }
  }
  void end_row() {
    if (!binary_) {
      out += '\n';
    }
    first_ = true;
  }
  std::string out;

 private:
  template <class T>
  void raw(T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) {
      std::reverse(bytes, bytes + sizeof(T));
    }
    out.append(bytes, sizeof(T));
  }
  void separate() {
    if (!first_) {
      out += ' ';
    }
    first_ = false;
  }
  bool binary_;
  bool first_ = true;
};

}  // namespace

std::string write_ply(const PolygonMesh& mesh, const MeshWriteOptions& options) {
  std::vector<Eigen::Vector3d> vertex_normals;
  std::vector<Eigen::Vector2d> vertex_uvs;
  const bool normals = options.normals && mesh.has_normals() &&
                       per_vertex_values(mesh, mesh.normals, mesh.corner_normals, vertex_normals);
  const bool uv = options.texcoords && mesh.has_texcoords();
  const bool vertex_uv =
      uv && per_vertex_values(mesh, mesh.texcoords, mesh.corner_texcoords, vertex_uvs);
  const bool corner_uv = uv && !vertex_uv;
  const bool colors = options.vertex_colors && mesh.has_vertex_colors();
  const bool face_colors = options.face_colors && mesh.has_face_colors() &&
                           mesh.face_colors.size() == static_cast<size_t>(mesh.num_faces());
  int max_face = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    max_face = std::max(max_face, mesh.face_size(f));
  }
  // List lengths are uchar when they fit, as most readers expect.
  const bool byte_counts = max_face <= 127;

  PlyWriter w(options.binary);
  std::string& out = w.out;
  out = "ply\nformat ";
  out += options.binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
  out +=
      "comment written by libelastic\nelement vertex " + std::to_string(mesh.num_vertices()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  if (normals) {
    out += "property double nx\nproperty double ny\nproperty double nz\n";
  }
  if (colors) {
    out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  }
  if (vertex_uv) {
    out += "property double u\nproperty double v\n";
  }
  out += "element face " + std::to_string(mesh.num_faces()) + "\n";
  const char* count_type = byte_counts ? "uchar" : "int";
  out += std::string("property list ") + count_type + " int vertex_indices\n";
  if (corner_uv) {
    out += std::string("property list ") + count_type + " double texcoord\n";
  }
  if (face_colors) {
    out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  }
  out += "end_header\n";
  auto count = [&](int n) {
    if (byte_counts) {
      w.byte(n);
    } else {
      w.integer(n);
    }
  };
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    for (int k = 0; k < 3; ++k) {
      w.real(mesh.positions[v][k]);
    }
    if (normals) {
      for (int k = 0; k < 3; ++k) {
        w.real(vertex_normals[v][k]);
      }
    }
    if (colors) {
      for (int k = 0; k < 3; ++k) {
        w.byte(to_byte(mesh.vertex_colors[v][k]));
      }
    }
    if (vertex_uv) {
      w.real(vertex_uvs[v][0]);
      w.real(vertex_uvs[v][1]);
    }
    w.end_row();
  }
  for (int f = 0; f < mesh.num_faces(); ++f) {
    count(mesh.face_size(f));
    for (int v : mesh.face(f)) {
      w.integer(v);
    }
    if (corner_uv) {
      count(2 * mesh.face_size(f));
      for (int c = mesh.face_offsets[static_cast<size_t>(f)];
           c < mesh.face_offsets[static_cast<size_t>(f) + 1]; ++c) {
        const Eigen::Vector2d& t =
            mesh.texcoords[static_cast<size_t>(mesh.corner_texcoords[static_cast<size_t>(c)])];
        w.real(t[0]);
        w.real(t[1]);
      }
    }
    if (face_colors) {
      for (int k = 0; k < 3; ++k) {
        w.byte(to_byte(mesh.face_colors[static_cast<size_t>(f)][k]));
      }
    }
    w.end_row();
  }
  return std::move(w.out);
}

}  // namespace elastic::detail
