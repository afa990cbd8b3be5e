#pragma once
/// \file
/// The set-up shared by the two relaxation solvers (relaxation.h): validation of a
/// RelaxationProblem, the interior/boundary split, tangent-plane projection of gradients, the
/// stopping bounds and the final measurements. Used by lbfgs_solver.cpp and
/// explicit_integrator.cpp; not meant for callers of `relax`. The solvers' other shared pieces
/// have headers of their own, included here for them: the spring Laplacian and its inverse
/// (spring_laplacian.h, ordered by nested_dissection.h), the retraction (retraction.h) and the
/// timer (solver_clock.h).

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "elastic/solvers/relaxation.h"
#include "elastic/solvers/retraction.h"
#include "elastic/solvers/solver_clock.h"
#include "elastic/solvers/spring_laplacian.h"

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
  // Sliding boundary (BoundaryMode::Slide, fast solver): the boundary particles are free entries
  // too (at the end of `interior`), each moving along the curve only.
  bool slide = false;
  /// BoundaryMode::Free: every particle is free except RelaxationProblem::pinned.
  bool free_boundary = false;
  /// Per entry of `interior`: its index in grid.boundary_loop when it is a sliding boundary
  /// particle, -1 for an interior particle.
  std::vector<int> sliding;
  /// Per grid.boundary_loop entry: the current curve parameter s (unwrapped: continuous in time).
  std::vector<double> curve_s;
  /// 3 x #P: unit tangent of the curve at each sliding boundary particle (zero elsewhere).
  Eigen::Matrix3Xd curve_tangent;
  /// Per grid.boundary_loop entry: |dc/ds|, the curve's length per unit of s.
  std::vector<double> curve_speed;
  /// The curve (problem.boundary_curve).
  const std::function<SurfacePoint(double)>* curve = nullptr;
  /// Position, unit tangent and speed of the curve at s (central differences of c).
  void curve_frame(double s, SurfacePoint& point, Eigen::Vector3d& position,
                   Eigen::Vector3d& tangent, double& speed) const;
  /// True when the parameters `s` (grid.boundary_loop order, unwrapped) are still strictly in
  /// order along the curve: every gap to the next one positive, and all within one turn.
  static bool in_order(const std::vector<double>& s);
  double absolute_bound = 0.0;  ///< the absolute stopping bound on |P g|

  int num_free() const { return static_cast<int>(interior.size()); }
};

/// Euclidean norm of the tangential part of `gradient` over the interior particles:
/// sqrt(sum_i |g_i - n_i (n_i . g_i)|^2).
double tangential_norm(const RelaxationSetup& setup, const Eigen::Matrix3Xd& gradient,
                       const Eigen::Matrix3Xd& normals);

/// Adds to `gradient` the part of the barrier's gradient that comes from the normals following the
/// free particles (SpringSystem::evaluate's `normal_gradient`, pulled back through the Weingarten
/// map, LimitSurface::normal_variation_adjoint): with it, `gradient` is the derivative of the
/// energy evaluated with each particle's own normal. `frames` (one per entry of setup.interior,
/// the SurfaceDerivatives at its point) may be null: then they are evaluated here.
void add_normal_motion(const RelaxationSetup& setup, const Eigen::Matrix3Xd& normal_gradient,
                       const std::vector<SurfaceDerivatives>* frames, Eigen::Matrix3Xd& gradient);

/// tangential_norm of the gradient of E_len + E_ang alone (no barrier) at the setup's positions.
double spring_gradient_norm(const RelaxationSetup& setup);

/// Fills the final measurements of `result` from the setup's current positions, points and normals:
/// energies, tangential gradient (relative to `initial_gradient_norm`), folds, boundary residual,
/// rest scale; then moves the positions and points into it (the setup's are left empty).
void finish_result(RelaxationSetup& setup, const RelaxationProblem& problem,
                   double initial_gradient_norm, RelaxationResult& result);

/// The largest distance between a boundary particle and its target position
/// (problem.boundary_targets, or the initial position when that is empty).
double boundary_residual(const RelaxationProblem& problem, const Eigen::Matrix3Xd& positions);

/// The start parameters of a sliding boundary: problem.boundary_parameters, or the grid's.
const std::vector<double>& boundary_start(const RelaxationProblem& problem);

/// RelaxationResult::boundary_slide: the largest distance from `start` to `end` of one boundary
/// particle's correspondence parameter (period 1, the shorter way round).
double boundary_slide(const std::vector<double>& start, const std::vector<double>& end);

}  // namespace elastic::solver_detail
