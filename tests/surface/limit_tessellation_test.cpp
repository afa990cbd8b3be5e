// tessellate(): welded by topology, watertight, same boundary loops and Euler characteristic as the
// control mesh, vertices on the limit surface, consistent winding, sizes as documented.
#include "elastic/surface/limit_tessellation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "elastic/core/error.h"
#include "surface/surface_test_meshes.h"

namespace elastic {
namespace {

struct Topology {
  long vertices = 0, edges = 0, faces = 0;
  int boundary_loops = 0;
  bool manifold_and_oriented = true;
  long euler() const { return vertices - edges + faces; }
};

/// Counts from the polygons alone (directed-edge bookkeeping): every undirected edge must be used
/// once (boundary) or twice in opposite directions (interior); boundary edges are chained into
/// loops.
Topology topology(int num_vertices, const std::vector<std::vector<int>>& polygons) {
  Topology t;
  t.vertices = num_vertices;
  t.faces = static_cast<long>(polygons.size());
  std::map<std::pair<int, int>, int> directed;
  for (const auto& poly : polygons) {
    for (size_t i = 0; i < poly.size(); ++i) {
      ++directed[{poly[i], poly[(i + 1) % poly.size()]}];
    }
  }
  std::map<int, int> boundary_next;
  std::set<std::pair<int, int>> undirected;
  for (const auto& [e, count] : directed) {
    undirected.insert({std::min(e.first, e.second), std::max(e.first, e.second)});
    if (count != 1) {
      t.manifold_and_oriented = false;
    }
    if (!directed.count({e.second, e.first})) {
      if (boundary_next.count(e.first)) {
        t.manifold_and_oriented = false;
      }
      boundary_next[e.first] = e.second;
    }
  }
  t.edges = static_cast<long>(undirected.size());
  std::set<int> seen;
  for (const auto& [start, next] : boundary_next) {
    if (seen.count(start)) {
      continue;
    }
    ++t.boundary_loops;
    for (int v = start; !seen.count(v); v = boundary_next.count(v) ? boundary_next[v] : start) {
      seen.insert(v);
    }
  }
  return t;
}

Topology topology(const PolygonMesh& mesh) {
  std::vector<std::vector<int>> polys;
  polys.reserve(static_cast<size_t>(mesh.num_faces()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    polys.emplace_back(mesh.face(f).begin(), mesh.face(f).end());
  }
  return topology(mesh.num_vertices(), polys);
}

Topology topology(const LimitTessellation& t) {
  std::vector<std::vector<int>> polys;
  for (const auto& tri : t.triangles) {
    polys.push_back({tri[0], tri[1], tri[2]});
  }
  return topology(static_cast<int>(t.positions.size()), polys);
}

void expect_matches_control_topology(const LimitSurface& s, const LimitTessellation& t) {
  const Topology control = topology(s.control_mesh());
  const Topology mesh = topology(t);
  EXPECT_TRUE(mesh.manifold_and_oriented);
  EXPECT_EQ(mesh.boundary_loops, control.boundary_loops);
  EXPECT_EQ(mesh.euler(), control.euler());
  ASSERT_EQ(t.points.size(), t.positions.size());
  ASSERT_EQ(t.triangle_face.size(), t.triangles.size());
  // Every vertex is the limit position of its SurfacePoint (exactly: the same evaluation).
  for (size_t i = 0; i < t.points.size(); ++i) {
    ASSERT_TRUE(s.in_domain(t.points[i]));
    EXPECT_EQ(t.positions[i], s.position(t.points[i]));
  }
  // Triangles wind like the control mesh: each triangle's normal agrees with the limit surface
  // normals at its corners (the tessellations here are fine enough for that to be unambiguous).
  std::vector<Eigen::Vector3d> normals(t.points.size());
  for (size_t i = 0; i < t.points.size(); ++i) {
    normals[i] = s.curvature(t.points[i]).normal;
  }
  for (const auto& tri : t.triangles) {
    const Eigen::Vector3d& a = t.positions[static_cast<size_t>(tri[0])];
    const Eigen::Vector3d n = (t.positions[static_cast<size_t>(tri[1])] - a)
                                  .cross(t.positions[static_cast<size_t>(tri[2])] - a);
    const Eigen::Vector3d surface_normal = normals[static_cast<size_t>(tri[0])] +
                                           normals[static_cast<size_t>(tri[1])] +
                                           normals[static_cast<size_t>(tri[2])];
    EXPECT_GT(n.dot(surface_normal), 0.0);
  }
}

TEST(Tessellation, QuadMeshCountsAndTopology) {
  const LimitSurface s(test::cube());
  const LimitTessellation t = tessellate(s, {.resolution = 5});
  EXPECT_EQ(t.resolution, 5);
  // V = control vertices + (N-1) per edge + (N-1)^2 per face; T = 2 N^2 per face.
  EXPECT_EQ(t.positions.size(), 8u + 12u * 4u + 6u * 16u);
  EXPECT_EQ(t.triangles.size(), 6u * 2u * 25u);
  expect_matches_control_topology(s, t);
}

TEST(Tessellation, OpenAndGenusOneMeshes) {
  const LimitSurface grid(test::quad_grid(4, 3, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, true));
  expect_matches_control_topology(grid, tessellate(grid, {.resolution = 3}));
  const LimitSurface torus(test::torus(8, 6, 1.0, 0.4));
  const LimitTessellation t = tessellate(torus, {.resolution = 2});
  EXPECT_EQ(topology(t).euler(), 0);
  expect_matches_control_topology(torus, t);
}

TEST(Tessellation, LoopMeshes) {
  const LimitSurface sphere(test::icosphere(1, 1.0));
  const LimitTessellation t = tessellate(sphere, {.resolution = 4});
  EXPECT_EQ(t.triangles.size(), 80u * 16u);
  EXPECT_EQ(topology(t).euler(), 2);
  expect_matches_control_topology(sphere, t);
  const LimitSurface grid(test::triangle_grid(3, 2, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  expect_matches_control_topology(grid, tessellate(grid, {.resolution = 1}));
}

TEST(Tessellation, MixedMeshesAreWatertightAcrossQuadAndNgonEdges) {
  // Quads get N segments per edge, n-gon sub-faces N/2 on their half edges: both sides of each
  // control edge carry the same N + 1 vertices. An odd resolution is rounded up.
  const LimitSurface mixed(test::mixed_solid());
  const LimitTessellation t = tessellate(mixed, {.resolution = 3});
  EXPECT_EQ(t.resolution, 4);
  EXPECT_EQ(t.triangles.size(), 5u * 2u * 16u + 20u * 2u * 4u);
  expect_matches_control_topology(mixed, t);
  const LimitSurface wheel(test::flat_wheel(5, false));
  expect_matches_control_topology(wheel, tessellate(wheel, {.resolution = 2}));
}

TEST(Tessellation, SharedVerticesAreWeldedNotDuplicated) {
  // No two vertices at the same position (position hashing is not used, so duplicates would show
  // up as coincident vertices).
  const LimitSurface s(test::mixed_solid());
  const LimitTessellation t = tessellate(s, {.resolution = 4});
  std::vector<Eigen::Vector3d> sorted = t.positions;
  std::sort(sorted.begin(), sorted.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  });
  for (size_t i = 1; i < sorted.size(); ++i) {
    EXPECT_GT((sorted[i] - sorted[i - 1]).norm(), 1e-9);
  }
}

TEST(Tessellation, TargetTriangleCount) {
  const LimitSurface s(test::cube());
  for (long target : {100L, 10000L, 100000L}) {
    const LimitTessellation t = tessellate(s, {.target_triangles = target});
    const double ratio = static_cast<double>(t.triangles.size()) / static_cast<double>(target);
    // N is rounded to an integer: 12 N^2 is within a factor (1 +- 1/(2N))^2 of the target.
    const double slack = 1.0 / t.resolution + 0.25 / (t.resolution * t.resolution);
    EXPECT_NEAR(ratio, 1.0, slack) << target;
  }
  const LimitSurface mixed(test::mixed_solid());
  EXPECT_EQ(tessellate(mixed, {.target_triangles = 1}).resolution % 2, 0);
}

TEST(Tessellation, MaxTrianglesLowersTheResolution) {
  const LimitSurface s(test::cube());  // 6 quads: 12 N^2 triangles
  EXPECT_EQ(tessellate(s, {.resolution = 8, .max_triangles = 12L * 8 * 8}).resolution, 8);
  EXPECT_EQ(tessellate(s, {.resolution = 8, .max_triangles = (12L * 8 * 8) - 1}).resolution, 7);
  const LimitTessellation t = tessellate(s, {.resolution = 8, .max_triangles = 100});
  EXPECT_EQ(t.resolution, 2);  // 48 triangles; 3 would make 108
  EXPECT_EQ(t.triangles.size(), 48U);
  EXPECT_EQ(tessellate(s, {.resolution = 8, .max_triangles = 1}).resolution, 1);  // never below 1
  // It never raises the resolution, and target_triangles takes precedence.
  EXPECT_EQ(tessellate(s, {.resolution = 3, .max_triangles = 1000000}).resolution, 3);
  EXPECT_EQ(
      tessellate(s, {.resolution = 8, .target_triangles = 10000, .max_triangles = 100}).resolution,
      29);
  // Catmull-Clark with n-gons keeps an even resolution.
  const LimitSurface mixed(test::mixed_solid());
  EXPECT_EQ(tessellate(mixed, {.resolution = 8, .max_triangles = 1}).resolution, 2);
}

TEST(Tessellation, RejectsBadOptions) {
  const LimitSurface s(test::cube(), {.name = "cube"});
  EXPECT_THROW(tessellate(s, {.resolution = 0}), InvalidInputError);
  EXPECT_THROW(tessellate(s, {.resolution = 1025}), InvalidInputError);
  EXPECT_THROW(tessellate(s, {.resolution = 8, .target_triangles = -5}), InvalidInputError);
  EXPECT_THROW(tessellate(s, {.resolution = 8, .max_triangles = -5}), InvalidInputError);
}

}  // namespace
}  // namespace elastic
