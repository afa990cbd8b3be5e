#include "elastic/projection/exponential_map.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "elastic/core/error.h"
#include "elastic/projection/foot_point.h"
#include "elastic/surface/ptex_domain.h"

namespace elastic {

namespace {

constexpr const char* kName = "exponential map";

// Arc length of a geodesic step from its chord and the normal curvature the chord shows at its two
// ends (see the header): 2 asin(kappa c / 2) / kappa, kappa = |(n_y - n_x) . chord| / c^2.
double arc_length(const Eigen::Vector3d& chord, const Eigen::Vector3d& normal_x,
                  const Eigen::Vector3d& normal_y) {
  const double c = chord.norm();
  if (c == 0.0) {
    return 0.0;
  }
  const double half_angle =
      std::min(1.0, 0.5 * std::abs((normal_y - normal_x).dot(chord)) / c);  // kappa c / 2
  if (half_angle < 1e-8) {
    return c;
  }
  return c * std::asin(half_angle) / half_angle;
}

struct Step {
  FootPoint foot;
  Eigen::Vector3d position;
  double arc = 0.0;
  bool ok = false;
};

// One step of length h along t from (p, x), put back on the surface.
// The geodesic's second-order point h along t: x + h t - (h^2 / 2) k(t) n, k(t) the normal
// curvature in direction t (limit_surface.h's sign: positive where the surface bends away from n).
Eigen::Vector3d second_order_goal(const SurfaceDerivatives& d, const Eigen::Vector3d& normal,
                                  const Eigen::Vector3d& t, double h) {
  Eigen::Vector2d ab;
  if (!pull_back(d.du, d.dv, t, ab)) {
    return d.position + h * t;
  }
  const Eigen::Vector3d d2 =
      ab.x() * ab.x() * d.duu + 2.0 * ab.x() * ab.y() * d.duv + ab.y() * ab.y() * d.dvv;
  const double k = -d2.dot(normal) / (ab.x() * d.du + ab.y() * d.dv).squaredNorm();
  return d.position + h * t - 0.5 * h * h * k * normal;
}

Step take_step(const LimitSurface& surface, const SurfacePoint& p, const SurfaceDerivatives& d,
               const Eigen::Vector3d& normal, const Eigen::Vector3d& t, double h) {
  const Eigen::Vector3d& x = d.position;
  const FootPointOptions foot{.tolerance = 1e-13 * std::max(1.0, x.norm()), .max_steps = 8};
  const Eigen::Vector3d goal = second_order_goal(d, normal, t, h);
  Step step;
  step.foot = foot_point(surface, goal, p, foot);
  if (step.foot.failed && !surface.on_boundary(step.foot.point)) {
    // A singular parameterisation at the start: from just inside the face instead.
    step.foot = foot_point(surface, goal,
                           surface.domain().towards_centre(step.foot.point, kSingularNudge), foot);
  }
  // A foot point that neither converged nor failed against the boundary's tolerance 1e-12, but
  // sits on it within 1e-9 (ptex units), was pressed against the boundary too: stop there.
  if (!step.foot.failed && !step.foot.converged && surface.on_boundary(step.foot.point, 1e-9)) {
    step.foot.failed = true;
  }
  step.ok = !step.foot.failed;
  // A failed foot point stops at the point it could not go on from (its derivatives are the
  // previous point's).
  step.position = step.ok ? step.foot.d.position : surface.position(step.foot.point);
  step.arc = arc_length(step.position - x, normal, step.ok ? step.foot.normal : normal);
  return step;
}

}  // namespace

UpFrame world_up_frame(const Eigen::Vector3d& normal) {
  UpFrame frame;
  frame.normal = normal.normalized();
  const Eigen::Vector3d axis = std::abs(frame.normal.y()) > 0.99
                                   ? Eigen::Vector3d(-Eigen::Vector3d::UnitZ())
                                   : Eigen::Vector3d(Eigen::Vector3d::UnitY());
  frame.up = (axis - frame.normal * frame.normal.dot(axis)).normalized();
  frame.right = frame.up.cross(frame.normal);
  return frame;
}

GeodesicShot exponential_map(const LimitSurface& surface, const SurfacePoint& from,
                             const Eigen::Vector3d& v, const ExponentialMapOptions& options) {
  if (!from.valid() || from.face >= surface.num_faces()) {
    throw InvalidInputError(kName, "the start is not a point of the surface");
  }
  if (!v.allFinite()) {
    throw InvalidInputError(kName, "the tangent vector is not finite");
  }
  GeodesicShot shot;
  shot.point = from;
  shot.position = surface.position(from);
  // LimitSurface::curvature's normal: du x dv, nudged off a singular parameterisation.
  const Eigen::Vector3d n0 = surface.curvature(from).normal;
  Eigen::Vector3d t = v - n0 * n0.dot(v);
  const double total = t.norm();
  if (v.norm() == 0.0) {
    shot.direction = world_up_frame(n0).right;
    return shot;
  }
  if (!(total > 1e-12 * v.norm())) {
    throw InvalidInputError(kName, "the tangent vector is normal to the surface");
  }
  t /= total;
  if (total <= 1e-12 * std::max(1.0, shot.position.norm())) {
    // Below the round-off of the positions: no step can resolve it (the centre particle of a
    // decal sits 1e-15 from the centre).
    shot.direction = t;
    return shot;
  }
  Eigen::Vector3d normal = n0;
  const double longest = std::min(options.step > 0.0 ? options.step : total / 32.0, total / 4.0);
  double h = longest;
  SurfacePoint p = from;
  Eigen::Vector3d x = shot.position;
  SurfaceDerivatives here = surface.derivatives(from);
  double walked = 0.0;
  while (walked < total * (1.0 - 1e-12)) {
    if (shot.steps >= options.max_steps) {
      throw InvalidInputError(
          kName, "the walk needs more than " + std::to_string(options.max_steps) + " steps");
    }
    const double remaining = total - walked;
    const bool last = remaining <= h * 1.5;
    double length = last ? remaining : h;
    Step step = take_step(surface, p, here, normal, t, length);
    if (step.ok && !step.foot.converged) {
      // The step is long for the curvature here: Gauss-Newton did not settle. Shorter steps.
      ++shot.steps;
      h = 0.5 * length;
      continue;
    }
    if (last && step.ok) {
      // The chord falls short of the arc asked for by O(h^3 kappa^2): two secant corrections.
      for (int k = 0;
           k < 2 && step.ok && step.arc > 0.0 && std::abs(step.arc - remaining) > 1e-12 * total;
           ++k) {
        length *= remaining / step.arc;
        step = take_step(surface, p, here, normal, t, length);
      }
    }
    ++shot.steps;
    if (!step.ok) {
      // The boundary of an open surface: stop there.
      shot.hit_boundary = true;
      walked += step.arc;
      p = step.foot.point;
      x = step.position;
      break;
    }
    // The tangent transported to y by the least rotation that takes the normal at x to the
    // normal at y (the discrete Levi-Civita transport), then made tangent again.
    const Eigen::Vector3d n = step.foot.normal;
    Eigen::Vector3d next = Eigen::Quaterniond::FromTwoVectors(normal, n) * t;
    next -= n * n.dot(next);
    if (next.norm() > 0.0) {
      t = next.normalized();
    }
    normal = n;
    walked += last ? remaining : step.arc;
    h = std::min(longest, 2.0 * h);  // back up after a halving
    p = step.foot.point;
    x = step.position;
    here = step.foot.d;
    if (last) {
      break;
    }
  }
  shot.point = p;
  shot.position = x;
  shot.direction = t;
  shot.length = std::min(walked, total);
  return shot;
}

}  // namespace elastic
