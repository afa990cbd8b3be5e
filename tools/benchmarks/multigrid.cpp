// Multigrid benchmarks (solvers/multigrid.h) on the spring Laplacian of an m x m quad grid with a
// fixed boundary (the matrix interior_laplacian builds for the fast solver's H0, C = C_a = 1):
// hierarchy set-up, and one application (a V-cycle on three right-hand sides, as L-BFGS uses it).
//
//   bench_multigrid --benchmark_filter=Apply/1000

#include "elastic/numerics/multigrid.h"

#include <benchmark/benchmark.h>

#include <Eigen/SparseCore>
#include <vector>

namespace {

using elastic::Multigrid;

// Per unit normal spring 2 on the diagonals and -2 between the ends; per face corner (i; a, b) the
// Gram matrix 2 v v^T of v = (1, -1/2, -1/2). Rows of the boundary ring are dropped.
Eigen::SparseMatrix<double> spring_grid_laplacian(int m) {
  const int side = m + 2;
  const auto index = [&](int x, int y) {
    return x > 0 && y > 0 && x <= m && y <= m ? (y - 1) * m + (x - 1) : -1;
  };
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<std::size_t>(m) * m * 40);
  const auto add = [&](int a, int b, double v) {
    if (a >= 0 && b >= 0) t.emplace_back(a, b, v);
  };
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x)
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        if (x + dx >= side || y + dy >= side) continue;
        const int a = index(x, y), b = index(x + dx, y + dy);
        add(a, a, 2.0);
        add(b, b, 2.0);
        add(a, b, -2.0);
        add(b, a, -2.0);
      }
  for (int y = 0; y + 1 < side; ++y)
    for (int x = 0; x + 1 < side; ++x) {
      const int c[4] = {index(x, y), index(x + 1, y), index(x + 1, y + 1), index(x, y + 1)};
      for (int k = 0; k < 4; ++k) {
        const int p[3] = {c[k], c[(k + 1) % 4], c[(k + 3) % 4]};
        const double v[3] = {1.0, -0.5, -0.5};
        for (int r = 0; r < 3; ++r)
          for (int s = 0; s < 3; ++s) add(p[r], p[s], 2.0 * v[r] * v[s]);
      }
    }
  Eigen::SparseMatrix<double> a(m * m, m * m);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

void BM_Setup(benchmark::State& state) {
  const Eigen::SparseMatrix<double> a = spring_grid_laplacian(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    const Multigrid mg(a);
    benchmark::DoNotOptimize(&mg);
  }
  const Multigrid mg(a);
  state.counters["unknowns"] = static_cast<double>(a.rows());
  state.counters["levels"] = static_cast<double>(mg.level_sizes().size());
  state.counters["complexity"] = mg.operator_complexity();
}
BENCHMARK(BM_Setup)
    ->Name("Setup")
    ->Arg(100)
    ->Arg(316)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Apply(benchmark::State& state) {
  const Eigen::SparseMatrix<double> a = spring_grid_laplacian(static_cast<int>(state.range(0)));
  const Multigrid mg(a);
  const Multigrid::Block b = Multigrid::Block::Random(a.rows(), 3);
  for (auto _ : state) {
    Multigrid::Block x = mg.apply(b);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["unknowns"] = static_cast<double>(a.rows());
}
BENCHMARK(BM_Apply)
    ->Name("Apply")
    ->Arg(100)
    ->Arg(316)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
