#include "elastic/numerics/multigrid.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <numeric>
#include <string>

#include "elastic/core/error.h"
#include "elastic/core/huge_pages.h"

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
                      for (int i = range.begin(); i != range.end(); ++i) {
                        body(i);
                      }
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
      for (int w = 0; w < W; ++w) {
        sum[w] += v * xj[w];
      }
    }
    double* yi = y + static_cast<std::ptrdiff_t>(W) * i;
    for (int w = 0; w < W; ++w) {
      yi[w] = sum[w];
    }
  });
}

Csr transpose(const Csr& a) {
  Csr t;
  t.rows = a.cols;
  t.cols = a.rows;
  assign_huge(t.start, static_cast<std::size_t>(t.rows) + 1, std::int64_t{0});
  for (const int j : a.index) {
    ++t.start[static_cast<std::size_t>(j) + 1];
  }
  std::partial_sum(t.start.begin(), t.start.end(), t.start.begin());
  assign_huge(t.index, a.nonzeros());
  assign_huge(t.value, a.nonzeros());
  std::vector<std::int64_t> fill(t.start.begin(), t.start.end() - 1);
  // Rows of `a` in increasing order: the columns of each row of the transpose come out sorted.
  for (int i = 0; i < a.rows; ++i) {
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      const auto slot = static_cast<std::size_t>(
          fill[static_cast<std::size_t>(a.index[static_cast<std::size_t>(e)])]++);
      t.index[slot] = i;
      t.value[slot] = a.value[static_cast<std::size_t>(e)];
    }
  }
  return t;
}

// Builds a Csr row by row: `row(i, index, value)` appends row i's entries (columns sorted). Rows
// are computed in fixed chunks, each into its own buffers, then concatenated in order: the result
// does not depend on the threads, and there is one allocation per chunk, not per row.
template <typename RowFn>
Csr build_rows(int rows, int cols, const RowFn& row) {
  constexpr int kChunk = 4096;
  const int chunks = (rows + kChunk - 1) / kChunk;
  struct Chunk {
    std::vector<int> index;
    std::vector<double> value;
    std::vector<std::int64_t> count;
  };
  std::vector<Chunk> parts(static_cast<std::size_t>(chunks));
  tbb::parallel_for(0, chunks, [&](int c) {
    Chunk& part = parts[static_cast<std::size_t>(c)];
    const int first = c * kChunk, last = std::min(rows, first + kChunk);
    part.count.reserve(static_cast<std::size_t>(last - first));
    for (int i = first; i < last; ++i) {
      const std::size_t before = part.index.size();
      row(i, part.index, part.value);
      part.count.push_back(static_cast<std::int64_t>(part.index.size() - before));
    }
  });
  Csr c;
  c.rows = rows;
  c.cols = cols;
  assign_huge(c.start, static_cast<std::size_t>(rows) + 1, std::int64_t{0});
  std::vector<std::int64_t> offset(static_cast<std::size_t>(chunks) + 1, 0);
  for (int k = 0; k < chunks; ++k) {
    const Chunk& part = parts[static_cast<std::size_t>(k)];
    for (std::size_t r = 0; r < part.count.size(); ++r) {
      const auto i = static_cast<std::size_t>(k) * kChunk + r;
      c.start[i + 1] = c.start[i] + part.count[r];
    }
    offset[static_cast<std::size_t>(k) + 1] =
        offset[static_cast<std::size_t>(k)] + static_cast<std::int64_t>(part.index.size());
  }
  assign_huge(c.index, static_cast<std::size_t>(c.start.back()));
  assign_huge(c.value, c.index.size());
  tbb::parallel_for(0, chunks, [&](int k) {
    Chunk& part = parts[static_cast<std::size_t>(k)];
    const auto at = static_cast<std::ptrdiff_t>(offset[static_cast<std::size_t>(k)]);
    std::copy(part.index.begin(), part.index.end(), c.index.begin() + at);
    std::copy(part.value.begin(), part.value.end(), c.value.begin() + at);
    part = Chunk{};
  });
  return c;
}

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
  return build_rows(
      a.rows, b.cols, [&](int i, std::vector<int>& index, std::vector<double>& value) {
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
        for (const int j : s.used) {
          index.push_back(j);
          value.push_back(s.sum[static_cast<std::size_t>(j)]);
        }
      });
}

// (A + A^T) / 2 for A with a symmetric pattern (a Galerkin product P^T A P): removes the round-off
// asymmetry of the product, so that the V-cycle is symmetric to the last bit.
void symmetrise(Csr& a) {
  const Csr t = transpose(a);
  for (std::size_t e = 0; e < a.value.size(); ++e) {
    a.value[e] = 0.5 * (a.value[e] + t.value[e]);
  }
}

// Full symmetric CSR from Eigen's column-major storage (both triangles, or the lower one mirrored).
Csr from_eigen(const Eigen::SparseMatrix<double>& m, bool lower_only) {
  const auto n = static_cast<int>(m.rows());
  Csr a;
  a.rows = a.cols = n;
  assign_huge(a.start, static_cast<std::size_t>(n) + 1, std::int64_t{0});
  for (Eigen::Index col = 0; col < m.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(m, col); it; ++it) {
      if (!lower_only) {
        ++a.start[static_cast<std::size_t>(col) + 1];  // column col of a symmetric A is row col
        continue;
      }
      if (it.row() < col) {
        continue;  // only the lower triangle is read
      }
      ++a.start[static_cast<std::size_t>(it.row()) + 1];
      if (it.row() != col) {
        ++a.start[static_cast<std::size_t>(col) + 1];
      }
    }
  }
  std::partial_sum(a.start.begin(), a.start.end(), a.start.begin());
  assign_huge(a.index, static_cast<std::size_t>(a.start.back()));
  assign_huge(a.value, a.index.size());
  std::vector<std::int64_t> fill(a.start.begin(), a.start.end() - 1);
  const auto put = [&](Eigen::Index row, Eigen::Index col, double v) {
    const auto slot = static_cast<std::size_t>(fill[static_cast<std::size_t>(row)]++);
    a.index[slot] = static_cast<int>(col);
    a.value[slot] = v;
  };
  // Columns in increasing order: row r receives its columns < r first (from the lower triangle),
  // then, at column r, the diagonal and its columns > r (mirrored); both runs are sorted.
  for (Eigen::Index col = 0; col < m.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(m, col); it; ++it) {
      if (!lower_only) {
        put(col, it.row(), it.value());
        continue;
      }
      if (it.row() < col) {
        continue;
      }
      put(it.row(), col, it.value());
      if (it.row() != col) {
        put(col, it.row(), it.value());
      }
    }
  }
  // Nothing below needs sorted input rows (products and transposes sort their output).
  return a;
}

Eigen::VectorXd diagonal(const Csr& a) {
  Eigen::VectorXd d = Eigen::VectorXd::Zero(a.rows);
  for (int i = 0; i < a.rows; ++i) {
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      if (a.index[static_cast<std::size_t>(e)] == i) {
        d[i] += a.value[static_cast<std::size_t>(e)];
      }
    }
  }
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
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      sum += std::abs(a.value[static_cast<std::size_t>(e)]);
    }
    gershgorin = std::max(gershgorin, sum * inv_diag[i]);
  }
  // Deterministic pseudo-random start (a multiplicative hash of the index), so that no eigenvector
  // is missed by symmetry.
  Eigen::VectorXd x, y;
  resize_huge(x, a.rows, 1);
  resize_huge(y, a.rows, 1);
  for (int i = 0; i < a.rows; ++i) {
    const std::uint32_t h = static_cast<std::uint32_t>(i) * 2654435761U;
    x[i] = static_cast<double>(h >> 8) / static_cast<double>(1U << 24) - 0.5;
  }
  double estimate = 0.0;
  for (int k = 0; k < 20; ++k) {
    sparse_times<1>(a, x.data(), y.data());  // y = A x
    // Rayleigh quotient of the generalised problem A x = lambda D x; then x = D^-1 y / |D^-1 y|.
    double xd = 0.0, xy = 0.0, norm = 0.0;
    for (int i = 0; i < a.rows; ++i) {
      xd += x[i] * x[i] / inv_diag[i];
      xy += x[i] * y[i];
      y[i] *= inv_diag[i];
      norm += y[i] * y[i];
    }
    if (!(xd > 0.0) || !(norm > 0.0)) {
      break;
    }
    estimate = xy / xd;
    x = y / std::sqrt(norm);
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
    if (agg[static_cast<std::size_t>(i)] >= 0) {
      continue;
    }
    bool free = true;
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         free && e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      if (strong(i, e) &&
          agg[static_cast<std::size_t>(a.index[static_cast<std::size_t>(e)])] >= 0) {
        free = false;
      }
    }
    if (!free) {
      continue;
    }
    agg[static_cast<std::size_t>(i)] = count;
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      if (strong(i, e)) {
        agg[static_cast<std::size_t>(a.index[static_cast<std::size_t>(e)])] = count;
      }
    }
    ++count;
  }
  // (2) Left-over nodes join the aggregate (from step 1) of their strongest strong neighbour.
  const std::vector<int> first = agg;
  for (int i = 0; i < a.rows; ++i) {
    if (first[static_cast<std::size_t>(i)] >= 0) {
      continue;
    }
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
    if (agg[static_cast<std::size_t>(i)] >= 0) {
      continue;
    }
    agg[static_cast<std::size_t>(i)] = count;
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      const auto j = static_cast<std::size_t>(a.index[static_cast<std::size_t>(e)]);
      if (strong(i, e) && agg[j] < 0) {
        agg[j] = count;
      }
    }
    ++count;
  }
  return agg;
}

// P = (I - omega D^-1 A) P_tent, P_tent(i, agg(i)) = 1.
Csr smoothed_prolongation(const Csr& a, const Eigen::VectorXd& inv_diag,
                          const std::vector<int>& agg, int coarse, double omega) {
  return build_rows(a.rows, coarse,
                    [&](int i, std::vector<int>& index, std::vector<double>& value) {
                      // A handful of aggregates per row: a small sorted list, merged by insertion.
                      const std::size_t first = index.size();
                      const auto add = [&](int j, double v) {
                        std::size_t k = first;
                        while (k < index.size() && index[k] < j) {
                          ++k;
                        }
                        if (k < index.size() && index[k] == j) {
                          value[k] += v;
                          return;
                        }
                        index.insert(index.begin() + static_cast<std::ptrdiff_t>(k), j);
                        value.insert(value.begin() + static_cast<std::ptrdiff_t>(k), v);
                      };
                      add(agg[static_cast<std::size_t>(i)], 1.0);
                      const double scale = -omega * inv_diag[i];
                      for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
                           e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
                        add(agg[static_cast<std::size_t>(a.index[static_cast<std::size_t>(e)])],
                            scale * a.value[static_cast<std::size_t>(e)]);
                      }
                    });
}

Eigen::SparseMatrix<double> to_eigen(const Csr& a) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(a.nonzeros());
  for (int i = 0; i < a.rows; ++i) {
    for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
         e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
      triplets.emplace_back(i, a.index[static_cast<std::size_t>(e)],
                            a.value[static_cast<std::size_t>(e)]);
    }
  }
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
  // Buffers of one application, rows x 3 each: allocated once (fresh pages cost a fault each; at a
  // million unknowns that was most of a V-cycle's time).
  struct Work {
    std::vector<double> b, x, r, d, t;
  };
  MultigridOptions options;
  std::vector<Level> levels;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> coarsest;
  std::mutex mutex;  // guards `work`; a concurrent apply() allocates its own
  std::vector<Work> work;

  std::vector<Work> make_work() const {
    std::vector<Work> w(levels.size());
    for (std::size_t l = 0; l < levels.size(); ++l) {
      const auto size = 3 * static_cast<std::size_t>(levels[l].a.rows);
      for (auto* v : {&w[l].b, &w[l].x, &w[l].r, &w[l].d, &w[l].t}) {
        // Level 0's b and x are the caller's, except for the second and later cycles (apply).
        if (l > 0 || options.cycles > 1 || (v != &w[l].b && v != &w[l].x)) {
          assign_huge(*v, size, 0.0);
        }
      }
    }
    return w;
  }

  // Chebyshev smoothing of A x = b on level l (see the file comment of multigrid.h), in place;
  // `zero`: x is 0 on entry (saves the first product). r is the residual b - A x throughout; the
  // update of r, d and x is one pass over the rows.
  void smooth(std::size_t l, const double* b, double* x, Work& w, bool zero) const {
    const Level& level = levels[l];
    const double hi = level.lambda;  // spectral_radius: an upper estimate
    const double lo = hi / options.smoothing_range;
    const double theta = 0.5 * (hi + lo), delta = 0.5 * (hi - lo);
    const double sigma = theta / delta;
    double rho = 1.0 / sigma;
    const double* inv = level.inv_diag.data();
    double* r = w.r.data();
    double* d = w.d.data();
    if (zero) {
      for_rows(level.a.rows, [&](int i) {
        for (int c = 0; c < 3; ++c) {
          const std::size_t k = 3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(c);
          r[k] = b[k];
          d[k] = inv[i] * b[k] / theta;
          x[k] = d[k];
        }
      });
    } else {
      residual(level.a, x, b, r);
      for_rows(level.a.rows, [&](int i) {
        for (int c = 0; c < 3; ++c) {
          const std::size_t k = 3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(c);
          d[k] = inv[i] * r[k] / theta;
          x[k] += d[k];
        }
      });
    }
    double* t = w.t.data();
    for (int step = 1; step < options.smoothing_degree; ++step) {
      sparse_times<3>(level.a, d, t);
      const double rho_next = 1.0 / (2.0 * sigma - rho);
      const double keep = rho_next * rho, gain = 2.0 * rho_next / delta;
      for_rows(level.a.rows, [&](int i) {
        for (int c = 0; c < 3; ++c) {
          const std::size_t k = 3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(c);
          r[k] -= t[k];
          d[k] = keep * d[k] + gain * inv[i] * r[k];
          x[k] += d[k];
        }
      });
      rho = rho_next;
    }
  }

  // out = b - A x.
  static void residual(const Csr& a, const double* x, const double* b, double* out) {
    for_rows(a.rows, [&](int i) {
      const std::ptrdiff_t row = 3 * static_cast<std::ptrdiff_t>(i);
      double sum[3] = {b[row], b[row + 1], b[row + 2]};
      for (std::int64_t e = a.start[static_cast<std::size_t>(i)];
           e < a.start[static_cast<std::size_t>(i) + 1]; ++e) {
        const double v = a.value[static_cast<std::size_t>(e)];
        const double* xj =
            x + 3 * static_cast<std::ptrdiff_t>(a.index[static_cast<std::size_t>(e)]);
        for (int c = 0; c < 3; ++c) {
          sum[c] -= v * xj[c];
        }
      }
      for (int c = 0; c < 3; ++c) {
        out[row + c] = sum[c];
      }
    });
  }

  // x += P y.
  static void add_product(const Csr& p, const double* y, double* x) {
    for_rows(p.rows, [&](int i) {
      const std::ptrdiff_t row = 3 * static_cast<std::ptrdiff_t>(i);
      double sum[3] = {0.0, 0.0, 0.0};
      for (std::int64_t e = p.start[static_cast<std::size_t>(i)];
           e < p.start[static_cast<std::size_t>(i) + 1]; ++e) {
        const double v = p.value[static_cast<std::size_t>(e)];
        const double* yj =
            y + 3 * static_cast<std::ptrdiff_t>(p.index[static_cast<std::size_t>(e)]);
        for (int c = 0; c < 3; ++c) {
          sum[c] += v * yj[c];
        }
      }
      for (int c = 0; c < 3; ++c) {
        x[row + c] += sum[c];
      }
    });
  }

  // x = V-cycle(b) on level l.
  void cycle(std::size_t l, const double* b, double* x, std::vector<Work>& w) const {
    const Level& level = levels[l];
    const auto n = static_cast<Eigen::Index>(level.a.rows);
    if (l + 1 == levels.size()) {
      const Eigen::MatrixXd rhs = Eigen::Map<const Block>(b, n, 3);
      Eigen::Map<Block>(x, n, 3) = coarsest.solve(rhs);
      return;
    }
    smooth(l, b, x, w[l], true);
    residual(level.a, x, b, w[l].r.data());
    sparse_times<3>(level.r, w[l].r.data(), w[l + 1].b.data());
    cycle(l + 1, w[l + 1].b.data(), w[l + 1].x.data(), w);
    add_product(level.p, w[l + 1].x.data(), x);
    smooth(l, b, x, w[l], false);
  }

  // `cycles` V-cycles from x = 0 (the stationary iteration x += B (b - A x)).
  void apply(const double* b, double* x, std::vector<Work>& w) const {
    cycle(0, b, x, w);
    if (options.cycles == 1) {
      return;
    }
    // The level-0 buffers b and x are free at this depth: the residual and the correction.
    double* r = w[0].b.data();
    double* y = w[0].x.data();
    for (int c = 1; c < options.cycles; ++c) {
      residual(levels[0].a, x, b, r);
      cycle(0, r, y, w);
      for_rows(levels[0].a.rows, [&](int i) {
        const std::ptrdiff_t row = 3 * static_cast<std::ptrdiff_t>(i);
        for (int k = 0; k < 3; ++k) {
          x[row + k] += y[row + k];
        }
      });
    }
  }
};

Multigrid::Multigrid(const Eigen::SparseMatrix<double>& matrix, bool lower_only,
                     const MultigridOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (matrix.rows() != matrix.cols()) {
    throw InvalidInputError(kName, "the matrix is not square (" + std::to_string(matrix.rows()) +
                                       " x " + std::to_string(matrix.cols()) + ")");
  }
  if (!(options.strength_threshold >= 0.0 && options.strength_threshold < 1.0) ||
      options.coarsest_size < 1 || options.max_levels < 1 || options.smoothing_degree < 1 ||
      !(options.smoothing_range > 1.0) || options.cycles < 1) {
    throw InvalidInputError(kName, "options out of range");
  }
  impl_->options = options;
  Csr a = from_eigen(matrix, lower_only);
  for (;;) {
    Impl::Level level;
    const Eigen::VectorXd diag = diagonal(a);
    for (Eigen::Index i = 0; i < diag.size(); ++i) {
      if (!(diag[i] > 0.0)) {
        throw InvalidInputError(kName, "diagonal entry " + std::to_string(i) + " of level " +
                                           std::to_string(impl_->levels.size()) +
                                           " is not positive");
      }
    }
    level.inv_diag = diag.cwiseInverse();
    const bool last = a.rows <= options.coarsest_size ||
                      static_cast<int>(impl_->levels.size()) + 1 >= options.max_levels;
    if (!last) {
      level.lambda = spectral_radius(a, level.inv_diag);
    }
    int coarse = 0;
    std::vector<int> agg;
    if (!last) {
      agg = aggregate(a, diag, options.strength_threshold, coarse);
    }
    // Stop when aggregation no longer coarsens (e.g. a diagonal matrix: every node alone).
    if (last || coarse >= a.rows || coarse == 0) {
      impl_->coarsest.compute(to_eigen(a));
      bool positive = impl_->coarsest.info() == Eigen::Success;
      const Eigen::VectorXd& pivots = impl_->coarsest.vectorD();
      for (Eigen::Index k = 0; positive && k < pivots.size(); ++k) {
        positive = pivots[k] > 0.0;
      }
      if (!positive) {
        throw NumericalError(kName, "the coarsest level (" + std::to_string(a.rows) +
                                        " unknowns) is not positive definite");
      }
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
  Block x;
  apply(b, x);
  return x;
}

void Multigrid::apply(const Block& b, Block& x) const {
  if (b.rows() != size()) {
    throw InvalidInputError(kName, "right-hand side has " + std::to_string(b.rows()) +
                                       " rows, expected " + std::to_string(size()));
  }
  if (x.rows() != b.rows()) {
    resize_huge(x, b.rows(), 3);
  }
  std::unique_lock<std::mutex> lock(impl_->mutex, std::try_to_lock);
  if (lock.owns_lock()) {
    if (impl_->work.empty()) {
      impl_->work = impl_->make_work();
    }
    impl_->apply(b.data(), x.data(), impl_->work);
  } else {
    std::vector<Impl::Work> own = impl_->make_work();
    impl_->apply(b.data(), x.data(), own);
  }
}

Eigen::VectorXd Multigrid::apply(const Eigen::VectorXd& b) const {
  Block block = Block::Zero(b.size(), 3);
  block.col(0) = b;
  return apply(block).col(0);
}

Multigrid::Block Multigrid::multiply(const Block& x) const {
  if (x.rows() != size()) {
    throw InvalidInputError(kName, "vector has " + std::to_string(x.rows()) + " rows, expected " +
                                       std::to_string(size()));
  }
  Block y(x.rows(), 3);
  sparse_times<3>(impl_->levels.front().a, x.data(), y.data());
  return y;
}

Eigen::Index Multigrid::size() const {
  return impl_->levels.front().a.rows;
}

std::vector<Eigen::Index> Multigrid::level_sizes() const {
  std::vector<Eigen::Index> sizes;
  for (const auto& level : impl_->levels) {
    sizes.push_back(level.a.rows);
  }
  return sizes;
}

double Multigrid::operator_complexity() const {
  double total = 0.0;
  for (const auto& level : impl_->levels) {
    total += static_cast<double>(level.a.nonzeros());
  }
  return total / static_cast<double>(std::max<std::size_t>(impl_->levels.front().a.nonzeros(), 1));
}

}  // namespace elastic
