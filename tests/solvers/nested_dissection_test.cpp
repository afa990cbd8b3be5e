// Geometric nested dissection (solvers/nested_dissection.h), the direct H0's order, on a grid,
// where the answer is known: a permutation whose last block is a separator, and O(n log n) fill
// against the band's n^1.5.
#include "elastic/solvers/nested_dissection.h"

#include <gtest/gtest.h>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <numeric>
#include <vector>

namespace elastic {
namespace {

using solver_detail::nested_dissection_order;

/// The 5-point Laplacian of a k x k grid plus the identity (lower triangle), node (i, j) = i k + j
/// at (j, i, 0), and the nodes' coordinates.
struct Grid {
  int k = 0;
  Eigen::SparseMatrix<double> lower;
  Eigen::Matrix3Xd xyz;
};

Grid make_grid(int k) {
  const Eigen::Index n = Eigen::Index{k} * k;
  Grid g{k, Eigen::SparseMatrix<double>(n, n), Eigen::Matrix3Xd(3, n)};
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      const int v = i * k + j;
      g.xyz.col(v) << j, i, 0.0;
      t.emplace_back(v, v, 5.0);
      if (j > 0) {
        t.emplace_back(v, v - 1, -1.0);
      }
      if (i > 0) {
        t.emplace_back(v, v - k, -1.0);
      }
    }
  }
  g.lower.setFromTriplets(t.begin(), t.end());
  return g;
}

/// Entries of L for the matrix factorised in the given order (order[p] = node at position p).
Eigen::Index fill_in_order(const Eigen::SparseMatrix<double>& lower,
                           const std::vector<int>& order) {
  Eigen::VectorXi position(static_cast<Eigen::Index>(order.size()));
  for (std::size_t p = 0; p < order.size(); ++p) {
    position[order[p]] = static_cast<int>(p);
  }
  const Eigen::PermutationMatrix<Eigen::Dynamic> perm(position);
  Eigen::SparseMatrix<double> permuted(lower.rows(), lower.cols());
  permuted.selfadjointView<Eigen::Lower>() = lower.selfadjointView<Eigen::Lower>().twistedBy(perm);
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower,
                              Eigen::NaturalOrdering<int>>
      ldlt(permuted);
  EXPECT_EQ(ldlt.info(), Eigen::Success);
  return ldlt.matrixL().nestedExpression().nonZeros();
}

TEST(NestedDissection, IsAPermutationEndingInASeparator) {
  const Grid g = make_grid(60);
  const std::vector<int> order = nested_dissection_order(g.lower, g.xyz);
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  std::vector<int> all(sorted.size());
  std::iota(all.begin(), all.end(), 0);
  ASSERT_EQ(sorted, all);
  EXPECT_EQ(nested_dissection_order(g.lower, g.xyz), order);  // deterministic

  // The first split is at the median of x: its separator, numbered last, is one grid column, and
  // removing it leaves two halves with no grid edge between them.
  const int n = g.k * g.k;
  std::vector<char> separator(static_cast<std::size_t>(n), 0);
  for (int p = n - g.k; p < n; ++p) {
    separator[static_cast<std::size_t>(order[static_cast<std::size_t>(p)])] = 1;
  }
  int column = -1;
  for (int v = 0; v < n; ++v) {
    if (separator[static_cast<std::size_t>(v)]) {
      column = column < 0 ? v % g.k : column;
      EXPECT_EQ(v % g.k, column) << "node " << v;
    }
  }
  EXPECT_GT(column, g.k / 4);
  EXPECT_LT(column, 3 * g.k / 4);
}

TEST(NestedDissection, FillsFarLessThanTheBandAndAboutAsMuchAsMinimumDegree) {
  const Grid g = make_grid(100);
  const int n = g.k * g.k;
  std::vector<int> natural(static_cast<std::size_t>(n));
  std::iota(natural.begin(), natural.end(), 0);
  const Eigen::Index band = fill_in_order(g.lower, natural);  // about k entries a row
  const Eigen::Index dissected = fill_in_order(g.lower, nested_dissection_order(g.lower, g.xyz));
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> amd(g.lower);
  const Eigen::Index minimum_degree = amd.matrixL().nestedExpression().nonZeros();
  EXPECT_GT(band, 90 * n);
  EXPECT_LT(dissected, band / 3);
  // On this regular grid AMD fills 252,000 entries and the dissection 306,000. (On irregular
  // tessellations of scans its separators are wide: ordering the LSCM flattening with it was tried
  // and lost to AMD there, docs/results/speed.md.)
  EXPECT_LT(dissected, minimum_degree * 3 / 2);
}

}  // namespace
}  // namespace elastic
