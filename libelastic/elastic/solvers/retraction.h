#pragma once
/// \file
/// The fast solver's retraction: a tangent step of a particle taken along the limit surface, with
/// the foot point of projection/foot_point.h as its correction. Internal to the solvers
/// (solver_detail).

#include <Eigen/Core>

#include "elastic/projection/closest_point.h"
#include "elastic/surface/limit_surface.h"

namespace elastic::solver_detail {

/// The parameter-space frame the retraction reads at a surface point: the surface's own
/// SurfaceDerivatives there (first and second derivatives with respect to the ptex (u, v); the
/// position is carried along).
SurfaceDerivatives tangent_frame(const LimitSurface& surface, const SurfacePoint& point);

/// The fast solver's retraction: moves the surface point `from` (limit position `x`, frame
/// `frame`) by the tangent step `t` along the surface. The step is pulled back into ptex
/// parameters to second order (delta = (J^T J)^-1 J^T (t - 1/2 delta^T H delta), J = [du dv]),
/// walked across ptex faces, and evaluated; if the landing point misses x + t tangentially by more
/// than 1e-3 |t| (the walk carries delta across an edge in parameter units, so around an
/// extraordinary vertex or into the sub-faces of a non-quad face it can land O(|t|) away),
/// Gauss-Newton steps move it to the foot of x + t on the surface, which is the magnet's answer.
/// To first order both are x + t: a retraction. On success fills `out` (point, position, unit
/// normal) and `out_frame`; returns false (the caller then uses the magnet) when the
/// parameterisation is degenerate, the walk stops on the surface boundary, or three corrections do
/// not reach the tolerance.
bool parametric_retraction(const LimitSurface& surface, const SurfacePoint& from,
                           const Eigen::Vector3d& x, const SurfaceDerivatives& frame,
                           const Eigen::Vector3d& t, ClosestPoint& out,
                           SurfaceDerivatives& out_frame);

}  // namespace elastic::solver_detail
