// ParticleGrid: springs and angular springs from the mesh (§4.1, Fig. 1).
#include "elastic/particles/particle_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>

namespace elastic {
namespace {

// Two unit quads side by side and a triangle on top of the left one:
//
//   6
//   | .
//   3--4--5
//   |  |  |
//   0--1--2
//
// Vertices: 0 (0,0), 1 (1,0), 2 (2,0), 3 (0,1), 4 (1,1), 5 (2,1), 6 (1,2) (6 drawn to the left for
// space). Faces (counter-clockwise seen from +z): quad 0-1-4-3, quad 1-2-5-4, triangle 3-4-6.
ParticleGrid small_grid() {
  ParticleGrid grid;
  const double xy[7][2] = {{0, 0}, {1, 0}, {2, 0}, {0, 1}, {1, 1}, {2, 1}, {1, 2}};
  std::vector<GridMesh::VertexHandle> v;
  for (const auto& p : xy) v.push_back(grid.mesh.add_vertex(GridMesh::Point(p[0], p[1], 0.0)));
  grid.mesh.add_face({v[0], v[1], v[4], v[3]});
  grid.mesh.add_face({v[1], v[2], v[5], v[4]});
  grid.mesh.add_face({v[3], v[4], v[6]});
  return grid;
}

TEST(ParticleGrid, SourcePositionsAreTheMeshPoints) {
  const ParticleGrid grid = small_grid();
  const Eigen::Matrix3Xd x = grid.source_positions();
  ASSERT_EQ(x.cols(), 7);
  EXPECT_EQ(x.col(5), Eigen::Vector3d(2, 1, 0));
  EXPECT_EQ(x.col(6), Eigen::Vector3d(1, 2, 0));
}

TEST(ParticleGrid, NormalSpringsAreTheEdgesWithSourceLengths) {
  ParticleGrid grid = small_grid();
  grid.build_springs();
  // 2 quads + 1 triangle sharing two edges: 4 + 4 + 3 - 2 = 9 edges.
  ASSERT_EQ(grid.springs.size(), 9u);
  std::set<std::pair<int, int>> edges;
  for (const Spring& s : grid.springs) {
    edges.insert({std::min(s.i, s.j), std::max(s.i, s.j)});
    // Hand-computed lengths: unit edges, except the triangle's side 3-6 from (0,1) to (1,2),
    // sqrt(2).
    const bool slanted = std::min(s.i, s.j) == 3 && std::max(s.i, s.j) == 6;
    EXPECT_DOUBLE_EQ(s.rest, slanted ? std::sqrt(2.0) : 1.0) << s.i << "-" << s.j;
  }
  const std::set<std::pair<int, int>> expected = {{0, 1}, {1, 2}, {0, 3}, {1, 4}, {2, 5},
                                                  {3, 4}, {4, 5}, {3, 6}, {4, 6}};
  EXPECT_EQ(edges, expected);
}

TEST(ParticleGrid, AngularSpringsAreFaceCornersWithVirtualMidpoints) {
  ParticleGrid grid = small_grid();
  grid.build_springs();
  ASSERT_EQ(grid.angular_springs.size(), 4u + 4u + 3u);
  std::set<std::tuple<int, int, int>> corners;
  for (const AngularSpring& a : grid.angular_springs) corners.insert({a.i, a.a, a.b});
  // Corner 1 of quad 0-1-4-3: neighbours 0 (before) and 4 (after); virtual point (0.5, 0.5):
  // distance from (1,0) is sqrt(0.5) -- a right angle between unit sides.
  EXPECT_TRUE(corners.count({1, 0, 4}));
  EXPECT_TRUE(corners.count({4, 3, 6}));  // triangle 3-4-6, corner 4
  EXPECT_TRUE(corners.count({6, 4, 3}));  // triangle corner 6
  for (const AngularSpring& a : grid.angular_springs) {
    if (a.i == 1 && a.a == 0 && a.b == 4) {
      EXPECT_DOUBLE_EQ(a.rest, std::sqrt(0.5));
    }
    // Triangle corner 6 at (1,2), neighbours (1,1) and (0,1): midpoint (0.5, 1), distance
    // sqrt(1.25).
    if (a.i == 6) {
      EXPECT_DOUBLE_EQ(a.rest, std::sqrt(1.25));
    }
  }
}

TEST(ParticleGrid, RestValuesFollowMovedSourcePositions) {
  ParticleGrid grid = small_grid();
  // Shear the grid: x += y. Rest values must be the new distances, e.g. edge 0-3 becomes sqrt(2).
  for (const auto v : grid.mesh.vertices()) {
    auto p = grid.mesh.point(v);
    grid.mesh.point(v) = GridMesh::Point(p[0] + p[1], p[1], p[2]);
  }
  grid.build_springs();
  for (const Spring& s : grid.springs) {
    if (std::min(s.i, s.j) == 0 && std::max(s.i, s.j) == 3) {
      EXPECT_DOUBLE_EQ(s.rest, std::sqrt(2.0));
    }
  }
  for (const AngularSpring& a : grid.angular_springs) {
    // Corner 0 of quad 0-1-4-3 after the shear: x0 = (0,0), x3 = (1,1), x1 = (1,0): midpoint (1,
    // 0.5).
    if (a.i == 0) {
      EXPECT_DOUBLE_EQ(a.rest, std::sqrt(1.25));
    }
  }
}

}  // namespace
}  // namespace elastic

namespace elastic {
namespace {

// Two quads sharing an edge, with source UVs: the written mesh has the grid's faces in order, the
// given positions, and per-particle texture coordinates.
TEST(ParticleGridOutput, PolygonMeshHasTheGridFacesPositionsAndUVs) {
  ParticleGrid grid;
  std::vector<GridMesh::VertexHandle> v;
  for (int k = 0; k < 6; ++k) v.push_back(grid.mesh.add_vertex(GridMesh::Point(k % 3, k / 3, 0)));
  grid.mesh.add_face(v[0], v[1], v[4], v[3]);
  grid.mesh.add_face(v[1], v[2], v[5], v[4]);
  for (int k = 0; k < 6; ++k) grid.source_uv.emplace_back(0.5 * (k % 3), k / 3);
  Eigen::Matrix3Xd moved = grid.source_positions();
  moved.row(2).setConstant(7.0);
  const PolygonMesh mesh = to_polygon_mesh(grid, moved);
  ASSERT_EQ(mesh.num_faces(), 2);
  EXPECT_EQ(std::vector<int>(mesh.face(1).begin(), mesh.face(1).end()),
            (std::vector<int>{1, 2, 5, 4}));
  EXPECT_EQ(mesh.positions[5], Eigen::Vector3d(2, 1, 7));
  ASSERT_TRUE(mesh.has_texcoords());
  EXPECT_EQ(mesh.texcoords[mesh.corner_texcoords[6]],
            Eigen::Vector2d(1.0, 1.0));  // face 1, corner 2: particle 5
}

}  // namespace
}  // namespace elastic
