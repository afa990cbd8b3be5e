#include "elastic/core/directed_edges.h"

namespace elastic {

DirectedEdges::DirectedEdges(const std::vector<Eigen::Vector3i>& triangles, int num_vertices,
                             const std::vector<int>* subset)
    : first_(static_cast<std::size_t>(num_vertices) + 1, 0) {
  const auto count = static_cast<int>(subset != nullptr ? subset->size() : triangles.size());
  const auto at = [&](int i) {
    return subset != nullptr ? (*subset)[static_cast<std::size_t>(i)] : i;
  };
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3i& tri = triangles[static_cast<std::size_t>(at(i))];
    for (int k = 0; k < 3; ++k) {
      ++first_[static_cast<std::size_t>(tri[k]) + 1];
    }
  }
  for (std::size_t v = 0; v + 1 < first_.size(); ++v) {
    first_[v + 1] += first_[v];
  }
  to_.resize(static_cast<std::size_t>(first_.back()));
  triangle_.resize(to_.size());
  std::vector<int> fill(first_.begin(), first_.end() - 1);
  for (int i = 0; i < count; ++i) {
    const int t = at(i);
    const Eigen::Vector3i& tri = triangles[static_cast<std::size_t>(t)];
    for (int k = 0; k < 3; ++k) {
      const auto e = static_cast<std::size_t>(fill[static_cast<std::size_t>(tri[k])]++);
      to_[e] = tri[(k + 1) % 3];
      triangle_[e] = t;
    }
  }
}

int DirectedEdges::find(int a, int b) const {
  for (int e = begin(a); e < end(a); ++e) {
    if (to(e) == b) {
      return e;
    }
  }
  return -1;
}

}  // namespace elastic
