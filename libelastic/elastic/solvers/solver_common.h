#pragma once
/// \file
/// Pieces shared by the two relaxation solvers (relaxation.h): validation of a RelaxationProblem,
/// the interior/boundary split, tangent-plane projection of gradients, the stopping bounds, the
/// spring-graph Laplacian and the final measurements. Used by lbfgs_solver.cpp and
/// explicit_integrator.cpp; not meant for callers of `relax`.

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <vector>

#include "elastic/solvers/relaxation.h"

namespace elastic::solver_detail {

/// The state both solvers start from: validated inputs, interior numbering, positions, surface
/// points and unit normals of all particles, and the spring energy.
struct RelaxationSetup {
  /// \throws InvalidInputError when the problem or options are inconsistent.
  RelaxationSetup(const RelaxationProblem& problem, const RelaxationOptions& options);

  const ParticleGrid& grid;
  const SurfaceProjector& target;
  SpringSystem springs;
  int num_particles = 0;
  std::vector<int> interior;         ///< particle indices of the free (non-boundary) particles
  std::vector<int> interior_index;   ///< #P: index into `interior`, or -1 for a boundary particle
  std::vector<char> is_free;         ///< #P: 1 for interior particles
  Eigen::Matrix3Xd positions;        ///< 3 x #P current positions
  std::vector<SurfacePoint> points;  ///< #P current surface points
  Eigen::Matrix3Xd normals;          ///< 3 x #P unit surface normals at `points`
  double mean_rest = 0.0;            ///< mean normal-spring rest length, times sigma
  double absolute_bound = 0.0;       ///< the absolute stopping bound on |P g|

  int num_free() const { return static_cast<int>(interior.size()); }
};

/// Euclidean norm of the tangential part of `gradient` over the interior particles:
/// sqrt(sum_i |g_i - n_i (n_i . g_i)|^2).
double tangential_norm(const RelaxationSetup& setup, const Eigen::Matrix3Xd& gradient,
                       const Eigen::Matrix3Xd& normals);

/// The spring-graph Laplacian restricted to the interior particles (n x n, n = num_free()): 2C per
/// normal spring, and for each angular spring the Gram matrix 2 C_a v v^T with v = (1, -1/2, -1/2)
/// on (i, a, b), which is the angular energy's Hessian with the unit-direction factor e e^T/|e|^2
/// replaced by the identity. Rows of boundary particles are dropped (they are fixed: Dirichlet
/// conditions), their couplings stay on the diagonal. Only the LOWER triangle (diagonal included)
/// is stored: use selfadjointView<Eigen::Lower>() for products.
Eigen::SparseMatrix<double> interior_laplacian(const RelaxationSetup& setup,
                                               const RelaxationOptions& options);

/// Factorises `laplacian` into `factor` (sparse LDL^T with AMD ordering).
/// \throws NumericalError when a pivot is not positive: an interior part of the grid is not
///         connected to the boundary by springs, so it could drift freely.
void factorize(const Eigen::SparseMatrix<double>& laplacian,
               Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& factor);

/// Fills the final measurements of `result` from the setup's current positions, points and normals:
/// energies, tangential gradient (relative to `initial_gradient_norm`), folds, boundary residual,
/// rest scale.
void finish_result(const RelaxationSetup& setup, const RelaxationProblem& problem,
                   double initial_gradient_norm, RelaxationResult& result);

/// The largest distance between a boundary particle and its target position
/// (problem.boundary_targets, or the initial position when that is empty).
double boundary_residual(const RelaxationProblem& problem, const Eigen::Matrix3Xd& positions);

/// Seconds since `start` on a steady clock.
double seconds_since(long long start_ticks);
long long now_ticks();

}  // namespace elastic::solver_detail
