#pragma once
// Control meshes for the limit-surface tests, built here so that the expected answers are known:
// flat grids (affine limit), a cube (valence-3 extraordinary vertices everywhere), spheres, a
// torus, flat meshes with extraordinary vertices and n-gons, and a mixed pentagon/quad/triangle
// solid.

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"

namespace elastic::test {

/// Flat grid of nx by ny quads: vertex (i, j) at origin + i a + j b, faces counter-clockwise for
/// a x b. When `rotate_faces`, face (i, j) lists its corners starting at corner (i + j) % 4, so
/// that neighbouring ptex faces are rotated against each other.
inline PolygonMesh quad_grid(int nx, int ny, const Eigen::Vector3d& origin,
                             const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             bool rotate_faces = false) {
  PolygonMesh mesh;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) mesh.positions.push_back(origin + i * a + j * b);
  }
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      std::vector<int> f{id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)};
      if (rotate_faces) std::rotate(f.begin(), f.begin() + (i + j) % 4, f.end());
      mesh.add_face(f);
    }
  }
  return mesh;
}

/// Flat grid of nx by ny squares, each split into two triangles along the same diagonal (all
/// interior vertices have valence 6, the regular Loop configuration).
inline PolygonMesh triangle_grid(int nx, int ny, const Eigen::Vector3d& origin,
                                 const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  PolygonMesh mesh;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) mesh.positions.push_back(origin + i * a + j * b);
  }
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      mesh.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.add_face({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return mesh;
}

/// Unit cube [-1,1]^3 as 6 outward quads (8 valence-3 vertices).
inline PolygonMesh cube() {
  PolygonMesh mesh;
  for (int k = 0; k < 8; ++k) {
    mesh.positions.emplace_back(k & 1 ? 1.0 : -1.0, k & 2 ? 1.0 : -1.0, k & 4 ? 1.0 : -1.0);
  }
  mesh.add_face({0, 2, 3, 1});  // z = -1
  mesh.add_face({4, 5, 7, 6});  // z = +1
  mesh.add_face({0, 1, 5, 4});  // y = -1
  mesh.add_face({2, 6, 7, 3});  // y = +1
  mesh.add_face({0, 4, 6, 2});  // x = -1
  mesh.add_face({1, 3, 7, 5});  // x = +1
  return mesh;
}

/// Latitude-longitude sphere of radius r: nlon meridians, nlat latitude bands, quads (or quads
/// split into two triangles along the same diagonal) between the poles and a triangle fan around
/// each pole vertex (valence nlon). Its grid lines are smooth, so away from the poles the limit
/// surface approaches the sphere at O(h^2) (cube or icosahedron based spheres do not: their grid
/// lines kink along the base solid's edges).
inline PolygonMesh uv_sphere(int nlon, int nlat, double r, bool triangles) {
  PolygonMesh mesh;
  const double pi = std::numbers::pi;
  mesh.positions.emplace_back(0, 0, -r);
  for (int j = 1; j < nlat; ++j) {
    const double lat = -pi / 2 + pi * j / nlat;
    for (int i = 0; i < nlon; ++i) {
      const double lon = 2 * pi * i / nlon;
      mesh.positions.emplace_back(r * std::cos(lat) * std::cos(lon),
                                  r * std::cos(lat) * std::sin(lon), r * std::sin(lat));
    }
  }
  mesh.positions.emplace_back(0, 0, r);
  const int north = mesh.num_vertices() - 1;
  auto id = [&](int i, int j) {
    return 1 + (j - 1) * nlon + (i + nlon) % nlon;
  };  // ring j in 1..nlat-1
  for (int i = 0; i < nlon; ++i) mesh.add_face({0, id(i + 1, 1), id(i, 1)});
  for (int j = 1; j + 1 < nlat; ++j) {
    for (int i = 0; i < nlon; ++i) {
      if (triangles) {
        mesh.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        mesh.add_face({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        mesh.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  }
  for (int i = 0; i < nlon; ++i) mesh.add_face({north, id(i, nlat - 1), id(i + 1, nlat - 1)});
  return mesh;
}

/// Icosahedron subdivided `levels` times (each triangle into 4), projected onto the sphere of
/// radius r (12 valence-5 vertices, the rest valence 6).
inline PolygonMesh icosphere(int levels, double r) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> p = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                    {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                    {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<Eigen::Vector3i> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& x : p) x.normalize();
  for (int level = 0; level < levels; ++level) {
    std::vector<Eigen::Vector3i> next;
    std::vector<std::pair<std::pair<int, int>, int>> mids;
    auto mid = [&](int a, int b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      for (const auto& [k, v] : mids) {
        if (k == key) return v;
      }
      p.push_back((p[static_cast<size_t>(a)] + p[static_cast<size_t>(b)]).normalized());
      mids.push_back({key, static_cast<int>(p.size()) - 1});
      return static_cast<int>(p.size()) - 1;
    };
    for (const auto& tri : t) {
      const int ab = mid(tri[0], tri[1]), bc = mid(tri[1], tri[2]), ca = mid(tri[2], tri[0]);
      next.push_back({tri[0], ab, ca});
      next.push_back({tri[1], bc, ab});
      next.push_back({tri[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    t = next;
  }
  PolygonMesh mesh;
  for (const auto& x : p) mesh.positions.push_back(r * x);
  for (const auto& tri : t) mesh.add_face({tri[0], tri[1], tri[2]});
  return mesh;
}

/// Torus around the z axis, major radius R, tube radius r, nu segments around z, nv around the
/// tube; outward quads. Vertex (i, j) at angle 2 pi i / nu around z and 2 pi j / nv around the
/// tube.
inline PolygonMesh torus(int nu, int nv, double R, double r) {
  PolygonMesh mesh;
  const double pi = std::numbers::pi;
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const double a = 2 * pi * i / nu, b = 2 * pi * j / nv;
      mesh.positions.emplace_back((R + r * std::cos(b)) * std::cos(a),
                                  (R + r * std::cos(b)) * std::sin(a), r * std::sin(b));
    }
  }
  auto id = [&](int i, int j) { return ((i + nu) % nu) * nv + (j + nv) % nv; };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      mesh.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return mesh;
}

/// Appends face `f`, reversed if its (planar, z = const) polygon is clockwise seen from +z.
inline void add_ccw_face(PolygonMesh& mesh, std::vector<int> f) {
  double area = 0.0;
  for (size_t i = 0; i < f.size(); ++i) {
    const Eigen::Vector3d& a = mesh.positions[static_cast<size_t>(f[i])];
    const Eigen::Vector3d& b = mesh.positions[static_cast<size_t>(f[(i + 1) % f.size()])];
    area += a.x() * b.y() - a.y() * b.x();
  }
  if (area < 0.0) std::reverse(f.begin(), f.end());
  mesh.add_face(f);
}

/// Flat wheel in z = 0 around the origin: an inner ring of n vertices (radius 1) and an outer ring
/// of 2n (radius 2.2). With `centre_vertex`: n kites around a centre vertex of valence n (quads
/// only, inner ring vertices of valence 3). Without: an n-gon in the middle, n triangles, n quads
/// (mixed).
inline PolygonMesh flat_wheel(int n, bool centre_vertex) {
  PolygonMesh mesh;
  const double pi = std::numbers::pi;
  for (int i = 0; i < n; ++i) {
    mesh.positions.emplace_back(std::cos(2 * pi * i / n), std::sin(2 * pi * i / n), 0.0);
  }
  for (int j = 0; j < 2 * n; ++j) {
    mesh.positions.emplace_back(2.2 * std::cos(pi * j / n), 2.2 * std::sin(pi * j / n), 0.0);
  }
  auto inner = [&](int i) { return (i + n) % n; };
  auto outer = [&](int j) { return n + (j + 2 * n) % (2 * n); };
  if (centre_vertex) {
    mesh.positions.emplace_back(0.0, 0.0, 0.0);
    const int c = 3 * n;
    for (int i = 0; i < n; ++i) add_ccw_face(mesh, {c, inner(i), outer(2 * i + 1), inner(i + 1)});
  } else {
    std::vector<int> middle;
    for (int i = 0; i < n; ++i) middle.push_back(inner(i));
    add_ccw_face(mesh, middle);
    for (int i = 0; i < n; ++i) add_ccw_face(mesh, {inner(i), outer(2 * i + 1), inner(i + 1)});
  }
  for (int i = 0; i < n; ++i) {
    add_ccw_face(mesh, {inner(i), outer(2 * i - 1), outer(2 * i), outer(2 * i + 1)});
  }
  return mesh;
}

/// Closed solid with a pentagon, quads and triangles: a pentagonal prism whose top is a fan of 5
/// triangles around an apex (valence 5), outward faces.
inline PolygonMesh mixed_solid() {
  PolygonMesh mesh;
  const double pi = std::numbers::pi;
  for (int i = 0; i < 5; ++i) {
    mesh.positions.emplace_back(std::cos(2 * pi * i / 5), std::sin(2 * pi * i / 5), -0.6);
  }
  for (int i = 0; i < 5; ++i) {
    mesh.positions.emplace_back(1.1 * std::cos(2 * pi * i / 5), 1.1 * std::sin(2 * pi * i / 5),
                                0.5);
  }
  mesh.positions.emplace_back(0.0, 0.0, 1.3);
  mesh.add_face({4, 3, 2, 1, 0});  // bottom, normal -z
  for (int i = 0; i < 5; ++i) {
    const int j = (i + 1) % 5;
    mesh.add_face({i, j, 5 + j, 5 + i});
    mesh.add_face({5 + i, 5 + j, 10});
  }
  return mesh;
}

/// Moves every vertex by a random vector of length <= amplitude (fixed seed).
inline void jitter(PolygonMesh& mesh, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (auto& p : mesh.positions)
    p += amplitude * Eigen::Vector3d(uni(rng), uni(rng), uni(rng)) / std::sqrt(3.0);
}

}  // namespace elastic::test
