#include "elastic/numerics/bicgstab.h"

#include <cmath>

#include "elastic/numerics/vector_kernels.h"

namespace elastic {
namespace {

double norm(const Eigen::VectorXd& v) {
  return std::sqrt(parallel_dot(v, v));
}

/// r = b - A x.
void true_residual(const LinearOperator& a, const Eigen::VectorXd& b, const Eigen::VectorXd& x,
                   Eigen::VectorXd& ax, Eigen::VectorXd& r) {
  a(x, ax);
  r = b;
  parallel_axpy(-1.0, ax, r);
}

}  // namespace

BicgstabResult bicgstab(const LinearOperator& a, const LinearOperator& preconditioner,
                        const Eigen::VectorXd& b, Eigen::VectorXd& x,
                        const BicgstabOptions& options) {
  BicgstabResult result;
  if (x.size() != b.size()) {
    x = Eigen::VectorXd::Zero(b.size());
  }
  const double b_norm = norm(b);
  if (!(b_norm > 0.0)) {
    x.setZero();
    result.converged = true;
    return result;
  }
  const double target = options.tolerance * b_norm;
  Eigen::VectorXd r, ax, shadow, p, v, s, t, p_hat, s_hat;
  true_residual(a, b, x, ax, r);
  double r_norm = norm(r);
  while (true) {
    if (r_norm <= target) {
      result.converged = true;
      break;
    }
    if (result.iterations >= options.max_iterations || result.restarts > options.max_restarts) {
      break;
    }
    // One run of the recursion from the current x; it ends on convergence of the recursive
    // residual, a breakdown or the budget, and the true residual decides what happens next.
    shadow = r;
    p = Eigen::VectorXd::Zero(b.size());
    v = Eigen::VectorXd::Zero(b.size());
    double rho = 1.0, alpha = 1.0, omega = 1.0;
    while (result.iterations < options.max_iterations) {
      const double rho_next = parallel_dot(shadow, r);
      if (rho_next == 0.0 || omega == 0.0 || !std::isfinite(rho_next)) {
        break;
      }
      const double beta = (rho_next / rho) * (alpha / omega);
      rho = rho_next;
      // p = r + beta (p - omega v)
      parallel_axpy(-omega, v, p);
      parallel_xpby(r, beta, p);
      preconditioner(p, p_hat);
      a(p_hat, v);
      const double shadow_v = parallel_dot(shadow, v);
      if (shadow_v == 0.0 || !std::isfinite(shadow_v)) {
        break;
      }
      alpha = rho / shadow_v;
      s = r;
      parallel_axpy(-alpha, v, s);
      ++result.iterations;
      if (norm(s) <= target) {
        parallel_axpy(alpha, p_hat, x);
        break;
      }
      preconditioner(s, s_hat);
      a(s_hat, t);
      const double tt = parallel_dot(t, t);
      if (!(tt > 0.0)) {
        break;
      }
      omega = parallel_dot(t, s) / tt;
      parallel_axpy(alpha, p_hat, x);
      parallel_axpy(omega, s_hat, x);
      r = s;
      parallel_axpy(-omega, t, r);
      if (norm(r) <= target) {
        break;
      }
    }
    true_residual(a, b, x, ax, r);
    const double previous = r_norm;
    r_norm = norm(r);
    if (!std::isfinite(r_norm)) {
      break;
    }
    if (r_norm > target) {
      ++result.restarts;
      if (!(r_norm < previous)) {
        break;  // no progress since the last restart: give up rather than loop on round-off
      }
    }
  }
  result.relative_residual = r_norm / b_norm;
  return result;
}

}  // namespace elastic
