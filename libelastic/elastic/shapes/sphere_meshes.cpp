// The sphere meshes of make_sphere (detail/shape_building.h): the quad cube sphere and the
// triangle icosphere.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <unordered_map>
#include <utility>

#include "elastic/shapes/detail/shape_building.h"

namespace elastic::shapes_detail {

// ---------------------------------------------------------------------------------------------------
// Sphere

// Quads: each cube face is an N x N grid with the equal-angle map x = tan(pi/4 * xi), xi in [-1,
// 1], before projecting onto the sphere, which makes the quads far more uniform than an evenly
// spaced grid (area ratio about 1.4 instead of 5). Vertices are keyed by their integer lattice
// point on the cube's surface, so the cube's edges and corners are shared exactly.
PolygonMesh cube_sphere(int N) {
  PolygonMesh mesh;
  std::unordered_map<std::int64_t, int> lattice;
  const std::int64_t side = N + 1;
  auto coordinate = [N](int i) { return std::tan(0.25 * kPi * (2.0 * i / N - 1.0)); };
  auto vertex = [&](const std::array<int, 3>& c) {
    const std::int64_t key = (c[0] * side + c[1]) * side + c[2];
    auto [it, inserted] = lattice.try_emplace(key, mesh.num_vertices());
    if (inserted) {
      mesh.positions.push_back(
          Eigen::Vector3d(coordinate(c[0]), coordinate(c[1]), coordinate(c[2])).normalized());
    }
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int b = (axis + 1) % 3;
    const int c = (axis + 2) % 3;
    for (int sign : {-1, 1}) {
      auto corner = [&](int i, int j) {
        std::array<int, 3> lattice_point{};
        lattice_point[axis] = sign > 0 ? N : 0;
        lattice_point[b] = i;
        lattice_point[c] = j;
        return vertex(lattice_point);
      };
      for (int i = 0; i < N; ++i) {
        for (int j = 0; j < N; ++j) {
          // e_b x e_c = +e_axis: counter-clockwise seen from outside on the + face.
          const int v00 = corner(i, j), v10 = corner(i + 1, j), v11 = corner(i + 1, j + 1),
                    v01 = corner(i, j + 1);
          if (sign > 0) {
            mesh.add_face({v00, v10, v11, v01});
          } else {
            mesh.add_face({v00, v01, v11, v10});
          }
        }
      }
    }
  }
  return mesh;
}

// Triangles: an icosahedron whose faces are split into k^2 triangles (frequency k, barycentric
// grid), then projected. Every vertex has valence 6 except the 12 icosahedron vertices (valence 5).
PolygonMesh icosphere(int k) {
  const double phi = 0.5 * (1.0 + std::sqrt(5.0));
  std::vector<Eigen::Vector3d> corners;
  for (double s1 : {-1.0, 1.0}) {
    for (double s2 : {-1.0, 1.0}) {
      corners.emplace_back(0.0, s1, s2 * phi);
      corners.emplace_back(s1, s2 * phi, 0.0);
      corners.emplace_back(s2 * phi, 0.0, s1);
    }
  }
  // Edges join corners at distance 2 (the edge length of this icosahedron); faces are mutually
  // joined triples, oriented so that their normal points away from the centre.
  auto adjacent = [&](size_t i, size_t j) {
    return std::abs((corners[i] - corners[j]).norm() - 2.0) < 1e-9;
  };
  std::vector<std::array<int, 3>> faces;
  for (size_t i = 0; i < 12; ++i) {
    for (size_t j = i + 1; j < 12; ++j) {
      for (size_t l = j + 1; l < 12; ++l) {
        if (!adjacent(i, j) || !adjacent(j, l) || !adjacent(i, l)) {
          continue;
        }
        std::array<int, 3> f{static_cast<int>(i), static_cast<int>(j), static_cast<int>(l)};
        const Eigen::Vector3d normal = (corners[j] - corners[i]).cross(corners[l] - corners[i]);
        if (normal.dot(corners[i] + corners[j] + corners[l]) < 0.0) {
          std::swap(f[1], f[2]);
        }
        faces.push_back(f);
      }
    }
  }

  PolygonMesh mesh;
  for (const Eigen::Vector3d& c : corners) {
    mesh.positions.push_back(c.normalized());
  }
  // Interior vertices of each edge, ordered from its lower to its higher corner index.
  std::unordered_map<int, int> edge_first;              // key lo * 12 + hi
  auto edge_vertex = [&](int u, int w, int weight_w) {  // point (k - weight_w) u + weight_w w
    if (u > w) {
      std::swap(u, w);
      weight_w = k - weight_w;
    }
    auto [it, inserted] = edge_first.try_emplace(u * 12 + w, mesh.num_vertices());
    if (inserted) {
      for (int t = 1; t < k; ++t) {
        mesh.positions.push_back(((k - t) * corners[u] + t * corners[w]).normalized());
      }
    }
    return it->second + weight_w - 1;
  };
  for (const std::array<int, 3>& f : faces) {
    const int A = f[0], B = f[1], C = f[2];
    // Grid point with weights (k - i - j, i, j) on corners (A, B, C).
    std::vector<int> grid(static_cast<size_t>((k + 1) * (k + 1)), -1);
    auto point = [&](int i, int j) -> int {
      int& slot = grid[static_cast<size_t>(i * (k + 1) + j)];
      if (slot >= 0) {
        return slot;
      }
      const int wa = k - i - j;
      if (i == 0 && j == 0) {
        return slot = A;
      }
      if (wa == 0 && j == 0) {
        return slot = B;
      }
      if (wa == 0 && i == 0) {
        return slot = C;
      }
      if (j == 0) {
        return slot = edge_vertex(A, B, i);
      }
      if (i == 0) {
        return slot = edge_vertex(A, C, j);
      }
      if (wa == 0) {
        return slot = edge_vertex(B, C, j);
      }
      slot = mesh.num_vertices();
      mesh.positions.push_back((wa * corners[A] + i * corners[B] + j * corners[C]).normalized());
      return slot;
    };
    for (int i = 0; i < k; ++i) {
      for (int j = 0; i + j < k; ++j) {
        mesh.add_face({point(i, j), point(i + 1, j), point(i, j + 1)});
        if (i + j + 2 <= k) {
          mesh.add_face({point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)});
        }
      }
    }
  }
  return mesh;
}

}  // namespace elastic::shapes_detail
