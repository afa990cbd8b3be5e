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

#include "elastic/core/error.h"
#include "elastic/core/huge_pages.h"
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
// Longest first trial step of a particle, in mean rest lengths (times sigma).
constexpr double kMaxStep = 2.0;

// Vector kernels over [0, n) in fixed chunks. Reductions join the chunks' partial sums in a fixed
// tree (parallel_deterministic_reduce), so every result is the same for any number of threads; at
// a million particles the serial Eigen versions of these passes took about a third of an
// iteration.
constexpr Eigen::Index kChunk = 16384;

// Per-particle work that evaluates the surface (retraction, frames): microseconds per item, so
// small chunks still pay for themselves.
constexpr Eigen::Index kSurfaceChunk = 256;

template <typename Body>
void for_chunks(Eigen::Index n, const Body& body, Eigen::Index chunk = kChunk) {
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, chunk),
                    [&](const tbb::blocked_range<Eigen::Index>& r) {
                      for (Eigen::Index i = r.begin(); i != r.end(); ++i) {
                        body(i);
                      }
                    });
}

template <typename Term>
double sum_chunks(Eigen::Index n, const Term& term) {
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<Eigen::Index>(0, n, kChunk), 0.0,
      [&](const tbb::blocked_range<Eigen::Index>& r, double sum) {
        for (Eigen::Index i = r.begin(); i != r.end(); ++i) {
          sum += term(i);
        }
        return sum;
      },
      std::plus<double>());
}

double dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return sum_chunks(a.size(), [&](Eigen::Index i) { return a[i] * b[i]; });
}

// y += alpha x
void axpy(double alpha, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  for_chunks(x.size(), [&](Eigen::Index i) { y[i] += alpha * x[i]; });
}

// Interior vectors have 3n entries laid out as an n x 3 column-major matrix (all x, then all y,
// then all z), so that the Laplacian solve takes the three coordinates as three right-hand sides.
struct InteriorLayout {
  const RelaxationSetup* setup;
  Eigen::Index n;

  // The tangent space of free entry k: the surface's tangent plane (g - n (n . g)), or for a
  // sliding boundary particle the curve's tangent line (t (t . g)); `tangents` holds the curve
  // tangents of the state the normals belong to.
  Eigen::Vector3d to_tangent(Eigen::Index k, const Eigen::Vector3d& g,
                             const Eigen::Matrix3Xd& normals,
                             const Eigen::Matrix3Xd& tangents) const {
    const int p = setup->interior[static_cast<std::size_t>(k)];
    if (setup->sliding[static_cast<std::size_t>(k)] >= 0) {
      const Eigen::Vector3d t = tangents.col(p);
      return t * t.dot(g);
    }
    const Eigen::Vector3d nrm = normals.col(p);
    return g - nrm * nrm.dot(g);
  }

  // q = tangential part of the gradient at the free particles.
  void tangential(const Eigen::Matrix3Xd& gradient, const Eigen::Matrix3Xd& normals,
                  const Eigen::Matrix3Xd& tangents, Eigen::VectorXd& q) const {
    for_chunks(n, [&](Eigen::Index k) {
      const int p = setup->interior[static_cast<std::size_t>(k)];
      const Eigen::Vector3d t = to_tangent(k, gradient.col(p), normals, tangents);
      for (int c = 0; c < 3; ++c) {
        q[c * n + k] = t[c];
      }
    });
  }

  void project(Eigen::VectorXd& v, const Eigen::Matrix3Xd& normals,
               const Eigen::Matrix3Xd& tangents) const {
    for_chunks(n, [&](Eigen::Index k) {
      const Eigen::Vector3d u =
          to_tangent(k, Eigen::Vector3d(v[k], v[n + k], v[2 * n + k]), normals, tangents);
      for (int c = 0; c < 3; ++c) {
        v[c * n + k] = u[c];
      }
    });
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
  if (lb.memory < 0 || lb.max_backtracks < 1 || !(lb.armijo > 0.0 && lb.armijo < 1.0)) {
    throw InvalidInputError("relaxation", "L-BFGS options out of range");
  }

  RelaxationResult result;
  result.solver = SolverKind::Fast;
  const long max_iterations = options.max_iterations > 0 ? options.max_iterations : 2000;
  const Eigen::Index n = setup.num_free();
  const Eigen::Index m = 3 * n;
  const InteriorLayout layout{&setup, n};

  Eigen::Matrix3Xd gradient;
  resize_huge(gradient, 3, setup.num_particles);
  SpringEnergies energies = setup.springs.evaluate(setup.positions, &gradient, &setup.normals);
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
  const auto is_held = [&](Eigen::Index i) { return held[static_cast<std::size_t>(i % n)] != 0; };
  const auto mask = [&](Eigen::VectorXd& v) {
    if (held_count == 0) {
      return;
    }
    for_chunks(m, [&](Eigen::Index i) {
      if (is_held(i)) {
        v[i] = 0.0;
      }
    });
  };
  // The norm of the rows that are not held.
  const auto free_norm = [&](const Eigen::VectorXd& v) {
    if (held_count == 0) {
      return std::sqrt(dot(v, v));
    }
    return std::sqrt(sum_chunks(m, [&](Eigen::Index i) { return is_held(i) ? 0.0 : v[i] * v[i]; }));
  };
  // out = masked L^-1 (masked v); v is masked in place.
  Eigen::VectorXd solved;
  resize_huge(solved, m, 1);
  const auto apply_h0 = [&](Eigen::VectorXd& v) {
    mask(v);
    laplacian.solve3(v, solved);
    v.swap(solved);
    mask(v);
  };

  std::vector<char> folded;
  setup.springs.folded_corners(setup.positions, setup.normals, folded);
  const bool with_barrier = setup.springs.options().barrier_stiffness > 0.0;

  // Round-off of an energy evaluation. Each term C (|d| - k)^2 carries an error of about
  // 2 C |e| delta, e = |d| - k, delta the error of |d|: a few ulps of the coordinates, i.e.
  // eps (k + extent) for particles at distance `extent` from the origin. Summed linearly and by
  // Cauchy-Schwarz: 2 eps (1 + extent / k) sqrt(E S), S = sum C k^2 over all springs. Near a
  // perfect map (E -> 0) this floor falls only like sqrt(E), far slower than E, and line-search
  // trials that differ from E by less than it are decided on the gradient instead.
  double rest_sum = 0.0;
  for (const Spring& spring : setup.grid.springs) {
    rest_sum += options.stiffness * spring.rest * spring.rest;
  }
  for (const AngularSpring& spring : setup.grid.angular_springs) {
    rest_sum += angular_stiffness(options) * spring.rest * spring.rest;
  }
  rest_sum *= problem.rest_scale * problem.rest_scale;
  const double extent = setup.positions.cwiseAbs().maxCoeff();
  const double noise_factor = 8.0 * std::numeric_limits<double>::epsilon() *
                              (1.0 + extent / std::max(setup.mean_rest, 1e-300)) *
                              std::sqrt(rest_sum);
  const auto round_off = [&](double energy) {
    return std::max(1e-13 * energy, noise_factor * std::sqrt(std::max(energy, 0.0)));
  };

  // The solver's vectors, allocated once (see core/huge_pages.h for why that matters at scale).
  Eigen::VectorXd q, q_free, direction, trial_q;
  for (Eigen::VectorXd* v : {&q, &q_free, &direction, &trial_q}) {
    resize_huge(*v, m, 1);
  }
  layout.tangential(gradient, setup.normals, setup.curve_tangent, q);
  double q_norm = std::sqrt(dot(q, q));
  // The relative stopping test is scaled by the springs' own initial gradient: near-collapsed
  // triangles of the start can make the barrier's share of the first gradient orders of magnitude
  // larger, and a tolerance relative to that would stop far from the minimum.
  const double spring_norm = with_barrier ? solver_detail::spring_gradient_norm(setup) : q_norm;
  const double initial_norm = problem.reference_gradient_norm > 0.0
                                  ? problem.reference_gradient_norm
                              : spring_norm > 0.0 ? spring_norm
                                                  : q_norm;
  result.setup_seconds = solver_detail::seconds_since(start);
  const long long solve_start = solver_detail::now_ticks();

  std::deque<Pair> memory;
  Pair next;        // storage of the next (s, y) pair; the oldest pair's once the memory is full
  int stalled = 0;  // consecutive steps that changed the energy by less than its round-off
  // Tangent frames (du, dv) of the interior particles at their current and trial surface points.
  std::vector<SurfaceDerivatives> frames, trial_frames;
  assign_huge(frames, static_cast<std::size_t>(n));
  assign_huge(trial_frames, static_cast<std::size_t>(n));
  for_chunks(
      n,
      [&](Eigen::Index k) {
        frames[static_cast<std::size_t>(k)] = solver_detail::tangent_frame(
            setup.target.surface(),
            setup.points[static_cast<std::size_t>(setup.interior[static_cast<std::size_t>(k)])]);
      },
      kSurfaceChunk);
  // The trial state. Boundary particles never move, so their columns are copied once here and stay
  // equal in both buffers through the swaps; the retraction writes the interior columns.
  Eigen::Matrix3Xd trial_positions, trial_normals, trial_gradient;
  resize_huge(trial_positions, 3, setup.num_particles);
  resize_huge(trial_normals, 3, setup.num_particles);
  resize_huge(trial_gradient, 3, setup.num_particles);
  trial_positions = setup.positions;
  trial_normals = setup.normals;
  std::vector<SurfacePoint> trial_points;
  trial_points.reserve(setup.points.size());
  advise_huge_pages(trial_points.data(), setup.points.size() * sizeof(SurfacePoint));
  trial_points.assign(setup.points.begin(), setup.points.end());
  std::vector<char> trial_folded;
  // Sliding boundary: trial curve parameters, tangents and speeds.
  Eigen::Matrix3Xd trial_tangents = setup.curve_tangent;
  std::vector<double> trial_s = setup.curve_s, trial_speed = setup.curve_speed;

  const auto emit_frame = [&](long iteration) {
    if (options.frame && iteration % options.frame_interval == 0) {
      options.frame({iteration, &setup.positions, energies.total(),
                     initial_norm > 0.0 ? q_norm / initial_norm : 0.0});
    }
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
    q_free = q;
    mask(q_free);
    if (held_count > 0) {
      const double norm = std::sqrt(dot(q_free, q_free));
      if (norm <= options.relative_gradient_tolerance * initial_norm ||
          norm <= setup.absolute_bound) {
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
    // At the energy's round-off floor no step can be told from another by the energy: stopped
    // there with a small gradient the map is at its minimum to working precision (the barrier's
    // stiffness can keep the last digits of the gradient from 1e-6 while the energy no longer
    // changes in its 13th digit).
    const bool at_round_off = q_norm <= options.round_off_gradient_tolerance * initial_norm;
    if (stalled >= kMaxStalled) {
      result.reason = at_round_off ? StopReason::RoundOff : StopReason::LineSearchFailed;
      break;
    }
    if (iteration >= max_iterations) {
      break;
    }
    if (!report_progress(options.progress, {.stage = "relax",
                                            .iteration = iteration,
                                            .total = max_iterations,
                                            .energy = energies.total(),
                                            .gradient = q_norm / initial_norm})) {
      result.reason = StopReason::Cancelled;
      break;
    }

    // Two-loop recursion with H0 = L^-1 (newest pair first, then back).
    direction = q_free;
    std::vector<double> alphas(memory.size());
    for (std::size_t k = memory.size(); k-- > 0;) {
      alphas[k] = memory[k].rho * dot(memory[k].s, direction);
      axpy(-alphas[k], memory[k].y, direction);
    }
    apply_h0(direction);
    for (std::size_t k = 0; k < memory.size(); ++k) {
      const double beta = memory[k].rho * dot(memory[k].y, direction);
      axpy(alphas[k] - beta, memory[k].s, direction);
    }
    direction = -direction;
    layout.project(direction, setup.normals, setup.curve_tangent);
    double slope = dot(q_free, direction);
    if (!(slope < 0.0)) {
      memory.clear();
      direction = q_free;
      apply_h0(direction);
      direction = -direction;
      layout.project(direction, setup.normals, setup.curve_tangent);
      slope = dot(q_free, direction);
      if (!(slope < 0.0)) {  // L is SPD, so only round-off gets here: fall back to steepest descent
        direction = -q_free;
        slope = -dot(q_free, q_free);
      }
    }

    // Backtracking line search along the retraction (solver_detail::parametric_retraction, the
    // magnet where it declines).
    const auto retract = [&](double alpha) {
      for_chunks(
          n,
          [&](Eigen::Index k) {
            const auto kk = static_cast<std::size_t>(k);
            const auto p = static_cast<std::size_t>(setup.interior[kk]);
            const auto col = static_cast<Eigen::Index>(p);
            const Eigen::Vector3d step = alpha * layout.at(direction, k);
            SurfaceDerivatives& frame = trial_frames[kk];
            if (step.isZero(0.0)) {  // blocked (or converged) particle: exactly where it is
              trial_points[p] = setup.points[p];
              trial_positions.col(col) = setup.positions.col(col);
              trial_normals.col(col) = setup.normals.col(col);
              frame = frames[kk];
              if (setup.sliding[kk] >= 0) {
                const auto b = static_cast<std::size_t>(setup.sliding[kk]);
                trial_s[b] = setup.curve_s[b];
                trial_speed[b] = setup.curve_speed[b];
                trial_tangents.col(col) = setup.curve_tangent.col(col);
              }
              return;
            }
            const int on_curve = setup.sliding[kk];
            if (on_curve >= 0) {  // along the curve: ds = (t . step) / |dc/ds|
              const auto b = static_cast<std::size_t>(on_curve);
              trial_s[b] = setup.curve_s[b] + setup.curve_tangent.col(col).dot(step) /
                                                  std::max(setup.curve_speed[b], 1e-300);
              Eigen::Vector3d position, tangent;
              setup.curve_frame(trial_s[b], trial_points[p], position, tangent, trial_speed[b]);
              trial_positions.col(col) = position;
              trial_tangents.col(col) = tangent;
              const SurfaceDerivatives d = setup.target.surface().derivatives(trial_points[p]);
              const Eigen::Vector3d normal = d.du.cross(d.dv);
              trial_normals.col(col) = normal.norm() > 1e-300
                                           ? Eigen::Vector3d(normal.normalized())
                                           : Eigen::Vector3d(setup.normals.col(col));
              return;
            }
            ClosestPoint out;
            if (!solver_detail::parametric_retraction(setup.target.surface(), setup.points[p],
                                                      setup.positions.col(col), frames[kk], step,
                                                      out, frame)) {
              // Magnet fallback: the closest point of x + alpha p, warm started.
              out = setup.target.closest(Eigen::Vector3d(setup.positions.col(col) + step),
                                         setup.points[p]);
              frame = solver_detail::tangent_frame(setup.target.surface(), out.point);
            }
            trial_points[p] = out.point;
            trial_positions.col(col) = out.position;
            trial_normals.col(col) = out.normal;
          },
          kSurfaceChunk);
    };
    bool accepted = false;
    bool trial_q_ready = false;
    // The first trial moves no particle farther than kMaxStep rest lengths: a step far beyond
    // the grid's own scale (the barrier's gradient near a collapsing triangle can be orders of
    // magnitude above the springs') would only be halved back, after walking every particle
    // across many ptex faces for each halving.
    double alpha = 1.0;
    {
      const double longest = std::sqrt(tbb::parallel_deterministic_reduce(
          tbb::blocked_range<Eigen::Index>(0, n, kChunk), 0.0,
          [&](const tbb::blocked_range<Eigen::Index>& r, double best) {
            for (Eigen::Index k = r.begin(); k != r.end(); ++k) {
              best = std::max(best, layout.at(direction, k).squaredNorm());
            }
            return best;
          },
          [](double a, double b) { return std::max(a, b); }));
      const double cap = kMaxStep * setup.mean_rest;
      if (longest > cap && cap > 0.0) {
        alpha = cap / longest;
      }
    }
    SpringEnergies trial_energies;
    int backtracks = 0, block_rounds = 0, fold_halvings = 0;
    while (backtracks < lb.max_backtracks && slope < 0.0) {
      trial_q_ready = false;
      retract(alpha);
      setup.springs.folded_corners(trial_positions, trial_normals, trial_folded);
      if (setup.slide && !solver_detail::RelaxationSetup::in_order(trial_s)) {
        // A boundary particle would pass its neighbour on the curve: shorten the step.
        alpha *= 0.5;
        ++backtracks;
        continue;
      }
      // A first few folding trials only shorten the step; then the folding particles are blocked.
      // With the injectivity barrier (EnergyKind::Robust) a short enough step never folds (the
      // energy grows without bound first), so folding trials are only shortened, never blocked.
      const bool block_now =
          !with_barrier && fold_halvings >= kFoldHalvings && block_rounds < kMaxBlockRounds;
      bool new_fold = false;
      for (std::size_t c = 0; c < folded.size(); ++c) {
        if (!trial_folded[c] || folded[c]) {
          continue;
        }
        new_fold = true;
        if (!block_now) {
          break;
        }
        // Hold the free particles of the newly folded corner: they keep their position from now
        // on (until a release).
        const SpringSystem::Corner& corner = setup.springs.corners()[c];
        for (const int p : {corner.i, corner.next, corner.prev}) {
          const int k = setup.interior_index[static_cast<std::size_t>(p)];
          if (k < 0 || held[static_cast<std::size_t>(k)]) {
            continue;
          }
          held[static_cast<std::size_t>(k)] = 1;
          ++held_count;
          for (int d = 0; d < 3; ++d) {
            direction[d * n + k] = 0.0;
          }
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
          q_free = q;
          mask(q_free);
          direction = q_free;
          apply_h0(direction);
          direction = -direction;
          layout.project(direction, setup.normals, setup.curve_tangent);
          slope = dot(q_free, direction);
        } else {
          alpha *= 0.5;
          ++backtracks;
          ++fold_halvings;
        }
        continue;
      }
      // The barrier sees each triangle along its apex normal (SpringSystem::evaluate): the current
      // iterate's normals, held fixed through the line search, so that every trial and the slope
      // belong to one function of the positions (with the trials' own normals, whose turning the
      // gradient does not see, thin triangles made the Armijo test fail near the minimum).
      trial_energies = setup.springs.evaluate(trial_positions, &trial_gradient, &setup.normals);
      ++result.evaluations;
      const double energy = energies.total();
      const double trial_energy = trial_energies.total();
      if (std::isfinite(trial_energy)) {
        if (trial_energy <= energy + lb.armijo * alpha * slope) {
          accepted = true;
        } else if (trial_energy <= energy + round_off(energy)) {
          // Within round-off of the current energy: accept on a smaller tangential gradient.
          layout.tangential(trial_gradient, trial_normals, trial_tangents, trial_q);
          trial_q_ready = true;
          accepted = free_norm(trial_q) < std::sqrt(dot(q_free, q_free));
        }
      }
      if (accepted) {
        break;
      }
      alpha *= 0.5;
      ++backtracks;
    }
    if (!accepted) {
      if (!memory.empty()) {  // retry from the preconditioned gradient before giving up
        memory.clear();
        continue;
      }
      result.reason = at_round_off ? StopReason::RoundOff : StopReason::LineSearchFailed;
      break;
    }

    if (!trial_q_ready) {
      layout.tangential(trial_gradient, trial_normals, trial_tangents, trial_q);
    }
    if (next.s.size() != m) {
      resize_huge(next.s, m, 1);
      resize_huge(next.y, m, 1);
    }
    for_chunks(n, [&](Eigen::Index k) {
      const auto p = static_cast<Eigen::Index>(setup.interior[static_cast<std::size_t>(k)]);
      const bool free = !held[static_cast<std::size_t>(k)];
      for (int c = 0; c < 3; ++c) {
        next.s[c * n + k] = trial_positions(c, p) - setup.positions(c, p);
        // y = (free part of the new gradient) - (free part of the old one)
        next.y[c * n + k] = free ? trial_q[c * n + k] - q_free[c * n + k] : 0.0;
      }
    });
    const double sy = dot(next.s, next.y);
    if (sy > 1e-12 * std::sqrt(dot(next.s, next.s) * dot(next.y, next.y)) && lb.memory > 0) {
      next.rho = 1.0 / sy;
      memory.push_back(std::move(next));
      next = Pair{};
      if (memory.size() > static_cast<std::size_t>(lb.memory)) {
        next = std::move(memory.front());
        memory.pop_front();
      }
    }

    setup.positions.swap(trial_positions);
    setup.normals.swap(trial_normals);
    if (setup.slide) {
      setup.curve_s.swap(trial_s);
      setup.curve_speed.swap(trial_speed);
      setup.curve_tangent.swap(trial_tangents);
      // Entries that did not move keep their values in both buffers (the retraction copies them).
      trial_s = setup.curve_s;
      trial_speed = setup.curve_speed;
      trial_tangents = setup.curve_tangent;
    }
    setup.points.swap(trial_points);
    frames.swap(trial_frames);
    folded.swap(trial_folded);
    gradient.swap(trial_gradient);
    stalled = energies.total() - trial_energies.total() <= 0.1 * round_off(energies.total())
                  ? stalled + 1
                  : 0;
    energies = trial_energies;
    if (energies.barrier > 0.0) {
      // At the accepted point the barrier is taken again with its own normals (nothing changes
      // where no triangle is near collapse: the barrier is zero there).
      energies = setup.springs.evaluate(setup.positions, &gradient, &setup.normals);
      ++result.evaluations;
      layout.tangential(gradient, setup.normals, setup.curve_tangent, trial_q);
    }
    q.swap(trial_q);
    q_norm = std::sqrt(dot(q, q));
    emit_frame(iteration + 1);
  }

  for (Eigen::Index k = 0; k < n; ++k) {
    if (held[static_cast<std::size_t>(k)]) {
      result.held_particles.push_back(setup.interior[static_cast<std::size_t>(k)]);
    }
  }
  result.iterations = iteration;
  result.solve_seconds = solver_detail::seconds_since(solve_start);
  solver_detail::finish_result(setup, problem, initial_norm, result);
  return result;
}

}  // namespace elastic
