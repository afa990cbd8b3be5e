#include "elastic/solvers/explicit_integrator.h"

#include <Eigen/SparseCholesky>
#include <cmath>

#include "elastic/core/error.h"
#include "elastic/solvers/solver_common.h"

namespace elastic {

namespace {

constexpr long kCheckInterval = 10;  // steps between equilibrium checks

bool valid_parameter(double value) {
  return std::isfinite(value) && value >= 0.0;
}

// The integrator's constants (see the header): the magnet's stiffness, the time step and the
// damping, stable defaults from the interior spring Laplacian where the options leave them 0.
struct IntegratorConstants {
  double magnet = 0.0, dt = 0.0, damping = 0.0;
};

IntegratorConstants integrator_constants(const solver_detail::RelaxationSetup& setup,
                                         const RelaxationOptions& options) {
  const ExplicitOptions& eo = options.explicit_integrator;
  const Eigen::SparseMatrix<double> laplacian = solver_detail::interior_laplacian(setup, options);
  // Absolute row sums of the symmetric L from its stored lower triangle: an off-diagonal entry
  // counts in its row and in its column.
  Eigen::VectorXd row_sums = Eigen::VectorXd::Zero(laplacian.rows());
  double max_diagonal = 0.0;
  for (Eigen::Index col = 0; col < laplacian.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, col); it; ++it) {
      row_sums[it.row()] += std::abs(it.value());
      if (it.row() == col) {
        max_diagonal = std::max(max_diagonal, it.value());
      } else {
        row_sums[col] += std::abs(it.value());
      }
    }
  }
  double max_row_sum = 0.0;
  for (Eigen::Index k = 0; k < row_sums.size(); ++k) {
    max_row_sum = std::max(max_row_sum, row_sums[k]);
  }
  IntegratorConstants c;
  c.magnet = eo.magnet_stiffness > 0.0 ? eo.magnet_stiffness : max_diagonal;
  const double lambda_max = max_row_sum + c.magnet;
  const double mass = eo.mass;
  c.dt =
      eo.time_step > 0.0 ? eo.time_step : eo.stability_factor * 2.0 * std::sqrt(mass / lambda_max);
  c.damping = eo.damping;
  if (c.damping == 0.0) {
    const solver_detail::LaplacianFactor factor(laplacian, interior_coordinates(setup));
    // Inverse iteration from the all-ones vector (the slowest Dirichlet mode has one sign).
    Eigen::VectorXd v = Eigen::VectorXd::Ones(laplacian.rows()).normalized();
    for (int it = 0; it < 30; ++it) {
      v = factor.solve(v).normalized();
    }
    // Rayleigh quotient, |v| = 1.
    const double lambda_min = v.dot(laplacian.selfadjointView<Eigen::Lower>() * v);
    c.damping = 2.0 * std::sqrt(mass * 0.5 * lambda_min);
  }
  return c;
}

// One call of relax_explicit: eqs. 9-12 with the magnet, step by step.
class ExplicitRun {
 public:
  ExplicitRun(const RelaxationProblem& problem, const RelaxationOptions& options)
      : problem_(problem),
        options_(options),
        eo_(options.explicit_integrator),
        setup_(problem, options) {
    if (!(eo_.mass > 0.0) || !std::isfinite(eo_.mass) || !valid_parameter(eo_.damping) ||
        !valid_parameter(eo_.time_step) || !valid_parameter(eo_.magnet_stiffness) ||
        !(eo_.stability_factor > 0.0 && eo_.stability_factor < 1.0) ||
        !(eo_.drift_tolerance > 0.0)) {
      throw InvalidInputError("relaxation", "explicit integrator options out of range");
    }
    result_.solver = SolverKind::Faithful;
  }

  RelaxationResult run() {
    energies_ = setup_.springs.evaluate(setup_.positions, &gradient_);
    result_.initial_energy = energies_.total();
    result_.evaluations = 1;
    result_.initial_folded_faces = setup_.springs.folded_faces(setup_.positions, setup_.normals);
    const double start_norm = solver_detail::tangential_norm(setup_, gradient_, setup_.normals);
    initial_norm_ =
        problem_.reference_gradient_norm > 0.0 ? problem_.reference_gradient_norm : start_norm;
    if (n_ == 0) {
      result_.reason = StopReason::NoFreeParticles;
      result_.setup_seconds = solver_detail::seconds_since(start_);
      solver_detail::finish_result(setup_, problem_, 0.0, result_);
      return std::move(result_);
    }
    constants_ = integrator_constants(setup_, options_);
    result_.time_step = constants_.dt;
    result_.damping = constants_.damping;
    result_.magnet_stiffness = constants_.magnet;
    result_.setup_seconds = solver_detail::seconds_since(start_);
    const long long solve_start = solver_detail::now_ticks();

    velocity_ = Eigen::Matrix3Xd::Zero(3, setup_.num_particles);
    query_.resize(n_);
    hints_.resize(n_);
    projected_.resize(n_);
    closest_ = setup_.positions;
    relative_ = initial_norm_ > 0.0 ? start_norm / initial_norm_ : 0.0;
    integrate();

    // The magnet energy of the last state, then the state placed exactly on the surface.
    result_.magnet_energy =
        magnet_energy(setup_.positions, closest_, constants_.magnet, setup_.is_free);
    setup_.positions = closest_;
    result_.iterations = step_;
    result_.solve_seconds = solver_detail::seconds_since(solve_start);
    solver_detail::finish_result(setup_, problem_, initial_norm_, result_);
    return std::move(result_);
  }

 private:
  void integrate() {
    result_.reason = StopReason::MaxIterations;
    for (step_ = 0;; ++step_) {
      attract();
      if (step_ % kCheckInterval == 0 && at_equilibrium_or_stopped()) {
        break;
      }
      if (step_ >= max_steps_) {
        break;
      }
      if (options_.frame && step_ % options_.frame_interval == 0) {
        options_.frame({step_, &setup_.positions, energies_.total(), relative_});
      }
      if (!time_step()) {
        result_.reason = StopReason::Diverged;
        break;
      }
    }
  }

  // The magnet: closest points x' of the current state, warm started; past the drift limit the
  // particles move onto them (exact re-projection, see the header).
  void attract() {
    for (std::size_t k = 0; k < n_; ++k) {
      const int p = setup_.interior[k];
      query_[k] = setup_.positions.col(p);
      hints_[k] = setup_.points[static_cast<std::size_t>(p)];
    }
    setup_.target.closest(query_, projected_, hints_);
    double drift = 0.0;
    for (std::size_t k = 0; k < n_; ++k) {
      const int p = setup_.interior[k];
      closest_.col(p) = projected_[k].position;
      setup_.normals.col(p) = projected_[k].normal;
      setup_.points[static_cast<std::size_t>(p)] = projected_[k].point;
      drift = std::max(drift, projected_[k].distance);
    }
    if (drift > eo_.drift_tolerance * setup_.mean_rest) {
      ++result_.reprojections;
      for (const int p : setup_.interior) {
        setup_.positions.col(p) = closest_.col(p);
        const Eigen::Vector3d normal = setup_.normals.col(p);
        velocity_.col(p) -= normal * normal.dot(velocity_.col(p));
      }
    }
  }

  // Equilibrium check at the projected positions x' (what the solver would return now); true
  // with the reason set when the run stops here.
  bool at_equilibrium_or_stopped() {
    energies_ = setup_.springs.evaluate(closest_, &check_gradient_);
    ++result_.evaluations;
    if (!std::isfinite(energies_.total())) {
      result_.reason = StopReason::Diverged;
      return true;
    }
    const double norm = solver_detail::tangential_norm(setup_, check_gradient_, setup_.normals);
    relative_ = initial_norm_ > 0.0 ? norm / initial_norm_ : 0.0;
    if (norm <= options_.relative_gradient_tolerance * initial_norm_) {
      result_.reason = StopReason::RelativeGradient;
      return true;
    }
    if (norm <= setup_.absolute_bound) {
      result_.reason = StopReason::AbsoluteGradient;
      return true;
    }
    if (!report_progress(options_.progress, {.stage = "relax",
                                             .iteration = step_,
                                             .total = max_steps_,
                                             .energy = energies_.total(),
                                             .gradient = relative_})) {
      result_.reason = StopReason::Cancelled;
      return true;
    }
    return false;
  }

  // Eq. 9 with f_int = grad E (springs + magnet), then eqs. 10-12. False when it diverged.
  bool time_step() {
    setup_.springs.evaluate(setup_.positions, &gradient_);
    ++result_.evaluations;
    const double mass = eo_.mass, magnet = constants_.magnet, damping = constants_.damping;
    const double dt = constants_.dt;
    for (const int p : setup_.interior) {
      const Eigen::Vector3d force = -gradient_.col(p) -
                                    magnet * (setup_.positions.col(p) - closest_.col(p)) -
                                    damping * velocity_.col(p);
      const Eigen::Vector3d acceleration = force / mass;  // eq. 10
      velocity_.col(p) += acceleration * dt;              // eq. 11
      setup_.positions.col(p) += velocity_.col(p) * dt;   // eq. 12
    }
    return setup_.positions.allFinite();
  }

  const long long start_ = solver_detail::now_ticks();
  const RelaxationProblem& problem_;
  const RelaxationOptions& options_;
  const ExplicitOptions& eo_;
  solver_detail::RelaxationSetup setup_;
  RelaxationResult result_;
  const long max_steps_ = options_.max_iterations > 0 ? options_.max_iterations : 200000;
  const std::size_t n_ = static_cast<std::size_t>(setup_.num_free());
  IntegratorConstants constants_;
  double initial_norm_ = 0.0, relative_ = 0.0;
  SpringEnergies energies_;
  Eigen::Matrix3Xd gradient_, check_gradient_, velocity_;
  Eigen::Matrix3Xd closest_;  // x' of every particle (boundary ones: themselves)
  std::vector<Eigen::Vector3d> query_;
  std::vector<SurfacePoint> hints_;
  std::vector<ClosestPoint> projected_;
  long step_ = 0;
};

}  // namespace

RelaxationResult relax_explicit(const RelaxationProblem& problem,
                                const RelaxationOptions& options) {
  ExplicitRun run(problem, options);
  return run.run();
}

}  // namespace elastic
