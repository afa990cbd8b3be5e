#pragma once
/// \file
/// Assembly of a weighted graph Laplacian restricted to the free nodes of a graph (the others are
/// Dirichlet nodes: their rows and columns are dropped, their edges stay on the diagonal):
///
///     L_ii = sum_{j ~ i} c_ij,   L_ij = -c_ij   (i, j free),
///
/// both triangles stored, columns sorted. Symmetric when c is (c_ij = c_ji), positive definite when
/// every connected part of the free nodes has an edge to a Dirichlet node and the weights are
/// positive. Built column by column in parallel, without triplets.

#include <Eigen/SparseCore>
#include <functional>
#include <vector>

namespace elastic {

/// A graph in compressed rows: the neighbours of node v are items[start[v] .. start[v + 1]).
struct GraphAdjacency {
  std::vector<int> start{0};
  std::vector<int> items;
  int nodes() const { return static_cast<int>(start.size()) - 1; }
};

/// `free_index[v]`: the row of node v, or -1 for a Dirichlet node (rows 0 .. n-1 each used once);
/// `weight(v, w)`: c_vw of an edge (called for both directions, must be symmetric).
/// \throws InvalidInputError when free_index does not match the graph.
Eigen::SparseMatrix<double> graph_laplacian(const GraphAdjacency& graph,
                                            const std::vector<int>& free_index,
                                            const std::function<double(int, int)>& weight);

/// The symmetric counterpart of a nonsymmetric Laplacian-like M-matrix A (positive diagonal,
/// off-diagonals <= 0, rows summing to >= 0, e.g. mean-value weights with Dirichlet boundary
/// rows): off-diagonal (a_ij + a_ji) / 2, diagonal chosen so that every row sums to A's row sum.
/// It is then a weakly diagonally dominant symmetric M-matrix, positive definite when A's rows
/// reach a positive row sum through the graph, and a preconditioner for A (e.g. one multigrid
/// V-cycle of it for BiCGSTAB) that differs from A only by the weights' asymmetry. The plain
/// symmetric part (A + A^T) / 2 would not do: its rows sum to sum_j (a_ji - a_ij) / 2 more than
/// A's, which can make them negative and the matrix indefinite.
Eigen::SparseMatrix<double> symmetrised_laplacian(const Eigen::SparseMatrix<double>& a);

}  // namespace elastic
