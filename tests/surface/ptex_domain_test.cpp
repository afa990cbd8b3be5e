// PtexDomain against the domain's plane geometry, derived here from the corners alone: edge lines
// through consecutive corners, distances by the 2D cross product, the centroid as the centre.
#include "elastic/surface/ptex_domain.h"

#include <gtest/gtest.h>

#include <cmath>

#include "elastic/surface/limit_surface.h"
#include "surface/surface_test_meshes.h"

namespace elastic {
namespace {

// Distance from q to the line through a and b, positive on the left of a -> b (the inside of a
// counter-clockwise domain): cross(b - a, q - a) / |b - a|.
double left_distance(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& q) {
  const Eigen::Vector2d e = b - a, w = q - a;
  return (e.x() * w.y() - e.y() * w.x()) / e.norm();
}

TEST(PtexDomain, CornersAreTheUnitSquareAndTriangle) {
  const PtexDomain square(false), triangle(true);
  EXPECT_EQ(square.num_corners(), 4);
  EXPECT_EQ(triangle.num_corners(), 3);
  EXPECT_EQ(square.corner(2), Eigen::Vector2d(1, 1));
  EXPECT_EQ(square.corner(3), Eigen::Vector2d(0, 1));
  EXPECT_EQ(triangle.corner(1), Eigen::Vector2d(1, 0));
  EXPECT_EQ(triangle.corner(2), Eigen::Vector2d(0, 1));
  EXPECT_EQ(square.centre(), Eigen::Vector2d(0.5, 0.5));
  EXPECT_EQ(triangle.centre(),
            (triangle.corner(0) + triangle.corner(1) + triangle.corner(2)) / 3.0);
}

TEST(PtexDomain, EdgesAgreeWithTheLinesThroughTheCorners) {
  const Eigen::Vector2d probes[] = {{0.3, 0.2}, {0.0, 0.7}, {0.9, 0.05}, {1.4, -0.3}, {0.5, 0.5}};
  for (const bool tri : {false, true}) {
    const PtexDomain domain(tri);
    const int n = domain.num_corners();
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector2d a = domain.corner(k), b = domain.corner((k + 1) % n);
      const DomainEdge& e = domain.edge(k);
      EXPECT_NEAR(e.normal.norm(), 1.0, 1e-15);
      EXPECT_NEAR(std::abs(e.tangent.dot((b - a).normalized())), 1.0, 1e-15);
      EXPECT_NEAR((e.midpoint - 0.5 * (a + b)).norm(), 0.0, 1e-15);
      EXPECT_NEAR((domain.edge_point(k, 0.25) - (0.75 * a + 0.25 * b)).norm(), 0.0, 1e-15);
      for (const Eigen::Vector2d& q : probes) {
        EXPECT_NEAR(domain.inside_distance(k, q), left_distance(a, b, q), 1e-15) << k;
        // edge_parameter inverts edge_point along the edge.
        EXPECT_NEAR(domain.edge_parameter(k, domain.edge_point(k, q.x())), q.x(), 1e-15);
      }
      // The midpoint lies on its edge and on no other.
      EXPECT_EQ(domain.edges_within(e.midpoint, 1e-12), 1);
      EXPECT_EQ(domain.edges_within(a, 1e-12), 2);
    }
  }
}

TEST(PtexDomain, ContainsAndClamp) {
  const PtexDomain square(false), triangle(true);
  EXPECT_TRUE(square.contains({1.0, 1.0}));
  EXPECT_FALSE(square.contains({1.0 + 1e-9, 0.5}));
  EXPECT_TRUE(square.contains({1.0 + 1e-9, 0.5}, 1e-8));
  EXPECT_FALSE(square.contains({std::nan(""), 0.5}));
  EXPECT_TRUE(triangle.contains({0.5, 0.5}));
  EXPECT_FALSE(triangle.contains({0.6, 0.5}));
  EXPECT_EQ(square.clamp(Eigen::Vector2d(-0.1, 1.2)), Eigen::Vector2d(0.0, 1.0));
  // Beyond the hypotenuse: back onto it along the ray from the origin.
  const Eigen::Vector2d pulled = triangle.clamp(Eigen::Vector2d(0.6, 0.6));
  EXPECT_NEAR(pulled.x() + pulled.y(), 1.0, 1e-15);
  EXPECT_NEAR(pulled.x(), pulled.y(), 1e-15);
  const SurfacePoint p = triangle.clamp(SurfacePoint{7, -1.0, 0.25});
  EXPECT_EQ(p, (SurfacePoint{7, 0.0, 0.25}));
}

TEST(PtexDomain, TheNudgeMovesTheGivenDistanceTowardsTheCentre) {
  for (const bool tri : {false, true}) {
    const PtexDomain domain(tri);
    for (int k = 0; k < domain.num_corners(); ++k) {
      const Eigen::Vector2d c = domain.corner(k);
      const SurfacePoint p{3, c.x(), c.y()};
      const SurfacePoint q = domain.towards_centre(p, kSingularNudge);
      EXPECT_EQ(q.face, 3);
      // (u, v) near 1 carry a rounding of eps = 1.1e-16 each: the tolerance is a few of those.
      EXPECT_NEAR((q.uv() - p.uv()).norm(), kSingularNudge, 1e-15);
      // On the segment from the corner to the centre, and inside the domain.
      EXPECT_NEAR(left_distance(p.uv(), domain.centre(), q.uv()), 0.0, 1e-15);
      EXPECT_TRUE(domain.contains(q.uv()));
      EXPECT_EQ(domain.edges_within(domain.towards_centre(p, kInsideNudge).uv(), 0.0), 0);
    }
  }
}

TEST(PtexDomain, IsTheLimitSurfacesDomain) {
  const LimitSurface quads(test::cube());
  const LimitSurface tris(test::triangle_grid(2, 2, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  EXPECT_FALSE(quads.domain().triangle());
  EXPECT_TRUE(tris.domain().triangle());
  EXPECT_EQ(tris.face_center(1).uv(), tris.domain().centre());
  EXPECT_EQ(quads.face_center(4).uv(), quads.domain().centre());
}

}  // namespace
}  // namespace elastic
