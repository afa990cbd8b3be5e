// DirectedEdges against edges listed by hand on a small fan.
#include "elastic/core/directed_edges.h"

#include <gtest/gtest.h>

#include <vector>

namespace elastic {
namespace {

// Four counter-clockwise triangles around vertex 0: (0 1 2), (0 2 3), (0 3 4), and (0 1 2) again.
const std::vector<Eigen::Vector3i> kFan = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 1, 2}};

TEST(DirectedEdges, EachEdgeLeavesItsFirstVertexInTriangleOrder) {
  const DirectedEdges edges(kFan, 5);
  EXPECT_EQ(edges.num_vertices(), 5);
  EXPECT_EQ(edges.end(0) - edges.begin(0), 4);  // 0->1, 0->2, 0->3, 0->1
  EXPECT_EQ(edges.end(4) - edges.begin(4), 1);  // 4->0
  std::vector<int> out;
  for (int e = edges.begin(0); e < edges.end(0); ++e) {
    out.push_back(edges.to(e));
  }
  EXPECT_EQ(out, (std::vector<int>{1, 2, 3, 1}));
  // 2 -> 3 is in triangle 1 only; 3 -> 2 is in none; 1 -> 2 first in triangle 0, repeated in 3.
  EXPECT_EQ(edges.triangle(edges.find(2, 3)), 1);
  EXPECT_EQ(edges.find(3, 2), -1);
  EXPECT_EQ(edges.triangle(edges.find(1, 2)), 0);
  EXPECT_EQ(edges.find(4, 3), -1);
  EXPECT_EQ(edges.triangle(edges.find(4, 0)), 2);
}

TEST(DirectedEdges, ASubsetKeepsOnlyItsTrianglesWithTheirOwnIndices) {
  const std::vector<int> subset = {2, 1};
  const DirectedEdges edges(kFan, 5, &subset);
  EXPECT_EQ(edges.find(0, 1), -1);
  EXPECT_EQ(edges.triangle(edges.find(0, 3)), 2);  // (0 3 4) has 0 -> 3, (0 2 3) has 3 -> 0
  EXPECT_EQ(edges.triangle(edges.find(3, 0)), 1);
  EXPECT_EQ(edges.triangle(edges.find(3, 4)), 2);
  EXPECT_EQ(edges.end(1) - edges.begin(1), 0);
}

}  // namespace
}  // namespace elastic
