#include "elastic/mesh/default_material.h"

namespace elastic {

Material default_material() {
  Material m;
  m.name = "default";
  m.diffuse = Eigen::Vector3d(0.8, 0.8, 0.8);
  return m;
}

int assign_default_material(PolygonMesh& mesh) {
  const int faces = mesh.num_faces();
  if (mesh.face_materials.size() != static_cast<size_t>(faces)) {
    mesh.face_materials.assign(static_cast<size_t>(faces), -1);
  }
  int missing = 0;
  for (const int m : mesh.face_materials) {
    missing += m < 0 ? 1 : 0;
  }
  if (missing == 0) {
    return 0;
  }
  int index = -1;
  for (size_t m = 0; m < mesh.materials.size(); ++m) {
    if (mesh.materials[m].name == "default") {
      index = static_cast<int>(m);
      break;
    }
  }
  if (index < 0) {
    index = static_cast<int>(mesh.materials.size());
    mesh.materials.push_back(default_material());
  }
  for (int& m : mesh.face_materials) {
    if (m < 0) {
      m = index;
    }
  }
  return missing;
}

std::filesystem::path first_diffuse_texture(const PolygonMesh& mesh) {
  for (const Material& m : mesh.materials) {
    if (!m.diffuse_texture.empty()) {
      return m.diffuse_texture;
    }
  }
  return {};
}

}  // namespace elastic
