// OpenMesh's PropertyT<T>::push_back() appends a default-constructed VectorT, whose components are
// deliberately left uninitialised; with sanitizers GCC 12 reports that as -Wmaybe-uninitialized
// inside the instantiations this file makes (add_vertex, add_face). The values are overwritten
// before use.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include "elastic/mesh/openmesh_adapter.h"

#include <map>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_validation.h"

namespace elastic {

HalfedgeMesh to_openmesh(const PolygonMesh& mesh, const ToOpenMeshOptions& options) {
  // Refuse up front what OpenMesh's add_face cannot represent: it would print and drop the face.
  // Unreferenced vertices, zero-area faces, several components and no faces at all are
  // representable and accepted.
  ManifoldRequirements representable;
  representable.allow_several_components = true;
  representable.allow_zero_area_faces = true;
  representable.allow_unreferenced_vertices = true;
  representable.allow_no_faces = true;
  representable.validation.max_examples = 5;
  const std::string problem =
      manifold_problem(mesh, validate_mesh(mesh, representable.validation), representable);
  if (!problem.empty()) {
    throw InvalidInputError(options.name, "cannot build a halfedge mesh: " + problem);
  }

  HalfedgeMesh out;
  out.reserve(static_cast<size_t>(mesh.num_vertices()), mesh.face_vertices.size(),
              static_cast<size_t>(mesh.num_faces()));
  for (const Eigen::Vector3d& p : mesh.positions) {
    out.add_vertex(HalfedgeMesh::Point(p.x(), p.y(), p.z()));
  }

  const bool uv = options.texcoords && mesh.has_texcoords();
  std::vector<HalfedgeMesh::VertexHandle> corners;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    corners.clear();
    for (int i : mesh.face(f)) {
      corners.push_back(out.vertex_handle(static_cast<unsigned>(i)));
    }
    const HalfedgeMesh::FaceHandle fh = out.add_face(corners);
    if (!fh.is_valid()) {
      // Validation guarantees manifoldness; this is a safety net, not an expected path.
      throw InvalidInputError(options.name, "OpenMesh rejected face " + std::to_string(f));
    }
    // Make the face start at its first corner, and attach the corner texture coordinates.
    const size_t n = corners.size();
    for (size_t k = 0; k < n; ++k) {
      const auto h = out.find_halfedge(corners[(k + n - 1) % n], corners[k]);
      if (k == 0) {
        out.set_halfedge_handle(fh, h);
      }
      if (uv) {
        const int corner = mesh.face_offsets[static_cast<size_t>(f)] + static_cast<int>(k);
        const Eigen::Vector2d& t =
            mesh.texcoords[static_cast<size_t>(mesh.corner_texcoords[static_cast<size_t>(corner)])];
        out.set_texcoord2D(h, HalfedgeMesh::TexCoord2D(t.x(), t.y()));
      }
    }
  }
  if (options.compute_normals) {
    out.update_normals();
  }
  return out;
}

PolygonMesh from_openmesh(const HalfedgeMesh& mesh, const FromOpenMeshOptions& options) {
  PolygonMesh out;
  std::vector<int> index(mesh.n_vertices(), -1);
  for (const auto vh : mesh.vertices()) {  // vertices() skips deleted elements
    index[static_cast<size_t>(vh.idx())] = out.num_vertices();
    const auto& p = mesh.point(vh);
    out.positions.emplace_back(p[0], p[1], p[2]);
  }
  const bool uv = options.texcoords && mesh.has_halfedge_texcoords2D();
  std::map<std::pair<double, double>, int> uv_index;
  std::vector<int> face;
  for (const auto fh : mesh.faces()) {
    face.clear();
    for (const auto h : mesh.fh_range(fh)) {
      face.push_back(index[static_cast<size_t>(mesh.to_vertex_handle(h).idx())]);
      if (uv) {
        const auto& t = mesh.texcoord2D(h);
        const auto [it, inserted] =
            uv_index.try_emplace({t[0], t[1]}, static_cast<int>(out.texcoords.size()));
        if (inserted) {
          out.texcoords.emplace_back(t[0], t[1]);
        }
        out.corner_texcoords.push_back(it->second);
      }
    }
    out.add_face(face);
  }
  if (options.normals && mesh.has_vertex_normals()) {
    for (const auto vh : mesh.vertices()) {
      const auto& n = mesh.normal(vh);
      out.normals.emplace_back(n[0], n[1], n[2]);
    }
    out.corner_normals = out.face_vertices;
  }
  return out;
}

}  // namespace elastic
