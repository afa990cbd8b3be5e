#include "elastic/numerics/conjugate_gradient.h"

#include <cmath>

#include "elastic/numerics/vector_kernels.h"

namespace elastic {

ConjugateGradientResult conjugate_gradient(const LinearOperator& a,
                                           const LinearOperator& preconditioner,
                                           const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                           const ConjugateGradientOptions& options) {
  ConjugateGradientResult result;
  x = Eigen::VectorXd::Zero(b.size());
  Eigen::VectorXd r = b, z, p, q;
  preconditioner(r, z);
  double rz = parallel_dot(r, z);
  if (!(rz > 0.0)) {
    result.converged = true;
    return result;
  }
  const double start = std::sqrt(rz);
  p = z;
  for (int it = 0; it < options.max_iterations; ++it) {
    a(p, q);
    const double pq = parallel_dot(p, q);
    if (!(pq > 0.0)) {
      break;
    }
    const double alpha = rz / pq;
    parallel_axpy(alpha, p, x);
    parallel_axpy(-alpha, q, r);
    preconditioner(r, z);
    const double rz_next = parallel_dot(r, z);
    result.iterations = it + 1;
    result.relative_residual = std::sqrt(std::max(rz_next, 0.0)) / start;
    if (result.relative_residual < options.tolerance) {
      result.converged = true;
      break;
    }
    parallel_xpby(z, rz_next / rz, p);
    rz = rz_next;
  }
  return result;
}

}  // namespace elastic
