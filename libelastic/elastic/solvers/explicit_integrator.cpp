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

}  // namespace

RelaxationResult relax_explicit(const RelaxationProblem& problem,
                                const RelaxationOptions& options) {
  const long long start = solver_detail::now_ticks();
  solver_detail::RelaxationSetup setup(problem, options);
  const ExplicitOptions& eo = options.explicit_integrator;
  if (!(eo.mass > 0.0) || !std::isfinite(eo.mass) || !valid_parameter(eo.damping) ||
      !valid_parameter(eo.time_step) || !valid_parameter(eo.magnet_stiffness) ||
      !(eo.stability_factor > 0.0 && eo.stability_factor < 1.0) || !(eo.drift_tolerance > 0.0)) {
    throw InvalidInputError("relaxation", "explicit integrator options out of range");
  }

  RelaxationResult result;
  result.solver = SolverKind::Faithful;
  const long max_steps = options.max_iterations > 0 ? options.max_iterations : 200000;
  const auto n = static_cast<std::size_t>(setup.num_free());

  Eigen::Matrix3Xd gradient;
  SpringEnergies energies = setup.springs.evaluate(setup.positions, &gradient);
  result.initial_energy = energies.total();
  result.evaluations = 1;
  result.initial_folded_faces = setup.springs.folded_faces(setup.positions, setup.normals);
  const double start_norm = solver_detail::tangential_norm(setup, gradient, setup.normals);
  const double initial_norm =
      problem.reference_gradient_norm > 0.0 ? problem.reference_gradient_norm : start_norm;
  if (n == 0) {
    result.reason = StopReason::NoFreeParticles;
    result.setup_seconds = solver_detail::seconds_since(start);
    solver_detail::finish_result(setup, problem, 0.0, result);
    return result;
  }

  // Stable defaults from the interior spring Laplacian (see the header).
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
  const double magnet = eo.magnet_stiffness > 0.0 ? eo.magnet_stiffness : max_diagonal;
  const double lambda_max = max_row_sum + magnet;
  const double mass = eo.mass;
  const double dt =
      eo.time_step > 0.0 ? eo.time_step : eo.stability_factor * 2.0 * std::sqrt(mass / lambda_max);
  double damping = eo.damping;
  if (damping == 0.0) {
    const solver_detail::LaplacianFactor factor(laplacian, interior_coordinates(setup));
    // Inverse iteration from the all-ones vector (the slowest Dirichlet mode has one sign).
    Eigen::VectorXd v = Eigen::VectorXd::Ones(laplacian.rows()).normalized();
    for (int it = 0; it < 30; ++it) {
      v = factor.solve(v).normalized();
    }
    // Rayleigh quotient, |v| = 1.
    const double lambda_min = v.dot(laplacian.selfadjointView<Eigen::Lower>() * v);
    damping = 2.0 * std::sqrt(mass * 0.5 * lambda_min);
  }
  result.time_step = dt;
  result.damping = damping;
  result.magnet_stiffness = magnet;
  result.setup_seconds = solver_detail::seconds_since(start);
  const long long solve_start = solver_detail::now_ticks();

  Eigen::Matrix3Xd velocity = Eigen::Matrix3Xd::Zero(3, setup.num_particles);
  std::vector<Eigen::Vector3d> query(n);
  std::vector<SurfacePoint> hints(n);
  std::vector<ClosestPoint> projected(n);
  Eigen::Matrix3Xd closest = setup.positions;  // x' of every particle (boundary ones: themselves)
  Eigen::Matrix3Xd check_gradient;
  const double drift_limit = eo.drift_tolerance * setup.mean_rest;
  double relative = initial_norm > 0.0 ? start_norm / initial_norm : 0.0;

  result.reason = StopReason::MaxIterations;
  long step = 0;
  for (;; ++step) {
    // The magnet: closest points of the current state, warm started.
    for (std::size_t k = 0; k < n; ++k) {
      const int p = setup.interior[k];
      query[k] = setup.positions.col(p);
      hints[k] = setup.points[static_cast<std::size_t>(p)];
    }
    setup.target.closest(query, projected, hints);
    double drift = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const int p = setup.interior[k];
      closest.col(p) = projected[k].position;
      setup.normals.col(p) = projected[k].normal;
      setup.points[static_cast<std::size_t>(p)] = projected[k].point;
      drift = std::max(drift, projected[k].distance);
    }
    if (drift > drift_limit) {  // exact re-projection (see the header)
      ++result.reprojections;
      for (const int p : setup.interior) {
        setup.positions.col(p) = closest.col(p);
        const Eigen::Vector3d normal = setup.normals.col(p);
        velocity.col(p) -= normal * normal.dot(velocity.col(p));
      }
    }

    if (step % kCheckInterval == 0) {
      // Equilibrium check at the projected positions x' (what the solver would return now).
      energies = setup.springs.evaluate(closest, &check_gradient);
      ++result.evaluations;
      if (!std::isfinite(energies.total())) {
        result.reason = StopReason::Diverged;
        break;
      }
      const double norm = solver_detail::tangential_norm(setup, check_gradient, setup.normals);
      relative = initial_norm > 0.0 ? norm / initial_norm : 0.0;
      if (norm <= options.relative_gradient_tolerance * initial_norm) {
        result.reason = StopReason::RelativeGradient;
        break;
      }
      if (norm <= setup.absolute_bound) {
        result.reason = StopReason::AbsoluteGradient;
        break;
      }
      if (!report_progress(options.progress, {.stage = "relax",
                                              .iteration = step,
                                              .total = max_steps,
                                              .energy = energies.total(),
                                              .gradient = relative})) {
        result.reason = StopReason::Cancelled;
        break;
      }
    }
    if (step >= max_steps) {
      break;
    }
    if (options.frame && step % options.frame_interval == 0) {
      options.frame({step, &setup.positions, energies.total(), relative});
    }

    // Eq. 9 with f_int = grad E (springs + magnet), then eqs. 10-12.
    setup.springs.evaluate(setup.positions, &gradient);
    ++result.evaluations;
    for (const int p : setup.interior) {
      const Eigen::Vector3d force = -gradient.col(p) -
                                    magnet * (setup.positions.col(p) - closest.col(p)) -
                                    damping * velocity.col(p);
      const Eigen::Vector3d acceleration = force / mass;  // eq. 10
      velocity.col(p) += acceleration * dt;               // eq. 11
      setup.positions.col(p) += velocity.col(p) * dt;     // eq. 12
    }
    if (!setup.positions.allFinite()) {
      result.reason = StopReason::Diverged;
      break;
    }
  }

  // The magnet energy of the last state, then the state placed exactly on the surface.
  result.magnet_energy = magnet_energy(setup.positions, closest, magnet, setup.is_free);
  setup.positions = closest;
  result.iterations = step;
  result.solve_seconds = solver_detail::seconds_since(solve_start);
  solver_detail::finish_result(setup, problem, initial_norm, result);
  return result;
}

}  // namespace elastic
