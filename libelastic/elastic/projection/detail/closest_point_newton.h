#pragma once
/// \file
/// The Newton iteration of the projector (closest_point.h): from a start on the limit surface to
/// the local minimum of the distance to a query point. Private to projection/ (not installed):
/// SurfaceProjector seeds it and picks among its runs.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "elastic/projection/closest_point.h"
#include "elastic/surface/limit_surface.h"
#include "elastic/surface/ptex_domain.h"

namespace elastic::detail {

/// What a Newton run reads of its projector.
struct NewtonSetup {
  const LimitSurface* surface = nullptr;
  PtexDomain domain{false};
  const ProjectionOptions* options = nullptr;
  /// Per ptex face: bit k set when domain edge k lies on the surface boundary.
  const std::vector<std::uint8_t>* boundary_edges = nullptr;
};

/// One Newton run's outcome.
struct NewtonRun {
  SurfacePoint point;
  SurfaceDerivatives d;                                    ///< at `point`
  double dist2 = std::numeric_limits<double>::infinity();  ///< |d(point) - x|^2
  double travel = 0.0;                                     ///< summed parameter-space step lengths
  /// The sub-tolerance step not taken (finish() applies it to first order).
  Eigen::Vector2d last_step = Eigen::Vector2d::Zero();
  bool converged = false;
  bool on_boundary = false;
};

/// Newton's method on E(u, v) = 1/2 |d(u, v) - x|^2 from `start` (see closest_point_newton.cpp).
NewtonRun newton_closest_point(const NewtonSetup& setup, const Eigen::Vector3d& x,
                               const SurfacePoint& start);

}  // namespace elastic::detail
