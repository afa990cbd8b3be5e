// The interior spring Laplacian of the relaxation (spring_laplacian.h), its exact factorisation in
// nested-dissection order, and the H0 operator of the L-BFGS solver built on either.
#include "elastic/solvers/spring_laplacian.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include "elastic/core/error.h"
#include "elastic/core/huge_pages.h"
#include "elastic/solvers/nested_dissection.h"
#include "elastic/solvers/solver_common.h"

namespace elastic::solver_detail {

namespace {

const std::string kName = "relaxation";

// Normal spring: C (|d| - k)^2 has Hessian 2C d d^T/|d|^2 at rest; the isotropic 2C I per
// coordinate. Angular spring: e = x_i - (x_a + x_b)/2 = v . (x_i, x_a, x_b), Gram matrix
// 2 C_a v v^T with v = (1, -1/2, -1/2): diagonal (2, 1/2, 1/2) C_a, (i,a) and (i,b) -C_a,
// (a,b) +C_a/2. Hands every contribution (particle, particle, value) to `emit`.
template <typename Emit>
void visit_spring_hessian(const RelaxationSetup& setup, const RelaxationOptions& options,
                          const Emit& emit) {
  const double w = 2.0 * options.stiffness, ca = angular_stiffness(options);
  for (const Spring& sp : setup.grid.springs) {
    emit(sp.i, sp.i, w);
    emit(sp.j, sp.j, w);
    emit(sp.i, sp.j, -w);
  }
  for (const AngularSpring& sp : setup.grid.angular_springs) {
    emit(sp.i, sp.i, 2.0 * ca);
    emit(sp.a, sp.a, 0.5 * ca);
    emit(sp.b, sp.b, 0.5 * ca);
    emit(sp.i, sp.a, -ca);
    emit(sp.i, sp.b, -ca);
    emit(sp.a, sp.b, 0.5 * ca);
  }
}

// The lower triangle of the interior Laplacian, column by column: entry (max, min) goes to column
// min. Column c spans [start[c], start[c + 1]) of rows/values, its diagonal first. Counted and
// scattered into per-column buckets, then each column sorted and its duplicates summed, in
// parallel (a triplet list and Eigen's setFromTriplets took 2 s at a million particles).
class LowerColumns {
 public:
  LowerColumns(const RelaxationSetup& setup, const RelaxationOptions& options)
      : setup_(setup), options_(options), n_(setup.num_free()) {
    count();
    scatter();
    sort_and_sum();
  }

  Eigen::SparseMatrix<double> matrix() const {
    Eigen::SparseMatrix<double> laplacian(n_, n_);
    std::int64_t nonzeros = 0;
    for (const int k : kept_) {
      nonzeros += k;
    }
    laplacian.resizeNonZeros(static_cast<Eigen::Index>(nonzeros));
    int* outer = laplacian.outerIndexPtr();
    outer[0] = 0;
    for (int c = 0; c < n_; ++c) {
      outer[c + 1] = outer[c] + kept_[static_cast<std::size_t>(c)];
    }
    tbb::parallel_for(tbb::blocked_range<int>(0, n_, 4096), [&](const tbb::blocked_range<int>& r) {
      for (int c = r.begin(); c != r.end(); ++c) {
        const auto from = static_cast<std::ptrdiff_t>(start_[static_cast<std::size_t>(c)]);
        const auto length = static_cast<std::ptrdiff_t>(kept_[static_cast<std::size_t>(c)]);
        std::copy(rows_.begin() + from, rows_.begin() + from + length,
                  laplacian.innerIndexPtr() + outer[c]);
        std::copy(values_.begin() + from, values_.begin() + from + length,
                  laplacian.valuePtr() + outer[c]);
      }
    });
    return laplacian;
  }

 private:
  int interior(int p) const { return setup_.interior_index[static_cast<std::size_t>(p)]; }

  // The diagonal, and start[c + 2] = the number of column c's off-diagonal entries plus one slot
  // for the diagonal; then prefix sums, after which start[c + 1] is the fill position of column c.
  void count() {
    assign_huge(start_, static_cast<std::size_t>(n_) + 2, std::int64_t{0});
    diagonal_ = Eigen::VectorXd::Zero(n_);
    visit_spring_hessian(setup_, options_, [&](int p, int q, double value) {
      const int a = interior(p), b = interior(q);
      if (a < 0 || b < 0) {
        return;
      }
      if (a == b) {
        // A sliding boundary row is weighted up by a tenth: with no particle held the spring
        // Laplacian is singular (translations), and the preconditioner must stay definite.
        diagonal_[a] += setup_.sliding[static_cast<std::size_t>(a)] >= 0 ? 1.1 * value : value;
      } else {
        ++start_[static_cast<std::size_t>(std::min(a, b)) + 2];
      }
    });
    for (int c = 0; c < n_; ++c) {
      start_[static_cast<std::size_t>(c) + 2] += 1;
    }
    for (std::size_t c = 2; c < start_.size(); ++c) {
      start_[c] += start_[c - 1];
    }
  }

  // Fills the buckets (diagonal first); afterwards start[c] is column c's start again.
  void scatter() {
    assign_huge(rows_, static_cast<std::size_t>(start_.back()));
    assign_huge(values_, rows_.size());
    for (int c = 0; c < n_; ++c) {
      const auto slot = static_cast<std::size_t>(start_[static_cast<std::size_t>(c) + 1]++);
      rows_[slot] = c;
      values_[slot] = diagonal_[c];
    }
    visit_spring_hessian(setup_, options_, [&](int p, int q, double value) {
      const int a = interior(p), b = interior(q);
      if (a < 0 || b < 0 || a == b) {
        return;
      }
      const auto slot =
          static_cast<std::size_t>(start_[static_cast<std::size_t>(std::min(a, b)) + 1]++);
      rows_[slot] = std::max(a, b);
      values_[slot] = value;
    });
  }

  // Sorts each column by row (a dozen entries: insertion sort) and sums duplicates in place;
  // kept[c] receives the column's length.
  void sort_and_sum() {
    kept_.assign(static_cast<std::size_t>(n_), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, n_, 4096), [&](const tbb::blocked_range<int>& r) {
      for (int c = r.begin(); c != r.end(); ++c) {
        const auto first = static_cast<std::size_t>(start_[static_cast<std::size_t>(c)]);
        const auto last = static_cast<std::size_t>(start_[static_cast<std::size_t>(c) + 1]);
        for (std::size_t i = first + 1; i < last; ++i) {
          for (std::size_t j = i; j > first && rows_[j - 1] > rows_[j]; --j) {
            std::swap(rows_[j - 1], rows_[j]);
            std::swap(values_[j - 1], values_[j]);
          }
        }
        std::size_t out = first;
        for (std::size_t i = first + 1; i < last; ++i) {
          if (rows_[i] == rows_[out]) {
            values_[out] += values_[i];
          } else {
            ++out;
            rows_[out] = rows_[i];
            values_[out] = values_[i];
          }
        }
        kept_[static_cast<std::size_t>(c)] = static_cast<int>(out + 1 - first);
      }
    });
  }

  const RelaxationSetup& setup_;
  const RelaxationOptions& options_;
  const int n_;
  std::vector<std::int64_t> start_;
  Eigen::VectorXd diagonal_;
  std::vector<int> rows_;
  std::vector<double> values_;
  std::vector<int> kept_;
};

}  // namespace

Eigen::SparseMatrix<double> interior_laplacian(const RelaxationSetup& setup,
                                               const RelaxationOptions& options) {
  return LowerColumns(setup, options).matrix();
}

Eigen::Matrix3Xd interior_coordinates(const RelaxationSetup& setup) {
  Eigen::Matrix3Xd x(3, setup.num_free());
  for (int k = 0; k < setup.num_free(); ++k) {
    x.col(k) = setup.positions.col(setup.interior[static_cast<std::size_t>(k)]);
  }
  return x;
}

LaplacianFactor::LaplacianFactor(const Eigen::SparseMatrix<double>& laplacian,
                                 const Eigen::Matrix3Xd& coordinates)
    : order_(nested_dissection_order(laplacian, coordinates)) {
  const auto n = static_cast<std::size_t>(laplacian.rows());
  std::vector<int> position(n);
  for (std::size_t k = 0; k < n; ++k) {
    position[static_cast<std::size_t>(order_[k])] = static_cast<int>(k);
  }
  // P L P^T, lower triangle again.
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(laplacian.nonZeros()));
  for (Eigen::Index col = 0; col < laplacian.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, col); it; ++it) {
      const int a = position[static_cast<std::size_t>(it.row())];
      const int b = position[static_cast<std::size_t>(col)];
      triplets.emplace_back(std::max(a, b), std::min(a, b), it.value());
    }
  }
  Eigen::SparseMatrix<double> permuted(laplacian.rows(), laplacian.cols());
  permuted.setFromTriplets(triplets.begin(), triplets.end());
  factor_.compute(permuted);
  bool positive = factor_.info() == Eigen::Success;
  const Eigen::VectorXd& pivots = factor_.vectorD();
  for (Eigen::Index k = 0; positive && k < pivots.size(); ++k) {
    positive = pivots[k] > 0.0;
  }
  if (!positive) {
    throw NumericalError(kName,
                         "the spring Laplacian of the interior particles is singular (an interior "
                         "part of the grid is not connected to the boundary)");
  }
}

Eigen::VectorXd LaplacianFactor::solve(const Eigen::VectorXd& b) const {
  const Eigen::Index n = size();
  Eigen::VectorXd permuted(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    permuted[k] = b[order_[static_cast<std::size_t>(k)]];
  }
  const Eigen::VectorXd y = factor_.solve(permuted);
  Eigen::VectorXd x(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    x[order_[static_cast<std::size_t>(k)]] = y[k];
  }
  return x;
}

Eigen::VectorXd LaplacianFactor::solve3(const Eigen::VectorXd& b) const {
  const Eigen::Index n = size();
  Eigen::VectorXd r(3 * n);
  const auto solve_column = [&](int c) { r.segment(c * n, n) = solve(b.segment(c * n, n)); };
  // Independent const solves of one factor; each column's arithmetic is the same either way.
  if (n >= 20000) {
    tbb::parallel_for(0, 3, solve_column);
  } else {
    for (int c = 0; c < 3; ++c) {
      solve_column(c);
    }
  }
  return r;
}

LaplacianInverse::LaplacianInverse(const Eigen::SparseMatrix<double>& laplacian,
                                   const Eigen::Matrix3Xd& coordinates,
                                   const LbfgsOptions& options) {
  kind_ = options.preconditioner;
  if (kind_ == Preconditioner::Direct) {
    direct_ = std::make_unique<LaplacianFactor>(laplacian, coordinates);
    return;
  }
  try {
    multigrid_ = std::make_unique<Multigrid>(laplacian, true, options.multigrid);
  } catch (const NumericalError&) {
    // Only a singular Laplacian makes a coarse level indefinite: the same message as the direct
    // factorisation gives.
    throw NumericalError(kName,
                         "the spring Laplacian of the interior particles is singular (an interior "
                         "part of the grid is not connected to the boundary)");
  }
}

void LaplacianInverse::solve3(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  if (direct_) {
    x = direct_->solve3(b);
    return;
  }
  const Eigen::Index n = multigrid_->size();
  if (block_b_.rows() != n) {
    resize_huge(block_b_, n, 3);
    resize_huge(block_x_, n, 3);
  }
  if (x.size() != 3 * n) {
    resize_huge(x, 3 * n, 1);
  }
  // Column blocks <-> rows of three, in parallel chunks.
  const auto rows = [&](const auto& body) {
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, 16384),
                      [&](const tbb::blocked_range<Eigen::Index>& r) {
                        for (Eigen::Index i = r.begin(); i != r.end(); ++i) {
                          body(i);
                        }
                      });
  };
  rows([&](Eigen::Index i) {
    for (int c = 0; c < 3; ++c) {
      block_b_(i, c) = b[c * n + i];
    }
  });
  multigrid_->apply(block_b_, block_x_);
  rows([&](Eigen::Index i) {
    for (int c = 0; c < 3; ++c) {
      x[c * n + i] = block_x_(i, c);
    }
  });
}

}  // namespace elastic::solver_detail
