#include "elastic/numerics/vector_kernels.h"

#include <tbb/parallel_for.h>

#include <vector>

namespace elastic {
namespace {

constexpr Eigen::Index kBlock = 4096;
// Below this many entries the kernels run sequentially: a TBB task costs more than the loop.
constexpr Eigen::Index kParallelFrom = 4 * kBlock;

}  // namespace

double parallel_dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::Index n = a.size();
  const Eigen::Index blocks = (n + kBlock - 1) / kBlock;
  std::vector<double> partial(static_cast<size_t>(blocks), 0.0);
  auto block_sum = [&](Eigen::Index k) {
    const Eigen::Index begin = k * kBlock, size = std::min(kBlock, n - begin);
    partial[static_cast<size_t>(k)] = a.segment(begin, size).dot(b.segment(begin, size));
  };
  if (n < kParallelFrom) {
    for (Eigen::Index k = 0; k < blocks; ++k) {
      block_sum(k);
    }
  } else {
    tbb::parallel_for(Eigen::Index{0}, blocks, block_sum);
  }
  double sum = 0.0;
  for (const double p : partial) {
    sum += p;
  }
  return sum;
}

void parallel_axpy(double alpha, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  const Eigen::Index n = x.size();
  if (n < kParallelFrom) {
    y += alpha * x;
    return;
  }
  tbb::parallel_for(Eigen::Index{0}, (n + kBlock - 1) / kBlock, [&](Eigen::Index k) {
    const Eigen::Index begin = k * kBlock, size = std::min(kBlock, n - begin);
    y.segment(begin, size) += alpha * x.segment(begin, size);
  });
}

void parallel_xpby(const Eigen::VectorXd& x, double beta, Eigen::VectorXd& y) {
  const Eigen::Index n = x.size();
  if (n < kParallelFrom) {
    y = x + beta * y;
    return;
  }
  tbb::parallel_for(Eigen::Index{0}, (n + kBlock - 1) / kBlock, [&](Eigen::Index k) {
    const Eigen::Index begin = k * kBlock, size = std::min(kBlock, n - begin);
    y.segment(begin, size) = x.segment(begin, size) + beta * y.segment(begin, size);
  });
}

}  // namespace elastic
