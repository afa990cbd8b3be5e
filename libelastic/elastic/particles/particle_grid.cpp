#include "elastic/particles/particle_grid.h"

namespace elastic {

Eigen::Matrix3Xd ParticleGrid::source_positions() const {
  Eigen::Matrix3Xd out(3, num_particles());
  for (const auto vh : mesh.vertices()) {
    const OpenMesh::Vec3d& p = mesh.point(vh);
    out.col(vh.idx()) = Eigen::Vector3d(p[0], p[1], p[2]);
  }
  return out;
}

void ParticleGrid::build_springs() {
  const Eigen::Matrix3Xd x = source_positions();

  // Normal springs (eq. 13): one per edge, rest length = current source chord length.
  springs.clear();
  springs.reserve(mesh.n_edges());
  for (const auto eh : mesh.edges()) {
    const auto heh = mesh.halfedge_handle(eh, 0);
    Spring s;
    s.i = mesh.from_vertex_handle(heh).idx();
    s.j = mesh.to_vertex_handle(heh).idx();
    s.rest = (x.col(s.j) - x.col(s.i)).norm();
    springs.push_back(s);
  }

  // Angular springs (Fig. 1): one per face corner. At corner i of a face, a is the vertex before i
  // and b the vertex after i (counter-clockwise); the virtual point is their midpoint, and the rest
  // value is the source distance from i to it. In a quad this distance encodes the corner angle
  // given the two adjacent edge lengths (law of cosines on the median), which is what resists
  // shear.
  angular_springs.clear();
  angular_springs.reserve(mesh.n_halfedges());
  for (const auto fh : mesh.faces()) {
    for (const auto heh : mesh.fh_range(fh)) {
      // heh runs a -> i; the next halfedge runs i -> b.
      AngularSpring s;
      s.a = mesh.from_vertex_handle(heh).idx();
      s.i = mesh.to_vertex_handle(heh).idx();
      s.b = mesh.to_vertex_handle(mesh.next_halfedge_handle(heh)).idx();
      const Eigen::Vector3d m = 0.5 * (x.col(s.a) + x.col(s.b));
      s.rest = (x.col(s.i) - m).norm();
      angular_springs.push_back(s);
    }
  }
}

std::vector<Eigen::Vector3i> grid_triangles(const ParticleGrid& grid, std::vector<int>* faces) {
  std::vector<Eigen::Vector3i> triangles;
  triangles.reserve(grid.mesh.n_faces() * 2);
  if (faces != nullptr) {
    faces->clear();
  }
  std::vector<int> corners;
  for (const auto fh : grid.mesh.faces()) {
    corners.clear();
    for (const auto vh : grid.mesh.fv_range(fh)) {
      corners.push_back(vh.idx());
    }
    for (size_t k = 1; k + 1 < corners.size(); ++k) {
      triangles.emplace_back(corners[0], corners[k], corners[k + 1]);
      if (faces != nullptr) {
        faces->push_back(fh.idx());
      }
    }
  }
  return triangles;
}

PolygonMesh to_polygon_mesh(const ParticleGrid& grid, const Eigen::Matrix3Xd& positions) {
  PolygonMesh mesh;
  mesh.positions.reserve(static_cast<size_t>(positions.cols()));
  for (Eigen::Index p = 0; p < positions.cols(); ++p) {
    mesh.positions.emplace_back(positions.col(p));
  }
  std::vector<int> corners;
  for (const auto f : grid.mesh.faces()) {
    corners.clear();
    for (const auto v : grid.mesh.fv_range(f)) {
      corners.push_back(v.idx());
    }
    mesh.add_face(corners);
  }
  if (!grid.source_uv.empty()) {
    mesh.texcoords = grid.source_uv;
    mesh.corner_texcoords = mesh.face_vertices;  // texcoord index = particle index
  }
  return mesh;
}

}  // namespace elastic
