#include "elastic/core/triangle_locator_2d.h"

#include <gtest/gtest.h>

#include <random>

namespace elastic {
namespace {

// An n x n grid of the unit square split into 2 n^2 triangles.
void unit_square_grid(int n, std::vector<Eigen::Vector2d>& v, std::vector<Eigen::Vector3i>& t) {
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) v.emplace_back(double(i) / n, double(j) / n);
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      t.emplace_back(a, a + 1, a + n + 2);
      t.emplace_back(a, a + n + 2, a + n + 1);
    }
  }
}

TEST(TriangleLocator2D, FindsContainingTriangleAndReproducesPoint) {
  std::vector<Eigen::Vector2d> v;
  std::vector<Eigen::Vector3i> t;
  unit_square_grid(17, v, t);
  const TriangleLocator2D locator(v, t);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector2d p(u(rng), u(rng));
    const auto hit = locator.locate(p);
    ASSERT_TRUE(hit.found());
    EXPECT_GE(hit.barycentric.minCoeff(), -1e-12);
    EXPECT_NEAR(hit.barycentric.sum(), 1.0, 1e-14);
    const Eigen::Vector3i& tri = t[hit.triangle];
    const Eigen::Vector2d q = hit.barycentric[0] * v[tri[0]] + hit.barycentric[1] * v[tri[1]] +
                              hit.barycentric[2] * v[tri[2]];
    EXPECT_LT((q - p).norm(), 1e-14);
  }
}

TEST(TriangleLocator2D, OutsideIsNotFoundAndNearestClamps) {
  std::vector<Eigen::Vector2d> v;
  std::vector<Eigen::Vector3i> t;
  unit_square_grid(5, v, t);
  const TriangleLocator2D locator(v, t);
  EXPECT_FALSE(locator.locate({1.5, 0.5}).found());
  EXPECT_FALSE(locator.locate({-0.01, -0.01}).found());
  // The nearest point of the square to (1.5, 0.5) is (1, 0.5).
  const auto hit = locator.nearest({1.5, 0.5});
  ASSERT_TRUE(hit.found());
  const Eigen::Vector3i& tri = t[hit.triangle];
  const Eigen::Vector2d q = hit.barycentric[0] * v[tri[0]] + hit.barycentric[1] * v[tri[1]] +
                            hit.barycentric[2] * v[tri[2]];
  EXPECT_NEAR(q.x(), 1.0, 1e-14);
  EXPECT_NEAR(q.y(), 0.5, 1e-14);
  // Far away: still the right corner.
  const auto far = locator.nearest({-100.0, -50.0});
  const Eigen::Vector3i& ft = t[far.triangle];
  const Eigen::Vector2d fq =
      far.barycentric[0] * v[ft[0]] + far.barycentric[1] * v[ft[1]] + far.barycentric[2] * v[ft[2]];
  EXPECT_LT(fq.norm(), 1e-14);
}

TEST(TriangleLocator2D, NonFiniteAndEmpty) {
  const TriangleLocator2D empty;
  EXPECT_FALSE(empty.locate({0, 0}).found());
  EXPECT_FALSE(empty.nearest({0, 0}).found());
  std::vector<Eigen::Vector2d> v;
  std::vector<Eigen::Vector3i> t;
  unit_square_grid(2, v, t);
  const TriangleLocator2D locator(v, t);
  EXPECT_FALSE(locator.locate({std::nan(""), 0.5}).found());
}

}  // namespace
}  // namespace elastic
