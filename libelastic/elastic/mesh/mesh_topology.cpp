// Mesh topology shared by validation and repair (detail/mesh_topology.h): components, the edge
// table, zero-area faces, the orientation solve, the wording of findings.
#include "elastic/mesh/detail/mesh_topology.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace elastic::detail {
namespace {

std::string edge_list(const std::vector<std::pair<int, int>>& edges) {
  std::ostringstream s;
  for (const auto& [a, b] : edges) {
    s << " (" << a << ", " << b << ")";
  }
  return s.str();
}

std::string index_list(const std::vector<int>& indices) {
  std::ostringstream s;
  for (int i : indices) {
    s << ' ' << i;
  }
  return s.str();
}

}  // namespace

/// Components, the one definition: faces joined through shared vertices (the union of every
/// face's corners). Per face the union-find root of its component, -1 for the faces `face_ok`
/// leaves out (empty: none).
std::vector<int> face_components(const PolygonMesh& mesh, const std::vector<char>& face_ok) {
  const int nf = mesh.num_faces();
  auto counted = [&](int f) { return face_ok.empty() || face_ok[static_cast<size_t>(f)]; };
  DisjointSets sets(mesh.num_vertices());
  for (int f = 0; f < nf; ++f) {
    if (counted(f)) {
      const auto face = mesh.face(f);
      for (size_t k = 1; k < face.size(); ++k) {
        sets.unite(face[0], face[k]);
      }
    }
  }
  std::vector<int> root(static_cast<size_t>(nf), -1);
  for (int f = 0; f < nf; ++f) {
    if (counted(f)) {
      root[static_cast<size_t>(f)] = sets.find(mesh.face(f)[0]);
    }
  }
  return root;
}

EdgeTable build_edges(const PolygonMesh& mesh, const std::vector<char>& face_ok) {
  struct Side {
    int lo, hi, face;
    bool forward;
  };
  std::vector<Side> sides;
  sides.reserve(mesh.face_vertices.size());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    if (!face_ok[static_cast<size_t>(f)]) {
      continue;
    }
    const auto face = mesh.face(f);
    for (size_t k = 0; k < face.size(); ++k) {
      const int a = face[k];
      const int b = face[(k + 1) % face.size()];
      if (a == b) {
        continue;
      }
      sides.push_back({std::min(a, b), std::max(a, b), f, a < b});
    }
  }
  std::sort(sides.begin(), sides.end(), [](const Side& x, const Side& y) {
    return x.lo != y.lo ? x.lo < y.lo : (x.hi != y.hi ? x.hi < y.hi : x.face < y.face);
  });
  EdgeTable table;
  table.all_uses.reserve(sides.size());
  for (size_t i = 0; i < sides.size(); ++i) {
    if (i == 0 || sides[i].lo != sides[i - 1].lo || sides[i].hi != sides[i - 1].hi) {
      table.edges.emplace_back(sides[i].lo, sides[i].hi);
      table.start.push_back(static_cast<int>(i));
    }
    table.all_uses.push_back({sides[i].face, sides[i].forward});
  }
  table.start.push_back(static_cast<int>(sides.size()));
  return table;
}

/// |vector area| of a polygon (Newell's formula: half the sum of cross products of consecutive
/// corners, exact for planar polygons and the area of the projection along the mean normal
/// otherwise), compared with the sum of squared edge lengths so that the test does not depend on
/// the mesh's scale.
bool is_zero_area(const PolygonMesh& mesh, int f, double relative_tolerance) {
  const auto face = mesh.face(f);
  Eigen::Vector3d twice_area = Eigen::Vector3d::Zero();
  double edge_sq = 0.0;
  const Eigen::Vector3d& origin = mesh.positions[static_cast<size_t>(face[0])];
  for (size_t k = 0; k < face.size(); ++k) {
    const Eigen::Vector3d a = mesh.positions[static_cast<size_t>(face[k])] - origin;
    const Eigen::Vector3d b =
        mesh.positions[static_cast<size_t>(face[(k + 1) % face.size()])] - origin;
    twice_area += a.cross(b);
    edge_sq += (b - a).squaredNorm();
  }
  return 0.5 * twice_area.norm() <= relative_tolerance * edge_sq;
}

/// Orientation flips per face that make every two-face edge consistent, per component of the graph
/// of faces joined through edges used by exactly two faces. flip[f] is 1 when face f must be
/// reversed. Returns false when some component cannot be oriented. In each component the smaller of
/// the two colour classes is the one flipped, so that the majority's orientation is kept.
bool solve_orientation(const PolygonMesh& mesh, const std::vector<char>& face_ok,
                       const EdgeTable& table, std::vector<char>& flip) {
  const int nf = mesh.num_faces();
  // Adjacency: (neighbour, must_differ). Two faces using the edge in the same direction must end up
  // with different flip states, in opposite directions with the same one.
  std::vector<std::vector<std::pair<int, bool>>> adjacency(static_cast<size_t>(nf));
  for (size_t e = 0; e < table.edges.size(); ++e) {
    const auto u = table.uses(e);
    if (u.size() != 2 || u[0].face == u[1].face) {
      continue;
    }
    const bool differ = u[0].forward == u[1].forward;
    adjacency[static_cast<size_t>(u[0].face)].emplace_back(u[1].face, differ);
    adjacency[static_cast<size_t>(u[1].face)].emplace_back(u[0].face, differ);
  }
  flip.assign(static_cast<size_t>(nf), 0);
  std::vector<char> seen(static_cast<size_t>(nf), 0);
  bool orientable = true;
  std::vector<int> stack;
  std::vector<int> members;
  for (int start = 0; start < nf; ++start) {
    if (seen[static_cast<size_t>(start)] || !face_ok[static_cast<size_t>(start)]) {
      continue;
    }
    members.clear();
    stack.assign(1, start);
    seen[static_cast<size_t>(start)] = 1;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      members.push_back(f);
      for (const auto& [g, differ] : adjacency[static_cast<size_t>(f)]) {
        const char want = static_cast<char>(flip[static_cast<size_t>(f)] ^ (differ ? 1 : 0));
        if (!seen[static_cast<size_t>(g)]) {
          seen[static_cast<size_t>(g)] = 1;
          flip[static_cast<size_t>(g)] = want;
          stack.push_back(g);
        } else if (flip[static_cast<size_t>(g)] != want) {
          orientable = false;
        }
      }
    }
    const auto flipped = std::count_if(members.begin(), members.end(),
                                       [&](int f) { return flip[static_cast<size_t>(f)] != 0; });
    if (2 * static_cast<size_t>(flipped) > members.size()) {
      for (int f : members) {
        flip[static_cast<size_t>(f)] ^= 1;
      }
    }
  }
  return orientable;
}

std::string finding_text(const IndexFindings& f, const char* what) {
  return std::to_string(f.count) + " " + what + ", e.g." + index_list(f.examples);
}

std::string finding_text(const EdgeFindings& f, const char* what) {
  return std::to_string(f.count) + " " + what + ", e.g." + edge_list(f.examples);
}

}  // namespace elastic::detail
