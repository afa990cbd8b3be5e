#pragma once
/// \file
/// Smoothed-aggregation algebraic multigrid (AMG) for a sparse symmetric positive definite matrix,
/// used as a fixed linear preconditioner: one V-cycle from a zero guess is a linear operator B ~
/// A^-1 that is symmetric and positive definite, so it can stand where an exact factorisation
/// stood, e.g. as the initial inverse Hessian H0 of L-BFGS (lbfgs_solver.h), at a cost linear in
/// the number of unknowns (a sparse LDL^T of a 2D grid costs O(n^1.5) to factorise and O(n log n)
/// per solve, which is what dominated the solver above about 50,000 particles).
///
/// Hierarchy (set-up) [Vanek, Mandel, Brezina 1996]:
/// - strength: j is a strong neighbour of i when |a_ij| >= `strength_threshold` sqrt(a_ii a_jj).
///   On the particle grid's spring Laplacian this keeps the grid edges (normal + angular springs,
///   |a_ij| ~ 0.3 a_ii) and drops the quad diagonals that angular springs couple weakly (+0.05);
/// - aggregation: greedy, in index order (deterministic): (1) a node whose strong neighbours are
///   all free founds an aggregate with them; (2) a left-over node joins the aggregate of its
///   strongest aggregated neighbour; (3) what is still left founds aggregates with its free strong
///   neighbours. The tentative prolongation is piecewise constant (the near-null space of a
///   Laplacian is the constants);
/// - smoothing: P = (I - omega D^-1 A) P_tent with omega = 4 / (3 lambda_max(D^-1 A));
/// - Galerkin coarse operator A_c = P^T A P, recursively, until at most `coarsest_size` unknowns,
///   which are factorised exactly (sparse LDL^T).
///
/// Cycle: Chebyshev polynomial smoothing of degree `smoothing_degree` in D^-1 A on
/// [lambda_max / `smoothing_range`, 1.1 lambda_max] (lambda_max from a power iteration, capped by
/// the Gershgorin bound), the same polynomial before and after the coarse correction. Each
/// smoother is then an A-norm contraction and the pre- and post-smoothers are adjoint, which makes
/// the V-cycle symmetric positive definite.
///
/// Deterministic: every result is bit-identical for any number of threads (rows are computed
/// independently; the set-up's reductions are sequential).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

namespace elastic {

struct MultigridOptions {
  /// Strong-connection threshold theta of the aggregation (see the file comment), in [0, 1).
  double strength_threshold = 0.08;
  /// Levels stop coarsening at this many unknowns or fewer; the coarsest level is solved exactly.
  int coarsest_size = 800;
  /// Upper bound on the number of levels (the finest included), >= 1.
  int max_levels = 25;
  /// Degree of the Chebyshev smoothing polynomial (>= 1); each degree costs one product with A.
  int smoothing_degree = 2;
  /// The smoother damps eigenvalues of D^-1 A in [lambda_max / smoothing_range, lambda_max]; the
  /// coarse levels handle the ones below. > 1. Aggregates of about 3 x 3 nodes leave the coarse
  /// level the lowest ninth of a 2D spectrum: 6 (with degree 2) gave the best contraction on the
  /// spring grid, 0.38 per cycle against 0.64 with 30.
  double smoothing_range = 6.0;
  /// V-cycles per application (>= 1): k cycles are k steps of the stationary iteration, still a
  /// fixed symmetric positive definite operator.
  int cycles = 1;
};

/// A V-cycle preconditioner for an n x n sparse SPD matrix A.
class Multigrid {
 public:
  /// Three right-hand sides (e.g. the x, y and z coordinates) of n rows, stored row by row.
  using Block = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

  /// `matrix`: A, either with both triangles stored or, when `lower_only`, only the lower triangle
  /// (diagonal included) as interior_laplacian gives it.
  /// \throws InvalidInputError when A is not square, an option is out of range, or a diagonal entry
  ///         is not positive; NumericalError when the coarsest level is not positive definite.
  explicit Multigrid(const Eigen::SparseMatrix<double>& matrix, bool lower_only = false,
                     const MultigridOptions& options = {});
  ~Multigrid();
  Multigrid(Multigrid&&) noexcept;
  Multigrid& operator=(Multigrid&&) noexcept;

  /// x = B b: `cycles` V-cycles from x = 0, for three right-hand sides at once.
  Block apply(const Block& b) const;
  /// The same into `x` (resized when needed). The cycle's buffers are allocated once per object;
  /// concurrent calls on one object are safe (a second caller gets buffers of its own).
  void apply(const Block& b, Block& x) const;
  /// The same for one right-hand side.
  Eigen::VectorXd apply(const Eigen::VectorXd& b) const;

  /// The product A x with the finest level's matrix (both triangles), three right-hand sides.
  Block multiply(const Block& x) const;

  Eigen::Index size() const;
  /// Unknowns per level, finest first.
  std::vector<Eigen::Index> level_sizes() const;
  /// Sum over levels of the stored entries of A_l divided by those of A (memory and work per cycle
  /// relative to one product with A).
  double operator_complexity() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace elastic
