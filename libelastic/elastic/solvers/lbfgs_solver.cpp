#include "elastic/solvers/lbfgs_solver.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
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
// Releases of the held particles (all at once) before the solver accepts that the minimum is
// fold-constrained.
constexpr int kMaxReleases = 1;
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

  // H0 = L^-1, L the interior spring Laplacian: factorised once in nested-dissection order, or
  // approximated by a multigrid V-cycle on large grids (LbfgsOptions::preconditioner).
  const solver_detail::LaplacianInverse laplacian(solver_detail::interior_laplacian(setup, options),
                                                  solver_detail::interior_coordinates(setup), lb);
  result.preconditioner = laplacian.kind();

  // Held particles (see the file comment of lbfgs_solver.h): interior particles that the line
  // search stopped from folding a face. They stay where they are, like boundary particles, until a
  // release; the solver works in the subspace of the others: the held rows of the tangential
  // gradient, of H0 = L^-1 and of the direction are zero.
  std::vector<char> held(static_cast<std::size_t>(n), 0);
  Eigen::Index held_count = 0;
  int releases = 0;
  const auto mask = [&](Eigen::VectorXd& v) {
    if (held_count == 0) return;
    for (Eigen::Index k = 0; k < n; ++k)
      if (held[static_cast<std::size_t>(k)])
        for (int d = 0; d < 3; ++d) v[d * n + k] = 0.0;
  };
  const auto apply_h0 = [&](Eigen::VectorXd v) {
    mask(v);
    v = laplacian.solve3(v);
    mask(v);
    return v;
  };
  // The tangential gradient of the particles that are not held.
  const auto free_part = [&](const Eigen::VectorXd& v) {
    Eigen::VectorXd w = v;
    mask(w);
    return w;
  };

  std::vector<char> folded;
  setup.springs.folded_corners(setup.positions, setup.normals, folded);

  Eigen::VectorXd q = layout.tangential(gradient, setup.normals);
  double q_norm = q.norm();
  const double initial_norm = q_norm;
  result.setup_seconds = solver_detail::seconds_since(start);
  const long long solve_start = solver_detail::now_ticks();

  std::deque<Pair> memory;
  int stalled = 0;  // consecutive steps that changed the energy by less than its round-off
  // Tangent frames (du, dv) of the interior particles at their current and trial surface points.
  std::vector<solver_detail::TangentFrame> frames(static_cast<std::size_t>(n)),
      trial_frames(frames.size());
  tbb::parallel_for(Eigen::Index{0}, n, [&](Eigen::Index k) {
    frames[static_cast<std::size_t>(k)] = solver_detail::tangent_frame(
        setup.target.surface(),
        setup.points[static_cast<std::size_t>(setup.interior[static_cast<std::size_t>(k)])]);
  });
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
    Eigen::VectorXd q_free = free_part(q);
    if (held_count > 0) {
      const double free_norm = q_free.norm();
      if (free_norm <= options.relative_gradient_tolerance * initial_norm ||
          free_norm <= setup.absolute_bound) {
        // Every particle that is not held is at equilibrium. Release the held ones once: if the
        // energy lets them move away from the fold, the solver goes on; if they are held again and
        // the rest settles again, the minimum lies beyond the no-fold constraint.
        if (releases >= kMaxReleases) {
          result.reason = StopReason::FoldConstrained;
          break;
        }
        ++releases;
        std::fill(held.begin(), held.end(), 0);
        held_count = 0;
        memory.clear();
        q_free = q;
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
    Eigen::VectorXd direction = q_free;
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
    double slope = q_free.dot(direction);
    if (!(slope < 0.0)) {
      memory.clear();
      direction = -apply_h0(q_free);
      layout.project(direction, setup.normals);
      slope = q_free.dot(direction);
      if (!(slope < 0.0)) {  // L is SPD, so only round-off gets here: fall back to steepest descent
        direction = -q_free;
        slope = -q_free.squaredNorm();
      }
    }

    // Backtracking line search along the retraction (see retract above).
    const auto retract = [&](double alpha) {
      tbb::parallel_for(
          tbb::blocked_range<Eigen::Index>(0, n, 1024),
          [&](const tbb::blocked_range<Eigen::Index>& range) {
            for (Eigen::Index k = range.begin(); k != range.end(); ++k) {
              const auto kk = static_cast<std::size_t>(k);
              const auto p = static_cast<std::size_t>(setup.interior[kk]);
              const Eigen::Vector3d step = alpha * layout.at(direction, k);
              ClosestPoint& out = projected[kk];
              solver_detail::TangentFrame& frame = trial_frames[kk];
              if (step.isZero(0.0)) {  // blocked (or converged) particle: exactly where it is
                out.point = setup.points[p];
                out.position = setup.positions.col(static_cast<Eigen::Index>(p));
                out.normal = setup.normals.col(static_cast<Eigen::Index>(p));
                frame = frames[kk];
                continue;
              }
              if (!solver_detail::parametric_retraction(
                      setup.target.surface(), setup.points[p],
                      setup.positions.col(static_cast<Eigen::Index>(p)), frames[kk], step, out,
                      frame)) {
                // Magnet fallback: the closest point of x + alpha p, warm started.
                out = setup.target.closest(
                    Eigen::Vector3d(setup.positions.col(static_cast<Eigen::Index>(p)) + step),
                    setup.points[p]);
                frame = solver_detail::tangent_frame(setup.target.surface(), out.point);
              }
            }
          });
    };
    bool accepted = false;
    double alpha = 1.0;
    SpringEnergies trial_energies;
    Eigen::VectorXd trial_q;
    int backtracks = 0, block_rounds = 0, fold_halvings = 0;
    while (backtracks < lb.max_backtracks && slope < 0.0) {
      trial_q.resize(0);
      retract(alpha);
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
        // Hold the free particles of the newly folded corner: they keep their position from now
        // on (until a release).
        const SpringSystem::Corner& corner = setup.springs.corners()[c];
        for (const int p : {corner.i, corner.next, corner.prev}) {
          const int k = setup.interior_index[static_cast<std::size_t>(p)];
          if (k < 0 || held[static_cast<std::size_t>(k)]) continue;
          held[static_cast<std::size_t>(k)] = 1;
          ++held_count;
          for (int d = 0; d < 3; ++d) direction[d * n + k] = 0.0;
        }
      }
      if (new_fold) {
        if (block_now) {
          // Retry the same step length without the held particles. Zeroing rows of a descent
          // direction need not leave a descent direction, so it is recomputed in the new subspace
          // (memory cleared: its pairs mix held and free rows): -P L^-1 q_free, which is one since
          // the masked L^-1 is positive semi-definite and positive on the free rows.
          ++block_rounds;
          memory.clear();
          q_free = free_part(q);
          direction = -apply_h0(q_free);
          layout.project(direction, setup.normals);
          slope = q_free.dot(direction);
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
          accepted = free_part(trial_q).norm() < q_free.norm();
        }
      }
      if (accepted) break;
      alpha *= 0.5;
      ++backtracks;
    }
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
    pair.y = free_part(trial_q) - q_free;
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
    frames.swap(trial_frames);
    folded.swap(trial_folded);
    gradient.swap(trial_gradient);
    stalled =
        energies.total() - trial_energies.total() <= 1e-14 * energies.total() ? stalled + 1 : 0;
    energies = trial_energies;
    q = std::move(trial_q);
    q_norm = q.norm();
    emit_frame(iteration + 1);
  }

  for (Eigen::Index k = 0; k < n; ++k)
    if (held[static_cast<std::size_t>(k)])
      result.held_particles.push_back(setup.interior[static_cast<std::size_t>(k)]);
  result.iterations = iteration;
  result.solve_seconds = solver_detail::seconds_since(solve_start);
  solver_detail::finish_result(setup, problem, initial_norm, result);
  return result;
}

}  // namespace elastic
