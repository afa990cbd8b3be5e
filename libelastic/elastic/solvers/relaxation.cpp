#include "elastic/solvers/relaxation.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <string>

#include "elastic/core/error.h"
#include "elastic/solvers/explicit_integrator.h"
#include "elastic/solvers/lbfgs_solver.h"
#include "elastic/solvers/solver_common.h"

namespace elastic {

std::string_view to_string(SolverKind kind) {
  return kind == SolverKind::Fast ? "fast" : "faithful";
}

SolverKind parse_solver_kind(std::string_view text, std::string_view input) {
  if (text == "fast") {
    return SolverKind::Fast;
  }
  if (text == "faithful") {
    return SolverKind::Faithful;
  }
  throw InvalidInputError(std::string(input),
                          "unknown solver '" + std::string(text) + "' (expected fast or faithful)");
}

std::string_view to_string(Preconditioner kind) {
  switch (kind) {
    case Preconditioner::Direct:
      return "direct";
    case Preconditioner::Multigrid:
      return "multigrid";
  }
  return "unknown";
}

Preconditioner parse_preconditioner(std::string_view text, std::string_view input) {
  if (text == "direct") {
    return Preconditioner::Direct;
  }
  if (text == "multigrid") {
    return Preconditioner::Multigrid;
  }
  throw InvalidInputError(std::string(input), "unknown preconditioner '" + std::string(text) +
                                                  "' (expected multigrid or direct)");
}

std::string_view to_string(NewtonMode mode) {
  switch (mode) {
    case NewtonMode::Auto:
      return "auto";
    case NewtonMode::On:
      return "on";
    case NewtonMode::Off:
      return "off";
  }
  return "unknown";
}

NewtonMode parse_newton_mode(std::string_view text, std::string_view input) {
  if (text == "auto") {
    return NewtonMode::Auto;
  }
  if (text == "on") {
    return NewtonMode::On;
  }
  if (text == "off") {
    return NewtonMode::Off;
  }
  throw InvalidInputError(std::string(input), "unknown Newton mode '" + std::string(text) +
                                                  "' (expected auto, on or off)");
}

std::string_view to_string(StopReason reason) {
  switch (reason) {
    case StopReason::RelativeGradient:
      return "relative tangential gradient below tolerance";
    case StopReason::AbsoluteGradient:
      return "tangential gradient below the absolute bound";
    case StopReason::RoundOff:
      return "energy at its round-off floor with a small tangential gradient";
    case StopReason::NoFreeParticles:
      return "no interior particles";
    case StopReason::MaxIterations:
      return "iteration limit reached";
    case StopReason::LineSearchFailed:
      return "line search found no fold-free decrease";
    case StopReason::FoldConstrained:
      return "stopped against the no-fold constraint (the energy minimum folds faces)";
    case StopReason::Diverged:
      return "diverged (non-finite energy or positions)";
    case StopReason::Cancelled:
      return "cancelled";
    case StopReason::Settled:
      return "energy settled";
    case StopReason::Stagnated:
      return "no progress (neither the energy nor the gradient improved over 100 iterations)";
  }
  return "unknown";
}

std::string_view to_string(BoundaryMode mode) {
  switch (mode) {
    case BoundaryMode::Fixed:
      return "fixed";
    case BoundaryMode::Slide:
      return "slide";
    case BoundaryMode::Free:
      return "free";
  }
  return "fixed";
}

BoundaryMode parse_boundary_mode(std::string_view text, std::string_view input) {
  if (text == "fixed") {
    return BoundaryMode::Fixed;
  }
  if (text == "slide") {
    return BoundaryMode::Slide;
  }
  if (text == "free") {
    return BoundaryMode::Free;
  }
  throw InvalidInputError(std::string(input), "unknown boundary mode '" + std::string(text) +
                                                  "' (expected fixed, slide or free)");
}

std::string_view to_string(EnergyKind kind) {
  return kind == EnergyKind::Robust ? "robust" : "paper";
}

EnergyKind parse_energy_kind(std::string_view text, std::string_view input) {
  if (text == "robust") {
    return EnergyKind::Robust;
  }
  if (text == "paper") {
    return EnergyKind::Paper;
  }
  throw InvalidInputError(std::string(input),
                          "unknown energy '" + std::string(text) + "' (expected robust or paper)");
}

double angular_stiffness(const RelaxationOptions& options) {
  if (options.angular_stiffness) {
    return *options.angular_stiffness;
  }
  // The faithful solver integrates the paper's forces whatever the energy asked for.
  const bool paper = options.energy == EnergyKind::Paper || options.solver == SolverKind::Faithful;
  return options.stiffness * (paper ? kPaperAngularStiffness : kRobustAngularStiffness);
}

namespace {

// Fast mode with the paper's energy, and when it stops against its no-fold constraint, the
// explicit integrator from its result (see RelaxationOptions::untangle_steps).
RelaxationResult relax_fast_paper(const RelaxationProblem& problem,
                                  const RelaxationOptions& options) {
  RelaxationResult fast = relax_lbfgs(problem, options);
  if (fast.reason != StopReason::FoldConstrained || options.untangle_steps <= 0) {
    return fast;
  }
  RelaxationProblem again = problem;
  again.initial_positions = fast.positions;
  again.initial_points = fast.points;
  again.boundary_parameters = fast.boundary_parameters;
  RelaxationOptions dynamics = options;
  dynamics.angular_stiffness = angular_stiffness(options);  // the same springs as the fast run
  dynamics.solver = SolverKind::Faithful;
  dynamics.max_iterations = options.untangle_steps;
  dynamics.frame = nullptr;  // the frames are the fast solver's iterations
  const RelaxationResult slow = relax_explicit(again, dynamics);
  fast.untangle_steps = slow.iterations;
  fast.setup_seconds += slow.setup_seconds;
  fast.solve_seconds += slow.solve_seconds;
  fast.evaluations += slow.evaluations;
  const double fast_energy = fast.length_energy + fast.angular_energy;
  const double slow_energy = slow.length_energy + slow.angular_energy;
  if (!slow.converged || slow.folded_faces > fast.folded_faces || !(slow_energy < fast_energy)) {
    return fast;  // a true fold-constrained minimum: the dynamics found nothing better
  }
  // The integrator's equilibrium replaces the stop. Its tolerance was relative to its own start
  // (the fast solver's last gradient), so relative to the original start it is tighter still.
  fast.positions = slow.positions;
  fast.points = slow.points;
  fast.length_energy = slow.length_energy;
  fast.angular_energy = slow.angular_energy;
  fast.gradient_norm = slow.gradient_norm;
  fast.relative_gradient =
      fast.initial_gradient_norm > 0.0 ? slow.gradient_norm / fast.initial_gradient_norm : 0.0;
  fast.folded_faces = slow.folded_faces;
  fast.held_particles.clear();
  fast.boundary_residual = slow.boundary_residual;
  fast.reason = slow.reason;
  fast.converged = true;
  fast.untangled = true;
  return fast;
}

// Adds `from`'s work (iterations, evaluations, seconds) to `to`: one relaxation reports the work of
// all its phases.
void add_work(RelaxationResult& to, const RelaxationResult& from) {
  to.iterations += from.iterations;
  to.evaluations += from.evaluations;
  to.newton_iterations += from.newton_iterations;
  to.newton_factorisations += from.newton_factorisations;
  to.setup_seconds += from.setup_seconds;
  to.solve_seconds += from.solve_seconds;
}

// The robust energy again from `from`'s fold-free end (every triangle in the barrier now: none
// is folded), judged against the first run's start; the first run's counts are added.
RelaxationResult restart_with_full_barrier(const RelaxationProblem& problem,
                                           const RelaxationOptions& options,
                                           const RelaxationResult& first,
                                           const RelaxationResult& from) {
  RelaxationProblem again = problem;
  again.initial_positions = from.positions;
  again.initial_points = from.points;
  again.boundary_parameters = from.boundary_parameters;
  again.reference_gradient_norm = first.initial_gradient_norm;
  RelaxationResult result = relax_lbfgs(again, options);
  if (result.boundary == BoundaryMode::Slide) {
    // The restart measured its slide from its own start: measure it from the problem's.
    result.boundary_slide = solver_detail::boundary_slide(solver_detail::boundary_start(problem),
                                                          result.boundary_parameters);
  }
  result.initial_energy = first.initial_energy;
  result.initial_folded_faces = first.initial_folded_faces;
  result.initial_gradient_norm = first.initial_gradient_norm;
  add_work(result, first);
  return result;
}

// Fast mode with the robust energy. The barrier keeps every triangle that starts unfolded away
// from collapse, but it cannot be crossed, so a start with folded faces (the naive map folds a few
// under extreme compression) is first untangled with the paper's energy (relax_fast_paper), and
// the barrier run starts again from that fold-free state.
RelaxationResult relax_fast_energy(const RelaxationProblem& problem,
                                   const RelaxationOptions& options) {
  if (options.energy == EnergyKind::Paper) {
    return relax_fast_paper(problem, options);
  }
  RelaxationResult robust = relax_lbfgs(problem, options);
  if (robust.reason == StopReason::Cancelled) {
    return robust;
  }
  if (robust.folded_faces == 0) {
    if (robust.converged || robust.initial_folded_faces == 0) {
      return robust;
    }
    // The start's folded triangles were left out of the barrier and have unfolded since, but
    // unprotected: one can stop at the fold guard's edge (a corner of orientation ~1e-18 that
    // every step, however short, would fold again), where no line search finds a decrease. From
    // this fold-free state every triangle joins the barrier, which pushes such a sliver open.
    return restart_with_full_barrier(problem, options, robust, robust);
  }
  RelaxationOptions paper_options = options;
  paper_options.angular_stiffness = angular_stiffness(options);  // untangle with the same springs
  paper_options.energy = EnergyKind::Paper;
  paper_options.frame = nullptr;
  const RelaxationResult paper = relax_fast_paper(problem, paper_options);
  if (paper.folded_faces > 0) {
    robust.untangle_phases = 1;
    robust.untangle_steps = paper.untangle_steps;
    add_work(robust, paper);  // the failed untangling's time is the user's too
    return robust;            // nothing fold-free to start the barrier from
  }
  RelaxationResult result = restart_with_full_barrier(problem, options, robust, paper);
  add_work(result, paper);
  result.untangle_steps = paper.untangle_steps;
  result.untangled = paper.untangled;
  result.untangle_phases = 1;
  return result;
}

// Fast mode. With a sliding boundary: first the boundary particles slide along the curve with the
// interior (up to kSlideIterations iterations: the curve is only piecewise smooth, a kink at each
// of its vertices, so the last digits of that stationarity come slowly), then the boundary is held
// where it slid and the interior relaxes to the tolerance, a smooth problem. The verdict is the
// second phase's.
constexpr long kSlideIterations = 500;

RelaxationResult relax_fast(const RelaxationProblem& problem, const RelaxationOptions& options) {
  if (options.boundary != BoundaryMode::Slide) {
    return relax_fast_energy(problem, options);
  }
  RelaxationOptions sliding = options;
  sliding.max_iterations = options.max_iterations > 0
                               ? std::min(options.max_iterations, kSlideIterations)
                               : kSlideIterations;
  sliding.relative_gradient_tolerance =
      std::max(options.relative_gradient_tolerance, options.slide_tolerance);
  RelaxationResult slid = relax_fast_energy(problem, sliding);  // not const: returned by move
  if (slid.reason == StopReason::Cancelled || slid.positions.cols() == 0) {
    return slid;
  }
  RelaxationProblem held = problem;
  held.initial_positions = slid.positions;
  held.initial_points = slid.points;
  held.boundary_parameters = slid.boundary_parameters;
  // One relaxation in two phases: the held phase's tolerances refer to the slide's start. Its own
  // start is the slide's end, often already close to equilibrium; judged against itself it would
  // have to reduce an already small gradient a million times more, which round-off forbids.
  held.reference_gradient_norm = slid.initial_gradient_norm;
  const std::vector<int>& loop = problem.grid->boundary_loop;
  held.boundary_targets.resize(3, static_cast<Eigen::Index>(loop.size()));
  for (std::size_t k = 0; k < loop.size(); ++k) {
    held.boundary_targets.col(static_cast<Eigen::Index>(k)) = slid.positions.col(loop[k]);
  }
  RelaxationOptions fixed = options;
  fixed.boundary = BoundaryMode::Fixed;
  RelaxationResult result = relax_fast_energy(held, fixed);
  // (A cancelled held phase stops here: the caller asked to stop, not for another start.)
  if (result.reason != StopReason::Cancelled && (!result.converged || result.folded_faces > 0)) {
    // The slid state did not settle (the slide stopped somewhere the interior cannot relax
    // from): the fixed boundary from the original start instead, when that converges fold-free.
    RelaxationResult plain = relax_fast_energy(problem, fixed);
    if (plain.converged && plain.folded_faces == 0) {
      plain.slide_iterations = slid.iterations;
      plain.slide_reason = slid.reason;
      add_work(plain, slid);
      add_work(plain, result);
      return plain;  // boundary = Fixed: the report says the slide was not kept
    }
    add_work(result, plain);  // tried and not kept: its time still counts
  }
  result.boundary = BoundaryMode::Slide;
  result.boundary_slide = slid.boundary_slide;
  result.slide_iterations = slid.iterations;
  result.slide_reason = slid.reason;
  result.initial_energy = slid.initial_energy;
  result.initial_folded_faces = slid.initial_folded_faces;
  add_work(result, slid);
  result.untangle_phases += slid.untangle_phases;
  result.untangle_steps += slid.untangle_steps;
  return result;
}

}  // namespace

RelaxationResult relax(const RelaxationProblem& problem, const RelaxationOptions& options) {
  const auto run = [&] {
    return options.solver == SolverKind::Fast ? relax_fast(problem, options)
                                              : relax_explicit(problem, options);
  };
  if (options.untangle_steps < 0) {
    throw InvalidInputError("relaxation", "untangle_steps must be >= 0");
  }
  if (options.threads < 0) {
    throw InvalidInputError("relaxation", "threads must be >= 0");
  }
  if (options.threads == 0) {
    return run();
  }
  tbb::task_arena arena(options.threads);
  return arena.execute(run);
}

}  // namespace elastic
