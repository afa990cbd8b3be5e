// The exponential map against answers it did not produce: on a plane it is p + v; a generalised
// cylinder (a curve times a line) is developable with z an isometric coordinate, so a geodesic at
// angle a from the axis climbs exactly L cos(a) over length L whatever the cross-section; on a
// sphere a geodesic of half the circumference reaches the antipode; the boundary stops a walk.
#include "elastic/projection/exponential_map.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "elastic/core/error.h"
#include "elastic/projection/closest_point.h"
#include "elastic/shapes/procedural_shapes.h"
#include "rigid_motion.h"

namespace elastic {
namespace {

TEST(ExponentialMap, OnAPlaneIsTheTranslation) {
  const LimitSurface plane(test::moved(make_plane({.resolution = 8}), test::rigid_motion()));
  const SurfacePoint from = plane.face_center(27);
  const Eigen::Vector3d p = plane.position(from);
  const Eigen::Matrix3d turn = test::rigid_motion().rotation();
  for (const Eigen::Vector3d& local : {Eigen::Vector3d(0.4, 0.1, 0), Eigen::Vector3d(-0.3, 0.55, 0),
                                       Eigen::Vector3d(0.0, -0.6, 0)}) {
    const Eigen::Vector3d v = turn * local;
    const GeodesicShot shot = exponential_map(plane, from, v);
    EXPECT_FALSE(shot.hit_boundary);
    EXPECT_LT((shot.position - (p + v)).norm(), 1e-12);
    EXPECT_NEAR(shot.length, v.norm(), 1e-12);
    EXPECT_LT((shot.direction - v.normalized()).norm(), 1e-12);
  }
  // The normal part of v is ignored; v = 0 stays.
  const Eigen::Vector3d normal = turn * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d v = turn * Eigen::Vector3d(0.2, 0.3, 0);
  EXPECT_LT((exponential_map(plane, from, v + 0.5 * normal).position - (p + v)).norm(), 1e-12);
  EXPECT_LT((exponential_map(plane, from, Eigen::Vector3d::Zero()).position - p).norm(), 1e-15);
  EXPECT_THROW(exponential_map(plane, from, normal), InvalidInputError);
  EXPECT_THROW(exponential_map(plane, from, Eigen::Vector3d(NAN, 0, 0)), InvalidInputError);
}

TEST(ExponentialMap, OnACylinderClimbsLinearly) {
  const LimitSurface cylinder(make_cylinder({.resolution = 24}));
  const SurfacePoint from = SurfaceProjector(cylinder).closest(Eigen::Vector3d(0.5, 0, 0.05)).point;
  const Eigen::Vector3d p = cylinder.position(from);
  const SurfaceDerivatives d = cylinder.derivatives(from);
  const Eigen::Vector3d n = d.du.cross(d.dv).normalized();
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d around = axis.cross(n).normalized();
  ASSERT_LT(std::abs(p.z()), 0.3);
  const double length = 0.6;  // a fifth of the way around
  for (const double degrees : {15.0, 40.0, 70.0, 90.0}) {
    const double a = degrees * std::numbers::pi / 180.0;
    const Eigen::Vector3d v = length * (std::cos(a) * axis + std::sin(a) * around);
    const GeodesicShot shot = exponential_map(cylinder, from, v, {.step = v.norm() / 64});
    ASSERT_FALSE(shot.hit_boundary) << degrees;
    // z is an isometric coordinate of the developable surface: exact up to the walk's O(h^2)
    // error (measured 1.6e-5 relative at 70 degrees, 4 times less per halving of the step; a
    // first-order walk is off by 1e-2).
    EXPECT_NEAR(shot.position.z() - p.z(), v.norm() * std::cos(a), 3e-5 * v.norm()) << degrees;
    // The tangent keeps its angle with the axis (Clairaut on a developable surface): the
    // transport turns it about the axis only.
    EXPECT_NEAR(shot.direction.dot(axis), std::cos(a), 1e-12) << degrees;
  }
}

TEST(ExponentialMap, OnASphereHalfTheCircumferenceReachesTheAntipode) {
  const LimitSurface sphere(make_sphere({.resolution = 96}));
  for (const int face : {5, 77, 301}) {
    const SurfacePoint from = sphere.face_center(face);
    const Eigen::Vector3d p = sphere.position(from);
    const SurfaceDerivatives d = sphere.derivatives(from);
    const double radius = p.norm();
    const GeodesicShot shot =
        exponential_map(sphere, from, std::numbers::pi * radius * d.du.normalized());
    // The limit of the subdivided cube is a sphere to about 1e-3 of its radius, and the walk
    // crosses two of the cube's extraordinary corners' neighbourhoods at most.
    EXPECT_LT((shot.position + p).norm(), 1e-2 * radius) << face;
  }
}

TEST(ExponentialMap, TheErrorIsSecondOrderInTheStep) {
  const LimitSurface torus(make_torus({.resolution = 32}));
  const SurfacePoint from = torus.face_center(100);
  const SurfaceDerivatives d = torus.derivatives(from);
  const Eigen::Vector3d v = 1.5 * (d.du.normalized() + 0.5 * d.dv.normalized());
  const Eigen::Vector3d reference =
      exponential_map(torus, from, v, {.step = v.norm() / 1024}).position;
  const double coarse =
      (exponential_map(torus, from, v, {.step = v.norm() / 16}).position - reference).norm();
  const double fine =
      (exponential_map(torus, from, v, {.step = v.norm() / 32}).position - reference).norm();
  EXPECT_GT(coarse, 0.0);
  // Halving the step divides the error by about 4 (2 for a first-order walk).
  EXPECT_LT(fine, coarse / 3.0) << coarse << " " << fine;
}

TEST(ExponentialMap, StopsAtTheBoundary) {
  const LimitSurface plane(make_plane({.resolution = 8}));  // [-1, 1]^2
  const SurfacePoint from = plane.face_center(27);
  const Eigen::Vector3d p = plane.position(from);
  const GeodesicShot shot = exponential_map(plane, from, Eigen::Vector3d(3.0, 0, 0));
  EXPECT_TRUE(shot.hit_boundary);
  EXPECT_NEAR(shot.position.x(), 1.0, 1e-9);
  EXPECT_NEAR(shot.length, 1.0 - p.x(), 1e-9);
}

TEST(ExponentialMap, WorldUpFrame) {
  const UpFrame f = world_up_frame(Eigen::Vector3d(0, 0, 1));
  EXPECT_LT((f.up - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  EXPECT_LT((f.right - Eigen::Vector3d::UnitX()).norm(), 1e-15);
  const UpFrame top = world_up_frame(Eigen::Vector3d(0, 1, 0));
  EXPECT_LT((top.up + Eigen::Vector3d::UnitZ()).norm(), 1e-15);
  EXPECT_NEAR(top.right.cross(top.up).dot(top.normal), 1.0, 1e-15);
}

}  // namespace
}  // namespace elastic
