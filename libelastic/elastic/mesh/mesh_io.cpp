#include "elastic/mesh/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>

#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"
#include "elastic/mesh/detail/io_common.h"

namespace elastic {

namespace detail {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::string read_whole_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    throw IoError(path.string(), "no such file");
  }
  if (std::filesystem::is_directory(path, ec)) {
    throw IoError(path.string(), "is a directory");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw IoError(path.string(), std::string("cannot open: ") + std::strerror(errno));
  }
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) {
    throw IoError(path.string(), "cannot determine the file size");
  }
  in.seekg(0, std::ios::beg);
  std::string bytes(static_cast<size_t>(size), '\0');
  if (size > 0 && !in.read(bytes.data(), size)) {
    throw IoError(path.string(), "read failed");
  }
  if (bytes.empty()) {
    throw InvalidInputError(path.string(), "empty file");
  }
  return bytes;
}

void check_writable(const PolygonMesh& mesh, const std::filesystem::path& path) {
  const std::string name = path.string();
  auto fail = [&](const std::string& problem) { throw InvalidInputError(name, problem); };
  const int nv = mesh.num_vertices();
  if (!mesh.face_offsets.empty()) {
    if (mesh.face_offsets.front() != 0 ||
        mesh.face_offsets.back() != static_cast<int>(mesh.face_vertices.size())) {
      fail("inconsistent face offsets");
    }
    for (int f = 0; f < mesh.num_faces(); ++f) {
      if (mesh.face_size(f) < 3) {
        fail("face " + std::to_string(f) + " has fewer than 3 corners");
      }
    }
  } else if (!mesh.face_vertices.empty()) {
    fail("face corners without face offsets");
  }
  for (int v : mesh.face_vertices) {
    if (v < 0 || v >= nv) {
      fail("face vertex index " + std::to_string(v) + " out of range");
    }
  }
  for (int v = 0; v < nv; ++v) {
    if (!mesh.positions[static_cast<size_t>(v)].allFinite()) {
      fail("vertex " + std::to_string(v) + " has a NaN or infinite coordinate");
    }
  }
  auto check_finite = [&](const auto& pool, const char* what) {
    for (size_t i = 0; i < pool.size(); ++i) {
      if (!pool[i].allFinite()) {
        fail(std::string(what) + " " + std::to_string(i) + " is NaN or infinite");
      }
    }
  };
  check_finite(mesh.texcoords, "texture coordinate");
  check_finite(mesh.normals, "normal");
  check_finite(mesh.vertex_colors, "vertex colour");
  check_finite(mesh.face_colors, "face colour");
  for (const Material& m : mesh.materials) {
    if (!m.diffuse.allFinite()) {
      fail("material '" + m.name + "' has a NaN or infinite diffuse colour");
    }
  }
  for (const Crease& c : mesh.creases) {
    if (!std::isfinite(c.sharpness)) {
      fail("crease " + std::to_string(c.v0) + "-" + std::to_string(c.v1) +
           " has a NaN or infinite sharpness");
    }
  }
  for (const auto& [v, sharpness] : mesh.corners) {
    if (!std::isfinite(sharpness)) {
      fail("corner " + std::to_string(v) + " has a NaN or infinite sharpness");
    }
  }
  auto check_corners = [&](const std::vector<int>& corners, size_t pool, const char* what) {
    if (corners.empty()) {
      return;
    }
    if (corners.size() != mesh.face_vertices.size()) {
      fail(std::string(what) + ": one index per face corner expected");
    }
    for (int i : corners) {
      if (i < 0 || static_cast<size_t>(i) >= pool) {
        fail(std::string(what) + " index out of range");
      }
    }
  };
  check_corners(mesh.corner_texcoords, mesh.texcoords.size(), "texture coordinates");
  check_corners(mesh.corner_normals, mesh.normals.size(), "normals");
  if (!mesh.vertex_colors.empty() && mesh.vertex_colors.size() != mesh.positions.size()) {
    fail("vertex colours: one per vertex expected");
  }
  if (!mesh.face_colors.empty() &&
      mesh.face_colors.size() != static_cast<size_t>(mesh.num_faces())) {
    fail("face colours: one per face expected");
  }
  if (!mesh.face_materials.empty()) {
    if (mesh.face_materials.size() != static_cast<size_t>(mesh.num_faces())) {
      fail("face materials: one per face expected");
    }
    for (int m : mesh.face_materials) {
      if (m < -1 || m >= static_cast<int>(mesh.materials.size())) {
        fail("material index out of range");
      }
    }
  }
  for (const Crease& c : mesh.creases) {
    if (c.v0 < 0 || c.v0 >= nv || c.v1 < 0 || c.v1 >= nv) {
      fail("crease vertex out of range");
    }
  }
  for (const auto& c : mesh.corners) {
    if (c.first < 0 || c.first >= nv) {
      fail("corner vertex out of range");
    }
  }
}

}  // namespace detail

MeshFormat format_from_extension(const std::filesystem::path& path) {
  const std::string ext = detail::lower_extension(path);
  if (ext == ".obj") {
    return MeshFormat::Obj;
  }
  if (ext == ".off") {
    return MeshFormat::Off;
  }
  if (ext == ".ply") {
    return MeshFormat::Ply;
  }
  if (ext == ".stl") {
    return MeshFormat::Stl;
  }
  return MeshFormat::Auto;
}

namespace {

MeshFormat resolve_format(const std::filesystem::path& path, MeshFormat format) {
  if (format != MeshFormat::Auto) {
    return format;
  }
  const MeshFormat from_name = format_from_extension(path);
  if (from_name == MeshFormat::Auto) {
    throw InvalidInputError(path.string(), "unknown mesh format '" + path.extension().string() +
                                               "' (expected .obj, .off, .ply or .stl)");
  }
  return from_name;
}

}  // namespace

MeshReadResult read_mesh(const std::filesystem::path& path, const MeshReadOptions& options) {
  const MeshFormat format = resolve_format(path, options.format);
  const std::string text = detail::read_whole_file(path);
  MeshReadResult result;
  switch (format) {
    case MeshFormat::Obj:
      result = detail::read_obj(text, path, options);
      break;
    case MeshFormat::Off:
      result = detail::read_off(text, path);
      break;
    case MeshFormat::Ply:
      result = detail::read_ply(text, path);
      break;
    case MeshFormat::Stl:
      result = detail::read_stl(text, path);
      break;
    case MeshFormat::Auto:
      break;
  }
  if (result.mesh.num_faces() == 0) {
    throw InvalidInputError(path.string(), "the file has no faces");
  }
  return result;
}

void write_mesh(const std::filesystem::path& path, const PolygonMesh& mesh,
                const MeshWriteOptions& options) {
  const MeshFormat format = resolve_format(path, options.format);
  detail::check_writable(mesh, path);
  std::string bytes;
  bool binary = false;
  switch (format) {
    case MeshFormat::Obj: {
      const bool with_mtl = options.write_materials && !mesh.materials.empty();
      std::filesystem::path mtl_path = path;
      mtl_path.replace_extension(".mtl");
      if (with_mtl) {
        const std::string mtl = detail::write_mtl(mesh, mtl_path);
        write_file_atomically(mtl_path, [&](std::ofstream& out) {
          out.write(mtl.data(), static_cast<std::streamsize>(mtl.size()));
        });
      }
      bytes = detail::write_obj(mesh, options, with_mtl ? mtl_path.filename().string() : "");
      break;
    }
    case MeshFormat::Off:
      bytes = detail::write_off(mesh, options);
      break;
    case MeshFormat::Ply:
      bytes = detail::write_ply(mesh, options);
      binary = options.binary;
      break;
    case MeshFormat::Stl:
      detail::check_stl_writable(mesh, path);
      bytes = detail::write_stl(mesh, options);
      binary = options.binary;
      break;
    case MeshFormat::Auto:
      break;
  }
  write_file_atomically(
      path,
      [&](std::ofstream& out) {
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      },
      binary);
}

}  // namespace elastic
