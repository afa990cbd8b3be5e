#pragma once
/// \file
/// Right-preconditioned BiCGSTAB (van der Vorst 1992, "Bi-CGSTAB: a fast and smoothly converging
/// variant of Bi-CG for the solution of nonsymmetric linear systems", SIAM J. Sci. Stat. Comput.
/// 13(2)) for a general nonsingular operator, with the deterministic reductions of
/// vector_kernels.h: the iterates are bit-identical for any number of threads when the operator
/// and the preconditioner are.
///
/// Right preconditioning (A B y = b, x = B y) makes the residual the iteration tracks the true
/// residual b - A x, so the stopping test is on ||b - A x|| / ||b|| whatever B is. The recursively
/// updated residual drifts from the true one by round-off; the true residual is recomputed when
/// the recursion says "converged", and the iteration restarts from the current x (with a fresh
/// shadow residual) when it disagrees, which also recovers from a breakdown (rho = 0 or
/// r0^T v = 0).

#include <Eigen/Core>

#include "elastic/numerics/conjugate_gradient.h"

namespace elastic {

struct BicgstabOptions {
  /// Iteration budget over all restarts (>= 1); each iteration costs two products with A and two
  /// applications of the preconditioner.
  int max_iterations = 200;
  /// Stop when the true residual ||b - A x|| has dropped below this fraction of ||b||.
  double tolerance = 1e-12;
  /// Restarts allowed after a breakdown or a drifted residual (>= 0).
  int max_restarts = 3;
};

struct BicgstabResult {
  int iterations = 0;
  int restarts = 0;
  /// ||b - A x|| / ||b|| at the end, recomputed from x (0 when b = 0).
  double relative_residual = 0.0;
  bool converged = false;
};

/// Solves A x = b with the preconditioner B ~ A^-1, starting from `x` when it has b's size and
/// from 0 otherwise (`x` is resized).
BicgstabResult bicgstab(const LinearOperator& a, const LinearOperator& preconditioner,
                        const Eigen::VectorXd& b, Eigen::VectorXd& x,
                        const BicgstabOptions& options = {});

}  // namespace elastic
