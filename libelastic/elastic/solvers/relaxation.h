#pragma once
/// \file
/// Least-distortion relaxation of a particle grid on the target surface (paper §4.2, §4.4-4.6): the
/// interior particles move on the target limit surface to a minimum of the spring energy E_len +
/// E_ang (particles/spring_energy.h) while the boundary particles stay where the boundary
/// correspondence put them.
///
/// Two solvers, one result (see docs/solvers.md):
/// - `SolverKind::Fast` (default): tangent-space L-BFGS preconditioned with a multigrid V-cycle of
///   the spring Laplacian, a parametric retraction that agrees with the magnet (closest point) to
///   third order, a fold-rejecting Armijo line search (lbfgs_solver.h).
/// - `SolverKind::Faithful`: the paper's damped explicit integrator, eqs. 9-12
///   (explicit_integrator.h).
///
/// Both stop when the tangential gradient |P g| (the spring gradient projected on the target's
/// tangent planes at the interior particles) falls below `relative_gradient_tolerance` times its
/// initial value, or below the scale-free absolute bound `absolute_gradient_tolerance * C_max *
/// sigma * mean_rest * sqrt(#P)`; never on an energy change alone.
///
/// Threads: the solvers run in a TBB arena of `threads` threads (0: all). Same inputs give
/// bit-identical results run to run; the energy and gradient are identical for any thread count
/// (the projector's batched query is as well, being one independent query per particle).

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

#include "elastic/core/progress.h"
#include "elastic/numerics/multigrid.h"
#include "elastic/particles/particle_grid.h"
#include "elastic/particles/spring_energy.h"
#include "elastic/projection/closest_point.h"
#include "elastic/surface/surface_point.h"

namespace elastic {

enum class SolverKind {
  Fast,     ///< tangent-space L-BFGS (default)
  Faithful  ///< the paper's explicit integrator (eqs. 9-12)
};
/// "fast", "faithful".
std::string_view to_string(SolverKind kind);
/// Parses "fast" or "faithful". \throws InvalidInputError naming `input` otherwise.
SolverKind parse_solver_kind(std::string_view text, std::string_view input = "solver");

/// Why a solver stopped.
enum class StopReason {
  RelativeGradient,  ///< converged: |P g| <= relative tolerance * initial |P g|
  AbsoluteGradient,  ///< converged: |P g| below the scale-free absolute bound
  /// converged to working precision (L-BFGS): no step changes the energy beyond its round-off
  /// floor and |P g| <= RelaxationOptions::round_off_gradient_tolerance * initial |P g|
  RoundOff,
  NoFreeParticles,   ///< converged trivially: every particle is on the boundary
  MaxIterations,     ///< not converged: the iteration budget ran out
  LineSearchFailed,  ///< not converged: no fold-free step decreases the energy (L-BFGS)
  FoldConstrained,   ///< not converged: all particles are at equilibrium except some that are held
                     ///< back from folding a face (the energy minimum is folded; L-BFGS); they
                     ///< are listed in RelaxationResult::held_particles
  Diverged,          ///< not converged: the energy or a position became non-finite (explicit)
  Cancelled,         ///< not converged: the progress callback asked to stop
  /// the slide phase of a sliding boundary only (L-BFGS): its energy fell by less than
  /// RelaxationOptions::slide_settle_tolerance over the last kSettleWindow iterations
  Settled,
  /// not converged (L-BFGS): over the last kStagnationWindow iterations the energy fell by less
  /// than kStagnationEnergy of itself and the smallest tangential gradient did not fall by 10%
  Stagnated
};
/// Iterations over which RelaxationOptions::slide_settle_tolerance is judged.
inline constexpr long kSettleWindow = 20;
/// Iterations over which StopReason::Stagnated is judged, and the energy's relative fall below
/// which a window counts as no progress.
inline constexpr long kStagnationWindow = 100;
inline constexpr double kStagnationEnergy = 1e-8;

/// A short lower-case description, e.g. "relative tangential gradient below tolerance".
std::string_view to_string(StopReason reason);
/// True for the reasons that mean convergence.
inline bool is_converged(StopReason reason) {
  return reason == StopReason::RelativeGradient || reason == StopReason::AbsoluteGradient ||
         reason == StopReason::RoundOff || reason == StopReason::NoFreeParticles;
}

/// One configuration handed to the frame callback.
struct RelaxationFrame {
  long iteration = 0;                           ///< iteration (L-BFGS) or time step (explicit)
  const Eigen::Matrix3Xd* positions = nullptr;  ///< 3 x #P current positions
  double energy = 0.0;                          ///< current E_len + E_ang
  double relative_gradient = 0.0;               ///< current |P g| / initial |P g|
};
/// Receives every `frame_interval`-th configuration (e.g. to write an animation).
using FrameCallback = std::function<void(const RelaxationFrame&)>;

/// Options of the explicit integrator (eqs. 9-12). Zero means "choose a stable default" (documented
/// in explicit_integrator.h).
struct ExplicitOptions {
  double mass = 1.0;              ///< m_i, the same for every particle (eq. 9)
  double damping = 0.0;           ///< gamma_i (eq. 9); 0: critical damping of the slowest mode
  double time_step = 0.0;         ///< dt (eqs. 11-12); 0: stability_factor * 2 sqrt(m / lambda_max)
  double stability_factor = 0.5;  ///< fraction of the stability limit used when time_step is 0
  double magnet_stiffness = 0.0;  ///< c of the magnet (§4.4); 0: the largest particle stiffness
  double drift_tolerance = 1e-3;  ///< re-project exactly when a particle is farther than this times
                                  ///< the mean rest length from the surface
};

/// How the L-BFGS solver applies its initial inverse Hessian H0 ~ L^-1 (L the interior spring
/// Laplacian, spring_laplacian.h).
enum class Preconditioner {
  Multigrid,  ///< one algebraic-multigrid V-cycle (multigrid.h): O(n) set-up and application; on
              ///< grids of at most MultigridOptions::coarsest_size interior particles it is the
              ///< exact factorisation itself (one level)
  Direct      ///< exact: sparse LDL^T in nested-dissection order, factorised once (O(n^1.5))
};
/// "multigrid", "direct".
std::string_view to_string(Preconditioner kind);
/// Parses "multigrid" or "direct". \throws InvalidInputError naming `input` otherwise.
Preconditioner parse_preconditioner(std::string_view text,
                                    std::string_view input = "preconditioner");

/// When the L-BFGS solver's H0 is the energy's own Hessian (newton_preconditioner.h) instead of
/// the spring Laplacian's inverse.
enum class NewtonMode {
  /// After NewtonOptions::after iterations without convergence, on grids of at most
  /// NewtonOptions::max_particles free particles: a solve that converges quickly never pays for
  /// a factorisation, and one that does not gets a Hessian that knows where the barrier stiffens
  /// and which springs are compressed.
  Auto,
  On,  ///< from the first iteration, at any size
  Off  ///< never: H0 is the Laplacian's inverse throughout
};
/// "auto", "on", "off".
std::string_view to_string(NewtonMode mode);
/// Parses "auto", "on" or "off". \throws InvalidInputError naming `input` otherwise.
NewtonMode parse_newton_mode(std::string_view text, std::string_view input = "newton");

struct NewtonOptions {
  NewtonMode mode = NewtonMode::Auto;
  /// NewtonMode::Auto: iterations of the Laplacian H0 first (per phase of the solve). 50: of the
  /// robustness benchmark's 56 cases 34 keep their results to the bit, and all take 13,447
  /// iterations instead of 22,383; its slowest cases 2.4 to 3.7 times fewer (docs/solvers.md).
  long after = 50;
  /// NewtonMode::Auto: the largest grid (free particles) that gets the Newton H0. Its sparse
  /// factorisation costs about as much as 1 L-BFGS iteration at 2,000 particles and 5 at 20,000.
  int max_particles = 10000;
  /// Iterations between two factorisations of the Hessian (the L-BFGS pairs correct the H0 of
  /// the iterations in between), >= 1. 4: on four of the benchmark's slowest cases about as few
  /// iterations as a factorisation every iteration, in 1.5-1.9x less time (every 8: up to 1.8x
  /// more iterations, and a different local minimum on one case); measured with the Newton H0
  /// in the slide too (in_slide).
  int refresh = 4;
  /// The Newton H0 is used only while the barrier's energy is at most this times the springs'
  /// (E_len + E_ang): far from its minimum the barrier (g/g0 - 1)^3 is steep, and a Newton step
  /// on a power law moves only a fraction of the way to its zero (on the star polygon's start,
  /// E = 2.7e10, it crept for 60 iterations where the Laplacian H0's longer steps took 12).
  double barrier_share = 1.0;
  /// Whether the slide phase of a sliding boundary uses it too. Off: the slide decides where the
  /// boundary goes, and with the Newton H0 it went elsewhere on the robustness benchmark's knife
  /// edge, the star polygon onto spot's flank (length energy 5% lower, but sigma_min 0.200
  /// against the bar's 0.2, where the Laplacian H0's slide ends at 0.208). Held where the slide
  /// left it, the interior has one minimum, which the Newton H0 reaches in fewer iterations.
  /// Still so beside LbfgsOptions::step_memory (docs/solvers.md).
  bool in_slide = false;
};

/// Options of the L-BFGS solver.
struct LbfgsOptions {
  int memory = 8;           ///< number of (s, y) pairs kept
  double armijo = 1e-4;     ///< sufficient-decrease constant c1 of the Armijo condition
  int max_backtracks = 40;  ///< step halvings per line search before giving up
  /// How H0 = L^-1 is applied. The V-cycle is the default: it was as fast or faster than the
  /// exact factorisation at every size measured, 405 to 100,000 particles (docs/solvers.md), and
  /// the only one that scales to millions.
  Preconditioner preconditioner = Preconditioner::Multigrid;
  MultigridOptions multigrid;  ///< the V-cycle's parameters (Preconditioner::Multigrid)
  /// The first trial of a line search: off, the full step (alpha = 1, or shorter when it would move
  /// a particle more than 2 rest lengths); on, that step times min(1, 2 f), f the fraction of its
  /// full step the previous iteration accepted (the full step again after the memory of pairs is
  /// cleared and after a search that took less than 1/256 of it). Where the injectivity barrier
  /// stiffens a few thin triangles the L^-1-based direction is too long by a steady factor, and
  /// every search from the full step halved it again; measurements in docs/solvers.md.
  bool step_memory = true;
  /// H0 times gamma = s.y / (y.H0 y) of the newest pair (Nocedal and Wright's scaling, eq. 7.20,
  /// with H0 in place of the identity), outside a sliding boundary's slide and with the Laplacian
  /// H0 only, while the barrier's energy is at most the springs' (E_len + E_ang). L^-1 knows
  /// nothing of the barrier's stiffness: where it holds thin triangles open, gamma is 0.01-0.1 and
  /// the unscaled direction was as many times too long at every iteration. Far from the barrier's
  /// minimum its stiffest triangles set gamma (1e-13 on the star polygon's start) and the scaled H0
  /// crawls, and in the slide it slowed the boundary's long-range motion until the settle test
  /// stopped it early: unscaled there. One more H0 application per iteration; measurements in
  /// docs/solvers.md.
  bool scale_h0 = true;
  NewtonOptions newton;  ///< when H0 is the energy's Hessian instead
};

/// What the boundary particles do during the relaxation.
enum class BoundaryMode {
  /// They stay where the boundary correspondence put them (the paper's arc-length boundary, §4.1).
  Fixed,
  /// They stay on the target curve, in order, and slide along it to lower the energy (fast solver;
  /// needs RelaxationProblem::boundary_curve), then are held there while the interior settles
  /// (RelaxationResult::slide_iterations). The faithful solver keeps them fixed.
  Slide,
  /// Nothing holds them to a curve: every particle moves on the target surface, except the ones
  /// in RelaxationProblem::pinned (at least one, which removes the translations). A decal's free
  /// boundary (mapping/map_decal.h): the angular springs keep the boundary's corners, the length
  /// springs its edges. Rotation about the pinned particle stays free; the energy chooses it (on
  /// a plane it is a null direction and the start's is kept).
  Free
};
/// "fixed", "slide", "free".
std::string_view to_string(BoundaryMode mode);
/// Parses "fixed", "slide" or "free". \throws InvalidInputError naming `input` otherwise.
BoundaryMode parse_boundary_mode(std::string_view text, std::string_view input = "boundary");

/// Which energy the relaxation minimises.
enum class EnergyKind {
  /// E_len + E_ang + the injectivity barrier E_bar (particles/spring_energy.h): the paper's
  /// minimum wherever no triangle comes close to collapse, and no slivers or folds where the
  /// paper's energy would buckle (compressed or stretched regions). The default.
  Robust,
  /// The paper's E_len + E_ang alone (eqs. 13-14, §4.1): reproduces Table 1 as published.
  Paper
};
/// "robust", "paper".
std::string_view to_string(EnergyKind kind);
/// Parses "robust" or "paper". \throws InvalidInputError naming `input` otherwise.
EnergyKind parse_energy_kind(std::string_view text, std::string_view input = "energy");

/// C_a / C of the angular springs when RelaxationOptions::angular_stiffness is not set, per energy.
/// The paper's energy keeps C_a = C (Table 1 as published). The robust energy softens the angular
/// springs to 0.25 C: its barrier already keeps every triangle from shearing into collapse, which
/// is what stiff angular springs guard against, and at C_a = C they pull the map away from the
/// length energy's minimum (eq. 13) wherever source and target differ in shape. On the robustness
/// cases (docs/results.md) 0.3 lowered the length energy by 5-30% with the symmetric Dirichlet
/// energy within 1% of C_a = C (measured at 0.3, 1 and 3), and 0.25 by up to 20% more than 0.3
/// with the symmetric Dirichlet energy within 0.3% of it (measured at 0.25 and 0.3 only; lower
/// values untried; docs/solvers.md).
inline constexpr double kPaperAngularStiffness = 1.0;
inline constexpr double kRobustAngularStiffness = 0.25;

struct RelaxationOptions {
  SolverKind solver = SolverKind::Fast;  ///< which solver
  /// Fixed or sliding boundary particles (BoundaryMode).
  BoundaryMode boundary = BoundaryMode::Fixed;
  /// The energy. The barrier of EnergyKind::Robust is used by the fast solver; the faithful
  /// solver (the paper's explicit integrator) always integrates the paper's forces.
  EnergyKind energy = EnergyKind::Robust;
  /// mu of the barrier relative to C (SpringEnergyOptions::barrier_stiffness); Robust only. 15:
  /// the value that held sigma_min >= 0.2 on the sharp-cornered sources of the robustness
  /// benchmark (36 and 60 degree tips opened to 180) without costing more length energy than the
  /// benchmark's bar allows; 10 let the star's tips fall to 0.19, 25 and more cost length energy
  /// (docs/solvers.md).
  double barrier_stiffness = 15.0;
  /// Smaller stretch below which the barrier acts (SpringEnergyOptions::barrier_sigma,
  /// kDefaultBarrierSigma).
  double barrier_sigma = kDefaultBarrierSigma;
  /// lambda of the distortion term relative to C (SpringEnergyOptions::distortion_stiffness);
  /// Robust only. 0 (off) by default: on the robustness benchmark 0.2 brings the two spot-back
  /// cases' symmetric Dirichlet within 1.02x of DCM's, but lifts the square and rectangle cases'
  /// length energy past 0.9x the best baseline's (docs/solvers.md). map_regions' distortion
  /// guard (MapOptions::distortion_guard) turns it on where it is needed.
  double distortion_stiffness = 0.0;
  double stiffness = 1.0;  ///< C of the normal springs (eq. 13)
  /// C_a of the angular springs; empty: the energy's default (kPaperAngularStiffness or
  /// kRobustAngularStiffness times `stiffness`), see angular_stiffness(const RelaxationOptions&).
  std::optional<double> angular_stiffness;
  /// Iteration (L-BFGS) or time-step (explicit) budget; 0: 2,000 for L-BFGS, 200,000 for explicit.
  long max_iterations = 0;
  double relative_gradient_tolerance = 1e-6;  ///< stop when |P g| <= this * initial |P g|
  /// ... or when |P g| <= this * C_max * sigma * mean_rest * sqrt(#P) (scale-free absolute bound)
  double absolute_gradient_tolerance = 1e-10;
  /// Sliding boundary (fast solver): the slide phase stops when |P g| <= this * its initial |P g|
  /// (or after 500 iterations); the interior then converges to `relative_gradient_tolerance` with
  /// the boundary held where it slid. The slide only has to find where the boundary goes: on the
  /// Plane -> Cap benchmark it leaves a plateau 0.09% above a lower minimum that the slide reached
  /// only after another 200-450 iterations (a slow escape from a symmetric saddle), 5-20x the
  /// whole solve. Values below `relative_gradient_tolerance` act as it.
  double slide_tolerance = 1e-3;
  /// Sliding boundary (fast solver): the slide phase also stops (StopReason::Settled) when its
  /// last kSettleWindow iterations lowered the energy by less than this fraction of it; 0: never.
  /// At a kink of the piecewise-smooth curve the gradient does not vanish, and the slide crept on
  /// with line-search steps of 1e-3 to 1e-8 after its energy had settled to six digits, until its
  /// 500-iteration limit: 280 of the triangle polygon -> spot flank case's slide iterations
  /// changed its energy by 4e-6 of it (docs/solvers.md). 1e-6 until 2026-12-06: the rectangle image
  /// onto spot's flank at 10,000 particles still crept by 7e-5 per 20 iterations from iteration
  /// 160 to its limit (34 s with a build beside it); at 1e-5 it settles at 422 (7.3 s, length
  /// energy +0.009%), and the robustness benchmark passes 56 of 56 in 12,160 iterations instead of
  /// 13,447 (30 cases changed, length energy at most +0.073%, the star polygons unchanged).
  double slide_settle_tolerance = 1e-5;
  /// L-BFGS: when the energy no longer changes beyond its round-off floor, the stop counts as
  /// converged (StopReason::RoundOff) if |P g| <= this * initial |P g|.
  double round_off_gradient_tolerance = 1e-4;
  int threads = 0;            ///< TBB threads; 0: all available
  ProgressCallback progress;  ///< called every iteration (L-BFGS) / check (explicit)
  FrameCallback frame;        ///< called every `frame_interval` iterations
  long frame_interval = 1;    ///< k of "every k-th configuration", >= 1
  /// Fast mode: when L-BFGS stops with StopReason::FoldConstrained, up to this many steps of the
  /// explicit integrator are run from its result. The integrator has no fold guard: it can pass
  /// through folded states the line search refuses and untangle folds inherited from the start
  /// (the naive map folds a few faces under extreme compression). Its result is taken only when it
  /// converges with no more folds and a lower energy; otherwise the fold-constrained stop stands
  /// (a true folded minimum, e.g. a square onto a disk). 0: off.
  long untangle_steps = 5000;
  ExplicitOptions explicit_integrator;  ///< faithful-mode parameters
  LbfgsOptions lbfgs;                   ///< fast-mode parameters
};

/// The input: a particle grid, the target surface, and the starting placement on it.
struct RelaxationProblem {
  const ParticleGrid* grid = nullptr;           ///< springs built; must outlive the call
  const SurfaceProjector* target = nullptr;     ///< the target limit surface's magnet
  Eigen::Matrix3Xd initial_positions;           ///< 3 x #P start positions on the target surface
  std::vector<SurfacePoint> initial_points;     ///< #P their surface points
  double rest_scale = 1.0;                      ///< sigma (rest_scale_factor)
  RestScale rest_scale_mode = RestScale::Auto;  ///< how sigma was chosen (echoed in the result)
  /// 3 x boundary_loop.size(): where each boundary particle belongs on the target curve (its
  /// arc-length position). Optional: when empty, the boundary residual is measured against
  /// initial_positions.
  Eigen::Matrix3Xd boundary_targets;
  /// The target boundary curve by correspondence parameter: boundary particle k of the grid sits
  /// at boundary_curve(s_k), s periodic with period 1 (e.g. RegionDiskMap::boundary_point). Needed
  /// by BoundaryMode::Slide.
  std::function<SurfacePoint(double)> boundary_curve;
  /// Start parameters s_k of the boundary particles (one per grid.boundary_loop entry) for
  /// BoundaryMode::Slide; empty: the grid's boundary_parameter.
  std::vector<double> boundary_parameters;
  /// BoundaryMode::Free: particles held where they start (at least one); ignored otherwise.
  std::vector<int> pinned;
  /// The |P g| that the relative tolerances (relative_gradient_tolerance,
  /// round_off_gradient_tolerance) refer to; 0: this start's own. A later phase of one relaxation
  /// (the held phase after a slide, the barrier run after an untangling) passes the first phase's,
  /// so that a start which is already nearly at equilibrium is judged against the problem's scale
  /// and not asked to reduce its own small gradient a million times again.
  double reference_gradient_norm = 0.0;
};

struct RelaxationResult {
  Eigen::Matrix3Xd positions;        ///< 3 x #P final positions, on the target surface
  std::vector<SurfacePoint> points;  ///< #P final surface points
  SolverKind solver = SolverKind::Fast;
  long iterations = 0;   ///< L-BFGS iterations or explicit time steps
  long evaluations = 0;  ///< energy evaluations (L-BFGS line-search trials included)
  bool converged = false;
  StopReason reason = StopReason::MaxIterations;
  /// L-BFGS: the H0 used.
  Preconditioner preconditioner = Preconditioner::Multigrid;
  /// L-BFGS: iterations whose H0 was the energy's Hessian (NewtonOptions), and the Hessian's
  /// factorisations.
  long newton_iterations = 0;
  long newton_factorisations = 0;
  double setup_seconds =
      0.0;  ///< incidence tables, Laplacian and its H0 (multigrid or factor), normals
  double solve_seconds = 0.0;              ///< the iterations
  double initial_energy = 0.0;             ///< E_len + E_ang at the start
  double length_energy = 0.0;              ///< final E_len (eq. 13)
  double angular_energy = 0.0;             ///< final E_ang
  double barrier_energy = 0.0;             ///< final E_bar (0 with EnergyKind::Paper)
  double distortion_energy = 0.0;          ///< final E_sd (0 when off)
  double angular_stiffness = 0.0;          ///< C_a of the run (angular_stiffness(options))
  EnergyKind energy = EnergyKind::Robust;  ///< the energy minimised (Paper for the faithful solver)
  /// Robust energy: runs of the paper's energy (with untangling) that were needed first because
  /// the start (or a fold-constrained stop) had folded faces, which the barrier cannot cross.
  int untangle_phases = 0;
  double magnet_energy = 0.0;  ///< explicit: magnet energy of the last integrator state before the
                               ///< final projection; L-BFGS: 0 (particles stay on the surface)
  double gradient_norm = 0.0;  ///< final |P g|
  double initial_gradient_norm = 0.0;  ///< initial |P g|
  /// gradient_norm / initial_gradient_norm (0 when the latter is 0)
  double relative_gradient = 0.0;
  int folded_faces = 0;  ///< faces with a folded corner at the end
  /// L-BFGS: interior particles held where they are at the end because moving them on would fold
  /// a face (non-empty with StopReason::FoldConstrained; they sit next to a nearly flat corner).
  std::vector<int> held_particles;
  int initial_folded_faces = 0;  ///< the same at the start
  /// Fast mode: explicit-integrator steps run after a fold-constrained stop
  /// (RelaxationOptions::untangle_steps), and whether their equilibrium was taken.
  long untangle_steps = 0;
  bool untangled = false;
  /// Max distance of a boundary particle from its target position (Fixed) or from the curve point
  /// at its parameter (Slide); of a pinned particle from its start (Free).
  double boundary_residual = 0.0;
  BoundaryMode boundary = BoundaryMode::Fixed;  ///< the boundary mode used
  /// Final correspondence parameter of each boundary particle (grid.boundary_loop order); with a
  /// fixed boundary the start's.
  std::vector<double> boundary_parameters;
  /// Largest distance a boundary particle slid, as a fraction of the curve (0 when fixed).
  double boundary_slide = 0.0;
  /// BoundaryMode::Slide runs in two phases: the boundary slides with the interior (at most 500
  /// iterations), then it is held where it slid while the interior relaxes to the tolerance (the
  /// result's `reason`, `converged` and gradients are that second phase's). The first phase's
  /// iterations (counted in `iterations` too) and why it stopped. When the held second phase does
  /// not converge fold-free, the fixed boundary from the original start is run and taken if it
  /// does; `boundary` then says Fixed.
  /// The slide phase's iterations and why it stopped:
  long slide_iterations = 0;
  StopReason slide_reason = StopReason::MaxIterations;
  double rest_scale = 1.0;                      ///< sigma used
  RestScale rest_scale_mode = RestScale::Auto;  ///< its mode, as given
  // Explicit integrator parameters actually used (0 for L-BFGS).
  double time_step = 0.0;         ///< dt
  double damping = 0.0;           ///< gamma
  double magnet_stiffness = 0.0;  ///< c
  long reprojections = 0;         ///< explicit: steps that re-projected drifting particles
};

/// C_a in effect: `options.angular_stiffness` when set, else the energy's default times C (the
/// paper's with EnergyKind::Paper or SolverKind::Faithful, which integrates the paper's forces).
double angular_stiffness(const RelaxationOptions& options);

/// Relaxes the interior particles of `problem` on the target surface.
/// \throws InvalidInputError when the problem is inconsistent (sizes, missing grid or target,
///         non-finite positions, invalid options); NumericalError when the spring Laplacian cannot
///         be factorised (an interior component not connected to the boundary).
RelaxationResult relax(const RelaxationProblem& problem, const RelaxationOptions& options = {});

}  // namespace elastic
