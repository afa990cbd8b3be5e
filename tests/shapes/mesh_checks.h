#pragma once
// Independent topology and geometry checks for the procedural-shape tests. Written here on purpose
// (not the library's validation module) so that the shapes are checked by code that did not build
// them.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <utility>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"

namespace elastic::test {

struct MeshReport {
  int vertices = 0;
  int edges = 0;
  int faces = 0;
  int unreferenced_vertices = 0;
  int faces_with_repeated_corner = 0;
  int non_manifold_edges = 0;     ///< used by more than two faces
  int inconsistent_edges = 0;     ///< used twice in the same direction
  int non_manifold_vertices = 0;  ///< faces around the vertex are not one fan
  int components = 0;             ///< connected through shared edges
  /// Boundary loops as vertex cycles, each following the boundary edges' direction.
  std::vector<std::vector<int>> boundary_loops;
  bool boundary_is_manifold = true;  ///< every boundary vertex starts exactly one boundary edge

  int euler_characteristic() const { return vertices - edges + faces; }
  bool is_clean() const {
    return unreferenced_vertices == 0 && faces_with_repeated_corner == 0 &&
           non_manifold_edges == 0 && inconsistent_edges == 0 && non_manifold_vertices == 0 &&
           boundary_is_manifold;
  }
};

inline int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

inline MeshReport analyse(const PolygonMesh& mesh) {
  MeshReport report;
  report.vertices = mesh.num_vertices();
  report.faces = mesh.num_faces();
  // Directed edge (u, v) -> faces using it in that direction.
  std::map<std::pair<int, int>, std::vector<int>> directed;
  std::vector<int> uses(static_cast<size_t>(mesh.num_vertices()), 0);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto face = mesh.face(f);
    std::vector<int> sorted(face.begin(), face.end());
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
      ++report.faces_with_repeated_corner;
    }
    for (size_t c = 0; c < face.size(); ++c) {
      ++uses[static_cast<size_t>(face[c])];
      directed[{face[c], face[(c + 1) % face.size()]}].push_back(f);
    }
  }
  report.unreferenced_vertices = static_cast<int>(std::count(uses.begin(), uses.end(), 0));

  std::vector<int> parent(static_cast<size_t>(mesh.num_faces()));
  std::iota(parent.begin(), parent.end(), 0);
  std::map<int, std::vector<int>> boundary_out;  // boundary vertex -> targets of its boundary edges
  for (const auto& [edge, faces] : directed) {
    const auto [u, v] = edge;
    if (faces.size() > 1) ++report.inconsistent_edges;
    const auto reverse = directed.find({v, u});
    const size_t total = faces.size() + (reverse == directed.end() ? 0 : reverse->second.size());
    if (u < v || reverse == directed.end()) ++report.edges;
    if (total > 2) ++report.non_manifold_edges;
    if (reverse == directed.end()) {
      boundary_out[u].push_back(v);
    } else {
      for (int g : reverse->second) parent[find_root(parent, faces[0])] = find_root(parent, g);
    }
    for (int g : faces) parent[find_root(parent, faces[0])] = find_root(parent, g);
  }
  for (int f = 0; f < mesh.num_faces(); ++f) {
    if (find_root(parent, f) == f) ++report.components;
  }

  // Vertex manifoldness: walk the fan of faces around each vertex through shared edges; it must
  // reach every face incident to the vertex.
  std::vector<std::vector<int>> vertex_faces(static_cast<size_t>(mesh.num_vertices()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int v : mesh.face(f)) vertex_faces[static_cast<size_t>(v)].push_back(f);
  }
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const std::vector<int>& around = vertex_faces[static_cast<size_t>(v)];
    if (around.empty()) continue;
    std::vector<int> local(around.size());
    std::iota(local.begin(), local.end(), 0);
    // Two faces around v are linked when they share an edge incident to v.
    std::map<int, std::vector<size_t>> by_neighbour;
    for (size_t i = 0; i < around.size(); ++i) {
      const auto face = mesh.face(around[i]);
      for (size_t c = 0; c < face.size(); ++c) {
        if (face[c] != v) continue;
        by_neighbour[face[(c + 1) % face.size()]].push_back(i);
        by_neighbour[face[(c + face.size() - 1) % face.size()]].push_back(i);
      }
    }
    for (const auto& [w, faces] : by_neighbour) {
      for (size_t i : faces) {
        local[static_cast<size_t>(find_root(local, static_cast<int>(i)))] =
            find_root(local, static_cast<int>(faces[0]));
      }
    }
    int roots = 0;
    for (size_t i = 0; i < local.size(); ++i)
      roots += find_root(local, static_cast<int>(i)) == static_cast<int>(i);
    if (roots != 1) ++report.non_manifold_vertices;
  }

  // Boundary loops.
  std::map<int, bool> visited;
  for (const auto& [u, targets] : boundary_out) {
    if (targets.size() != 1) report.boundary_is_manifold = false;
  }
  for (const auto& [start, targets] : boundary_out) {
    if (visited[start]) continue;
    std::vector<int> loop;
    int v = start;
    while (!visited[v]) {
      visited[v] = true;
      loop.push_back(v);
      const auto it = boundary_out.find(v);
      if (it == boundary_out.end()) {
        report.boundary_is_manifold = false;
        break;
      }
      v = it->second.front();
    }
    report.boundary_loops.push_back(loop);
  }
  return report;
}

/// Area vector of a polygon (half the sum of corner cross products; its direction is the normal by
/// the right-hand rule of the corner order, its length the area for a planar polygon).
inline Eigen::Vector3d area_vector(const PolygonMesh& mesh, int f) {
  const auto face = mesh.face(f);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t c = 0; c < face.size(); ++c) {
    sum += mesh.positions[static_cast<size_t>(face[c])].cross(
        mesh.positions[static_cast<size_t>(face[(c + 1) % face.size()])]);
  }
  return 0.5 * sum;
}

/// Signed volume enclosed by the mesh after closing every boundary loop with a fan to its centroid
/// (divergence theorem: sum over triangles of det(a, b, c) / 6). Positive for outward orientation.
inline double closed_up_volume(const PolygonMesh& mesh, const MeshReport& report) {
  auto tet = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    return a.dot(b.cross(c)) / 6.0;
  };
  double volume = 0.0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto face = mesh.face(f);
    const Eigen::Vector3d& a = mesh.positions[static_cast<size_t>(face[0])];
    for (size_t c = 1; c + 1 < face.size(); ++c) {
      volume += tet(a, mesh.positions[static_cast<size_t>(face[c])],
                    mesh.positions[static_cast<size_t>(face[c + 1])]);
    }
  }
  for (const std::vector<int>& loop : report.boundary_loops) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int v : loop) centre += mesh.positions[static_cast<size_t>(v)];
    centre /= static_cast<double>(loop.size());
    // Boundary edges run u -> v along the loop; the closing triangle uses them reversed.
    for (size_t i = 0; i < loop.size(); ++i) {
      const Eigen::Vector3d& u = mesh.positions[static_cast<size_t>(loop[i])];
      const Eigen::Vector3d& v = mesh.positions[static_cast<size_t>(loop[(i + 1) % loop.size()])];
      volume += tet(v, u, centre);
    }
  }
  return volume;
}

/// Smallest corner angle (radians) over all faces.
inline double min_corner_angle(const PolygonMesh& mesh) {
  double smallest = std::numbers::pi;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto face = mesh.face(f);
    const size_t n = face.size();
    for (size_t c = 0; c < n; ++c) {
      const Eigen::Vector3d& p = mesh.positions[static_cast<size_t>(face[c])];
      const Eigen::Vector3d a = mesh.positions[static_cast<size_t>(face[(c + 1) % n])] - p;
      const Eigen::Vector3d b = mesh.positions[static_cast<size_t>(face[(c + n - 1) % n])] - p;
      smallest = std::min(smallest, std::atan2(a.cross(b).norm(), a.dot(b)));
    }
  }
  return smallest;
}

/// Smallest distance between two distinct vertices (sweep over x-sorted vertices).
inline double min_vertex_distance(const PolygonMesh& mesh) {
  std::vector<int> order(static_cast<size_t>(mesh.num_vertices()));
  std::iota(order.begin(), order.end(), 0);
  auto pos = [&](int v) -> const Eigen::Vector3d& {
    return mesh.positions[static_cast<size_t>(v)];
  };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return pos(a).x() < pos(b).x(); });
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < order.size(); ++i) {
    for (size_t j = i + 1; j < order.size() && pos(order[j]).x() - pos(order[i]).x() < best; ++j) {
      best = std::min(best, (pos(order[j]) - pos(order[i])).norm());
    }
  }
  return best;
}

/// Vertex valences (number of distinct neighbours through face edges).
inline std::vector<int> valences(const PolygonMesh& mesh) {
  std::vector<std::vector<int>> neighbours(static_cast<size_t>(mesh.num_vertices()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto face = mesh.face(f);
    for (size_t c = 0; c < face.size(); ++c) {
      neighbours[static_cast<size_t>(face[c])].push_back(face[(c + 1) % face.size()]);
      neighbours[static_cast<size_t>(face[(c + 1) % face.size()])].push_back(face[c]);
    }
  }
  std::vector<int> result;
  for (std::vector<int>& n : neighbours) {
    std::sort(n.begin(), n.end());
    result.push_back(static_cast<int>(std::unique(n.begin(), n.end()) - n.begin()));
  }
  return result;
}

}  // namespace elastic::test
