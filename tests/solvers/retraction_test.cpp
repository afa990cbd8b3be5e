// The fast solver's retraction (solver_detail::parametric_retraction): a tangent step t from x
// must land where the magnet would put x + t (the foot of x + t on the surface), also where the
// step crosses ptex faces around an extraordinary vertex. The reference is the closest-point query
// (projection/closest_point.h), which shares no code with the parametric walk.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "elastic/projection/closest_point.h"
#include "elastic/shapes/procedural_shapes.h"
#include "elastic/solvers/solver_common.h"
#include "elastic/surface/limit_surface.h"

namespace elastic {
namespace {

using solver_detail::parametric_retraction;
using solver_detail::tangent_frame;

// A random tangent vector of length `length` at a point with unit normal n.
Eigen::Vector3d tangent_step(const Eigen::Vector3d& n, double length, std::mt19937& rng) {
  std::normal_distribution<double> g;
  Eigen::Vector3d v(g(rng), g(rng), g(rng));
  v -= n * n.dot(v);
  return length * v.normalized();
}

TEST(Retraction, LandsOnTheFootOfTheStepAroundExtraordinaryVertices) {
  // The quad sphere is a projected cube with 2 segments per edge: valence-3 vertices at the eight
  // cube corners, ptex faces about 0.5 across. Steps of 0.05-0.3 from points within 0.15 of a
  // corner cross one to three faces around it.
  const LimitSurface surface(
      make_sphere({.faces = ShapeFaces::Quads, .resolution = 8, .scale = 1.0}));
  const SurfaceProjector projector(surface);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> offset(-0.15, 0.15);
  int landed = 0, total = 0, hard = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d c =
        Eigen::Vector3d(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1) /
        std::sqrt(3.0);
    for (int k = 0; k < 12; ++k) {
      const ClosestPoint start =
          projector.closest(c + Eigen::Vector3d(offset(rng), offset(rng), offset(rng)));
      const SurfaceDerivatives frame = tangent_frame(surface, start.point);
      const double length = 0.05 + 0.25 * (k % 4) / 3.0;
      const Eigen::Vector3d t = tangent_step(start.normal, length, rng);
      ClosestPoint out;
      SurfaceDerivatives out_frame;
      ++total;
      // The plain first-order walk, for comparison: how far off it lands.
      const double a = frame.du.squaredNorm(), b = frame.du.dot(frame.dv),
                   cc = frame.dv.squaredNorm();
      const Eigen::Vector2d delta((cc * frame.du.dot(t) - b * frame.dv.dot(t)) / (a * cc - b * b),
                                  (a * frame.dv.dot(t) - b * frame.du.dot(t)) / (a * cc - b * b));
      const Eigen::Vector3d walked = surface.position(surface.walk(start.point, delta));
      const Eigen::Vector3d foot = projector.closest(start.position + t).position;
      if ((walked - foot).norm() > 0.05 * length) ++hard;
      if (!parametric_retraction(surface, start.point, start.position, frame, t, out, out_frame))
        continue;  // the caller falls back to the magnet: allowed
      ++landed;
      // The tangential tolerance of the retraction is 1e-3 |t|; the normal offset between the
      // landing point and the foot is second order in that.
      EXPECT_LT((out.position - foot).norm(), 2e-3 * length)
          << "corner " << corner << " step " << k << " length " << length;
      // The frame and normal belong to the landing point.
      const SurfaceDerivatives d = surface.derivatives(out.point);
      EXPECT_LT((out_frame.du - d.du).norm(), 1e-12 * d.du.norm());
      EXPECT_NEAR(out.normal.dot(d.du.cross(d.dv).normalized()), 1.0, 1e-12);
    }
  }
  // The cases must be hard for the plain walk (otherwise this test proves nothing) and the
  // corrected retraction must handle most of them itself.
  EXPECT_GT(hard, total / 10) << "steps do not cross irregular ptex edges";
  EXPECT_GT(landed, total * 9 / 10);
}

TEST(Retraction, IsExactOnAPlane) {
  const LimitSurface surface(make_plane({.faces = ShapeFaces::Quads, .resolution = 4}));
  const SurfaceProjector projector(surface);
  const ClosestPoint start = projector.closest(Eigen::Vector3d(0.1, -0.2, 0.0));
  const SurfaceDerivatives frame = tangent_frame(surface, start.point);
  const Eigen::Vector3d t(0.37, 0.21, 0.0);  // crosses ptex faces of size 0.5
  ClosestPoint out;
  SurfaceDerivatives out_frame;
  ASSERT_TRUE(
      parametric_retraction(surface, start.point, start.position, frame, t, out, out_frame));
  EXPECT_LT((out.position - (start.position + t)).norm(), 1e-9);
}

}  // namespace
}  // namespace elastic
