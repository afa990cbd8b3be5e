#pragma once
/// \file
/// Parallel vector kernels whose results do not depend on the number of threads: the vectors are
/// cut into fixed blocks of `kBlock` entries, each block is summed on its own, and the block sums
/// are added in block order. The rounding is therefore that of one fixed summation order, the same
/// on 1 and on 64 threads (a TBB reduction would add partial sums in whatever order the threads
/// finish).

#include <Eigen/Core>

namespace elastic {

/// a . b, deterministic (see the file comment). a and b must have the same size.
double parallel_dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

/// y += alpha x, in parallel (entry by entry, so trivially deterministic).
void parallel_axpy(double alpha, const Eigen::VectorXd& x, Eigen::VectorXd& y);

/// y = x + beta y, in parallel.
void parallel_xpby(const Eigen::VectorXd& x, double beta, Eigen::VectorXd& y);

}  // namespace elastic
