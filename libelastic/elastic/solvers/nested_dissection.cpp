#include "elastic/solvers/nested_dissection.h"

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <limits>
#include <utility>

namespace elastic::solver_detail {

namespace {

// Recursive geometric bisection (see nested_dissection_order). `nodes` is the subset to order;
// `side` and `stamp` are scratch arrays over all n particles; the ordered subset is appended to
// `order`.
struct Dissection {
  const std::vector<int>& start;  // symmetric adjacency, compressed rows
  const std::vector<int>& adjacent;
  const Eigen::Matrix3Xd& coordinates;
  std::vector<int>& side;   // 0: lower half, 1: upper half, valid where stamp == current
  std::vector<int>& stamp;  // which call last labelled the particle
  std::vector<int>& order;
  int calls = 0;

  static constexpr std::size_t kLeaf = 64;

  void run(std::vector<int> nodes) {
    if (nodes.size() <= kLeaf) {
      std::sort(nodes.begin(), nodes.end());
      order.insert(order.end(), nodes.begin(), nodes.end());
      return;
    }
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const int v : nodes) {
      lo = lo.cwiseMin(coordinates.col(v));
      hi = hi.cwiseMax(coordinates.col(v));
    }
    Eigen::Index axis = 0;
    (hi - lo).maxCoeff(&axis);
    // Median split along the axis; ties by index so that the result never depends on the sort.
    const auto half = nodes.begin() + static_cast<std::ptrdiff_t>(nodes.size() / 2);
    std::nth_element(nodes.begin(), half, nodes.end(), [&](int a, int b) {
      const double ca = coordinates(axis, a), cb = coordinates(axis, b);
      return ca < cb || (ca == cb && a < b);
    });
    const int call = ++calls;
    for (auto it = nodes.begin(); it != nodes.end(); ++it) {
      stamp[static_cast<std::size_t>(*it)] = call;
      side[static_cast<std::size_t>(*it)] = it < half ? 0 : 1;
    }
    // Separator: lower-half particles coupled to the upper half. Removing them disconnects the
    // halves, so their elimination creates no fill between the halves.
    std::vector<int> lower, upper, separator;
    for (auto it = nodes.begin(); it != nodes.end(); ++it) {
      const int v = *it;
      if (it >= half) {
        upper.push_back(v);
        continue;
      }
      bool on_cut = false;
      for (int k = start[static_cast<std::size_t>(v)];
           !on_cut && k < start[static_cast<std::size_t>(v) + 1]; ++k) {
        const auto w = static_cast<std::size_t>(adjacent[static_cast<std::size_t>(k)]);
        on_cut = stamp[w] == call && side[w] == 1;
      }
      (on_cut ? separator : lower).push_back(v);
    }
    nodes.clear();
    nodes.shrink_to_fit();
    std::sort(separator.begin(), separator.end());
    run(std::move(lower));
    run(std::move(upper));
    order.insert(order.end(), separator.begin(), separator.end());
  }
};

}  // namespace

std::vector<int> nested_dissection_order(const Eigen::SparseMatrix<double>& laplacian,
                                         const Eigen::Matrix3Xd& coordinates) {
  const auto n = static_cast<std::size_t>(laplacian.rows());
  // Symmetric adjacency from the stored lower triangle.
  std::vector<int> start(n + 1, 0);
  for (Eigen::Index col = 0; col < laplacian.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, col); it; ++it) {
      if (it.row() != col) {
        ++start[static_cast<std::size_t>(it.row()) + 1];
        ++start[static_cast<std::size_t>(col) + 1];
      }
    }
  }
  for (std::size_t v = 0; v < n; ++v) {
    start[v + 1] += start[v];
  }
  std::vector<int> adjacent(static_cast<std::size_t>(start[n]));
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (Eigen::Index col = 0; col < laplacian.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, col); it; ++it) {
      if (it.row() != col) {
        const auto r = static_cast<std::size_t>(it.row()), c = static_cast<std::size_t>(col);
        adjacent[static_cast<std::size_t>(fill[r]++)] = static_cast<int>(c);
        adjacent[static_cast<std::size_t>(fill[c]++)] = static_cast<int>(r);
      }
    }
  }
  std::vector<int> side(n, 0), stamp(n, 0), order;
  order.reserve(n);
  std::vector<int> all(n);
  for (std::size_t v = 0; v < n; ++v) {
    all[v] = static_cast<int>(v);
  }
  Dissection{start, adjacent, coordinates, side, stamp, order}.run(std::move(all));
  return order;
}

}  // namespace elastic::solver_detail
