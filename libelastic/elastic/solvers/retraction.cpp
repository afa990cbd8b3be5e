#include "elastic/solvers/retraction.h"

#include "elastic/projection/foot_point.h"

namespace elastic::solver_detail {

namespace {

// The landing point is corrected by foot_point() towards the foot of `goal` (x + t) while its
// tangential miss exceeds this fraction of the step, in at most kRetractionCorrections steps.
constexpr double kRetractionMiss = 1e-3;
constexpr int kRetractionCorrections = 3;
// Where |du x dv| <= this |du| |dv| the landing point's frame is degenerate: the magnet instead.
constexpr double kDegenerateFrame = 1e-6;

}  // namespace

SurfaceDerivatives tangent_frame(const LimitSurface& surface, const SurfacePoint& point) {
  return surface.derivatives(point);
}

// The retraction of the line search: a tangent step t at surface point `from` (position x)
// becomes the parameter step delta = (J^T J)^-1 J^T t, J = [du dv] (the least-squares pull-back
// of t), walked across ptex faces (LimitSurface::walk), and the particle goes to the limit position
// there. To first order in |t| this is x + t, as is the closest point of x + t (the magnet): both
// are retractions, and a minimum of the energy on the surface does not depend on which one the
// line search uses. This one costs one patch evaluation per particle, against the Newton
// iterations of the closest-point query.
//
// The walk carries delta across an edge in parameter units, so where the neighbouring face's
// parameterisation runs at another speed or direction (around an extraordinary vertex, into the
// sub-faces of a non-quad face) the landing point can miss x + t by O(|t|) along the surface. Such
// misses fold grids whose spacing is small against the step (seen at 300,000 particles on the cap,
// around its four extraordinary vertices), so the landing point is checked: if the part of
// x + t - landing tangent to the surface there exceeds kRetractionMiss |t|, foot_point's
// Gauss-Newton steps move it to the foot of x + t, which is the magnet's answer. Returns false,
// leaving the magnet to the caller, when the parameterisation is degenerate, the walk stops on the
// surface boundary, or the corrections do not converge.
bool parametric_retraction(const LimitSurface& surface, const SurfacePoint& from,
                           const Eigen::Vector3d& x, const SurfaceDerivatives& frame,
                           const Eigen::Vector3d& t, ClosestPoint& out,
                           SurfaceDerivatives& out_frame) {
  Eigen::Vector2d first;
  if (!pull_back(frame.du, frame.dv, t, first)) {
    return false;
  }
  // Second order: d(delta) = x + J delta + 1/2 delta^T H delta + O(delta^3). Removing the tangent
  // part of the quadratic term makes the tangent displacement t + O(|t|^3), like the closest point
  // of x + t, so the L-BFGS pairs see the same curvature as with the magnet.
  const Eigen::Vector3d bend =
      0.5 * (first.x() * first.x() * frame.duu + 2.0 * first.x() * first.y() * frame.duv +
             first.y() * first.y() * frame.dvv);
  Eigen::Vector2d correction;
  if (!pull_back(frame.du, frame.dv, bend, correction)) {
    return false;
  }
  const SurfacePoint landing = surface.walk(from, first - correction);
  const FootPoint foot = foot_point(surface, x + t, landing,
                                    {.tolerance = kRetractionMiss * t.norm(),
                                     .max_steps = kRetractionCorrections,
                                     .stop_at_boundary = true,
                                     .degenerate_ratio = kDegenerateFrame});
  if (!foot.converged) {
    return false;
  }
  out.point = foot.point;
  out.position = foot.d.position;
  out.normal = foot.normal;
  out.distance = 0.0;
  out.on_boundary = false;
  out.converged = true;
  out_frame = foot.d;
  return true;
}

}  // namespace elastic::solver_detail
