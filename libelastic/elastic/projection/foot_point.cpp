#include "elastic/projection/foot_point.h"

#include <Eigen/Geometry>

namespace elastic {

bool pull_back(const Eigen::Vector3d& du, const Eigen::Vector3d& dv, const Eigen::Vector3d& w,
               Eigen::Vector2d& out) {
  const double a = du.squaredNorm(), b = du.dot(dv), c = dv.squaredNorm();
  const double det = a * c - b * b;
  // det = |du x dv|^2: relative to a c it is sin^2 of the angle between du and dv.
  if (!(det > 1e-12 * a * c)) {
    return false;
  }
  const double wu = du.dot(w), wv = dv.dot(w);
  out = Eigen::Vector2d((c * wu - b * wv) / det, (a * wv - b * wu) / det);
  return true;
}

FootPoint foot_point(const LimitSurface& surface, const Eigen::Vector3d& goal,
                     const SurfacePoint& start, const FootPointOptions& options) {
  FootPoint out;
  SurfacePoint p = start;
  for (;; ++out.steps) {
    out.point = p;
    if (options.stop_at_boundary && surface.on_boundary(p)) {
      out.failed = true;
      return out;
    }
    out.d = surface.derivatives(p);
    const Eigen::Vector3d cross = out.d.du.cross(out.d.dv);
    const double length = cross.norm();
    if (!(length > options.degenerate_ratio * out.d.du.norm() * out.d.dv.norm())) {
      out.failed = true;
      return out;
    }
    out.normal = cross / length;
    // The stopping rule (see the header): the miss's part in the tangent plane.
    const Eigen::Vector3d miss = goal - out.d.position;
    const Eigen::Vector3d tangential = miss - out.normal * out.normal.dot(miss);
    out.miss = tangential.norm();
    if (out.miss <= options.tolerance) {
      out.converged = true;
      return out;
    }
    if (out.steps == options.max_steps) {
      return out;
    }
    Eigen::Vector2d step;
    if (!pull_back(out.d.du, out.d.dv, tangential, step)) {
      out.failed = true;
      return out;
    }
    p = surface.walk(p, step);
  }
}

}  // namespace elastic
