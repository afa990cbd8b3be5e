// Newton's method on E(u,v) = 1/2 |d(u,v) - x|^2 from a start point: the projector's local
// search (closest_point.h).
//
//   gradient  g = J^T r,                      r = d - x, J = [d_u d_v]
//   Hessian   H = J^T J + sum_i r_i d2 d_i    (the second term is r . d_uu, r . d_uv, r . d_vv)
//
// H is positive definite near a non-degenerate minimum (it fails only when the query is beyond a
// focal point, e.g. near the centre of curvature). When it is not, a modified Newton step with the
// absolute values of H's eigenvalues (floored) gives a descent step (LocalModel::free_step). Steps
// are capped at `max_step`, applied with walk() (which crosses ptex edges), and halved until E
// does not grow beyond its round-off (the backtracking guard). Every accepted trial point's
// derivatives are the next iteration's, so an iteration costs one evaluation.
//
// Boundaries are an active set: on a boundary edge of the domain, if steepest descent points out of
// the surface, the step is a 1D Newton step along the edge tangent t (g_t = t.g, h_t = |t^T H t|);
// at a corner of two boundary edges the descent direction is projected on each edge ray and the
// iteration stops (a KKT point) when neither ray descends.
//
// Convergence: the step is below `parameter_tolerance`, or the (projected) gradient is zero to
// round-off. r carries an absolute error of a few eps (|x| + |d|) per component, so g_u = d_u . r
// cannot be resolved below |d_u| times that.
//
// Face corners: where a step leaves the face through a corner and no step length descends, the
// iteration hops into the neighbouring face (NewtonIteration::hop) and continues in that chart.
#include "elastic/projection/detail/closest_point_newton.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace elastic::detail {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// A point closer than this (in ptex units) to a boundary edge is on it: walk() clips exactly onto
// the boundary, so the slack only absorbs round-off in (u, v).
constexpr double kActiveTolerance = 1e-11;

// A point within this (ptex units) of two domain edges is on a face corner.
constexpr double kCornerTolerance = 1e-9;

// Length (ptex units) of the hop into the neighbouring face at a corner (see NewtonIteration::hop).
constexpr double kCornerHop = 1e-7;

// Most backtracking halvings of a Newton step before the iteration gives up.
constexpr int kMaxHalvings = 30;

// Most chart hops at face corners per Newton run (a vertex has rarely more than 8 faces).
constexpr int kMaxHops = 8;

// The quadratic model of E at the current point: gradient, metric J^T J, Hessian H, and the
// round-off of the gradient.
struct LocalModel {
  Eigen::Vector2d g;
  double g00, g01, g11;  // J^T J
  double h00, h01, h11;  // H
  double r_noise;        // round-off of a component of r
  double noise_u, noise_v;
  // Curvatures smaller than this (relative to the metric J^T J) are raised to it: the step along
  // such a direction is then long and capped by max_step.
  double curvature_floor;

  LocalModel(const SurfaceDerivatives& d, const Eigen::Vector3d& r, const Eigen::Vector3d& x)
      : g(d.du.dot(r), d.dv.dot(r)),
        g00(d.du.squaredNorm()),
        g01(d.du.dot(d.dv)),
        g11(d.dv.squaredNorm()),
        h00(g00 + r.dot(d.duu)),
        h01(g01 + r.dot(d.duv)),
        h11(g11 + r.dot(d.dvv)),
        r_noise(8.0 * kEps * (x.cwiseAbs().maxCoeff() + d.position.cwiseAbs().maxCoeff())),
        noise_u(2.0 * r_noise * std::sqrt(g00)),
        noise_v(2.0 * r_noise * std::sqrt(g11)),
        curvature_floor(1e-6 * (g00 + g11) + 1e-300) {}

  // Newton step when H is safely positive definite (then `pure_newton` is set). Otherwise (beyond
  // a focal point, or where E is flat) the "saddle-free" Newton step: H's eigenvalues replaced by
  // their absolute values (floored), so a direction of negative curvature is followed downhill
  // with a long step instead of the creeping Gauss-Newton step (J^T J overestimates the curvature
  // there: measured on a torus, GN needed more than 30 iterations from inside the tube where this
  // takes a few).
  Eigen::Vector2d free_step(bool& pure_newton) const {
    const double det = h00 * h11 - h01 * h01;
    if (h00 > 0.0 && h11 > 0.0 && det > 1e-12 * h00 * h11) {
      pure_newton = true;
      return Eigen::Vector2d(-(h11 * g.x() - h01 * g.y()) / det,
                             -(h00 * g.y() - h01 * g.x()) / det);
    }
    const double mean = 0.5 * (h00 + h11);
    const double radius = std::hypot(0.5 * (h00 - h11), h01);
    const double l1 = mean + radius, l2 = mean - radius;
    Eigen::Vector2d v1 = std::abs(h01) > 1e-300 ? Eigen::Vector2d(l1 - h11, h01).normalized()
                         : h00 >= h11           ? Eigen::Vector2d(1.0, 0.0)
                                                : Eigen::Vector2d(0.0, 1.0);
    const Eigen::Vector2d v2(-v1.y(), v1.x());
    return Eigen::Vector2d(-v1.dot(g) / std::max(std::abs(l1), curvature_floor) * v1 -
                           v2.dot(g) / std::max(std::abs(l2), curvature_floor) * v2);
  }
  // 1D Newton along a unit direction t (a boundary edge), with the same absolute-curvature rule.
  Eigen::Vector2d edge_step(const Eigen::Vector2d& t, bool& pure_newton) const {
    const double ht = t.x() * t.x() * h00 + 2.0 * t.x() * t.y() * h01 + t.y() * t.y() * h11;
    const double jt = t.x() * t.x() * g00 + 2.0 * t.x() * t.y() * g01 + t.y() * t.y() * g11;
    pure_newton = ht > 1e-6 * jt;
    return Eigen::Vector2d(-t.dot(g) / std::max(std::abs(ht), 1e-6 * jt + 1e-300) * t);
  }
  // Steepest descent scaled by the curvature along it (a Cauchy step), used when Newton's step
  // would leave through a boundary edge although descent points inside.
  Eigen::Vector2d descent_step() const {
    const double gg = g.squaredNorm();
    if (!(gg > 0.0)) {
      return Eigen::Vector2d(Eigen::Vector2d::Zero());
    }
    const double ghg = g.x() * g.x() * h00 + 2.0 * g.x() * g.y() * h01 + g.y() * g.y() * h11;
    const double gjg = g.x() * g.x() * g00 + 2.0 * g.x() * g.y() * g01 + g.y() * g.y() * g11;
    return Eigen::Vector2d(-gg / std::max(std::abs(ghg), 1e-6 * gjg + 1e-300) * g);
  }
  // True when g along a unit parameter direction is zero to its round-off.
  bool gradient_zero(const Eigen::Vector2d& direction) const {
    const double noise = std::abs(direction.x()) * noise_u + std::abs(direction.y()) * noise_v;
    return std::abs(direction.dot(g)) <= noise;
  }
};

// What the active set makes of the model: a step to try, or convergence.
struct Proposal {
  Eigen::Vector2d step = Eigen::Vector2d::Zero();
  bool converged = false;    // stop here: a (constrained) minimum to round-off
  bool constrained = false;  // the step (or the minimum) is on a boundary edge
  bool pure_newton = false;  // the step is an exact Newton step (H positive definite)
};

// A point with its evaluation.
struct Evaluated {
  SurfacePoint point;
  SurfaceDerivatives d;
  Eigen::Vector3d r = Eigen::Vector3d::Zero();  // d.position - x
  double energy = 0.0;                          // 1/2 |r|^2
};

class NewtonIteration {
 public:
  NewtonIteration(const NewtonSetup& setup, const Eigen::Vector3d& x, const SurfacePoint& start)
      : surface_(*setup.surface),
        domain_(setup.domain),
        options_(*setup.options),
        boundary_edges_(*setup.boundary_edges),
        x_(x),
        tolerance_(options_.parameter_tolerance),
        early_tolerance_(1e-2 * std::sqrt(tolerance_)),
        here_(evaluate(start)) {}

  NewtonRun run() {
    for (int iteration = 0; iteration < options_.max_newton_iterations; ++iteration) {
      if (!step_once()) {
        break;
      }
    }
    run_.point = here_.point;
    run_.d = here_.d;
    run_.dist2 = here_.r.squaredNorm();
    if (!run_.on_boundary && run_.converged) {
      // A converged interior point can still sit on a boundary edge when descent points along it.
      run_.on_boundary = active_edges().count > 0;
    }
    return run_;
  }

 private:
  struct ActiveEdges {
    int edge[2] = {-1, -1};
    int count = 0;
  };

  Evaluated evaluate(const SurfacePoint& p) const {
    Evaluated e;
    e.point = p;
    e.d = surface_.derivatives(p);
    e.r = e.d.position - x_;
    e.energy = 0.5 * e.r.squaredNorm();
    return e;
  }

  // One iteration; false when the run ends (converged, or stuck).
  bool step_once() {
    const LocalModel model(here_.d, here_.r, x_);
    Proposal proposal = propose(model);
    if (proposal.converged) {
      run_.converged = true;
      run_.on_boundary = proposal.constrained;
      return false;
    }
    const double length = proposal.step.norm();
    if (length > options_.max_step) {
      proposal.step *= options_.max_step / length;
    }
    if (ends_short(proposal)) {
      return false;
    }
    Eigen::Vector2d step = proposal.step;
    Evaluated trial;
    bool accepted = backtrack(model, step, trial);
    if (!accepted && hops_ < kMaxHops && at_corner()) {
      accepted = hop(proposal.step, trial);
      if (accepted) {
        step = Eigen::Vector2d::Zero();
      }
    }
    if (!accepted) {
      // No descent at any step length above the tolerance: p is a minimum to within round-off.
      run_.converged = step.norm() < tolerance_;
      run_.on_boundary = proposal.constrained;
      return false;
    }
    if (trial.point == here_.point) {
      return false;  // blocked (walk could not move): leave it unconverged
    }
    run_.travel += step.norm();
    here_ = trial;
    return true;
  }

  // The boundary edges of this face that the current point lies on (at most two).
  ActiveEdges active_edges() const {
    ActiveEdges active;
    const std::uint8_t mask = boundary_edges_[static_cast<size_t>(here_.point.face)];
    if (mask) {
      const Eigen::Vector2d uv = here_.point.uv();
      for (int k = 0; k < domain_.num_corners() && active.count < 2; ++k) {
        if ((mask & (1u << k)) && domain_.inside_distance(k, uv) <= kActiveTolerance) {
          active.edge[active.count++] = k;
        }
      }
    }
    return active;
  }

  // The step the active set allows: free inside, sliding along one boundary edge, along one of
  // the two edge rays at a boundary corner, or convergence.
  Proposal propose(const LocalModel& m) const {
    Proposal out;
    const ActiveEdges active = active_edges();
    if (active.count == 0) {
      if (m.gradient_zero({1.0, 0.0}) && m.gradient_zero({0.0, 1.0})) {
        out.converged = true;
        return out;
      }
      out.step = m.free_step(out.pure_newton);
    } else if (active.count == 1) {
      const DomainEdge& e = domain_.edge(active.edge[0]);
      if (-m.g.dot(e.normal) <= 0.0) {  // descent points out of the surface: slide along the edge
        out.constrained = true;
        if (m.gradient_zero(e.tangent)) {
          out.converged = true;
          return out;
        }
        out.step = m.edge_step(e.tangent, out.pure_newton);
      } else {
        out.step = m.free_step(out.pure_newton);
        if (out.step.dot(e.normal) < 0.0) {
          out.step = m.descent_step();
        }
      }
    } else {
      corner_step(m, domain_.edge(active.edge[0]), domain_.edge(active.edge[1]), out);
    }
    return out;
  }

  // At a corner of two boundary edges a and b.
  static void corner_step(const LocalModel& m, const DomainEdge& a, const DomainEdge& b,
                          Proposal& out) {
    if (-m.g.dot(a.normal) > 0.0 && -m.g.dot(b.normal) > 0.0) {
      out.step = m.free_step(out.pure_newton);
      if (out.step.dot(a.normal) < 0.0 || out.step.dot(b.normal) < 0.0) {
        out.step = m.descent_step();
      }
      return;
    }
    // Rays from the corner along each boundary edge, pointing into the domain.
    const Eigen::Vector2d ray_a =
        a.tangent.dot(b.normal) >= 0.0 ? a.tangent : Eigen::Vector2d(-a.tangent);
    const Eigen::Vector2d ray_b =
        b.tangent.dot(a.normal) >= 0.0 ? b.tangent : Eigen::Vector2d(-b.tangent);
    out.constrained = true;
    if (-m.g.dot(ray_a) > 0.0 && !m.gradient_zero(ray_a)) {
      out.step = m.edge_step(ray_a, out.pure_newton);
    } else if (-m.g.dot(ray_b) > 0.0 && !m.gradient_zero(ray_b)) {
      out.step = m.edge_step(ray_b, out.pure_newton);
    } else {
      out.converged = true;  // KKT point at a boundary corner
    }
  }

  // True (and the run converged or not) when the step is too short to take: below the tolerance,
  // or a pure Newton step this short that finish() takes without another evaluation.
  bool ends_short(const Proposal& proposal) {
    const Eigen::Vector2d& step = proposal.step;
    if (!(step.norm() >= tolerance_)) {  // also catches a NaN step
      run_.converged = step.allFinite();
      run_.on_boundary = proposal.constrained;
      if (run_.converged) {
        run_.last_step = step;
      }
      return true;
    }
    // A pure Newton step this short ends within ~C |s|^2 (~1e-16 C) of the minimum, and d(p + s)
    // is d(p) + J s to O(|s|^2): finish() takes it without another evaluation (the last of the ~4
    // a warm start costs). Only inside the face (a step off it needs walk()).
    if (proposal.pure_newton && step.norm() <= early_tolerance_ &&
        domain_.contains(here_.point.uv() + step)) {
      run_.converged = true;
      run_.on_boundary = proposal.constrained;
      run_.last_step = step;
      return true;
    }
    return false;
  }

  // Backtracking guard on E: halves `step` until the walked trial point does not raise E beyond
  // its own round-off. True with `trial` set when a step is accepted.
  bool backtrack(const LocalModel& m, Eigen::Vector2d& step, Evaluated& trial) const {
    const double slack = 4.0 * std::sqrt(2.0 * here_.energy) * m.r_noise + 1e-300;
    const SurfacePoint& p = here_.point;
    for (int halving = 0; halving < kMaxHalvings; ++halving) {
      SurfacePoint to = surface_.walk(p, step);
      if (to == p) {
        // walk() cannot leave through a face corner (around an extraordinary vertex there is no
        // continuous chart to carry the direction on); start a hair inside the face (the one
        // nudge) so the path leaves through an edge instead. A boundary still stops it.
        to = surface_.walk(domain_.towards_centre(p, kInsideNudge), step);
      }
      trial = evaluate(to);
      if (trial.energy <= here_.energy + slack) {
        return true;
      }
      step *= 0.5;
      if (step.norm() < tolerance_) {
        return false;
      }
    }
    return false;
  }

  bool at_corner() const { return domain_.edges_within(here_.point.uv(), kCornerTolerance) >= 2; }

  // At a face corner a straight step in this face's chart may leave through the corner into a
  // sector where the chart does not continue smoothly (ptex charts are only C0 across edges at an
  // extraordinary vertex), so no step length descends. Hop kCornerHop into the neighbouring face
  // the step points to and recompute the step in that chart; E may grow by ~1e-7 |g| once per hop.
  // True with `trial` set when the hop reached another face.
  bool hop(const Eigen::Vector2d& first_step, Evaluated& trial) {
    const SurfacePoint inside = domain_.towards_centre(here_.point, kInsideNudge);
    const SurfacePoint to = surface_.walk(inside, kCornerHop * first_step.normalized());
    if (to.face == here_.point.face) {
      return false;
    }
    ++hops_;
    trial = evaluate(to);
    return true;
  }

  const LimitSurface& surface_;
  const PtexDomain domain_;
  const ProjectionOptions& options_;
  const std::vector<std::uint8_t>& boundary_edges_;
  const Eigen::Vector3d x_;
  const double tolerance_;
  const double early_tolerance_;
  Evaluated here_;  // the current point
  int hops_ = 0;    // chart hops at face corners
  NewtonRun run_;
};

}  // namespace

NewtonRun newton_closest_point(const NewtonSetup& setup, const Eigen::Vector3d& x,
                               const SurfacePoint& start) {
  return NewtonIteration(setup, x, start).run();
}

}  // namespace elastic::detail
