// LimitSurface::walk and on_boundary: straight walks across ptex faces land where the affine
// unfolding says (checked on flat affine meshes, whose limit is known exactly), are reversible, are
// continuous across every ptex edge, and stop on the boundary.
#include <gtest/gtest.h>

#include <array>
#include <random>

#include "elastic/surface/limit_surface.h"
#include "surface/surface_test_meshes.h"

namespace elastic {
namespace {

using test::quad_grid;

/// The 3D tangent step J * delta at p (J = [du dv]).
Eigen::Vector3d tangent_step(const LimitSurface& s, const SurfacePoint& p,
                             const Eigen::Vector2d& delta) {
  const SurfaceDerivatives d = s.derivatives(p);
  return delta.x() * d.du + delta.y() * d.dv;
}

/// On a surface that is an affine image of the plane (flat affine control grids), the parameter
/// step delta expressed in the new face is J_new^-1 J_old delta.
Eigen::Vector2d step_in_face(const LimitSurface& s, const SurfacePoint& p,
                             const Eigen::Vector3d& t) {
  const SurfaceDerivatives d = s.derivatives(p);
  Eigen::Matrix<double, 3, 2> J;
  J << d.du, d.dv;
  return J.colPivHouseholderQr().solve(t);
}

TEST(Walk, OnAnAffineQuadGridWithRotatedFacesLandsOnTheStraightLine) {
  // The limit of a flat affine grid is the affine map, so a straight parameter walk is a straight
  // 3D segment: the end point is start + J delta exactly, whichever way the faces are rotated.
  // Tolerance: round-off accumulated over a few crossings (coordinates ~10).
  const Eigen::Vector3d a(1.0, 0.1, 0.0), b(0.2, 0.9, 0.0);
  const LimitSurface s(quad_grid(8, 8, {0, 0, 0}, a, b, true), {.name = "rotated grid"});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uni(0.0, 1.0), step(-2.5, 2.5);
  int total_crossings = 0;
  for (int trial = 0; trial < 200; ++trial) {
    // Start in the middle 2 x 2 faces, walk up to 2.5 faces: never reaches the boundary.
    const int i = 3 + trial % 2, j = 3 + (trial / 2) % 2;
    const SurfacePoint from{j * 8 + i, uni(rng), uni(rng)};
    const Eigen::Vector2d delta(step(rng), step(rng));
    int crossed = 0;
    const SurfacePoint to = s.walk(from, delta, &crossed);
    total_crossings += crossed;
    ASSERT_TRUE(s.in_domain(to));
    const Eigen::Vector3d expected = s.position(from) + tangent_step(s, from, delta);
    EXPECT_LT((s.position(to) - expected).norm(), 1e-12) << "trial " << trial;
    // And back: the reverse step, expressed in the arrival face, returns to the start.
    const Eigen::Vector2d back = step_in_face(s, to, -tangent_step(s, from, delta));
    const SurfacePoint home = s.walk(to, back);
    EXPECT_LT((s.position(home) - s.position(from)).norm(), 1e-11) << "trial " << trial;
  }
  EXPECT_GT(total_crossings, 200);  // the walks did cross faces (most of them several)
}

TEST(Walk, OnAFlatRegularTriangleGridLandsOnTheStraightLine) {
  // Loop's box splines reproduce affine functions on a regular (valence-6) triangle grid; walk in
  // the interior, two rings away from the boundary where vertices are irregular.
  const Eigen::Vector3d a(1.0, 0.0, 0.0), b(0.5, 0.9, 0.0);
  const LimitSurface s(test::triangle_grid(10, 10, {0, 0, 0}, a, b), {.name = "triangle grid"});
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> uni(0.0, 1.0), step(-1.5, 1.5);
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int i = 4 + trial % 2, j = 4 + (trial / 2) % 2;
    const int face = 2 * (j * 10 + i) + trial % 2;
    double u = uni(rng), v = uni(rng);
    if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
    const SurfacePoint from{face, u, v};
    const Eigen::Vector2d delta(step(rng), step(rng));
    const SurfacePoint to = s.walk(from, delta);
    ASSERT_TRUE(s.in_domain(to, 1e-15));
    const Eigen::Vector3d expected = s.position(from) + tangent_step(s, from, delta);
    EXPECT_LT((s.position(to) - expected).norm(), 1e-12) << "trial " << trial;
    ++checked;
  }
  EXPECT_EQ(checked, 200);
}

TEST(Walk, IsReversibleOnCurvedMeshes) {
  // After a crossing the remaining step continues as A * delta in the neighbour, with A the linear
  // part of the edge's similarity (rotation by a multiple of 90 degrees, scale 2 or 1/2 between a
  // quad and an n-gon's sub-face). The walk is affine in the step once the exit point is fixed, so
  // A * delta = (walk(from, (1 + e) delta) - walk(from, delta)) / e exactly (to round-off
  // ~1e-16/e). Walking back by -A * delta must return to the start (to round-off).
  for (const PolygonMesh& mesh : {test::cube(), test::mixed_solid()}) {
    const LimitSurface s(mesh);
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> uni(0.05, 0.95), step(-0.8, 0.8);
    int checked = 0;
    for (int trial = 0; trial < 100; ++trial) {
      const SurfacePoint from{trial % s.num_faces(), uni(rng), uni(rng)};
      const Eigen::Vector2d delta(step(rng), step(rng));
      int crossed = 0, crossed_longer = 0;
      const SurfacePoint to = s.walk(from, delta, &crossed);
      const double e = 1e-3;
      const SurfacePoint longer = s.walk(from, (1 + e) * delta, &crossed_longer);
      if (crossed == 0 || crossed_longer != crossed || longer.face != to.face) continue;
      const Eigen::Vector2d continued = (longer.uv() - to.uv()) / e;
      int crossed_back = 0;
      const SurfacePoint home = s.walk(to, -continued, &crossed_back);
      EXPECT_EQ(crossed_back, crossed);
      EXPECT_EQ(home.face, from.face);
      EXPECT_NEAR(home.u, from.u, 1e-11);
      EXPECT_NEAR(home.v, from.v, 1e-11);
      ++checked;
    }
    EXPECT_GT(checked, 30);
  }
}

TEST(Walk, CrossingEveryPtexEdgeIsContinuous) {
  // From just inside every ptex edge, a tiny step across lands in the neighbour at the same 3D
  // point (to O(step)), on every kind of edge: quad-quad, quad-sub-face (scale 2), sub-face spokes,
  // Loop triangles, and rotated neighbours.
  PolygonMesh mixed = test::mixed_solid();
  test::jitter(mixed, 0.1, 2);
  const std::array<PolygonMesh, 3> meshes{mixed, test::cube(), test::icosphere(1, 1.0)};
  for (const PolygonMesh& mesh : meshes) {
    const LimitSurface s(mesh);
    const bool tri = s.triangular_domain();
    const double eps = 1e-9;
    for (int f = 0; f < s.num_faces(); ++f) {
      for (int k = 0; k < (tri ? 3 : 4); ++k) {
        for (double t : {0.1, 0.45, 0.55, 0.9}) {
          // Point on edge k at parameter t, its outward normal in (u, v).
          Eigen::Vector2d on, out;
          if (tri) {
            on = k == 0   ? Eigen::Vector2d(t, 0)
                 : k == 1 ? Eigen::Vector2d(1 - t, t)
                          : Eigen::Vector2d(0, 1 - t);
            out = k == 0   ? Eigen::Vector2d(0, -1)
                  : k == 1 ? Eigen::Vector2d(1, 1)
                           : Eigen::Vector2d(-1, 0);
          } else {
            on = k == 0   ? Eigen::Vector2d(t, 0)
                 : k == 1 ? Eigen::Vector2d(1, t)
                 : k == 2 ? Eigen::Vector2d(1 - t, 1)
                          : Eigen::Vector2d(0, 1 - t);
            out = k == 0   ? Eigen::Vector2d(0, -1)
                  : k == 1 ? Eigen::Vector2d(1, 0)
                  : k == 2 ? Eigen::Vector2d(0, 1)
                           : Eigen::Vector2d(-1, 0);
          }
          const SurfacePoint start{f, on.x() - eps * out.x(), on.y() - eps * out.y()};
          int crossed = 0;
          const SurfacePoint to = s.walk(start, 2 * eps * out, &crossed);
          EXPECT_EQ(crossed, 1);
          EXPECT_NE(to.face, f);
          const Eigen::Vector3d x0 = s.position({f, on.x(), on.y()});
          EXPECT_LT((s.position(to) - x0).norm(), 1e-7)
              << "face " << f << " edge " << k << " t " << t;
        }
      }
    }
  }
}

TEST(Walk, StopsOnTheBoundary) {
  const LimitSurface s(quad_grid(3, 3, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, true));
  // From the middle face, walk far to the right: stops on the boundary edge x = 3.
  int crossed = 0;
  const SurfacePoint to = s.walk(s.face_center(4), {0.0, 0.0}, &crossed);
  EXPECT_EQ(crossed, 0);
  EXPECT_EQ(to, s.face_center(4));
  for (const Eigen::Vector2d& dir :
       {Eigen::Vector2d(10, 0.3), Eigen::Vector2d(-0.2, -10), Eigen::Vector2d(7, 7)}) {
    const SurfacePoint end = s.walk(s.face_center(4), dir, &crossed);
    EXPECT_TRUE(s.on_boundary(end));
    EXPECT_TRUE(s.in_domain(end));
    EXPECT_GE(crossed, 1);
    const Eigen::Vector3d x = s.position(end);
    EXPECT_LT(
        std::min({std::abs(x.x()), std::abs(x.x() - 3), std::abs(x.y()), std::abs(x.y() - 3)}),
        1e-12);
  }
  // Interior points and interior edges are not on the boundary.
  EXPECT_FALSE(s.on_boundary(s.face_center(4)));
  EXPECT_FALSE(s.on_boundary({4, 0.0, 0.5}));
  EXPECT_FALSE(s.on_boundary({4, 1e-3, 0.5}, 1e-4));
}

TEST(Walk, ThroughAnExtraordinaryVertexTerminates) {
  // A walk aimed exactly at a cube corner (valence 3) passes through the vertex; it must end in a
  // valid point a finite number of crossings later.
  const LimitSurface s(test::cube());
  int crossed = 0;
  const SurfacePoint to = s.walk({0, 0.5, 0.5}, {-1.0, -1.0}, &crossed);
  EXPECT_TRUE(s.in_domain(to));
  EXPECT_LT(crossed, 100);
}

}  // namespace
}  // namespace elastic
