#include "elastic/mesh/polygon_mesh.h"

namespace elastic {

bool PolygonMesh::is_triangle_mesh() const {
  if (num_faces() == 0) {
    return false;
  }
  for (int f = 0; f < num_faces(); ++f) {
    if (face_size(f) != 3) {
      return false;
    }
  }
  return true;
}

bool PolygonMesh::is_quad_mesh() const {
  if (num_faces() == 0) {
    return false;
  }
  for (int f = 0; f < num_faces(); ++f) {
    if (face_size(f) != 4) {
      return false;
    }
  }
  return true;
}

int PolygonMesh::add_face(std::span<const int> vertices) {
  if (face_offsets.empty()) {
    face_offsets.push_back(0);
  }
  face_vertices.insert(face_vertices.end(), vertices.begin(), vertices.end());
  face_offsets.push_back(static_cast<int>(face_vertices.size()));
  return num_faces() - 1;
}

}  // namespace elastic
