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

}  // namespace elastic
