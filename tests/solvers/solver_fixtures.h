#pragma once
// Hand-built particle grids and target surfaces for the solver tests (independent of the sampling
// module: springs are filled here from the mesh, not by build_springs()).

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"
#include "elastic/particles/particle_grid.h"

namespace elastic::test {

/// A regular (nx x ny)-cell quad grid of spacing h in the plane z = 0 with its lower-left corner at
/// `origin`; faces counter-clockwise seen from +z; the outer ring is the boundary
/// (counter-clockwise loop starting at the lower-left corner, parameter = normalised arc length).
/// Springs and angular springs are filled with rest values from the source positions.
inline ParticleGrid make_quad_grid(int nx, int ny, double h, Eigen::Vector2d origin = {0.0, 0.0}) {
  ParticleGrid grid;
  const auto index = [nx](int i, int j) { return j * (nx + 1) + i; };
  std::vector<GridMesh::VertexHandle> vertices;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      vertices.push_back(
          grid.mesh.add_vertex(OpenMesh::Vec3d(origin.x() + i * h, origin.y() + j * h, 0.0)));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      grid.mesh.add_face(std::vector<GridMesh::VertexHandle>{
          vertices[index(i, j)], vertices[index(i + 1, j)], vertices[index(i + 1, j + 1)],
          vertices[index(i, j + 1)]});

  const int n = static_cast<int>(vertices.size());
  grid.is_boundary.assign(static_cast<std::size_t>(n), 0);
  for (int i = 0; i < nx; ++i) grid.boundary_loop.push_back(index(i, 0));
  for (int j = 0; j < ny; ++j) grid.boundary_loop.push_back(index(nx, j));
  for (int i = nx; i > 0; --i) grid.boundary_loop.push_back(index(i, ny));
  for (int j = ny; j > 0; --j) grid.boundary_loop.push_back(index(0, j));
  const double perimeter = 2.0 * (nx + ny) * h;
  for (std::size_t k = 0; k < grid.boundary_loop.size(); ++k) {
    grid.is_boundary[static_cast<std::size_t>(grid.boundary_loop[k])] = 1;
    grid.boundary_parameter.push_back(static_cast<double>(k) * h / perimeter);
  }
  grid.source_points.assign(static_cast<std::size_t>(n), SurfacePoint{});

  const auto point = [&](int v) {
    const auto& p = grid.mesh.point(GridMesh::VertexHandle(v));
    return Eigen::Vector3d(p[0], p[1], p[2]);
  };
  for (const auto eh : grid.mesh.edges()) {
    const auto heh = grid.mesh.halfedge_handle(eh, 0);
    const int i = grid.mesh.from_vertex_handle(heh).idx();
    const int j = grid.mesh.to_vertex_handle(heh).idx();
    grid.springs.push_back({i, j, (point(j) - point(i)).norm()});
  }
  for (const auto fh : grid.mesh.faces()) {
    std::vector<int> face;
    const auto first = grid.mesh.halfedge_handle(fh);
    auto heh = first;
    do {  // next-halfedge order: the face's counter-clockwise order
      face.push_back(grid.mesh.to_vertex_handle(heh).idx());
      heh = grid.mesh.next_halfedge_handle(heh);
    } while (heh != first);
    const std::size_t k = face.size();
    for (std::size_t c = 0; c < k; ++c) {
      const int i = face[c], a = face[(c + 1) % k], b = face[(c + k - 1) % k];
      grid.angular_springs.push_back({i, a, b, (point(i) - 0.5 * (point(a) + point(b))).norm()});
    }
  }
  return grid;
}

/// Source positions of a grid as 3 x #P.
inline Eigen::Matrix3Xd grid_positions(const ParticleGrid& grid) {
  Eigen::Matrix3Xd x(3, grid.num_particles());
  for (int v = 0; v < grid.num_particles(); ++v) {
    const auto& p = grid.mesh.point(GridMesh::VertexHandle(v));
    x.col(v) = Eigen::Vector3d(p[0], p[1], p[2]);
  }
  return x;
}

/// A planar quad control mesh of (m x m) cells over [-half, half]^2, z = 0, mapped by `motion`.
inline PolygonMesh make_plane_mesh(int m, double half, const Eigen::Isometry3d& motion) {
  PolygonMesh mesh;
  for (int j = 0; j <= m; ++j)
    for (int i = 0; i <= m; ++i)
      mesh.positions.push_back(
          motion * Eigen::Vector3d(-half + 2.0 * half * i / m, -half + 2.0 * half * j / m, 0.0));
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const int v = j * (m + 1) + i;
      mesh.add_face({v, v + 1, v + m + 2, v + m + 1});
    }
  return mesh;
}

/// An open cylinder control mesh of radius r around the z axis, `segments` around, `rows` rows over
/// z in [-half_height, half_height], normals outward (faces counter-clockwise seen from outside).
inline PolygonMesh make_cylinder_mesh(double r, int segments, int rows, double half_height) {
  PolygonMesh mesh;
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i < segments; ++i) {
      const double angle = 2.0 * M_PI * i / segments;
      mesh.positions.emplace_back(r * std::cos(angle), r * std::sin(angle),
                                  -half_height + 2.0 * half_height * j / rows);
    }
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < segments; ++i) {
      const int i1 = (i + 1) % segments;
      // Seen from outside (+radial), going around counter-clockwise in angle then up in z.
      mesh.add_face(
          {j * segments + i, j * segments + i1, (j + 1) * segments + i1, (j + 1) * segments + i});
    }
  return mesh;
}

}  // namespace elastic::test
