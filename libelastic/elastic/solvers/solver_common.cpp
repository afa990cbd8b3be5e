#include "elastic/solvers/solver_common.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "elastic/core/error.h"

namespace elastic::solver_detail {

namespace {

const std::string kName = "relaxation";

const ParticleGrid& checked_grid(const RelaxationProblem& problem) {
  if (problem.grid == nullptr) throw InvalidInputError(kName, "no particle grid given");
  if (problem.target == nullptr) throw InvalidInputError(kName, "no target surface given");
  return *problem.grid;
}

SpringEnergyOptions energy_options(const RelaxationProblem& problem,
                                   const RelaxationOptions& options) {
  return {.stiffness = options.stiffness,
          .angular_stiffness = options.angular_stiffness,
          .rest_scale = problem.rest_scale};
}

}  // namespace

RelaxationSetup::RelaxationSetup(const RelaxationProblem& problem, const RelaxationOptions& options)
    : grid(checked_grid(problem)),
      target(*problem.target),
      springs(*problem.grid, energy_options(problem, options)),
      num_particles(problem.grid->num_particles()) {
  const auto P = static_cast<std::size_t>(num_particles);
  if (problem.initial_positions.cols() != num_particles || problem.initial_points.size() != P)
    throw InvalidInputError(kName, "initial positions/points do not have one entry per particle (" +
                                       std::to_string(num_particles) + ")");
  if (grid.is_boundary.size() != P)
    throw InvalidInputError(kName,
                            "particle grid: is_boundary does not have one entry per particle");
  if (!problem.initial_positions.allFinite())
    throw InvalidInputError(kName, "initial positions are not finite");
  if (problem.boundary_targets.cols() != 0 &&
      problem.boundary_targets.cols() != static_cast<Eigen::Index>(grid.boundary_loop.size()))
    throw InvalidInputError(kName, "boundary targets do not have one entry per boundary particle");
  if (!(options.relative_gradient_tolerance >= 0.0) ||
      !(options.absolute_gradient_tolerance >= 0.0))
    throw InvalidInputError(kName, "gradient tolerances must be non-negative");
  if (options.max_iterations < 0 || options.frame_interval < 1 || options.threads < 0)
    throw InvalidInputError(kName, "max_iterations, frame_interval or threads out of range");
  for (std::size_t p = 0; p < P; ++p)
    if (!problem.initial_points[p].valid() ||
        problem.initial_points[p].face >= target.surface().num_faces())
      throw InvalidInputError(kName,
                              "particle " + std::to_string(p) + " has no valid surface point");

  interior_index.assign(P, -1);
  is_free.assign(P, 0);
  for (std::size_t p = 0; p < P; ++p) {
    if (grid.is_boundary[p]) continue;
    interior_index[p] = static_cast<int>(interior.size());
    is_free[p] = 1;
    interior.push_back(static_cast<int>(p));
  }

  positions = problem.initial_positions;
  points = problem.initial_points;

  // Unit normals du x dv / |du x dv| at the given surface points (the fold test and the tangent
  // projection need them for every particle; interior ones are refreshed by each retraction).
  normals.resize(3, num_particles);
  const LimitSurface& surface = target.surface();
  tbb::parallel_for(tbb::blocked_range<int>(0, num_particles, 256),
                    [&](const tbb::blocked_range<int>& range) {
                      for (int p = range.begin(); p != range.end(); ++p) {
                        const SurfaceDerivatives d = surface.derivatives(points[p]);
                        const Eigen::Vector3d n = d.du.cross(d.dv);
                        const double length = n.norm();
                        if (length > 1e-300) {
                          normals.col(p) = n / length;
                        } else {
                          // Degenerate parameterisation (a singular corner): ask the magnet.
                          normals.col(p) = target.closest(positions.col(p), points[p]).normal;
                        }
                      }
                    });

  double sum = 0.0;
  for (const Spring& s : grid.springs) sum += s.rest;
  mean_rest = grid.springs.empty()
                  ? 0.0
                  : problem.rest_scale * sum / static_cast<double>(grid.springs.size());
  // |P g| has units of stiffness x length per particle, summed in quadrature over #P particles.
  const double stiffness = std::max(options.stiffness, options.angular_stiffness);
  absolute_bound = options.absolute_gradient_tolerance * stiffness * mean_rest *
                   std::sqrt(static_cast<double>(num_particles));
}

double tangential_norm(const RelaxationSetup& setup, const Eigen::Matrix3Xd& gradient,
                       const Eigen::Matrix3Xd& normals) {
  double sum = 0.0;
  for (const int p : setup.interior) {
    const Eigen::Vector3d g = gradient.col(p);
    const Eigen::Vector3d n = normals.col(p);
    sum += (g - n * n.dot(g)).squaredNorm();
  }
  return std::sqrt(sum);
}

Eigen::SparseMatrix<double> interior_laplacian(const RelaxationSetup& setup,
                                               const RelaxationOptions& options) {
  const int n = setup.num_free();
  // Only the lower triangle is stored (what the LDL^T factorisation reads); the diagonal is summed
  // densely first, which keeps the triplet list (and its sort) small.
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(n);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(setup.grid.springs.size() + 3 * setup.grid.angular_springs.size() +
                   static_cast<std::size_t>(n));
  const auto add = [&](int p, int q, double value) {
    const int a = setup.interior_index[static_cast<std::size_t>(p)];
    const int b = setup.interior_index[static_cast<std::size_t>(q)];
    if (a < 0 || b < 0) return;
    if (a == b)
      diagonal[a] += value;
    else
      triplets.emplace_back(std::max(a, b), std::min(a, b), value);
  };
  // Normal spring: C (|d| - k)^2 has Hessian 2C d d^T/|d|^2 at rest; the isotropic 2C I per
  // coordinate.
  const double w = 2.0 * options.stiffness;
  for (const Spring& s : setup.grid.springs) {
    add(s.i, s.i, w);
    add(s.j, s.j, w);
    add(s.i, s.j, -w);
  }
  // Angular spring: e = x_i - (x_a + x_b)/2 = v . (x_i, x_a, x_b), Gram matrix 2 C_a v v^T with
  // v = (1, -1/2, -1/2): diagonal (2, 1/2, 1/2) C_a, (i,a) and (i,b) -C_a, (a,b) +C_a/2.
  const double ca = options.angular_stiffness;
  for (const AngularSpring& s : setup.grid.angular_springs) {
    add(s.i, s.i, 2.0 * ca);
    add(s.a, s.a, 0.5 * ca);
    add(s.b, s.b, 0.5 * ca);
    add(s.i, s.a, -ca);
    add(s.i, s.b, -ca);
    add(s.a, s.b, 0.5 * ca);
  }
  for (int k = 0; k < n; ++k) triplets.emplace_back(k, k, diagonal[k]);
  Eigen::SparseMatrix<double> laplacian(n, n);
  laplacian.setFromTriplets(triplets.begin(), triplets.end());
  return laplacian;
}

void factorize(const Eigen::SparseMatrix<double>& laplacian,
               Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& factor) {
  factor.compute(laplacian);
  bool positive = factor.info() == Eigen::Success;
  const Eigen::VectorXd& pivots = factor.vectorD();
  for (Eigen::Index k = 0; positive && k < pivots.size(); ++k) positive = pivots[k] > 0.0;
  if (!positive)
    throw NumericalError(kName,
                         "the spring Laplacian of the interior particles is singular (an interior "
                         "part of the grid is not connected to the boundary)");
}

double boundary_residual(const RelaxationProblem& problem, const Eigen::Matrix3Xd& positions) {
  const std::vector<int>& loop = problem.grid->boundary_loop;
  double residual = 0.0;
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const Eigen::Vector3d target =
        problem.boundary_targets.cols() != 0
            ? Eigen::Vector3d(problem.boundary_targets.col(static_cast<Eigen::Index>(k)))
            : Eigen::Vector3d(problem.initial_positions.col(loop[k]));
    residual = std::max(residual, (positions.col(loop[k]) - target).norm());
  }
  return residual;
}

void finish_result(const RelaxationSetup& setup, const RelaxationProblem& problem,
                   double initial_gradient_norm, RelaxationResult& result) {
  Eigen::Matrix3Xd gradient;
  const SpringEnergies energies = setup.springs.evaluate(setup.positions, &gradient);
  result.positions = setup.positions;
  result.points = setup.points;
  result.length_energy = energies.length;
  result.angular_energy = energies.angular;
  result.initial_gradient_norm = initial_gradient_norm;
  result.gradient_norm = tangential_norm(setup, gradient, setup.normals);
  result.relative_gradient =
      initial_gradient_norm > 0.0 ? result.gradient_norm / initial_gradient_norm : 0.0;
  result.folded_faces = setup.springs.folded_faces(setup.positions, setup.normals);
  result.boundary_residual = boundary_residual(problem, setup.positions);
  result.rest_scale = problem.rest_scale;
  result.rest_scale_mode = problem.rest_scale_mode;
  result.converged = is_converged(result.reason);
}

long long now_ticks() {
  return std::chrono::steady_clock::now().time_since_epoch().count();
}

double seconds_since(long long start_ticks) {
  const auto elapsed = std::chrono::steady_clock::now().time_since_epoch().count() - start_ticks;
  return std::chrono::duration<double>(std::chrono::steady_clock::duration(elapsed)).count();
}

}  // namespace elastic::solver_detail
