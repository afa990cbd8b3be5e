#pragma once
/// \file
/// Mesh topology shared by validation (mesh_validation.cpp) and repair (mesh_repair.cpp), private
/// to mesh/ (not installed): the one union-find, mesh components, the edge table, zero-area faces,
/// the orientation solve, and the wording of findings. Defined in mesh_topology.cpp.

#include <numeric>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "elastic/mesh/mesh_validation.h"
#include "elastic/mesh/polygon_mesh.h"

namespace elastic::detail {

/// Union-find over 0..n-1 with path halving.
class DisjointSets {
 public:
  explicit DisjointSets(int n) : parent_(static_cast<size_t>(n)) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  int find(int x) {
    while (parent_[static_cast<size_t>(x)] != x) {
      auto& p = parent_[static_cast<size_t>(x)];
      p = parent_[static_cast<size_t>(p)];
      x = p;
    }
    return x;
  }
  void unite(int a, int b) { parent_[static_cast<size_t>(find(a))] = find(b); }

 private:
  std::vector<int> parent_;
};

/// Components, the one definition: faces joined through shared vertices (the union of every
/// face's corners). Per face the union-find root of its component, -1 for the faces `face_ok`
/// leaves out (empty: none).
std::vector<int> face_components(const PolygonMesh& mesh, const std::vector<char>& face_ok);

/// One use of an edge by a face: the face and whether it goes from the smaller to the larger
/// vertex.
struct EdgeUse {
  int face;
  bool forward;
};

/// All edges of the well-formed faces with the faces that use them, in compressed rows: edge e is
/// edges[e] = (min, max) and is used by uses(e). Edges are sorted by (min, max), so every report is
/// deterministic. Built by sorting one record per face side: cache-friendly, no per-edge
/// allocation.
struct EdgeTable {
  std::vector<std::pair<int, int>> edges;
  std::vector<int> start;  ///< edges.size() + 1 offsets into `all_uses`
  std::vector<EdgeUse> all_uses;
  std::span<const EdgeUse> uses(size_t e) const {
    return {all_uses.data() + start[e], static_cast<size_t>(start[e + 1] - start[e])};
  }
};

/// The edge table of the faces with face_ok[f] set.
EdgeTable build_edges(const PolygonMesh& mesh, const std::vector<char>& face_ok);

/// |vector area| of a polygon (Newell's formula: half the sum of cross products of consecutive
/// corners, exact for planar polygons and the area of the projection along the mean normal
/// otherwise), compared with the sum of squared edge lengths so that the test does not depend on
/// the mesh's scale.
bool is_zero_area(const PolygonMesh& mesh, int f, double relative_tolerance);

/// Orientation flips per face that make every two-face edge consistent, per component of the graph
/// of faces joined through edges used by exactly two faces. flip[f] is 1 when face f must be
/// reversed. Returns false when some component cannot be oriented. In each component the smaller of
/// the two colour classes is the one flipped, so that the majority's orientation is kept.
bool solve_orientation(const PolygonMesh& mesh, const std::vector<char>& face_ok,
                       const EdgeTable& table, std::vector<char>& flip);

/// "<count> <what>, e.g. <examples>", the wording of a finding in reports and errors.
std::string finding_text(const IndexFindings& f, const char* what);
std::string finding_text(const EdgeFindings& f, const char* what);

}  // namespace elastic::detail
