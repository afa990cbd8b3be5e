// foot_point against answers it did not produce: the foot on a flat grid (the limit surface of an
// affine control net is the plane itself, so the foot of (x, y, h) is (x, y, 0)), the optimality
// condition on curved surfaces (goal - foot along the normal), and the stopping rule itself.
#include "elastic/projection/foot_point.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "elastic/core/error.h"
#include "surface/surface_test_meshes.h"

namespace elastic {
namespace {

TEST(FootPoint, OnAPlaneIsTheOrthogonalProjection) {
  // 4 x 4 unit quads on [0, 4]^2; the flat limit surface is the plane z = 0 (boundary included).
  const LimitSurface plane(test::quad_grid(4, 4, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  const Eigen::Vector3d goal(1.7, 2.2, 0.4);
  const SurfacePoint start = plane.vertex_point(12);  // (2, 2, 0), a face or so away
  const FootPoint foot = foot_point(plane, goal, start, {.tolerance = 1e-12, .max_steps = 6});
  ASSERT_TRUE(foot.converged);
  EXPECT_FALSE(foot.failed);
  EXPECT_NEAR((foot.d.position - Eigen::Vector3d(1.7, 2.2, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(std::abs(foot.normal.z()), 1.0, 1e-12);
  EXPECT_LE(foot.miss, 1e-12);
  EXPECT_GE(foot.steps, 1);
}

TEST(FootPoint, OnACurvedSurfaceTheMissIsNormal) {
  const LimitSurface sphere(test::uv_sphere(16, 12, 1.0, false));
  const SurfacePoint start = sphere.face_center(40);
  const SurfaceDerivatives d = sphere.derivatives(start);
  // A goal off the surface and a little along it from the start. Gauss-Newton converges linearly
  // here, with the rate curvature x normal distance (about 0.02 per step).
  const Eigen::Vector3d n = d.du.cross(d.dv).normalized();
  const Eigen::Vector3d goal = d.position + 0.05 * d.du.normalized() + 0.02 * n;
  const FootPoint foot = foot_point(sphere, goal, start, {.tolerance = 1e-13, .max_steps = 20});
  ASSERT_TRUE(foot.converged);
  const Eigen::Vector3d miss = goal - foot.d.position;
  EXPECT_LE((miss - foot.normal * foot.normal.dot(miss)).norm(), 1e-13);
  EXPECT_NEAR(miss.norm(), std::abs(foot.normal.dot(miss)), 1e-12);
  // Nearer than the start, and it moved.
  EXPECT_LT(miss.norm(), (goal - d.position).norm());
  EXPECT_FALSE(foot.point == start);
}

TEST(FootPoint, TheStoppingRule) {
  const LimitSurface plane(test::quad_grid(4, 4, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  const SurfacePoint start = plane.vertex_point(12);
  const Eigen::Vector3d goal(1.5, 2.5, 0.0);  // 0.707 away along the plane
  // A tolerance the start already meets: converged without a step.
  const FootPoint at_start = foot_point(plane, goal, start, {.tolerance = 1.0});
  EXPECT_TRUE(at_start.converged);
  EXPECT_EQ(at_start.steps, 0);
  EXPECT_EQ(at_start.point, start);
  EXPECT_NEAR(at_start.miss, std::sqrt(0.5), 1e-12);
  // No steps allowed and a miss above the tolerance: not converged, not failed.
  const FootPoint no_steps = foot_point(plane, goal, start, {.tolerance = 1e-3, .max_steps = 0});
  EXPECT_FALSE(no_steps.converged);
  EXPECT_FALSE(no_steps.failed);
  EXPECT_EQ(no_steps.steps, 0);
  // On the boundary with stop_at_boundary: gives up there.
  const SurfacePoint corner = plane.vertex_point(0);
  const FootPoint stopped = foot_point(plane, goal, corner, {.tolerance = 1e-9});
  EXPECT_TRUE(stopped.failed);
  EXPECT_FALSE(stopped.converged);
  // Without it, the boundary is just a start.
  const FootPoint through = foot_point(
      plane, goal, corner, {.tolerance = 1e-9, .max_steps = 20, .stop_at_boundary = false});
  EXPECT_TRUE(through.converged);
}

TEST(FootPoint, RejectsAPointOffTheSurface) {
  const LimitSurface plane(test::quad_grid(2, 2, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  EXPECT_THROW(foot_point(plane, {0, 0, 0}, SurfacePoint{99, 0.5, 0.5}), InvalidInputError);
}

TEST(PullBack, InvertsTheTangentMapAndRefusesParallelTangents) {
  const Eigen::Vector3d du(2, 0, 0), dv(1, 3, 0);
  Eigen::Vector2d delta;
  ASSERT_TRUE(pull_back(du, dv, 0.5 * du - 2.0 * dv + Eigen::Vector3d(0, 0, 7), delta));
  EXPECT_NEAR((delta - Eigen::Vector2d(0.5, -2.0)).norm(), 0.0, 1e-15);
  delta = Eigen::Vector2d(9, 9);
  EXPECT_FALSE(pull_back(du, 3.0 * du, dv, delta));
  EXPECT_EQ(delta, Eigen::Vector2d(9, 9));
}

}  // namespace
}  // namespace elastic
