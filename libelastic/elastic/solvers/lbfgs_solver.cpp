#include "elastic/solvers/lbfgs_solver.h"

#include <tbb/parallel_for.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "elastic/core/error.h"
#include "elastic/solvers/solver_common.h"

namespace elastic {

namespace {

using solver_detail::RelaxationSetup;

// Halvings of a folding step before the folding particles are blocked instead.
constexpr int kFoldHalvings = 4;
// Rounds of blocking fold-making particles per line search before the step is halved instead.
constexpr int kMaxBlockRounds = 8;
// Consecutive steps without an energy change beyond round-off before the solver gives up.
constexpr int kMaxStalled = 20;

// Interior vectors have 3n entries laid out as an n x 3 column-major matrix (all x, then all y,
// then all z), so that the Laplacian solve takes the three coordinates as three right-hand sides.
struct InteriorLayout {
  const RelaxationSetup* setup;
  Eigen::Index n;

  // Tangential part of the gradient at the interior particles: g_i - n_i (n_i . g_i).
  Eigen::VectorXd tangential(const Eigen::Matrix3Xd& gradient,
                             const Eigen::Matrix3Xd& normals) const {
    Eigen::VectorXd q(3 * n);
    for (Eigen::Index k = 0; k < n; ++k) {
      const int p = setup->interior[static_cast<std::size_t>(k)];
      const Eigen::Vector3d g = gradient.col(p);
      const Eigen::Vector3d nrm = normals.col(p);
      const Eigen::Vector3d t = g - nrm * nrm.dot(g);
      for (int c = 0; c < 3; ++c) q[c * n + k] = t[c];
    }
    return q;
  }

  void project(Eigen::VectorXd& v, const Eigen::Matrix3Xd& normals) const {
    for (Eigen::Index k = 0; k < n; ++k) {
      const int p = setup->interior[static_cast<std::size_t>(k)];
      const Eigen::Vector3d nrm = normals.col(p);
      const Eigen::Vector3d t(v[k], v[n + k], v[2 * n + k]);
      const Eigen::Vector3d u = t - nrm * nrm.dot(t);
      for (int c = 0; c < 3; ++c) v[c * n + k] = u[c];
    }
  }

  Eigen::Vector3d at(const Eigen::VectorXd& v, Eigen::Index k) const {
    return {v[k], v[n + k], v[2 * n + k]};
  }
};

struct Pair {
  Eigen::VectorXd s, y;
  double rho = 0.0;  // 1 / (s . y)
};

}  // namespace

RelaxationResult relax_lbfgs(const RelaxationProblem& problem, const RelaxationOptions& options) {
  const long long start = solver_detail::now_ticks();
  RelaxationSetup setup(problem, options);
  const LbfgsOptions& lb = options.lbfgs;
  if (lb.memory < 0 || lb.max_backtracks < 1 || !(lb.armijo > 0.0 && lb.armijo < 1.0))
    throw InvalidInputError("relaxation", "L-BFGS options out of range");

  RelaxationResult result;
  result.solver = SolverKind::Fast;
  const long max_iterations = options.max_iterations > 0 ? options.max_iterations : 2000;
  const Eigen::Index n = setup.num_free();
  const InteriorLayout layout{&setup, n};

  Eigen::Matrix3Xd gradient;
  SpringEnergies energies = setup.springs.evaluate(setup.positions, &gradient);
  result.initial_energy = energies.total();
  result.evaluations = 1;
  result.initial_folded_faces = setup.springs.folded_faces(setup.positions, setup.normals);

  if (n == 0) {
    result.reason = StopReason::NoFreeParticles;
    result.setup_seconds = solver_detail::seconds_since(start);
    solver_detail::finish_result(setup, problem, 0.0, result);
    return result;
  }

  // H0 = L^-1: the interior spring Laplacian, factorised once (AMD ordering inside SimplicialLDLT).
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> laplacian;
  solver_detail::factorize(solver_detail::interior_laplacian(setup, options), laplacian);
  // The x, y and z solves are independent (const solves of one factor): run them in parallel when
  // the system is large enough for it to pay. Each column's arithmetic is the same either way.
  const auto apply_h0 = [&](const Eigen::VectorXd& q) {
    Eigen::VectorXd r(3 * n);
    const auto solve_column = [&](int c) {
      r.segment(c * n, n) = laplacian.solve(q.segment(c * n, n));
    };
    if (n >= 20000) {
      tbb::parallel_for(0, 3, solve_column);
    } else {
      for (int c = 0; c < 3; ++c) solve_column(c);
    }
    return r;
  };

  std::vector<char> folded;
  setup.springs.folded_corners(setup.positions, setup.normals, folded);

  Eigen::VectorXd q = layout.tangential(gradient, setup.normals);
  double q_norm = q.norm();
  const double initial_norm = q_norm;
  result.setup_seconds = solver_detail::seconds_since(start);
  const long long solve_start = solver_detail::now_ticks();

  std::deque<Pair> memory;
  std::vector<char> blocked(static_cast<std::size_t>(n), 0);  // free particles held back this step
  bool last_blocked = false;
  Eigen::Index blocked_count = 0;
  int stalled = 0;  // consecutive steps that changed the energy by less than its round-off
  std::vector<Eigen::Vector3d> trial_query(static_cast<std::size_t>(n));
  std::vector<SurfacePoint> hints(static_cast<std::size_t>(n));
  std::vector<ClosestPoint> projected(static_cast<std::size_t>(n));
  Eigen::Matrix3Xd trial_positions, trial_normals, trial_gradient;
  std::vector<char> trial_folded;

  const auto emit_frame = [&](long iteration) {
    if (options.frame && iteration % options.frame_interval == 0)
      options.frame({iteration, &setup.positions, energies.total(),
                     initial_norm > 0.0 ? q_norm / initial_norm : 0.0});
  };
  emit_frame(0);

  result.reason = StopReason::MaxIterations;
  long iteration = 0;
  for (;; ++iteration) {
    if (q_norm <= options.relative_gradient_tolerance * initial_norm) {
      result.reason = StopReason::RelativeGradient;
      break;
    }
    if (q_norm <= setup.absolute_bound) {
      result.reason = StopReason::AbsoluteGradient;
      break;
    }
    if (last_blocked && blocked_count <= std::max<Eigen::Index>(1, n / 20)) {
      // A few particles were held back from folding a face in the last step. If every other
      // particle is at equilibrium, the energy minimum lies beyond the no-fold constraint: stop and
      // say so. (With many blocked particles the remaining gradient says little: go on.)
      double free_sum = 0.0;
      for (Eigen::Index k = 0; k < n; ++k)
        if (!blocked[static_cast<std::size_t>(k)]) free_sum += layout.at(q, k).squaredNorm();
      const double free_norm = std::sqrt(free_sum);
      if (free_norm <= options.relative_gradient_tolerance * initial_norm ||
          free_norm <= setup.absolute_bound) {
        result.reason = StopReason::FoldConstrained;
        break;
      }
    }
    if (stalled >= kMaxStalled) {
      result.reason = StopReason::LineSearchFailed;
      break;
    }
    if (iteration >= max_iterations) break;
    if (!report_progress(options.progress, {.stage = "relax",
                                            .iteration = iteration,
                                            .total = max_iterations,
                                            .energy = energies.total(),
                                            .gradient = q_norm / initial_norm})) {
      result.reason = StopReason::Cancelled;
      break;
    }

    // Two-loop recursion with H0 = L^-1 (newest pair first, then back).
    Eigen::VectorXd direction = q;
    std::vector<double> alphas(memory.size());
    for (std::size_t m = memory.size(); m-- > 0;) {
      alphas[m] = memory[m].rho * memory[m].s.dot(direction);
      direction -= alphas[m] * memory[m].y;
    }
    direction = apply_h0(direction);
    for (std::size_t m = 0; m < memory.size(); ++m) {
      const double beta = memory[m].rho * memory[m].y.dot(direction);
      direction += (alphas[m] - beta) * memory[m].s;
    }
    direction = -direction;
    layout.project(direction, setup.normals);
    double slope = q.dot(direction);
    if (!(slope < 0.0)) {
      memory.clear();
      direction = -apply_h0(q);
      layout.project(direction, setup.normals);
      slope = q.dot(direction);
      if (!(slope < 0.0)) {  // L is SPD, so only round-off gets here: fall back to steepest descent
        direction = -q;
        slope = -q_norm * q_norm;
      }
    }

    // Backtracking line search along the retraction x + alpha p -> closest point.
    for (Eigen::Index k = 0; k < n; ++k)
      hints[static_cast<std::size_t>(k)] =
          setup.points[static_cast<std::size_t>(setup.interior[k])];
    bool accepted = false;
    double alpha = 1.0;
    SpringEnergies trial_energies;
    Eigen::VectorXd trial_q;
    std::fill(blocked.begin(), blocked.end(), 0);
    int backtracks = 0, block_rounds = 0, fold_halvings = 0;
    blocked_count = 0;
    while (backtracks < lb.max_backtracks && slope < 0.0) {
      trial_q.resize(0);
      for (Eigen::Index k = 0; k < n; ++k)
        trial_query[static_cast<std::size_t>(k)] =
            setup.positions.col(setup.interior[static_cast<std::size_t>(k)]) +
            alpha * layout.at(direction, k);
      setup.target.closest(trial_query, projected, hints);
      trial_positions = setup.positions;
      trial_normals = setup.normals;
      for (Eigen::Index k = 0; k < n; ++k) {
        const int p = setup.interior[static_cast<std::size_t>(k)];
        trial_positions.col(p) = projected[static_cast<std::size_t>(k)].position;
        trial_normals.col(p) = projected[static_cast<std::size_t>(k)].normal;
      }
      setup.springs.folded_corners(trial_positions, trial_normals, trial_folded);
      // A first few folding trials only shorten the step; then the folding particles are blocked.
      const bool block_now = fold_halvings >= kFoldHalvings && block_rounds < kMaxBlockRounds;
      bool new_fold = false;
      for (std::size_t c = 0; c < folded.size(); ++c) {
        if (!trial_folded[c] || folded[c]) continue;
        new_fold = true;
        if (!block_now) break;
        // Block the free particles of the newly folded corner: they keep their position this step.
        const SpringSystem::Corner& corner = setup.springs.corners()[c];
        for (const int p : {corner.i, corner.next, corner.prev}) {
          const int k = setup.interior_index[static_cast<std::size_t>(p)];
          if (k < 0 || blocked[static_cast<std::size_t>(k)]) continue;
          blocked[static_cast<std::size_t>(k)] = 1;
          ++blocked_count;
          for (int d = 0; d < 3; ++d) direction[d * n + k] = 0.0;
        }
      }
      if (new_fold) {
        if (block_now) {
          ++block_rounds;  // retry the same step length without the blocked particles
          slope = q.dot(direction);
        } else {
          alpha *= 0.5;
          ++backtracks;
          ++fold_halvings;
        }
        continue;
      }
      trial_energies = setup.springs.evaluate(trial_positions, &trial_gradient);
      ++result.evaluations;
      const double energy = energies.total();
      const double trial_energy = trial_energies.total();
      if (std::isfinite(trial_energy)) {
        if (trial_energy <= energy + lb.armijo * alpha * slope) {
          accepted = true;
        } else if (trial_energy <= energy + 1e-13 * energy) {
          // Within round-off of the current energy: accept on a smaller tangential gradient.
          trial_q = layout.tangential(trial_gradient, trial_normals);
          accepted = trial_q.norm() < q_norm;
        }
      }
      if (accepted) break;
      alpha *= 0.5;
      ++backtracks;
    }
    last_blocked = block_rounds > 0;
    if (!accepted) {
      if (!memory.empty()) {  // retry from the preconditioned gradient before giving up
        memory.clear();
        continue;
      }
      result.reason = StopReason::LineSearchFailed;
      break;
    }

    if (trial_q.size() == 0) trial_q = layout.tangential(trial_gradient, trial_normals);
    Pair pair;
    pair.s.resize(3 * n);
    for (Eigen::Index k = 0; k < n; ++k) {
      const int p = setup.interior[static_cast<std::size_t>(k)];
      const Eigen::Vector3d step = trial_positions.col(p) - setup.positions.col(p);
      for (int c = 0; c < 3; ++c) pair.s[c * n + k] = step[c];
    }
    pair.y = trial_q - q;
    const double sy = pair.s.dot(pair.y);
    if (sy > 1e-12 * pair.s.norm() * pair.y.norm() && lb.memory > 0) {
      pair.rho = 1.0 / sy;
      memory.push_back(std::move(pair));
      if (memory.size() > static_cast<std::size_t>(lb.memory)) memory.pop_front();
    }

    setup.positions.swap(trial_positions);
    setup.normals.swap(trial_normals);
    for (Eigen::Index k = 0; k < n; ++k)
      setup.points[static_cast<std::size_t>(setup.interior[static_cast<std::size_t>(k)])] =
          projected[static_cast<std::size_t>(k)].point;
    folded.swap(trial_folded);
    gradient.swap(trial_gradient);
    stalled =
        energies.total() - trial_energies.total() <= 1e-14 * energies.total() ? stalled + 1 : 0;
    energies = trial_energies;
    q = std::move(trial_q);
    q_norm = q.norm();
    emit_frame(iteration + 1);
  }

  result.iterations = iteration;
  result.solve_seconds = solver_detail::seconds_since(solve_start);
  solver_detail::finish_result(setup, problem, initial_norm, result);
  return result;
}

}  // namespace elastic
