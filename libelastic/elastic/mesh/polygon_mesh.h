#pragma once
/// \file
/// `PolygonMesh`: the library's plain indexed polygon mesh, as files hold it. Readers produce it,
/// writers take it, validation checks it, and `to_openmesh()` (mesh/openmesh_adapter.h) turns a
/// valid one into halfedge data. Faces may have any number of corners (>= 3); their corners are
/// listed counter-clockwise seen from the side the surface normal points to.
///
/// Storage is "compressed rows": face f has the corners `face_vertices[face_offsets[f] ..
/// face_offsets[f+1])`. Per-corner attributes (texture coordinates, normals) use the same corner
/// numbering and index their own pools, as OBJ does, so UV seams are represented exactly.

#include <Eigen/Core>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace elastic {

/// A material as an OBJ .mtl file describes it (only what the library uses).
struct Material {
  std::string name;                        ///< `newmtl` name
  Eigen::Vector3d diffuse{0.8, 0.8, 0.8};  ///< `Kd`, linear RGB in [0,1]
  std::filesystem::path
      diffuse_texture;  ///< `map_Kd`, resolved relative to the .mtl file; empty if none
};

/// A sharp edge for Catmull-Clark/Loop limit surfaces (OBJ `t crease` tags). Sharpness 0 is smooth,
/// 10 or more is infinitely sharp.
struct Crease {
  int v0 = -1;
  int v1 = -1;
  double sharpness = 0.0;
};

struct PolygonMesh {
  /// #V vertex positions.
  std::vector<Eigen::Vector3d> positions;
  /// #F + 1 offsets into `face_vertices`; face_offsets[0] == 0. Empty for a mesh with no faces.
  std::vector<int> face_offsets;
  /// Vertex index of every face corner, faces one after the other.
  std::vector<int> face_vertices;

  /// Texture coordinates (pool) and, for every corner, an index into it. Both empty when the mesh
  /// has no UVs.
  std::vector<Eigen::Vector2d> texcoords;
  std::vector<int> corner_texcoords;
  /// Normals (pool) and, for every corner, an index into it. Both empty when the file had none.
  std::vector<Eigen::Vector3d> normals;
  std::vector<int> corner_normals;
  /// Per-vertex RGB colours in [0,1]: empty, or one per vertex.
  std::vector<Eigen::Vector3f> vertex_colors;
  /// Per-face RGB colours in [0,1]: empty, or one per face (PLY face `red green blue`; e.g. a
  /// per-triangle distortion heatmap).
  std::vector<Eigen::Vector3f> face_colors;

  /// Materials and, per face, the index of its material (-1 for none). Both may be empty.
  std::vector<Material> materials;
  std::vector<int> face_materials;

  /// Sharp edges (vertex pairs) and sharp corner vertices (vertex, sharpness) read from OBJ `t`
  /// tags.
  std::vector<Crease> creases;
  std::vector<std::pair<int, double>> corners;

  int num_vertices() const { return static_cast<int>(positions.size()); }
  int num_faces() const {
    return face_offsets.empty() ? 0 : static_cast<int>(face_offsets.size()) - 1;
  }
  int face_size(int f) const { return face_offsets[f + 1] - face_offsets[f]; }
  /// The vertex indices of face f, counter-clockwise.
  std::span<const int> face(int f) const {
    return {face_vertices.data() + face_offsets[f], static_cast<size_t>(face_size(f))};
  }
  bool has_texcoords() const { return !corner_texcoords.empty(); }
  bool has_normals() const { return !corner_normals.empty(); }
  bool has_vertex_colors() const { return !vertex_colors.empty(); }
  bool has_face_colors() const { return !face_colors.empty(); }
  /// True when every face is a triangle (and there is at least one face).
  bool is_triangle_mesh() const;
  /// True when every face is a quadrilateral (and there is at least one face).
  bool is_quad_mesh() const;

  /// Appends a face with the given vertex indices (no attribute corners); returns its index.
  int add_face(std::span<const int> vertices);
  int add_face(std::initializer_list<int> vertices) {
    return add_face(std::span<const int>(vertices.begin(), vertices.size()));
  }
};

}  // namespace elastic
