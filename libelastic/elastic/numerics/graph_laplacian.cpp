#include "elastic/numerics/graph_laplacian.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <string>
#include <utility>

#include "elastic/core/error.h"

namespace elastic {

Eigen::SparseMatrix<double> graph_laplacian(const GraphAdjacency& graph,
                                            const std::vector<int>& free_index,
                                            const std::function<double(int, int)>& weight) {
  const int nodes = graph.nodes();
  if (static_cast<int>(free_index.size()) != nodes) {
    throw InvalidInputError(
        "graph_laplacian", "free_index has " + std::to_string(free_index.size()) + " entries for " +
                               std::to_string(nodes) + " nodes");
  }
  std::vector<int> node_of_row;
  for (int v = 0; v < nodes; ++v) {
    if (free_index[v] >= 0) {
      if (free_index[v] != static_cast<int>(node_of_row.size())) {
        throw InvalidInputError("graph_laplacian", "free rows are not numbered in node order");
      }
      node_of_row.push_back(v);
    }
  }
  const int n = static_cast<int>(node_of_row.size());
  // Column c (= row c, the matrix is symmetric) holds the diagonal and one entry per free
  // neighbour.
  std::vector<int> outer(static_cast<size_t>(n) + 1, 0);
  for (int c = 0; c < n; ++c) {
    const int v = node_of_row[c];
    int count = 1;
    for (int k = graph.start[v]; k < graph.start[v + 1]; ++k) {
      count += free_index[graph.items[k]] >= 0 ? 1 : 0;
    }
    outer[c + 1] = outer[c] + count;
  }
  Eigen::SparseMatrix<double> matrix(n, n);
  matrix.resizeNonZeros(outer[n]);
  std::copy(outer.begin(), outer.end(), matrix.outerIndexPtr());
  int* inner = matrix.innerIndexPtr();
  double* values = matrix.valuePtr();
  tbb::parallel_for(0, n, [&](int c) {
    const int v = node_of_row[c];
    std::vector<std::pair<int, double>> column;
    double diagonal = 0.0;
    for (int k = graph.start[v]; k < graph.start[v + 1]; ++k) {
      const int w = graph.items[k];
      const double c_vw = weight(v, w);
      diagonal += c_vw;
      if (free_index[w] >= 0) {
        column.emplace_back(free_index[w], -c_vw);
      }
    }
    column.emplace_back(c, diagonal);
    std::sort(column.begin(), column.end());
    int at = outer[c];
    for (const auto& [row, value] : column) {
      inner[at] = row;
      values[at] = value;
      ++at;
    }
  });
  return matrix;
}

Eigen::SparseMatrix<double> symmetrised_laplacian(const Eigen::SparseMatrix<double>& a) {
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(a.cols());
  const Eigen::VectorXd row_sums = a * ones;
  Eigen::SparseMatrix<double> p = 0.5 * (a + Eigen::SparseMatrix<double>(a.transpose()));
  const Eigen::VectorXd p_sums = p * ones;
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    p.coeffRef(i, i) += row_sums[i] - p_sums[i];
  }
  return p;
}

}  // namespace elastic
