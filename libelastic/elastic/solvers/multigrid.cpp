#include "elastic/solvers/multigrid.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>

#include "elastic/core/error.h"

namespace elastic {

namespace {

constexpr const char* kName = "multigrid";

// Compressed sparse rows; column indices sorted within each row.
struct Csr {
  int rows = 0, cols = 0;
  std::vector<std::int64_t> start{0};
  std::vector<int> index;
  std::vector<double> value;

  std::size_t nonzeros() const { return index.size(); }
};

// Rows [0, rows) in fixed chunks: the chunking never depends on the thread count, and every row is
// computed on its own, so the results do not either.
template <typename Body>
void for_rows(int rows, const Body& body) {
  tbb::parallel_for(tbb::blocked_range<int>(0, rows, 2048),
                    [&](const tbb::blocked_range<int>& range) {
                      for (int i = range.begin(); i != range.end(); ++i) body(i);
                    });
}

// y = A x for W right-hand sides stored row by row (x: A.cols x W, y: A.rows x W).
template <int W>
void sparse_times(const Csr& a, const double* x, double* y) {
  for_rows(a.rows, [&](int i) {
    double sum[W] = {};
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      const double v = a.value[static_cast<std::size_t>(e)];
      const double* xj = x + static_cast<std::ptrdiff_t>(W) * a.index[static_cast<std::size_t>(e)];
      for (int w = 0; w < W; ++w) sum[w] += v * xj[w];
    }
    double* yi = y + static_cast<std::ptrdiff_t>(W) * i;
    for (int w = 0; w < W; ++w) yi[w] = sum[w];
  });
}

Csr transpose(const Csr& a) {
  Csr t;
  t.rows = a.cols;
  t.cols = a.rows;
  t.start.assign(static_cast<std::size_t>(t.rows) + 1, 0);
  for (const int j : a.index) ++t.start[static_cast<std::size_t>(j) + 1];
  std::partial_sum(t.start.begin(), t.start.end(), t.start.begin());
  t.index.resize(a.nonzeros());
  t.value.resize(a.nonzeros());
  std::vector<std::int64_t> fill(t.start.begin(), t.start.end() - 1);
  // Rows of `a` in increasing order: the columns of each row of the transpose come out sorted.
  for (int i = 0; i < a.rows; ++i)
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      const auto slot = static_cast<std::size_t>(
          fill[static_cast<std::size_t>(a.index[static_cast<std::size_t>(e)])]++);
      t.index[slot] = i;
      t.value[slot] = a.value[static_cast<std::size_t>(e)];
    }
  return t;
}

// Rows computed independently (each into its own list), then concatenated in order.
struct RowLists {
  std::vector<std::vector<int>> index;
  std::vector<std::vector<double>> value;
  explicit RowLists(int rows)
      : index(static_cast<std::size_t>(rows)), value(static_cast<std::size_t>(rows)) {}

  Csr gather(int rows, int cols) {
    Csr c;
    c.rows = rows;
    c.cols = cols;
    c.start.assign(static_cast<std::size_t>(rows) + 1, 0);
    for (int i = 0; i < rows; ++i)
      c.start[static_cast<std::size_t>(i) + 1] =
          c.start[static_cast<std::size_t>(i)] +
          static_cast<std::int64_t>(index[static_cast<std::size_t>(i)].size());
    c.index.resize(static_cast<std::size_t>(c.start.back()));
    c.value.resize(c.index.size());
    for_rows(rows, [&](int i) {
      const auto row = static_cast<std::size_t>(i);
      std::copy(index[row].begin(), index[row].end(),
                c.index.begin() + static_cast<std::ptrdiff_t>(c.start[row]));
      std::copy(value[row].begin(), value[row].end(),
                c.value.begin() + static_cast<std::ptrdiff_t>(c.start[row]));
      std::vector<int>().swap(index[row]);
      std::vector<double>().swap(value[row]);
    });
    return c;
  }
};

// C = A B, row by row with a dense accumulator per thread. The summation order within a row is
// fixed by the data (A's row order, then B's), so C does not depend on the threads.
Csr product(const Csr& a, const Csr& b) {
  struct Scratch {
    std::vector<double> sum;
    std::vector<int> mark;
    std::vector<int> used;
  };
  tbb::enumerable_thread_specific<Scratch> scratch([&] {
    return Scratch{std::vector<double>(static_cast<std::size_t>(b.cols), 0.0),
                   std::vector<int>(static_cast<std::size_t>(b.cols), -1),
                   {}};
  });
  RowLists rows(a.rows);
  for_rows(a.rows, [&](int i) {
    Scratch& s = scratch.local();
    s.used.clear();
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      const auto k = static_cast<std::size_t>(a.index[static_cast<std::size_t>(e)]);
      const double av = a.value[static_cast<std::size_t>(e)];
      for (std::int64_t f = b.start[k]; f < b.start[k + 1]; ++f) {
        const int j = b.index[static_cast<std::size_t>(f)];
        const auto jj = static_cast<std::size_t>(j);
        if (s.mark[jj] != i) {
          s.mark[jj] = i;
          s.sum[jj] = 0.0;
          s.used.push_back(j);
        }
        s.sum[jj] += av * b.value[static_cast<std::size_t>(f)];
      }
    }
    std::sort(s.used.begin(), s.used.end());
    auto& index = rows.index[static_cast<std::size_t>(i)];
    auto& value = rows.value[static_cast<std::size_t>(i)];
    index = s.used;
    value.reserve(s.used.size());
    for (const int j : s.used) value.push_back(s.sum[static_cast<std::size_t>(j)]);
  });
  return rows.gather(a.rows, b.cols);
}

// (A + A^T) / 2 for A with a symmetric pattern (a Galerkin product P^T A P): removes the round-off
// asymmetry of the product, so that the V-cycle is symmetric to the last bit.
void symmetrise(Csr& a) {
  const Csr t = transpose(a);
  for (std::size_t e = 0; e < a.value.size(); ++e) a.value[e] = 0.5 * (a.value[e] + t.value[e]);
}

// Full symmetric CSR from Eigen's column-major storage (both triangles, or the lower one mirrored).
Csr from_eigen(const Eigen::SparseMatrix<double>& m, bool lower_only) {
  const auto n = static_cast<int>(m.rows());
  Csr a;
  a.rows = a.cols = n;
  a.start.assign(static_cast<std::size_t>(n) + 1, 0);
  for (Eigen::Index col = 0; col < m.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(m, col); it; ++it) {
      if (!lower_only) {
        ++a.start[static_cast<std::size_t>(col) + 1];  // column col of a symmetric A is row col
        continue;
      }
      if (it.row() < col) continue;  // only the lower triangle is read
      ++a.start[static_cast<std::size_t>(it.row()) + 1];
      if (it.row() != col) ++a.start[static_cast<std::size_t>(col) + 1];
    }
  std::partial_sum(a.start.begin(), a.start.end(), a.start.begin());
  a.index.resize(static_cast<std::size_t>(a.start.back()));
  a.value.resize(a.index.size());
  std::vector<std::int64_t> fill(a.start.begin(), a.start.end() - 1);
  const auto put = [&](Eigen::Index row, Eigen::Index col, double v) {
    const auto slot = static_cast<std::size_t>(fill[static_cast<std::size_t>(row)]++);
    a.index[slot] = static_cast<int>(col);
    a.value[slot] = v;
  };
  // Columns in increasing order: row r receives its columns < r first (from the lower triangle),
  // then, at column r, the diagonal and its columns > r (mirrored); both runs are sorted.
  for (Eigen::Index col = 0; col < m.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(m, col); it; ++it) {
      if (!lower_only) {
        put(col, it.row(), it.value());
        continue;
      }
      if (it.row() < col) continue;
      put(it.row(), col, it.value());
      if (it.row() != col) put(col, it.row(), it.value());
    }
  // Nothing below needs sorted input rows (products and transposes sort their output).
  return a;
}

Eigen::VectorXd diagonal(const Csr& a) {
  Eigen::VectorXd d = Eigen::VectorXd::Zero(a.rows);
  for (int i = 0; i < a.rows; ++i)
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e)
      if (a.index[static_cast<std::size_t>(e)] == i) d[i] += a.value[static_cast<std::size_t>(e)];
  return d;
}

// An upper estimate of lambda_max(D^-1 A): 1.1 times the Rayleigh quotient after a power
// iteration (a lower bound that approaches lambda_max), never above the Gershgorin bound
// max_i sum_j |a_ij| / a_ii (an upper bound, tight for the checkerboard mode of a grid Laplacian).
double spectral_radius(const Csr& a, const Eigen::VectorXd& inv_diag) {
  double gershgorin = 0.0;
  for (int i = 0; i < a.rows; ++i) {
    double sum = 0.0;
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e)
      sum += std::abs(a.value[static_cast<std::size_t>(e)]);
    gershgorin = std::max(gershgorin, sum * inv_diag[i]);
  }
  // Deterministic pseudo-random start (a multiplicative hash of the index), so that no eigenvector
  // is missed by symmetry.
  Eigen::VectorXd x(a.rows), y(a.rows);
  for (int i = 0; i < a.rows; ++i) {
    const std::uint32_t h = static_cast<std::uint32_t>(i) * 2654435761U;
    x[i] = static_cast<double>(h >> 8) / static_cast<double>(1U << 24) - 0.5;
  }
  double estimate = 0.0;
  for (int k = 0; k < 15; ++k) {
    sparse_times<1>(a, x.data(), y.data());  // y = A x
    // Rayleigh quotient of the generalised problem A x = lambda D x.
    const double xd = x.dot(x.cwiseQuotient(inv_diag));
    if (!(xd > 0.0)) break;
    estimate = x.dot(y) / xd;
    x = y.cwiseProduct(inv_diag);
    const double norm = x.norm();
    if (!(norm > 0.0)) break;
    x /= norm;
  }
  return std::min(1.1 * estimate, gershgorin);
}

// Greedy aggregation over the strong connections (see the file comment of multigrid.h). Returns
// the aggregate of each node; `count` receives the number of aggregates.
std::vector<int> aggregate(const Csr& a, const Eigen::VectorXd& diag, double theta, int& count) {
  const auto n = static_cast<std::size_t>(a.rows);
  const auto strong = [&](int i, std::int64_t e) {
    const int j = a.index[static_cast<std::size_t>(e)];
    return j != i &&
           std::abs(a.value[static_cast<std::size_t>(e)]) >= theta * std::sqrt(diag[i] * diag[j]);
  };
  std::vector<int> agg(n, -1);
  count = 0;
  // (1) Nodes whose strong neighbourhood is entirely free found an aggregate.
  for (int i = 0; i < a.rows; ++i) {
    if (agg[static_cast<std::size_t>(i)] >= 0) continue;
    bool free = true;
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         free && e < a.start[static_cast<std::size_t>(i) + 1]; ++e)
      if (strong(i, e) && agg[static_cast<std::size_t>(a.index[static_cast<std::size_t>(e)])] >= 0)
        free = false;
    if (!free) continue;
    agg[static_cast<std::size_t>(i)] = count;
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e)
      if (strong(i, e)) agg[static_cast<std::size_t>(a.index[static_cast<std::size_t>(e)])] = count;
    ++count;
  }
  // (2) Left-over nodes join the aggregate (from step 1) of their strongest strong neighbour.
  const std::vector<int> first = agg;
  for (int i = 0; i < a.rows; ++i) {
    if (first[static_cast<std::size_t>(i)] >= 0) continue;
    double best = 0.0;
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      const int j = a.index[static_cast<std::size_t>(e)];
      const double v = std::abs(a.value[static_cast<std::size_t>(e)]);
      if (strong(i, e) && first[static_cast<std::size_t>(j)] >= 0 && v > best) {
        best = v;
        agg[static_cast<std::size_t>(i)] = first[static_cast<std::size_t>(j)];
      }
    }
  }
  // (3) What is left founds aggregates with its free strong neighbours.
  for (int i = 0; i < a.rows; ++i) {
    if (agg[static_cast<std::size_t>(i)] >= 0) continue;
    agg[static_cast<std::size_t>(i)] = count;
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      const auto j = static_cast<std::size_t>(a.index[static_cast<std::size_t>(e)]);
      if (strong(i, e) && agg[j] < 0) agg[j] = count;
    }
    ++count;
  }
  return agg;
}

// P = (I - omega D^-1 A) P_tent, P_tent(i, agg(i)) = 1.
Csr smoothed_prolongation(const Csr& a, const Eigen::VectorXd& inv_diag,
                          const std::vector<int>& agg, int coarse, double omega) {
  RowLists rows(a.rows);
  for_rows(a.rows, [&](int i) {
    auto& index = rows.index[static_cast<std::size_t>(i)];
    auto& value = rows.value[static_cast<std::size_t>(i)];
    const auto add = [&](int j, double v) {
      const auto it = std::find(index.begin(), index.end(), j);  // a handful of aggregates per row
      if (it == index.end()) {
        index.push_back(j);
        value.push_back(v);
      } else {
        value[static_cast<std::size_t>(it - index.begin())] += v;
      }
    };
    add(agg[static_cast<std::size_t>(i)], 1.0);
    const double scale = -omega * inv_diag[i];
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e)
      add(agg[static_cast<std::size_t>(a.index[static_cast<std::size_t>(e)])],
          scale * a.value[static_cast<std::size_t>(e)]);
    // Sort the row by column.
    std::vector<std::size_t> order(index.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(),
              [&](std::size_t p, std::size_t q) { return index[p] < index[q]; });
    std::vector<int> sorted_index(index.size());
    std::vector<double> sorted_value(index.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
      sorted_index[k] = index[order[k]];
      sorted_value[k] = value[order[k]];
    }
    index.swap(sorted_index);
    value.swap(sorted_value);
  });
  return rows.gather(a.rows, coarse);
}

Eigen::SparseMatrix<double> to_eigen(const Csr& a) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(a.nonzeros());
  for (int i = 0; i < a.rows; ++i)
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e)
      triplets.emplace_back(i, a.index[static_cast<std::size_t>(e)],
                            a.value[static_cast<std::size_t>(e)]);
  Eigen::SparseMatrix<double> m(a.rows, a.cols);
  m.setFromTriplets(triplets.begin(), triplets.end());
  return m;
}

}  // namespace

struct Multigrid::Impl {
  struct Level {
    Csr a;                     // both triangles
    Eigen::VectorXd inv_diag;  // 1 / a_ii
    double lambda = 0.0;       // upper estimate of lambda_max(D^-1 A)
    Csr p, r;                  // prolongation to this level from the next, and its transpose
  };
  MultigridOptions options;
  std::vector<Level> levels;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> coarsest;

  // Chebyshev smoothing of A x = b (see the file comment of multigrid.h), in place; `zero`: x is
  // 0 on entry (saves the first product).
  void smooth(const Level& level, const Block& b, Block& x, bool zero) const {
    const double hi = level.lambda;  // spectral_radius: an upper estimate
    const double lo = hi / options.smoothing_range;
    const double theta = 0.5 * (hi + lo), delta = 0.5 * (hi - lo);
    const double sigma = theta / delta;
    double rho = 1.0 / sigma;
    Block r(b.rows(), 3);
    if (zero) {
      r = b;
    } else {
      sparse_times<3>(level.a, x.data(), r.data());
      r = b - r;
    }
    Block d = level.inv_diag.asDiagonal() * r / theta;
    x += d;
    Block ad(b.rows(), 3);
    for (int k = 1; k < options.smoothing_degree; ++k) {
      sparse_times<3>(level.a, d.data(), ad.data());
      r -= ad;
      const double rho_next = 1.0 / (2.0 * sigma - rho);
      d = (rho_next * rho) * d + (2.0 * rho_next / delta) * (level.inv_diag.asDiagonal() * r);
      rho = rho_next;
      x += d;
    }
  }

  Block cycle(std::size_t l, const Block& b) const {
    if (l + 1 == levels.size()) {
      const Eigen::MatrixXd solution = coarsest.solve(Eigen::MatrixXd(b));
      return solution;
    }
    const Level& level = levels[l];
    Block x = Block::Zero(b.rows(), 3);
    smooth(level, b, x, true);
    Block residual(b.rows(), 3);
    sparse_times<3>(level.a, x.data(), residual.data());
    residual = b - residual;
    Block coarse_b(level.r.rows, 3);
    sparse_times<3>(level.r, residual.data(), coarse_b.data());
    const Block coarse_x = cycle(l + 1, coarse_b);
    Block correction(b.rows(), 3);
    sparse_times<3>(level.p, coarse_x.data(), correction.data());
    x += correction;
    smooth(level, b, x, false);
    return x;
  }
};

Multigrid::Multigrid(const Eigen::SparseMatrix<double>& matrix, bool lower_only,
                     const MultigridOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (matrix.rows() != matrix.cols())
    throw InvalidInputError(kName, "the matrix is not square (" + std::to_string(matrix.rows()) +
                                       " x " + std::to_string(matrix.cols()) + ")");
  if (!(options.strength_threshold >= 0.0 && options.strength_threshold < 1.0) ||
      options.coarsest_size < 1 || options.max_levels < 1 || options.smoothing_degree < 1 ||
      !(options.smoothing_range > 1.0) || options.cycles < 1)
    throw InvalidInputError(kName, "options out of range");
  impl_->options = options;
  Csr a = from_eigen(matrix, lower_only);
  for (;;) {
    Impl::Level level;
    const Eigen::VectorXd diag = diagonal(a);
    for (Eigen::Index i = 0; i < diag.size(); ++i)
      if (!(diag[i] > 0.0))
        throw InvalidInputError(kName, "diagonal entry " + std::to_string(i) + " of level " +
                                           std::to_string(impl_->levels.size()) +
                                           " is not positive");
    level.inv_diag = diag.cwiseInverse();
    const bool last = a.rows <= options.coarsest_size ||
                      static_cast<int>(impl_->levels.size()) + 1 >= options.max_levels;
    if (!last) level.lambda = spectral_radius(a, level.inv_diag);
    int coarse = 0;
    std::vector<int> agg;
    if (!last) agg = aggregate(a, diag, options.strength_threshold, coarse);
    // Stop when aggregation no longer coarsens (e.g. a diagonal matrix: every node alone).
    if (last || coarse >= a.rows || coarse == 0) {
      impl_->coarsest.compute(to_eigen(a));
      bool positive = impl_->coarsest.info() == Eigen::Success;
      const Eigen::VectorXd& pivots = impl_->coarsest.vectorD();
      for (Eigen::Index k = 0; positive && k < pivots.size(); ++k) positive = pivots[k] > 0.0;
      if (!positive)
        throw NumericalError(kName, "the coarsest level (" + std::to_string(a.rows) +
                                        " unknowns) is not positive definite");
      level.a = std::move(a);
      impl_->levels.push_back(std::move(level));
      break;
    }
    level.p = smoothed_prolongation(a, level.inv_diag, agg, coarse, 4.0 / (3.0 * level.lambda));
    level.r = transpose(level.p);
    Csr next = product(level.r, product(a, level.p));
    symmetrise(next);
    level.a = std::move(a);
    impl_->levels.push_back(std::move(level));
    a = std::move(next);
  }
}

Multigrid::~Multigrid() = default;
Multigrid::Multigrid(Multigrid&&) noexcept = default;
Multigrid& Multigrid::operator=(Multigrid&&) noexcept = default;

Multigrid::Block Multigrid::apply(const Block& b) const {
  if (b.rows() != size())
    throw InvalidInputError(kName, "right-hand side has " + std::to_string(b.rows()) +
                                       " rows, expected " + std::to_string(size()));
  Block x = impl_->cycle(0, b);
  for (int c = 1; c < impl_->options.cycles; ++c) {
    const Block residual = b - multiply(x);
    x += impl_->cycle(0, residual);
  }
  return x;
}

Eigen::VectorXd Multigrid::apply(const Eigen::VectorXd& b) const {
  Block block = Block::Zero(b.size(), 3);
  block.col(0) = b;
  return apply(block).col(0);
}

Multigrid::Block Multigrid::multiply(const Block& x) const {
  if (x.rows() != size())
    throw InvalidInputError(kName, "vector has " + std::to_string(x.rows()) + " rows, expected " +
                                       std::to_string(size()));
  Block y(x.rows(), 3);
  sparse_times<3>(impl_->levels.front().a, x.data(), y.data());
  return y;
}

Eigen::Index Multigrid::size() const {
  return impl_->levels.front().a.rows;
}

std::vector<Eigen::Index> Multigrid::level_sizes() const {
  std::vector<Eigen::Index> sizes;
  for (const auto& level : impl_->levels) sizes.push_back(level.a.rows);
  return sizes;
}

double Multigrid::operator_complexity() const {
  double total = 0.0;
  for (const auto& level : impl_->levels) total += static_cast<double>(level.a.nonzeros());
  return total / static_cast<double>(std::max<std::size_t>(impl_->levels.front().a.nonzeros(), 1));
}

}  // namespace elastic
