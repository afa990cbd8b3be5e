// The numerical kernels below sampling and solvers: graph Laplacian assembly, conjugate gradients,
// BiCGSTAB, deterministic vector reductions.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/numerics/bicgstab.h"
#include "elastic/numerics/conjugate_gradient.h"
#include "elastic/numerics/graph_laplacian.h"
#include "elastic/numerics/multigrid.h"
#include "elastic/numerics/vector_kernels.h"

namespace elastic {
namespace {

/// The 4-neighbour graph of an n x n grid, node (i, j) = i * n + j.
GraphAdjacency grid_graph(int n) {
  GraphAdjacency g;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (i > 0) g.items.push_back((i - 1) * n + j);
      if (j > 0) g.items.push_back(i * n + j - 1);
      if (j + 1 < n) g.items.push_back(i * n + j + 1);
      if (i + 1 < n) g.items.push_back((i + 1) * n + j);
      g.start.push_back(static_cast<int>(g.items.size()));
    }
  }
  return g;
}

/// Free rows for the interior nodes of the grid (the border is Dirichlet).
std::vector<int> interior_rows(int n) {
  std::vector<int> row(n * n, -1);
  int next = 0;
  for (int i = 1; i + 1 < n; ++i)
    for (int j = 1; j + 1 < n; ++j) row[i * n + j] = next++;
  return row;
}

TEST(GraphLaplacian, PathWithDirichletEndsIsTheTridiagonalMatrix) {
  // Path 0 - 1 - 2 - 3, ends fixed, weights c(v, w) = v + w: rows for nodes 1 and 2 only.
  GraphAdjacency g;
  g.items = {1, 0, 2, 1, 3, 2};
  g.start = {0, 1, 3, 5, 6};
  const Eigen::SparseMatrix<double> l =
      graph_laplacian(g, {-1, 0, 1, -1}, [](int v, int w) { return double(v + w); });
  Eigen::Matrix2d expected;
  expected << 1.0 + 3.0, -3.0, -3.0, 3.0 + 5.0;
  EXPECT_EQ((Eigen::MatrixXd(l) - expected).cwiseAbs().maxCoeff(), 0.0);
}

TEST(GraphLaplacian, BadRowNumberingIsAnError) {
  GraphAdjacency g;
  g.items = {1, 0};
  g.start = {0, 1, 2};
  EXPECT_THROW(graph_laplacian(g, {1, 0}, [](int, int) { return 1.0; }), InvalidInputError);
  EXPECT_THROW(graph_laplacian(g, {0}, [](int, int) { return 1.0; }), InvalidInputError);
}

TEST(ConjugateGradient, MultigridPreconditionedSolveMatchesTheFactorisation) {
  const int n = 60;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> weight(0.5, 4.0);
  std::vector<double> w(n * n);
  for (double& x : w) x = weight(rng);
  const Eigen::SparseMatrix<double> l =
      graph_laplacian(grid_graph(n), interior_rows(n), [&](int a, int b) { return w[a] * w[b]; });
  Eigen::VectorXd b = Eigen::VectorXd::Random(l.rows());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor(l);
  const Eigen::VectorXd exact = factor.solve(b);

  const Multigrid multigrid(l);
  const LinearOperator apply = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) { out = l * v; };
  const LinearOperator precondition = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
    out = multigrid.apply(v);
  };
  Eigen::VectorXd x;
  const ConjugateGradientResult r =
      conjugate_gradient(apply, precondition, b, x, {.max_iterations = 100, .tolerance = 1e-10});
  EXPECT_TRUE(r.converged);
  EXPECT_LT(r.iterations, 40);  // a V-cycle per iteration: far fewer than the ~3,000 unknowns
  EXPECT_LT((x - exact).norm(), 1e-7 * exact.norm());

  // Without a preconditioner (identity) the same answer, in more iterations.
  const LinearOperator identity = [](const Eigen::VectorXd& v, Eigen::VectorXd& out) { out = v; };
  Eigen::VectorXd y;
  const ConjugateGradientResult plain =
      conjugate_gradient(apply, identity, b, y, {.max_iterations = 2000, .tolerance = 1e-10});
  EXPECT_TRUE(plain.converged);
  EXPECT_GT(plain.iterations, 3 * r.iterations);
  EXPECT_LT((y - exact).norm(), 1e-7 * exact.norm());
}

TEST(ConjugateGradient, ZeroRightHandSideIsSolvedAtOnce) {
  const LinearOperator identity = [](const Eigen::VectorXd& v, Eigen::VectorXd& out) { out = v; };
  Eigen::VectorXd x;
  const ConjugateGradientResult r =
      conjugate_gradient(identity, identity, Eigen::VectorXd::Zero(5), x);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_EQ(x.norm(), 0.0);
}

/// A nonsymmetric M-matrix on the interior of an n x n grid: -Laplacian + upwinded convection
/// c . grad (first-order upwind differences, so every off-diagonal is <= 0 and the rows are
/// weakly diagonally dominant), the border Dirichlet. `c` in grid cells per unit step.
Eigen::SparseMatrix<double> convection_diffusion(int n, double cx, double cy) {
  const std::vector<int> row = interior_rows(n);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 1; i + 1 < n; ++i) {
    for (int j = 1; j + 1 < n; ++j) {
      const int r = row[i * n + j];
      // Neighbour weights: diffusion 1, plus the upwind side's convection.
      const std::array<std::pair<int, double>, 4> nb{{{(i - 1) * n + j, 1.0 + std::max(cy, 0.0)},
                                                      {(i + 1) * n + j, 1.0 + std::max(-cy, 0.0)},
                                                      {i * n + j - 1, 1.0 + std::max(cx, 0.0)},
                                                      {i * n + j + 1, 1.0 + std::max(-cx, 0.0)}}};
      for (const auto& [node, w] : nb) {
        t.emplace_back(r, r, w);
        if (row[node] >= 0) {
          t.emplace_back(r, row[node], -w);
        }
      }
    }
  }
  const int m = (n - 2) * (n - 2);
  Eigen::SparseMatrix<double> a(m, m);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

TEST(Bicgstab, NonsymmetricSolveMatchesTheSparseLu) {
  const Eigen::SparseMatrix<double> a = convection_diffusion(50, 0.4, -0.25);
  ASSERT_GT((Eigen::MatrixXd(a) - Eigen::MatrixXd(a.transpose())).cwiseAbs().maxCoeff(), 0.3);
  Eigen::VectorXd b = Eigen::VectorXd::Random(a.rows());
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(a);
  const Eigen::VectorXd exact = lu.solve(b);

  // Preconditioned by AMG on the symmetrised operator (as the mean-value disk map does).
  const Multigrid multigrid(symmetrised_laplacian(a));
  const LinearOperator apply = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) { out = a * v; };
  const LinearOperator precondition = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
    out = multigrid.apply(v);
  };
  Eigen::VectorXd x;
  const BicgstabResult r = bicgstab(apply, precondition, b, x, {.tolerance = 1e-12});
  EXPECT_TRUE(r.converged);
  EXPECT_LT(r.iterations, 40);
  EXPECT_LE(r.relative_residual, 1e-12);
  EXPECT_LE((b - a * x).norm(), 1e-12 * b.norm());  // the reported residual is the true one
  EXPECT_LT((x - exact).norm(), 1e-9 * exact.norm());

  // Unpreconditioned: the same answer in more iterations.
  const LinearOperator identity = [](const Eigen::VectorXd& v, Eigen::VectorXd& out) { out = v; };
  Eigen::VectorXd y;
  const BicgstabResult plain = bicgstab(apply, identity, b, y, {.max_iterations = 2000});
  EXPECT_TRUE(plain.converged);
  EXPECT_GT(plain.iterations, 3 * r.iterations);
  EXPECT_LT((y - exact).norm(), 1e-9 * exact.norm());

  // Started at the answer it stops at once; a budget too small is reported, not hidden.
  Eigen::VectorXd z = x;
  EXPECT_EQ(bicgstab(apply, precondition, b, z).iterations, 0);
  Eigen::VectorXd w;
  const BicgstabResult short_run = bicgstab(apply, identity, b, w, {.max_iterations = 3});
  EXPECT_FALSE(short_run.converged);
  EXPECT_LE(short_run.iterations, 3);
  EXPECT_NEAR(short_run.relative_residual, (b - a * w).norm() / b.norm(), 1e-12);
}

// The symmetrised Laplacian of a small nonsymmetric M-matrix, written out by hand: off-diagonals
// the mean of a_ij and a_ji, each row summing to A's row sum.
TEST(SymmetrisedLaplacian, AveragesTheOffDiagonalsAndKeepsTheRowSums) {
  Eigen::MatrixXd a(3, 3);
  a << 5.0, -1.0, -3.0,  // row sum 1
      -2.0, 4.0, -2.0,   // row sum 0
      -1.0, -1.0, 3.0;   // row sum 1
  Eigen::MatrixXd expected(3, 3);
  expected << 0.0, -1.5, -2.0,  //
      -1.5, 0.0, -1.5,          //
      -2.0, -1.5, 0.0;
  expected(0, 0) = 1.0 + 3.5;
  expected(1, 1) = 0.0 + 3.0;
  expected(2, 2) = 1.0 + 3.5;
  const Eigen::MatrixXd p = Eigen::MatrixXd(symmetrised_laplacian(a.sparseView()));
  EXPECT_LT((p - expected).cwiseAbs().maxCoeff(), 1e-15);
  // (A + A^T) / 2 would have row 0 summing to 5 - 1.5 - 2 = 1.5 and row 1 to 4 - 1.5 - 1.5 = 1, row
  // 2 to 3 - 2 - 1.5 = -0.5 < 0: the fix matters.
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(p).eigenvalues().minCoeff(), 0.0);
}

TEST(Bicgstab, IteratesAreTheSameOnOneAndManyThreads) {
  const Eigen::SparseMatrix<double> a = convection_diffusion(200, 2.0, 0.5);
  const Eigen::VectorXd b = Eigen::VectorXd::Random(a.rows());
  const LinearOperator apply = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) { out = a * v; };
  const LinearOperator jacobi = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
    out = v.cwiseQuotient(Eigen::VectorXd(a.diagonal()));
  };
  Eigen::VectorXd one, many;
  tbb::task_arena(1).execute([&] { bicgstab(apply, jacobi, b, one, {.max_iterations = 50}); });
  tbb::task_arena(4).execute([&] { bicgstab(apply, jacobi, b, many, {.max_iterations = 50}); });
  EXPECT_EQ((one - many).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Bicgstab, ZeroRightHandSideIsSolvedAtOnce) {
  const LinearOperator identity = [](const Eigen::VectorXd& v, Eigen::VectorXd& out) { out = v; };
  Eigen::VectorXd x = Eigen::VectorXd::Ones(5);
  const BicgstabResult r = bicgstab(identity, identity, Eigen::VectorXd::Zero(5), x);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_EQ(x.norm(), 0.0);
}

TEST(VectorKernels, DotIsTheSameOnOneAndManyThreads) {
  // 300,001 entries of mixed magnitude: a different summation order would change the last bits.
  Eigen::VectorXd a(300001), b(300001);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Eigen::Index k = 0; k < a.size(); ++k) {
    a[k] = u(rng) * std::pow(10.0, 6.0 * u(rng));
    b[k] = u(rng);
  }
  double one = 0.0;
  tbb::task_arena(1).execute([&] { one = parallel_dot(a, b); });
  double many = 0.0;
  tbb::task_arena(4).execute([&] { many = parallel_dot(a, b); });
  EXPECT_EQ(one, many);
  // And it is the dot product (to round-off of a 3e5-term sum).
  EXPECT_NEAR(one, a.dot(b), 1e-9 * a.cwiseAbs().dot(b.cwiseAbs()));

  Eigen::VectorXd y = b;
  parallel_axpy(2.0, a, y);
  EXPECT_LE((y - (b + 2.0 * a)).cwiseAbs().maxCoeff(), 1e-9);
  Eigen::VectorXd z = b;
  parallel_xpby(a, 0.5, z);
  EXPECT_LE((z - (a + 0.5 * b)).cwiseAbs().maxCoeff(), 1e-9);
}

}  // namespace
}  // namespace elastic
