#pragma once
/// \file
/// `foot_point`: the closest point of the limit surface to a 3D point `goal`, by Gauss-Newton from
/// a start already near it. The one routine for "put this point back on the surface near here"
/// that the solvers' retraction and the transfer's re-linearisation call; the projector
/// (closest_point.h) is the global query with its own Newton iteration.
///
/// Each step is the least-squares pull-back of the tangential miss into the parameter plane,
/// delta = (J^T J)^-1 J^T (I - n n^T)(goal - d(p)) with J = [du dv] and n the unit normal, walked
/// across ptex faces (LimitSurface::walk). Near a point whose miss is normal to the surface this
/// converges quadratically when the surface's curvature times the normal miss is small (the
/// Gauss-Newton term dropped from the Hessian, r . d2d, is that product).
///
/// The one stopping rule: at every evaluated point (the start included) the tangential miss
/// |(I - n n^T)(goal - d(p))| is compared with `tolerance`; at most, the point is the answer
/// (`converged`). After `max_steps` steps still above it, the last point is returned unconverged.
/// The iteration gives up early, unconverged with `failed` set, when the parameterisation is
/// degenerate at a point (|du x dv| <= `degenerate_ratio` |du| |dv|) or, with
/// `stop_at_boundary`, a point lies on the surface boundary (where the minimum is constrained and
/// Gauss-Newton in the open face does not apply).

#include <Eigen/Core>

#include "elastic/surface/limit_surface.h"

namespace elastic {

struct FootPointOptions {
  /// Converged when the tangential miss is at most this (3D length units). 0 runs all max_steps.
  double tolerance = 0.0;
  /// Gauss-Newton steps at most (each costs one evaluation with derivatives).
  int max_steps = 3;
  /// Give up (failed) at a point on the surface boundary.
  bool stop_at_boundary = true;
  /// Give up (failed) where |du x dv| <= this * |du| |dv| (sine of the angle between du and dv).
  double degenerate_ratio = 1e-6;
};

struct FootPoint {
  SurfacePoint point;                                 ///< the last evaluated point
  SurfaceDerivatives d;                               ///< derivatives at `point`
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit normal at `point` (du x dv side)
  double miss = 0.0;                                  ///< tangential miss at `point`
  int steps = 0;                                      ///< Gauss-Newton steps taken
  bool converged = false;                             ///< the miss met the tolerance
  bool failed = false;  ///< gave up: degenerate parameterisation or the boundary
};

/// The foot of `goal` on `surface` near `start` (see the file comment).
/// \throws InvalidInputError (naming the surface) when `start` is not a point of the surface.
FootPoint foot_point(const LimitSurface& surface, const Eigen::Vector3d& goal,
                     const SurfacePoint& start, const FootPointOptions& options = {});

/// The least-squares pull-back of a 3D vector w into the parameter plane of the tangents du, dv:
/// (J^T J)^-1 J^T w with J = [du dv]. False (and `out` untouched) when du and dv are (nearly)
/// parallel: |du x dv|^2 <= 1e-12 |du|^2 |dv|^2.
bool pull_back(const Eigen::Vector3d& du, const Eigen::Vector3d& dv, const Eigen::Vector3d& w,
               Eigen::Vector2d& out);

}  // namespace elastic
