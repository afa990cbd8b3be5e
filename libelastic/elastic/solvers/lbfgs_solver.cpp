#include "elastic/solvers/lbfgs_solver.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <optional>

#include "elastic/core/error.h"
#include "elastic/core/huge_pages.h"
#include "elastic/solvers/interior_vectors.h"
#include "elastic/solvers/newton_preconditioner.h"
#include "elastic/solvers/solver_common.h"
#include "elastic/solvers/stagnation.h"

namespace elastic {

namespace {

using solver_detail::axpy;
using solver_detail::dot;
using solver_detail::for_chunks;
using solver_detail::InteriorLayout;
using solver_detail::kChunk;
using solver_detail::kSurfaceChunk;
using solver_detail::RelaxationSetup;
using solver_detail::sum_chunks;

// Halvings of a folding step before the folding particles are blocked instead.
constexpr int kFoldHalvings = 4;
// Rounds of blocking fold-making particles per line search before the step is halved instead.
constexpr int kMaxBlockRounds = 8;
// Releases of the held particles (all at once) before the solver accepts that the minimum is
// fold-constrained.
constexpr int kMaxReleases = 1;
// Consecutive steps without an energy change beyond round-off before the solver gives up.
constexpr int kMaxStalled = 20;
// Longest first trial step of a particle, in mean rest lengths (times sigma).
constexpr double kMaxStep = 2.0;
// LbfgsOptions::step_memory forgets a search that needed more than 8 halvings: such a search met an
// obstacle (a trial that folds, a boundary particle reaching its neighbour), not a direction too
// long by a steady factor, and starting the next ones from it made them crawl back by doubling
// for 8 iterations or more, long enough to trip the slide's 20-iteration settle test
// (docs/solvers.md has the case).
constexpr double kStepMemoryFloor = 1.0 / 256.0;

// s and y in single precision: 8 pairs of 3n doubles were 384 MB of a million-particle map's
// peak; the two-loop recursion computes in double with the stored values (rho too, so each pair
// stays consistent), and a pair only shapes the direction, which the line search checks.
struct Pair {
  Eigen::VectorXf s, y;
  double rho = 0.0;    // 1 / (s . y)
  double gamma = 0.0;  // s . y / (y . H0 y): H0's scale after this pair (LbfgsOptions::scale_h0)
};

// One call of relax_lbfgs: the state its iterations share and its steps (lbfgs_solver.h's list)
// as named methods. run() reads as the algorithm: evaluate the start, prepare the preconditioner
// and buffers, iterate (stop tests, direction, line search, step), report.
class LbfgsRun {
 public:
  LbfgsRun(const RelaxationProblem& problem, const RelaxationOptions& options)
      : problem_(problem), options_(options), lb_(options.lbfgs), setup_(problem, options) {
    if (lb_.memory < 0 || lb_.max_backtracks < 1 || !(lb_.armijo > 0.0 && lb_.armijo < 1.0)) {
      throw InvalidInputError("relaxation", "L-BFGS options out of range");
    }
    result_.solver = SolverKind::Fast;
  }
  LbfgsRun(const LbfgsRun&) = delete;
  LbfgsRun& operator=(const LbfgsRun&) = delete;

  RelaxationResult run() {
    evaluate_start();
    if (n_ == 0) {
      result_.reason = StopReason::NoFreeParticles;
      result_.setup_seconds = solver_detail::seconds_since(start_);
      solver_detail::finish_result(setup_, problem_, 0.0, result_);
      return std::move(result_);
    }
    prepare();
    result_.setup_seconds = solver_detail::seconds_since(start_);
    const long long solve_start = solver_detail::now_ticks();
    iterate();
    for (Eigen::Index k = 0; k < n_; ++k) {
      if (held_[static_cast<std::size_t>(k)]) {
        result_.held_particles.push_back(setup_.interior[static_cast<std::size_t>(k)]);
      }
    }
    result_.iterations = iteration_;
    result_.solve_seconds = solver_detail::seconds_since(solve_start);
    release_buffers();
    solver_detail::finish_result(setup_, problem_, initial_norm_, result_);
    return std::move(result_);
  }

 private:
  // The energy, gradient and folded faces of the starting map.
  void evaluate_start() {
    resize_huge(gradient_, 3, setup_.num_particles);
    energies_ =
        setup_.springs.evaluate(setup_.positions, &gradient_, &setup_.normals, &normal_gradient_);
    result_.initial_energy = energies_.total();
    result_.evaluations = 1;
    result_.initial_folded_faces = setup_.springs.folded_faces(setup_.positions, setup_.normals);
  }

  // H0, the round-off model, the solver's vectors, the tangential gradient and its reference norm,
  // the tangent frames and the trial state.
  void prepare() {
    // H0 = L^-1, L the interior spring Laplacian: factorised once in nested-dissection order, or
    // approximated by a multigrid V-cycle on large grids (LbfgsOptions::preconditioner).
    Eigen::SparseMatrix<double> laplacian = solver_detail::interior_laplacian(setup_, options_);
    laplacian_.emplace(laplacian, solver_detail::interior_coordinates(setup_), lb_);
    result_.preconditioner = laplacian_->kind();
    const NewtonOptions& newton = lb_.newton;
    newton_allowed_ = (newton.mode == NewtonMode::On ||
                       (newton.mode == NewtonMode::Auto && n_ <= newton.max_particles)) &&
                      (newton.in_slide || !setup_.slide);
    if (newton_allowed_) {
      newton_laplacian_.swap(laplacian);  // kept for the Newton H0's regularisation
    }
    held_.assign(static_cast<std::size_t>(n_), 0);
    resize_huge(solved_, m_, 1);
    setup_.springs.folded_corners(setup_.positions, setup_.normals, folded_);
    with_barrier_ = setup_.springs.options().triangle_terms();
    noise_factor_ = energy_noise_factor();
    prepare_trial_state();
    solver_detail::add_normal_motion(setup_, normal_gradient_, &frames_, gradient_);

    // The solver's vectors, allocated once (see core/huge_pages.h for why that matters at scale).
    for (Eigen::VectorXd* v : {&q_, &q_free_, &direction_, &trial_q_}) {
      resize_huge(*v, m_, 1);
    }
    layout_.tangential(gradient_, setup_.normals, setup_.curve_tangent, q_);
    q_norm_ = std::sqrt(dot(q_, q_));
    // The relative stopping test is scaled by the springs' own initial gradient: near-collapsed
    // triangles of the start can make the barrier's share of the first gradient orders of
    // magnitude larger, and a tolerance relative to that would stop far from the minimum.
    const double spring_norm =
        with_barrier_ ? solver_detail::spring_gradient_norm(setup_) : q_norm_;
    initial_norm_ = problem_.reference_gradient_norm > 0.0 ? problem_.reference_gradient_norm
                    : spring_norm > 0.0                    ? spring_norm
                                                           : q_norm_;
  }

  // The iterations' buffers go before the final measurements, which evaluate the energy and its
  // gradient once more: at a million particles the pairs, trial state and frames are about 0.7 GB,
  // and with them live that evaluation set the map's peak.
  void release_buffers() {
    memory_.clear();
    next_ = Pair{};
    laplacian_.reset();
    newton_.reset();
    for (Eigen::VectorXd* v : {&q_, &q_free_, &direction_, &solved_, &trial_q_}) {
      *v = Eigen::VectorXd();
    }
    for (Eigen::Matrix3Xd* m :
         {&gradient_, &normal_gradient_, &trial_positions_, &trial_normals_, &trial_gradient_}) {
      *m = Eigen::Matrix3Xd();
    }
    std::vector<SurfacePoint>().swap(trial_points_);
    std::vector<SurfaceDerivatives>().swap(frames_);
    std::vector<SurfaceDerivatives>().swap(trial_frames_);
  }

  // Round-off of an energy evaluation. Each term C (|d| - k)^2 carries an error of about
  // 2 C |e| delta, e = |d| - k, delta the error of |d|: a few ulps of the coordinates, i.e.
  // eps (k + extent) for particles at distance `extent` from the origin. Summed linearly and by
  // Cauchy-Schwarz: 2 eps (1 + extent / k) sqrt(E S), S = sum C k^2 over all springs. Near a
  // perfect map (E -> 0) this floor falls only like sqrt(E), far slower than E, and line-search
  // trials that differ from E by less than it are decided on the gradient instead.
  double energy_noise_factor() const {
    double rest_sum = 0.0;
    for (const Spring& spring : setup_.grid.springs) {
      rest_sum += options_.stiffness * spring.rest * spring.rest;
    }
    for (const AngularSpring& spring : setup_.grid.angular_springs) {
      rest_sum += angular_stiffness(options_) * spring.rest * spring.rest;
    }
    rest_sum *= problem_.rest_scale * problem_.rest_scale;
    const double extent = setup_.positions.cwiseAbs().maxCoeff();
    return 8.0 * std::numeric_limits<double>::epsilon() *
           (1.0 + extent / std::max(setup_.mean_rest, 1e-300)) * std::sqrt(rest_sum);
  }

  double round_off(double energy) const {
    return std::max(1e-13 * energy, noise_factor_ * std::sqrt(std::max(energy, 0.0)));
  }

  // Tangent frames (du, dv) of the interior particles, and the trial buffers. Boundary particles
  // never move, so their columns are copied once here and stay equal in both buffers through the
  // swaps; the retraction writes the interior columns.
  void prepare_trial_state() {
    assign_huge(frames_, static_cast<std::size_t>(n_));
    assign_huge(trial_frames_, static_cast<std::size_t>(n_));
    for_chunks(
        n_,
        [&](Eigen::Index k) {
          frames_[static_cast<std::size_t>(k)] = solver_detail::tangent_frame(
              setup_.target.surface(),
              setup_
                  .points[static_cast<std::size_t>(setup_.interior[static_cast<std::size_t>(k)])]);
        },
        kSurfaceChunk);
    resize_huge(trial_positions_, 3, setup_.num_particles);
    resize_huge(trial_normals_, 3, setup_.num_particles);
    resize_huge(trial_gradient_, 3, setup_.num_particles);
    trial_positions_ = setup_.positions;
    trial_normals_ = setup_.normals;
    trial_points_.reserve(setup_.points.size());
    advise_huge_pages(trial_points_.data(), setup_.points.size() * sizeof(SurfacePoint));
    trial_points_.assign(setup_.points.begin(), setup_.points.end());
    // Sliding boundary: trial curve parameters, tangents and speeds.
    trial_tangents_ = setup_.curve_tangent;
    trial_s_ = setup_.curve_s;
    trial_speed_ = setup_.curve_speed;
  }

  void iterate() {
    emit_frame(0);
    result_.reason = StopReason::MaxIterations;
    for (iteration_ = 0;; ++iteration_) {
      if (converged() || !free_gradient_or_release() || out_of_budget()) {
        break;
      }
      choose_h0();
      choose_direction();
      if (!line_search()) {
        if (!memory_.empty()) {  // retry from the preconditioned gradient before giving up
          memory_.clear();
          continue;
        }
        result_.reason = at_round_off_ ? StopReason::RoundOff : StopReason::LineSearchFailed;
        break;
      }
      take_trial();
      emit_frame(iteration_ + 1);
    }
  }

  void emit_frame(long iteration) const {
    if (options_.frame && iteration % options_.frame_interval == 0) {
      options_.frame({iteration, &setup_.positions, energies_.total(),
                      initial_norm_ > 0.0 ? q_norm_ / initial_norm_ : 0.0});
    }
  }

  // The gradient tests of relaxation.h.
  bool converged() {
    if (q_norm_ <= options_.relative_gradient_tolerance * initial_norm_) {
      result_.reason = StopReason::RelativeGradient;
      return true;
    }
    if (q_norm_ <= setup_.absolute_bound) {
      result_.reason = StopReason::AbsoluteGradient;
      return true;
    }
    return false;
  }

  // q_free = the rows of q that are not held. When those are at equilibrium the held particles are
  // released once: if the energy lets them move away from the fold, the solver goes on; if they are
  // held again and the rest settles again, the minimum lies beyond the no-fold constraint (false:
  // stop, FoldConstrained).
  bool free_gradient_or_release() {
    q_free_ = q_;
    mask(q_free_);
    if (held_count_ == 0) {
      return true;
    }
    const double norm = std::sqrt(dot(q_free_, q_free_));
    if (norm > options_.relative_gradient_tolerance * initial_norm_ &&
        norm > setup_.absolute_bound) {
      return true;
    }
    if (releases_ >= kMaxReleases) {
      result_.reason = StopReason::FoldConstrained;
      return false;
    }
    ++releases_;
    std::fill(held_.begin(), held_.end(), 0);
    held_count_ = 0;
    memory_.clear();
    q_free_ = q_;
    return true;
  }

  // Stalled steps, the iteration limit and cancellation. At the energy's round-off floor no step
  // can be told from another by the energy: stopped there with a small gradient the map is at its
  // minimum to working precision (the barrier's stiffness can keep the last digits of the gradient
  // from 1e-6 while the energy no longer changes in its 13th digit).
  bool out_of_budget() {
    at_round_off_ = q_norm_ <= options_.round_off_gradient_tolerance * initial_norm_;
    if (stalled_ >= kMaxStalled) {
      result_.reason = at_round_off_ ? StopReason::RoundOff : StopReason::LineSearchFailed;
      return true;
    }
    if (iteration_ >= max_iterations_) {
      return true;
    }
    if (settled()) {
      result_.reason = StopReason::Settled;
      return true;
    }
    // No progress in any phase (stagnation.h): a run that goes nowhere stops instead of spending
    // its budget. A 5,000-particle map of a camel head's ear region onto bob spent 1,950
    // iterations (127 s) at one energy, falling by 3e-9 of itself per 100 iterations with the
    // gradient unchanged (a sliver the barrier holds open while every step has to be shortened to
    // keep the faces unfolded); the map fails either way, now in 57 s instead of 200.
    if (stagnation_.stagnated(energies_.total(), q_norm_)) {
      result_.reason = StopReason::Stagnated;
      return true;
    }
    if (!report_progress(options_.progress, {.stage = "relax",
                                             .iteration = iteration_,
                                             .total = max_iterations_,
                                             .energy = energies_.total(),
                                             .gradient = q_norm_ / initial_norm_})) {
      result_.reason = StopReason::Cancelled;
      return true;
    }
    return false;
  }

  // The slide's settle test (RelaxationOptions::slide_settle_tolerance): the energy of each
  // iterate is kept for kSettleWindow iterations.
  bool settled() {
    if (!(setup_.slide && options_.slide_settle_tolerance > 0.0)) {
      return false;
    }
    const double energy = energies_.total();
    recent_.push_back(energy);
    if (static_cast<long>(recent_.size()) <= kSettleWindow) {
      return false;
    }
    recent_.pop_front();
    return recent_.front() - energy <= options_.slide_settle_tolerance * std::abs(energy);
  }

  bool is_held(Eigen::Index i) const { return held_[static_cast<std::size_t>(i % n_)] != 0; }

  // Zeroes the held rows of v.
  void mask(Eigen::VectorXd& v) const {
    if (held_count_ == 0) {
      return;
    }
    for_chunks(m_, [&](Eigen::Index i) {
      if (is_held(i)) {
        v[i] = 0.0;
      }
    });
  }

  // The norm of the rows that are not held.
  double free_norm(const Eigen::VectorXd& v) const {
    if (held_count_ == 0) {
      return std::sqrt(dot(v, v));
    }
    return std::sqrt(
        sum_chunks(m_, [&](Eigen::Index i) { return is_held(i) ? 0.0 : v[i] * v[i]; }));
  }

  // Whether the barrier's energy is at most `share` times the springs' (E_len + E_ang): where it is
  // above, its stiffest triangles dominate the curvature, and neither the Newton H0 nor the
  // pairs' scale of L^-1 is used.
  bool barrier_within(double share) const {
    return energies_.barrier <= share * (energies_.length + energies_.angular);
  }

  // Which H0 this iteration uses (NewtonOptions): the Newton H0 once `after` iterations have
  // passed (at once for NewtonMode::On) while the barrier's energy is within its share of the
  // springs', refactorised every `refresh` iterations; else L^-1. A change of H0 clears the
  // memory: its pairs were taken with the other one.
  void choose_h0() {
    if (!newton_allowed_) {
      return;
    }
    const NewtonOptions& newton = lb_.newton;
    const long after = newton.mode == NewtonMode::On ? 0 : newton.after;
    bool use = iteration_ >= after && barrier_within(newton.barrier_share);
    if (use && !newton_) {  // built at its first use: most solves converge before `after`
      newton_.emplace(setup_, newton_laplacian_);
      newton_laplacian_ = Eigen::SparseMatrix<double>();  // the operator holds its copy
    }
    if (use && (!newton_->ready() || !newton_on_ ||
                iteration_ - last_factorisation_ >= std::max(newton.refresh, 1))) {
      use = refactorise();
    }
    if (use != newton_on_) {
      memory_.clear();
      newton_on_ = use;
    }
    result_.newton_iterations += use ? 1 : 0;
  }

  // Factorises the Newton H0 at the current iterate, without the held particles.
  bool refactorise() {
    const bool ok = newton_->refresh(setup_.positions, setup_.normals, setup_.curve_tangent,
                                     gradient_, frames_, held_);
    last_factorisation_ = iteration_;
    newton_held_ = held_count_;
    ++result_.newton_factorisations;
    return ok;
  }

  // v = masked H0 (masked v): L^-1, or the Newton H0 (refactorised when particles were held
  // since its last factorisation).
  void apply_h0(Eigen::VectorXd& v) {
    mask(v);
    if (newton_on_ && held_count_ != newton_held_ && !refactorise()) {
      newton_on_ = false;  // particles were held since: K without them, or L^-1 if that fails
      memory_.clear();
    }
    if (newton_on_) {
      newton_->apply(v);
      mask(v);
      return;
    }
    laplacian_->solve3(v, solved_);
    v.swap(solved_);
    mask(v);
  }

  // direction = -P H q_free by the two-loop recursion with H0 = L^-1 (newest pair first, then
  // back); if that is no descent direction, -P L^-1 q_free with the memory cleared, and in the end
  // (round-off only: L is SPD) steepest descent.
  void choose_direction() {
    direction_ = q_free_;
    std::vector<double> alphas(memory_.size());
    for (std::size_t k = memory_.size(); k-- > 0;) {
      alphas[k] = memory_[k].rho * dot(memory_[k].s, direction_);
      axpy(-alphas[k], memory_[k].y, direction_);
    }
    apply_h0(direction_);
    scaled_ = !memory_.empty() && memory_.back().gamma > 0.0 && barrier_within(1.0);
    if (scaled_) {
      direction_ *= memory_.back().gamma;  // LbfgsOptions::scale_h0
    }
    for (std::size_t k = 0; k < memory_.size(); ++k) {
      const double beta = memory_[k].rho * dot(memory_[k].y, direction_);
      axpy(alphas[k] - beta, memory_[k].s, direction_);
    }
    direction_ = -direction_;
    layout_.project(direction_, setup_.normals, setup_.curve_tangent);
    slope_ = dot(q_free_, direction_);
    if (!(slope_ < 0.0)) {
      preconditioned_gradient_direction();
      if (!(slope_ < 0.0)) {
        direction_ = -q_free_;
        slope_ = -dot(q_free_, q_free_);
      }
    }
  }

  // direction = -P L^-1 q_free, the memory cleared (its pairs may mix held and free rows). It is a
  // descent direction since the masked L^-1 is positive semi-definite and positive on the free
  // rows.
  void preconditioned_gradient_direction() {
    memory_.clear();
    scaled_ = false;
    direction_ = q_free_;
    apply_h0(direction_);
    direction_ = -direction_;
    layout_.project(direction_, setup_.normals, setup_.curve_tangent);
    slope_ = dot(q_free_, direction_);
  }

  // The first trial moves no particle farther than kMaxStep rest lengths: a step far beyond the
  // grid's own scale (the barrier's gradient near a collapsing triangle can be orders of magnitude
  // above the springs') would only be halved back, after walking every particle across many ptex
  // faces for each halving.
  double first_step() const {
    const double longest = std::sqrt(tbb::parallel_deterministic_reduce(
        tbb::blocked_range<Eigen::Index>(0, n_, kChunk), 0.0,
        [&](const tbb::blocked_range<Eigen::Index>& r, double best) {
          for (Eigen::Index k = r.begin(); k != r.end(); ++k) {
            best = std::max(best, layout_.at(direction_, k).squaredNorm());
          }
          return best;
        },
        [](double a, double b) { return std::max(a, b); }));
    const double cap = kMaxStep * setup_.mean_rest;
    return longest > cap && cap > 0.0 ? cap / longest : 1.0;
  }

  // Backtracking line search along the retraction. True when a trial is accepted (the trial state
  // holds it).
  bool line_search() {
    const double full = first_step();
    // LbfgsOptions::step_memory: start where the last iteration's search ended, doubled.
    double alpha =
        lb_.step_memory && !scaled_ && !memory_.empty() && accepted_fraction_ >= kStepMemoryFloor
            ? full * std::min(1.0, 2.0 * accepted_fraction_)
            : full;
    int backtracks = 0, block_rounds = 0, fold_halvings = 0;
    while (backtracks < lb_.max_backtracks && slope_ < 0.0) {
      trial_q_ready_ = false;
      retract(alpha);
      setup_.springs.folded_corners(trial_positions_, trial_normals_, trial_folded_);
      if (setup_.slide && !solver_detail::RelaxationSetup::in_order(trial_s_)) {
        // A boundary particle would pass its neighbour on the curve: shorten the step.
        alpha *= 0.5;
        ++backtracks;
        continue;
      }
      // A first few folding trials only shorten the step; then the folding particles are blocked.
      // With the injectivity barrier (EnergyKind::Robust) a short enough step never folds (the
      // energy grows without bound first), so folding trials are only shortened, never blocked.
      const bool block_now =
          !with_barrier_ && fold_halvings >= kFoldHalvings && block_rounds < kMaxBlockRounds;
      if (new_fold(block_now)) {
        if (block_now) {
          // Retry the same step length without the held particles. Zeroing rows of a descent
          // direction need not leave a descent direction, so it is recomputed in the new subspace.
          ++block_rounds;
          q_free_ = q_;
          mask(q_free_);
          preconditioned_gradient_direction();
        } else {
          alpha *= 0.5;
          ++backtracks;
          ++fold_halvings;
        }
        continue;
      }
      if (acceptable(alpha)) {
        accepted_fraction_ = alpha / full;
        return true;
      }
      alpha *= 0.5;
      ++backtracks;
    }
    return false;
  }

  // True when the trial folds a corner that was not folded. With `hold`, the free particles of
  // every such corner are held: they keep their position from now on (until a release) and their
  // rows of the direction are zeroed.
  bool new_fold(bool hold) {
    bool found = false;
    for (std::size_t c = 0; c < folded_.size(); ++c) {
      if (!trial_folded_[c] || folded_[c]) {
        continue;
      }
      found = true;
      if (!hold) {
        break;
      }
      const SpringSystem::Corner& corner = setup_.springs.corners()[c];
      for (const int p : {corner.i, corner.next, corner.prev}) {
        const int k = setup_.interior_index[static_cast<std::size_t>(p)];
        if (k < 0 || held_[static_cast<std::size_t>(k)]) {
          continue;
        }
        held_[static_cast<std::size_t>(k)] = 1;
        ++held_count_;
        for (int d = 0; d < 3; ++d) {
          direction_[d * n_ + k] = 0.0;
        }
      }
    }
    return found;
  }

  // Evaluates the trial: the Armijo condition, or within the energy's round-off a smaller
  // tangential gradient. The barrier sees each triangle along the sum of its corners' surface
  // normals (SpringSystem::evaluate), and the gradient includes the turning of those normals as the
  // corners move (add_normal_motion), so that every trial, every iterate and the slope belong to
  // one function of the positions. (Normals held fixed through each line search and re-taken at the
  // accepted point made the energy jump between iterations: the solver stalled at its iteration
  // limit on the robustness benchmark's tightest cases.)
  bool acceptable(double alpha) {
    trial_energies_ = setup_.springs.evaluate(trial_positions_, &trial_gradient_, &trial_normals_,
                                              with_barrier_ ? &normal_gradient_ : nullptr);
    if (with_barrier_) {
      solver_detail::add_normal_motion(setup_, normal_gradient_, &trial_frames_, trial_gradient_);
    }
    ++result_.evaluations;
    const double energy = energies_.total();
    const double trial_energy = trial_energies_.total();
    if (!std::isfinite(trial_energy)) {
      return false;
    }
    if (trial_energy <= energy + lb_.armijo * alpha * slope_) {
      return true;
    }
    if (trial_energy <= energy + round_off(energy)) {
      layout_.tangential(trial_gradient_, trial_normals_, trial_tangents_, trial_q_);
      trial_q_ready_ = true;
      return free_norm(trial_q_) < std::sqrt(dot(q_free_, q_free_));
    }
    return false;
  }

  // The trial state at step alpha along the direction (solver_detail::parametric_retraction, the
  // magnet where it declines; sliding boundary particles along their curve).
  void retract(double alpha) {
    for_chunks(
        n_,
        [&](Eigen::Index k) {
          const Eigen::Vector3d step = alpha * layout_.at(direction_, k);
          if (step.isZero(0.0)) {  // blocked (or converged) particle: exactly where it is
            retract_unmoved(k);
          } else if (setup_.sliding[static_cast<std::size_t>(k)] >= 0) {
            retract_on_curve(k, step);
          } else {
            retract_on_surface(k, step);
          }
        },
        kSurfaceChunk);
  }

  void retract_unmoved(Eigen::Index k) {
    const auto kk = static_cast<std::size_t>(k);
    const auto p = static_cast<std::size_t>(setup_.interior[kk]);
    const auto col = static_cast<Eigen::Index>(p);
    trial_points_[p] = setup_.points[p];
    trial_positions_.col(col) = setup_.positions.col(col);
    trial_normals_.col(col) = setup_.normals.col(col);
    trial_frames_[kk] = frames_[kk];
    if (setup_.sliding[kk] >= 0) {
      const auto b = static_cast<std::size_t>(setup_.sliding[kk]);
      trial_s_[b] = setup_.curve_s[b];
      trial_speed_[b] = setup_.curve_speed[b];
      trial_tangents_.col(col) = setup_.curve_tangent.col(col);
    }
  }

  // Along the curve: ds = (t . step) / |dc/ds|.
  void retract_on_curve(Eigen::Index k, const Eigen::Vector3d& step) {
    const auto kk = static_cast<std::size_t>(k);
    const auto p = static_cast<std::size_t>(setup_.interior[kk]);
    const auto col = static_cast<Eigen::Index>(p);
    const auto b = static_cast<std::size_t>(setup_.sliding[kk]);
    trial_s_[b] = setup_.curve_s[b] +
                  setup_.curve_tangent.col(col).dot(step) / std::max(setup_.curve_speed[b], 1e-300);
    Eigen::Vector3d position, tangent;
    setup_.curve_frame(trial_s_[b], trial_points_[p], position, tangent, trial_speed_[b]);
    trial_positions_.col(col) = position;
    trial_tangents_.col(col) = tangent;
    const SurfaceDerivatives& d = trial_frames_[kk] =
        setup_.target.surface().derivatives(trial_points_[p]);
    const Eigen::Vector3d normal = d.du.cross(d.dv);
    trial_normals_.col(col) = normal.norm() > 1e-300 ? Eigen::Vector3d(normal.normalized())
                                                     : Eigen::Vector3d(setup_.normals.col(col));
  }

  void retract_on_surface(Eigen::Index k, const Eigen::Vector3d& step) {
    const auto kk = static_cast<std::size_t>(k);
    const auto p = static_cast<std::size_t>(setup_.interior[kk]);
    const auto col = static_cast<Eigen::Index>(p);
    SurfaceDerivatives& frame = trial_frames_[kk];
    ClosestPoint out;
    if (!solver_detail::parametric_retraction(setup_.target.surface(), setup_.points[p],
                                              setup_.positions.col(col), frames_[kk], step, out,
                                              frame)) {
      // Magnet fallback: the closest point of x + alpha p, warm started.
      out = setup_.target.closest(Eigen::Vector3d(setup_.positions.col(col) + step),
                                  setup_.points[p]);
      frame = solver_detail::tangent_frame(setup_.target.surface(), out.point);
    }
    trial_points_[p] = out.point;
    trial_positions_.col(col) = out.position;
    trial_normals_.col(col) = out.normal;
  }

  // Moves to the accepted trial: the memory's new pair, the swaps, the stall count.
  void take_trial() {
    if (!trial_q_ready_) {
      layout_.tangential(trial_gradient_, trial_normals_, trial_tangents_, trial_q_);
    }
    remember_step();
    setup_.positions.swap(trial_positions_);
    setup_.normals.swap(trial_normals_);
    if (setup_.slide) {
      setup_.curve_s.swap(trial_s_);
      setup_.curve_speed.swap(trial_speed_);
      setup_.curve_tangent.swap(trial_tangents_);
      // Entries that did not move keep their values in both buffers (the retraction copies them).
      trial_s_ = setup_.curve_s;
      trial_speed_ = setup_.curve_speed;
      trial_tangents_ = setup_.curve_tangent;
    }
    setup_.points.swap(trial_points_);
    frames_.swap(trial_frames_);
    folded_.swap(trial_folded_);
    gradient_.swap(trial_gradient_);
    stalled_ = energies_.total() - trial_energies_.total() <= 0.1 * round_off(energies_.total())
                   ? stalled_ + 1
                   : 0;
    energies_ = trial_energies_;
    q_.swap(trial_q_);
    q_norm_ = std::sqrt(dot(q_, q_));
  }

  // The pair (s, y) of the accepted step, kept when s . y > 1e-12 |s| |y| (curvature condition);
  // y is the change of the free part of the tangential gradient.
  void remember_step() {
    if (next_.s.size() != m_) {
      resize_huge(next_.s, m_, 1);
      resize_huge(next_.y, m_, 1);
    }
    for_chunks(n_, [&](Eigen::Index k) {
      const auto p = static_cast<Eigen::Index>(setup_.interior[static_cast<std::size_t>(k)]);
      const bool free = !held_[static_cast<std::size_t>(k)];
      for (int c = 0; c < 3; ++c) {
        next_.s[c * n_ + k] = static_cast<float>(trial_positions_(c, p) - setup_.positions(c, p));
        next_.y[c * n_ + k] =
            free ? static_cast<float>(trial_q_[c * n_ + k] - q_free_[c * n_ + k]) : 0.0F;
      }
    });
    const double sy = dot(next_.s, next_.y);
    if (sy > 1e-12 * std::sqrt(dot(next_.s, next_.s) * dot(next_.y, next_.y)) && lb_.memory > 0) {
      next_.rho = 1.0 / sy;
      next_.gamma = 0.0;
      if (lb_.scale_h0 && !setup_.slide && !newton_on_) {
        // direction_ as scratch: the next direction starts again from q_free.
        direction_ = next_.y.cast<double>();
        apply_h0(direction_);
        const double yhy = dot(next_.y, direction_);
        next_.gamma = yhy > 0.0 && std::isfinite(yhy) ? sy / yhy : 0.0;
      }
      memory_.push_back(std::move(next_));
      next_ = Pair{};
      if (memory_.size() > static_cast<std::size_t>(lb_.memory)) {
        next_ = std::move(memory_.front());
        memory_.pop_front();
      }
    }
  }

  const long long start_ = solver_detail::now_ticks();
  const RelaxationProblem& problem_;
  const RelaxationOptions& options_;
  const LbfgsOptions& lb_;
  RelaxationSetup setup_;
  RelaxationResult result_;
  const long max_iterations_ = options_.max_iterations > 0 ? options_.max_iterations : 2000;
  const Eigen::Index n_ = setup_.num_free();
  const Eigen::Index m_ = 3 * n_;
  const InteriorLayout layout_{&setup_, n_};
  std::optional<solver_detail::LaplacianInverse> laplacian_;
  // The Newton H0 (LbfgsOptions::newton): whether this solve may use it, the operator (built at
  // its first use), whether it is in use now.
  bool newton_allowed_ = false;
  Eigen::SparseMatrix<double> newton_laplacian_;  // L, until the Newton H0 is built from it
  std::optional<solver_detail::NewtonPreconditioner> newton_;
  bool newton_on_ = false;
  long last_factorisation_ = 0;   // iteration of the Newton H0's last factorisation
  Eigen::Index newton_held_ = 0;  // held particles at that factorisation
  bool with_barrier_ = false;
  double noise_factor_ = 0.0;
  double initial_norm_ = 0.0;  // the reference of the relative gradient test

  // Current iterate: gradient, energies, tangential gradient q (and its free rows), folded corners.
  Eigen::Matrix3Xd gradient_;
  Eigen::Matrix3Xd normal_gradient_;  // dE/dn per particle (SpringSystem::evaluate), scratch
  SpringEnergies energies_;
  Eigen::VectorXd q_, q_free_;
  double q_norm_ = 0.0;
  std::vector<char> folded_;
  std::vector<SurfaceDerivatives> frames_;  // tangent frames (du, dv) of the interior particles

  // Held particles (see the file comment of lbfgs_solver.h): interior particles that the line
  // search stopped from folding a face. They stay where they are, like boundary particles, until a
  // release; the solver works in the subspace of the others: the held rows of the tangential
  // gradient, of H0 = L^-1 and of the direction are zero.
  std::vector<char> held_;
  Eigen::Index held_count_ = 0;
  int releases_ = 0;

  // The step: direction, its slope, the memory of pairs and the storage of the next pair (the
  // oldest pair's once the memory is full).
  Eigen::VectorXd direction_, solved_;
  double slope_ = 0.0;
  double accepted_fraction_ = 1.0;  // the last accepted alpha over that search's full step
  bool scaled_ = false;             // this iteration's H0 is scaled (LbfgsOptions::scale_h0)
  std::deque<Pair> memory_;
  Pair next_;

  // The trial state (written by the retraction, evaluated by the line search).
  Eigen::Matrix3Xd trial_positions_, trial_normals_, trial_gradient_, trial_tangents_;
  std::vector<SurfacePoint> trial_points_;
  std::vector<SurfaceDerivatives> trial_frames_;
  std::vector<char> trial_folded_;
  std::vector<double> trial_s_, trial_speed_;
  SpringEnergies trial_energies_;
  Eigen::VectorXd trial_q_;
  bool trial_q_ready_ = false;  // trial_q_ already holds the trial's tangential gradient

  long iteration_ = 0;
  std::deque<double> recent_;  // energies of the last iterates (settled())
  solver_detail::StagnationMonitor stagnation_;
  int stalled_ = 0;  // consecutive steps that changed the energy by less than its round-off
  bool at_round_off_ = false;
};

}  // namespace

RelaxationResult relax_lbfgs(const RelaxationProblem& problem, const RelaxationOptions& options) {
  LbfgsRun run(problem, options);
  return run.run();
}

}  // namespace elastic
