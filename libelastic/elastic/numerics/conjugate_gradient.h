#pragma once
/// \file
/// Preconditioned conjugate gradients for a symmetric positive (semi-)definite operator given as a
/// function, with the deterministic reductions of vector_kernels.h: the iterates are bit-identical
/// for any number of threads when the operator and the preconditioner are.
///
/// On a semi-definite operator the iteration still converges when b is orthogonal to the null
/// space (e.g. the gradient of an energy that is invariant under a motion), starting from x = 0:
/// every iterate then stays in the range of the operator.

#include <Eigen/Core>
#include <functional>

namespace elastic {

/// out = Op(in); `out` has the size of `in` on return.
using LinearOperator = std::function<void(const Eigen::VectorXd& in, Eigen::VectorXd& out)>;

struct ConjugateGradientOptions {
  /// Iteration budget (>= 1).
  int max_iterations = 100;
  /// Stop when the preconditioned residual norm sqrt(r^T B r) has dropped by this factor from
  /// its value at x = 0.
  double tolerance = 1e-4;
};

struct ConjugateGradientResult {
  int iterations = 0;
  /// sqrt(r^T B r) at the end over its value at the start (0 when b = 0).
  double relative_residual = 0.0;
  bool converged = false;
};

/// Solves A x = b from x = 0 with the preconditioner B ~ A^-1 (symmetric positive definite).
/// `x` is resized. A breakdown (p^T A p <= 0, only from round-off on a semi-definite A) ends the
/// iteration with the current x.
ConjugateGradientResult conjugate_gradient(const LinearOperator& a,
                                           const LinearOperator& preconditioner,
                                           const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                           const ConjugateGradientOptions& options = {});

}  // namespace elastic
