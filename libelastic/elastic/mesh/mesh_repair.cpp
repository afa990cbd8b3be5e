// Mesh repair (mesh_validation.h, repair_mesh): what is safely repairable is repaired (malformed,
// repeated-index and zero-area faces dropped, orientation made consistent, unreferenced vertices
// removed, the largest component kept), each change counted; validation is mesh_validation.cpp.
#include <algorithm>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/mesh/detail/mesh_topology.h"
#include "elastic/mesh/mesh_validation.h"

namespace elastic {

namespace {

/// Keeps the faces with keep[f] != 0, with their corner attributes and materials, in order.
void keep_faces(PolygonMesh& mesh, const std::vector<char>& keep) {
  const bool uv = mesh.has_texcoords();
  const bool nrm = mesh.has_normals();
  const bool mat = !mesh.face_materials.empty();
  const bool col = mesh.has_face_colors();
  std::vector<Eigen::Vector3f> colors;
  std::vector<int> offsets{0};
  std::vector<int> vertices;
  std::vector<int> uvs;
  std::vector<int> normals;
  std::vector<int> materials;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    if (!keep[static_cast<size_t>(f)]) {
      continue;
    }
    const auto b = static_cast<size_t>(mesh.face_offsets[static_cast<size_t>(f)]);
    const auto e = static_cast<size_t>(mesh.face_offsets[static_cast<size_t>(f) + 1]);
    for (size_t c = b; c < e; ++c) {
      vertices.push_back(mesh.face_vertices[c]);
      if (uv) {
        uvs.push_back(mesh.corner_texcoords[c]);
      }
      if (nrm) {
        normals.push_back(mesh.corner_normals[c]);
      }
    }
    offsets.push_back(static_cast<int>(vertices.size()));
    if (mat) {
      materials.push_back(mesh.face_materials[static_cast<size_t>(f)]);
    }
    if (col) {
      colors.push_back(mesh.face_colors[static_cast<size_t>(f)]);
    }
  }
  if (offsets.size() == 1) {
    offsets.clear();
  }
  mesh.face_offsets = std::move(offsets);
  mesh.face_vertices = std::move(vertices);
  mesh.corner_texcoords = std::move(uvs);
  mesh.corner_normals = std::move(normals);
  mesh.face_materials = std::move(materials);
  mesh.face_colors = std::move(colors);
}

/// Reverses face f's orientation, keeping its first corner first (so that a quad's ptex
/// parameterisation keeps its origin): corners 0 1 2 3 become 0 3 2 1.
void flip_face(PolygonMesh& mesh, int f) {
  const auto b = static_cast<size_t>(mesh.face_offsets[static_cast<size_t>(f)]) + 1;
  const auto e = static_cast<size_t>(mesh.face_offsets[static_cast<size_t>(f) + 1]);
  auto reverse = [&](std::vector<int>& corners) {
    if (!corners.empty()) {
      std::reverse(corners.begin() + static_cast<std::ptrdiff_t>(b),
                   corners.begin() + static_cast<std::ptrdiff_t>(e));
    }
  };
  reverse(mesh.face_vertices);
  reverse(mesh.corner_texcoords);
  reverse(mesh.corner_normals);
}

/// Removes the vertices no face uses; returns how many. Creases and corners on removed vertices go
/// too.
int remove_unreferenced(PolygonMesh& mesh) {
  const int nv = mesh.num_vertices();
  std::vector<int> remap(static_cast<size_t>(nv), -1);
  for (int v : mesh.face_vertices) {
    remap[static_cast<size_t>(v)] = 0;
  }
  int next = 0;
  for (int v = 0; v < nv; ++v) {
    if (remap[static_cast<size_t>(v)] == 0) {
      remap[static_cast<size_t>(v)] = next;
      mesh.positions[static_cast<size_t>(next)] = mesh.positions[static_cast<size_t>(v)];
      if (mesh.has_vertex_colors()) {
        mesh.vertex_colors[static_cast<size_t>(next)] = mesh.vertex_colors[static_cast<size_t>(v)];
      }
      ++next;
    }
  }
  if (next == nv) {
    return 0;
  }
  mesh.positions.resize(static_cast<size_t>(next));
  if (mesh.has_vertex_colors()) {
    mesh.vertex_colors.resize(static_cast<size_t>(next));
  }
  for (int& v : mesh.face_vertices) {
    v = remap[static_cast<size_t>(v)];
  }
  auto gone = [&](int v) { return v < 0 || v >= nv || remap[static_cast<size_t>(v)] < 0; };
  std::erase_if(mesh.creases, [&](const Crease& c) { return gone(c.v0) || gone(c.v1); });
  for (Crease& c : mesh.creases) {
    c.v0 = remap[static_cast<size_t>(c.v0)];
    c.v1 = remap[static_cast<size_t>(c.v1)];
  }
  std::erase_if(mesh.corners, [&](const std::pair<int, double>& c) { return gone(c.first); });
  for (auto& c : mesh.corners) {
    c.first = remap[static_cast<size_t>(c.first)];
  }
  return nv - next;
}

bool has_repeated_index(const PolygonMesh& mesh, int f, std::vector<int>& scratch) {
  const auto face = mesh.face(f);
  scratch.assign(face.begin(), face.end());
  std::sort(scratch.begin(), scratch.end());
  return std::adjacent_find(scratch.begin(), scratch.end()) != scratch.end();
}

}  // namespace

namespace {

/// Keeps the component with the most faces (ties: the one with the lowest face index).
void keep_largest_component(PolygonMesh& mesh, RepairResult& result) {
  const std::vector<int> component = detail::face_components(mesh, {});
  std::unordered_map<int, int> count;
  std::unordered_map<int, int> first_face;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int r = component[static_cast<size_t>(f)];
    ++count[r];
    first_face.try_emplace(r, f);
  }
  int best = -1;
  for (const auto& [root, n] : count) {
    if (best < 0 || n > count[best] || (n == count[best] && first_face[root] < first_face[best])) {
      best = root;
    }
  }
  if (count.size() > 1) {
    std::vector<char> keep(static_cast<size_t>(mesh.num_faces()));
    for (int f = 0; f < mesh.num_faces(); ++f) {
      keep[static_cast<size_t>(f)] = component[static_cast<size_t>(f)] == best ? 1 : 0;
    }
    result.removed_components = static_cast<int>(count.size()) - 1;
    result.removed_component_faces = mesh.num_faces() - count[best];
    keep_faces(mesh, keep);
    result.actions.push_back("kept the largest of " + std::to_string(count.size()) +
                             " components, removing " +
                             std::to_string(result.removed_component_faces) + " faces");
  }
}

}  // namespace

RepairResult repair_mesh(PolygonMesh& mesh, const RepairOptions& options) {
  RepairResult result;
  const MeshValidation before = validate_mesh(mesh, options.validation);
  if (before.malformed_faces.count > 0) {
    throw InvalidInputError(options.name,
                            detail::finding_text(before.malformed_faces,
                                                 "malformed faces (< 3 corners or index out of "
                                                 "range); cannot repair"));
  }
  const int nf0 = mesh.num_faces();

  if (options.remove_degenerate_faces &&
      (before.repeated_index_faces.count > 0 || before.zero_area_faces.count > 0)) {
    std::vector<char> keep(static_cast<size_t>(nf0), 1);
    std::vector<int> scratch;
    for (int f = 0; f < nf0; ++f) {
      if (has_repeated_index(mesh, f, scratch)) {
        keep[static_cast<size_t>(f)] = 0;
        ++result.removed_repeated_index_faces;
      } else if (detail::is_zero_area(mesh, f, options.validation.zero_area_relative_tolerance)) {
        keep[static_cast<size_t>(f)] = 0;
        ++result.removed_zero_area_faces;
      }
    }
    keep_faces(mesh, keep);
    if (result.removed_repeated_index_faces) {
      result.actions.push_back("removed " + std::to_string(result.removed_repeated_index_faces) +
                               " faces with a repeated vertex index");
    }
    if (result.removed_zero_area_faces) {
      result.actions.push_back("removed " + std::to_string(result.removed_zero_area_faces) +
                               " zero-area faces");
    }
  }

  if (options.keep_largest_component && mesh.num_faces() > 0) {
    keep_largest_component(mesh, result);
  }

  if (options.fix_winding) {
    const std::vector<char> all(static_cast<size_t>(mesh.num_faces()), 1);
    const detail::EdgeTable table = detail::build_edges(mesh, all);
    bool inconsistent = false;
    for (size_t e = 0; e < table.edges.size(); ++e) {
      const auto uses = table.uses(e);
      if (uses.size() == 2 && uses[0].forward == uses[1].forward) {
        inconsistent = true;
      }
      // An edge used by more faces is consistent only if its uses alternate; leave that to
      // validation.
    }
    if (inconsistent) {
      std::vector<char> flip;
      if (detail::solve_orientation(mesh, all, table, flip)) {
        for (int f = 0; f < mesh.num_faces(); ++f) {
          if (flip[static_cast<size_t>(f)]) {
            flip_face(mesh, f);
            ++result.flipped_faces;
          }
        }
        result.actions.push_back("flipped " + std::to_string(result.flipped_faces) +
                                 " faces to make the winding consistent");
      } else {
        result.winding_unfixable = true;
      }
    }
  }

  if (options.remove_unreferenced_vertices) {
    result.removed_vertices = remove_unreferenced(mesh);
    if (result.removed_vertices) {
      result.actions.push_back("removed " + std::to_string(result.removed_vertices) +
                               " unreferenced vertices");
    }
  }
  result.after = validate_mesh(mesh, options.validation);
  return result;
}

}  // namespace elastic
