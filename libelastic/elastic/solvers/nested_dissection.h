#pragma once
/// \file
/// Geometric nested dissection: the fill-reducing ordering of the spring Laplacian's
/// factorisation (spring_laplacian.h). Internal to the solvers (solver_detail).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

namespace elastic::solver_detail {

/// A fill-reducing ordering of the interior particles by geometric nested dissection: the
/// particles (columns of `coordinates`, n = laplacian.rows()) are split at the median of the
/// longest axis of their bounding box; the particles of the lower half that have a neighbour in the
/// upper half (in the sparsity graph of `laplacian`, lower triangle stored) form the separator,
/// numbered last; both halves are ordered recursively, down to leaves of 64 particles kept in their
/// given order. On a grid of n particles this gives the O(n log n) fill and O(n^1.5) work of nested
/// dissection [George 1973], against the larger constants of minimum degree on 2D meshes.
/// Returns `order`: order[k] = the particle placed at position k. Deterministic (ties broken by
/// index).
std::vector<int> nested_dissection_order(const Eigen::SparseMatrix<double>& laplacian,
                                         const Eigen::Matrix3Xd& coordinates);

}  // namespace elastic::solver_detail
