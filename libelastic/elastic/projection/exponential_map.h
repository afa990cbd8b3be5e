#pragma once
/// \file
/// The exponential map of the limit surface: from a point p and a tangent vector v at p, the point
/// reached by walking |v| along the geodesic that leaves p in the direction of v. A decal placed by
/// the exponential map (mapping/map_decal.h, baselines/decal_baseline.h) lays a flat feature on the
/// surface by its geodesic polar coordinates around p, as in Schmidt et al. 2006 ("Interactive
/// decal compositing with discrete exponential maps") and the log-map decals of the vector heat
/// method; here the geodesics are shot directly on the smooth limit surface.
///
/// Numerics (geodesic shooting). Each step goes h along the current unit tangent t, x + h t, and
/// is put back on the surface by foot_point (projection/foot_point.h), warm-started at the
/// current point: the new point y, off the geodesic by O(h^3) (the geodesic's curvature is normal
/// to the surface). A geodesic's tangent is parallel along it, so the tangent at y is t turned by
/// the least rotation taking the unit normal at x to the one at y (the discrete Levi-Civita
/// transport), projected onto the tangent plane at y and normalised: exact on a sphere, O(h^3) per
/// step elsewhere, so the walk's error is O(h^2) (a reflection of t about the chord, exact on a
/// sphere too, was measured first order on a torus). A step whose foot point does not settle
/// (curvature large for h) is halved. The arc
/// length of a step is measured from its chord |y - x| and the normal curvature kappa = 2 |n_y .
/// (y - x)| / |y - x|^2 it shows (exact for a circular arc): 2 asin(kappa |y - x| / 2) / kappa.
/// The last step is shortened (two secant corrections) so that the arc lengths add up to |v|
/// within 1e-12 relative.
///
/// The walk stops early where it meets the surface's boundary (an open mesh): `hit_boundary` then
/// says so and `length` how far it got.

#include <Eigen/Core>

#include "elastic/surface/limit_surface.h"
#include "elastic/surface/surface_point.h"

namespace elastic {

struct ExponentialMapOptions {
  /// Largest step along the geodesic, in 3D length units. 0: |v| / 32. A step is also never
  /// longer than |v| / 4.
  double step = 0.0;
  /// Give up (InvalidInputError) after this many steps: a guard against a step far below |v|.
  int max_steps = 100000;
};

struct GeodesicShot {
  SurfacePoint point;                                   ///< where the walk ended
  Eigen::Vector3d position = Eigen::Vector3d::Zero();   ///< its limit position
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  ///< unit tangent of the geodesic there
  double length = 0.0;        ///< arc length walked (|v| unless the boundary stopped it)
  int steps = 0;              ///< steps taken
  bool hit_boundary = false;  ///< the walk reached the surface boundary before |v|
};

/// exp_p(v): walks |v| from `from` along the geodesic leaving it in the direction of `v`, a 3D
/// vector whose component normal to the surface at `from` is ignored. v = 0, or |v| below the
/// positions' round-off (1e-12 times max(1, |d(from)|)), returns `from`.
/// \throws InvalidInputError when `from` is not a point of `surface`, v is not finite, v has a
///         non-zero normal part only (no tangential direction), or the step budget runs out.
GeodesicShot exponential_map(const LimitSurface& surface, const SurfacePoint& from,
                             const Eigen::Vector3d& v, const ExponentialMapOptions& options = {});

/// A right-handed unit frame (right, up, normal) of the tangent plane at a point with unit normal
/// `normal`: `up` is the world +Y projected onto the tangent plane, or, where the normal is within
/// about 8 degrees of +Y or -Y (|normal . Y| > 0.99), the world -Z projected; right = up x normal.
/// The frame in which decal placements give their angle (mapping/map_decal.h).
struct UpFrame {
  Eigen::Vector3d right = Eigen::Vector3d::UnitX();
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};
UpFrame world_up_frame(const Eigen::Vector3d& normal);

}  // namespace elastic
