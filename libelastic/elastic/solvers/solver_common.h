#pragma once
/// \file
/// Pieces shared by the two relaxation solvers (relaxation.h): validation of a RelaxationProblem,
/// the interior/boundary split, tangent-plane projection of gradients, the stopping bounds, the
/// spring-graph Laplacian and the final measurements. Used by lbfgs_solver.cpp and
/// explicit_integrator.cpp; not meant for callers of `relax`.

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
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
  // Sliding boundary (BoundaryMode::Slide, fast solver): the boundary particles are free entries
  // too (at the end of `interior`), each moving along the curve only.
  bool slide = false;
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

/// tangential_norm of the gradient of E_len + E_ang alone (no barrier) at the setup's positions.
double spring_gradient_norm(const RelaxationSetup& setup);

/// The spring-graph Laplacian restricted to the interior particles (n x n, n = num_free()): 2C per
/// normal spring, and for each angular spring the Gram matrix 2 C_a v v^T with v = (1, -1/2, -1/2)
/// on (i, a, b), which is the angular energy's Hessian with the unit-direction factor e e^T/|e|^2
/// replaced by the identity. Rows of boundary particles are dropped (they are fixed: Dirichlet
/// conditions), their couplings stay on the diagonal. Only the LOWER triangle (diagonal included)
/// is stored: use selfadjointView<Eigen::Lower>() for products.
Eigen::SparseMatrix<double> interior_laplacian(const RelaxationSetup& setup,
                                               const RelaxationOptions& options);

/// 3 x num_free(): the current positions of the interior particles, in interior order.
Eigen::Matrix3Xd interior_coordinates(const RelaxationSetup& setup);

/// A fill-reducing ordering of the interior particles by geometric nested dissection: the
/// particles (columns of `coordinates`, n = laplacian.rows()) are split at the median of the
/// longest axis of their bounding box; the particles of the lower half that have a neighbour in the
/// upper half (in the sparsity graph of `laplacian`, lower triangle stored) form the separator,
/// numbered last; both halves are ordered recursively, down to leaves of 64 particles kept in their
/// given order. On a grid of n particles this gives the O(n log n) fill and O(n^1.5) work of nested
/// dissection [George 1973], against the larger constants of minimum degree on 2D meshes.
/// Returns `order`: order[k] = the particle placed at position k. Deterministic (ties broken by
/// index).
std::vector<int> nested_dissection_order(const Eigen::SparseMatrix<double>& laplacian,
                                         const Eigen::Matrix3Xd& coordinates);

/// The interior spring Laplacian, reordered by nested_dissection_order and factorised (sparse
/// LDL^T, no further ordering); solves with the original numbering.
class LaplacianFactor {
 public:
  /// `laplacian`: lower triangle stored (interior_laplacian); `coordinates`: 3 x n positions of the
  /// interior particles, used only for the ordering.
  /// \throws NumericalError when a pivot is not positive: an interior part of the grid is not
  ///         connected to the boundary by springs, so it could drift freely.
  LaplacianFactor(const Eigen::SparseMatrix<double>& laplacian,
                  const Eigen::Matrix3Xd& coordinates);
  /// L^-1 b for one right-hand side of n entries.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  /// L^-1 for the three n-blocks of b (x, y, z); the three solves run in parallel on large
  /// systems, each with the same arithmetic as solve().
  Eigen::VectorXd solve3(const Eigen::VectorXd& b) const;
  Eigen::Index size() const { return static_cast<Eigen::Index>(order_.size()); }

 private:
  std::vector<int> order_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>>
      factor_;
};

/// H0 = L^-1 of the L-BFGS solver, applied exactly (LaplacianFactor) or by a multigrid V-cycle
/// (multigrid.h), as LbfgsOptions::preconditioner asks.
class LaplacianInverse {
 public:
  /// `laplacian`: lower triangle stored (interior_laplacian); `coordinates`: 3 x n positions of the
  /// interior particles (the direct factorisation's ordering).
  LaplacianInverse(const Eigen::SparseMatrix<double>& laplacian,
                   const Eigen::Matrix3Xd& coordinates, const LbfgsOptions& options);
  /// x = the operator on the three n-blocks of b (x, y, z); x is resized when needed. Not for
  /// concurrent calls (the multigrid path reuses conversion buffers).
  void solve3(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;
  Preconditioner kind() const { return kind_; }

 private:
  Preconditioner kind_ = Preconditioner::Multigrid;
  std::unique_ptr<LaplacianFactor> direct_;
  std::unique_ptr<Multigrid> multigrid_;
  mutable Multigrid::Block block_b_, block_x_;  // row-major copies of b and x for the V-cycle
};

/// The parameter-space frame of a surface point: first and second derivatives of the limit
/// position with respect to the ptex (u, v).
struct TangentFrame {
  Eigen::Vector3d du = Eigen::Vector3d::Zero();
  Eigen::Vector3d dv = Eigen::Vector3d::Zero();
  Eigen::Vector3d duu = Eigen::Vector3d::Zero();
  Eigen::Vector3d duv = Eigen::Vector3d::Zero();
  Eigen::Vector3d dvv = Eigen::Vector3d::Zero();
};
TangentFrame tangent_frame(const SurfaceDerivatives& d);
TangentFrame tangent_frame(const LimitSurface& surface, const SurfacePoint& point);

/// The fast solver's retraction: moves the surface point `from` (limit position `x`, frame
/// `frame`) by the tangent step `t` along the surface. The step is pulled back into ptex
/// parameters to second order (delta = (J^T J)^-1 J^T (t - 1/2 delta^T H delta), J = [du dv]),
/// walked across ptex faces, and evaluated; if the landing point misses x + t tangentially by more
/// than 1e-3 |t| (the walk carries delta across an edge in parameter units, so around an
/// extraordinary vertex or into the sub-faces of a non-quad face it can land O(|t|) away),
/// Gauss-Newton steps move it to the foot of x + t on the surface, which is the magnet's answer.
/// To first order both are x + t: a retraction. On success fills `out` (point, position, unit
/// normal) and `out_frame`; returns false (the caller then uses the magnet) when the
/// parameterisation is degenerate, the walk stops on the surface boundary, or three corrections do
/// not reach the tolerance.
bool parametric_retraction(const LimitSurface& surface, const SurfacePoint& from,
                           const Eigen::Vector3d& x, const TangentFrame& frame,
                           const Eigen::Vector3d& t, ClosestPoint& out, TangentFrame& out_frame);

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
