#pragma once
/// \file
/// The directed edges of a triangle list, grouped by the vertex they leave: each triangle (i, j, k)
/// contributes i -> j, j -> k and k -> i, in the triangles' order. Built by a counting sort, O(#T),
/// so that "which triangle holds the edge a -> b" is a scan of a's few outgoing edges. A hash map
/// or sorted 64-bit keys of every edge, which this replaces, took 1.1 s for the two million
/// triangles of a million-particle grid (the queryable mapping's neighbours) and 26-31 ms for a
/// whole cap's region (its topology check).
///
/// Immutable after construction; its queries are thread-safe.

#include <Eigen/Core>
#include <vector>

namespace elastic {

class DirectedEdges {
 public:
  /// The edges of `triangles`, or only of the triangles listed in `subset` (in that order) when it
  /// is given. Vertex indices must lie in [0, num_vertices).
  DirectedEdges(const std::vector<Eigen::Vector3i>& triangles, int num_vertices,
                const std::vector<int>* subset = nullptr);

  int num_vertices() const { return static_cast<int>(first_.size()) - 1; }
  /// The edges leaving v are the indices [begin(v), end(v)), in triangle order.
  int begin(int v) const { return first_[static_cast<std::size_t>(v)]; }
  int end(int v) const { return first_[static_cast<std::size_t>(v) + 1]; }
  /// Edge e's end vertex and the triangle it belongs to.
  int to(int e) const { return to_[static_cast<std::size_t>(e)]; }
  int triangle(int e) const { return triangle_[static_cast<std::size_t>(e)]; }
  /// The first edge a -> b (the first triangle holding it, in the order given), or -1.
  int find(int a, int b) const;

 private:
  std::vector<int> first_;     // #V + 1 offsets
  std::vector<int> to_;        // per edge: end vertex
  std::vector<int> triangle_;  // per edge: triangle index (into `triangles`)
};

}  // namespace elastic
