#pragma once
/// \file
/// The spring-graph Laplacian of the relaxation restricted to its free particles, its exact
/// factorisation (in nested-dissection order, nested_dissection.h) and the H0 operator of the
/// L-BFGS solver built on it (exact, or the multigrid V-cycle of multigrid.h). Internal to the
/// solvers (solver_detail), like solver_common.h.

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "elastic/numerics/multigrid.h"
#include "elastic/solvers/relaxation.h"

namespace elastic::solver_detail {

struct RelaxationSetup;

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

}  // namespace elastic::solver_detail
