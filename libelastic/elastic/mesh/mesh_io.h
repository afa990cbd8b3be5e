#pragma once
/// \file
/// Reading and writing polygon meshes: OBJ (+MTL), OFF, PLY (ASCII and binary, vertex colours), STL
/// (ASCII and binary). The format comes from the file extension unless given.
///
/// Readers tolerate what real files contain: CRLF line ends, runs of spaces and tabs, unknown
/// statements (OBJ `bsdf`, `s`, `o`, `g`, ...), polygons of any size, negative (relative) OBJ
/// indices, a missing material library (a warning, not an error). OpenSubdiv's OBJ `t crease` / `t
/// corner` tags are read into PolygonMesh::creases / corners. Readers do not validate topology:
/// call validate_mesh() (mesh_validation.h) for that. They do reject what cannot be a mesh: an
/// empty or truncated file, an unparsable number, NaN or infinite coordinates, face indices out of
/// range, faces with fewer than three corners, a file without faces. docs/file-formats.md lists the
/// details.
///
/// Writers write with full precision (the shortest decimal that reads back as the same double, as
/// std::to_chars gives it: as exact as max_digits10 digits) and atomically (core/atomic_file.h): on
/// failure the destination is untouched.

#include <filesystem>
#include <string>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"

namespace elastic {

enum class MeshFormat { Auto, Obj, Off, Ply, Stl };

/// The format named by a path's extension (case-insensitive); Auto when unknown.
MeshFormat format_from_extension(const std::filesystem::path& path);

struct MeshReadOptions {
  /// File format; Auto picks it from the extension.
  MeshFormat format = MeshFormat::Auto;
  /// OBJ: read the `mtllib` material libraries (texture paths resolved relative to the .mtl file).
  bool load_materials = true;
};

struct MeshReadResult {
  PolygonMesh mesh;
  /// Things the reader tolerated and a user may want to know (missing .mtl, skipped statements,
  /// ...).
  std::vector<std::string> warnings;
};

/// Reads a mesh file.
/// \throws IoError when the file cannot be opened or read; InvalidInputError (naming the file and,
///         where it applies, the line) when its content is malformed.
MeshReadResult read_mesh(const std::filesystem::path& path, const MeshReadOptions& options = {});

struct MeshWriteOptions {
  /// File format; Auto picks it from the extension.
  MeshFormat format = MeshFormat::Auto;
  /// PLY and STL: binary (little-endian) instead of ASCII.
  bool binary = false;
  /// OBJ and PLY: write texture coordinates / normals when the mesh has them. PLY writes them per
  /// vertex when all corners of a vertex agree; otherwise texture coordinates go to a per-corner
  /// `texcoord` face list (MeshLab's convention) and normals are left out.
  bool texcoords = true;
  bool normals = true;
  /// Write per-vertex colours when the mesh has them: PLY and OFF (COFF) as 8-bit values, OBJ as
  /// `v x y z r g b`. STL has none.
  bool vertex_colors = true;
  /// Write per-face colours when the mesh has them: PLY only (face `red green blue` as 8-bit
  /// values); the other formats have none.
  bool face_colors = true;
  /// OBJ: also write a .mtl beside the .obj (same stem) for the mesh's materials. Texture paths are
  /// written relative to the .mtl's folder when possible.
  bool write_materials = true;
};

/// Writes a mesh file atomically. STL output triangulates polygons (fan).
/// \throws IoError when the file cannot be written; InvalidInputError when the mesh is inconsistent
///         (indices out of range, attribute arrays of the wrong size) or the format is unknown.
void write_mesh(const std::filesystem::path& path, const PolygonMesh& mesh,
                const MeshWriteOptions& options = {});

}  // namespace elastic
