#include "elastic/mesh/mesh_validation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <span>
#include <sstream>
#include <unordered_map>

#include "elastic/core/error.h"

namespace elastic {

namespace {

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

void note(IndexFindings& findings, int index, int max_examples) {
  if (findings.count++ < max_examples) {
    findings.examples.push_back(index);
  }
}

void note(EdgeFindings& findings, int a, int b, int max_examples) {
  if (findings.count++ < max_examples) {
    findings.examples.emplace_back(std::min(a, b), std::max(a, b));
  }
}

bool face_is_wellformed(const PolygonMesh& mesh, int f) {
  if (mesh.face_size(f) < 3) {
    return false;
  }
  for (int v : mesh.face(f)) {
    if (v < 0 || v >= mesh.num_vertices()) {
      return false;
    }
  }
  return true;
}

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

std::string finding_text(const IndexFindings& f, const char* what) {
  return std::to_string(f.count) + " " + what + ", e.g." + index_list(f.examples);
}

std::string finding_text(const EdgeFindings& f, const char* what) {
  return std::to_string(f.count) + " " + what + ", e.g." + edge_list(f.examples);
}

}  // namespace

bool MeshValidation::is_oriented_manifold() const {
  return malformed_faces.count == 0 && repeated_index_faces.count == 0 &&
         non_manifold_edges.count == 0 && inconsistent_edges.count == 0 &&
         non_manifold_vertices.count == 0;
}

bool MeshValidation::is_clean() const {
  return is_oriented_manifold() && num_components <= 1 && zero_area_faces.count == 0 &&
         unreferenced_vertices.count == 0 && non_finite_vertices.count == 0;
}

std::vector<std::string> MeshValidation::describe() const {
  std::vector<std::string> lines;
  if (malformed_faces.count) {
    lines.push_back(
        finding_text(malformed_faces, "malformed faces (< 3 corners or index out of range)"));
  }
  if (non_finite_vertices.count) {
    lines.push_back(finding_text(non_finite_vertices, "vertices with NaN/infinite coordinates"));
  }
  if (non_manifold_edges.count) {
    lines.push_back(finding_text(non_manifold_edges, "non-manifold edges (used by > 2 faces)"));
  }
  if (non_manifold_vertices.count) {
    lines.push_back(finding_text(non_manifold_vertices,
                                 "non-manifold vertices (faces around them form no single fan)"));
  }
  if (inconsistent_edges.count) {
    lines.push_back(finding_text(
        inconsistent_edges, orientable ? "edges whose two faces disagree in orientation"
                                       : "edges whose two faces disagree in orientation (the mesh "
                                         "is not orientable)"));
  }
  if (repeated_index_faces.count) {
    lines.push_back(finding_text(repeated_index_faces, "faces with a repeated vertex index"));
  }
  if (zero_area_faces.count) {
    lines.push_back(finding_text(zero_area_faces, "zero-area faces"));
  }
  if (num_components > 1) {
    std::ostringstream s;
    s << num_components << " connected components (faces per component:";
    for (size_t i = 0; i < component_faces.size() && i < 10; ++i) {
      s << ' ' << component_faces[i];
    }
    s << (component_faces.size() > 10 ? " ...)" : ")");
    lines.push_back(s.str());
  }
  if (unreferenced_vertices.count) {
    lines.push_back(finding_text(unreferenced_vertices, "unreferenced vertices"));
  }
  return lines;
}

namespace {

// Non-manifold and inconsistent edges, boundary edges, and boundary loops (the connected pieces of
// the graph of boundary edges).
void note_edge_findings(const EdgeTable& table, int nv, int max_examples, MeshValidation& result) {
  DisjointSets boundary(nv);
  for (size_t e = 0; e < table.edges.size(); ++e) {
    const auto uses = table.uses(e);
    const auto [a, b] = table.edges[e];
    if (uses.size() == 1) {
      ++result.num_boundary_edges;
      boundary.unite(a, b);
    } else if (uses.size() > 2) {
      note(result.non_manifold_edges, a, b, max_examples);
    } else if (uses[0].forward == uses[1].forward) {
      note(result.inconsistent_edges, a, b, max_examples);
    }
  }
  {
    std::vector<char> root_seen(static_cast<size_t>(nv), 0);
    for (size_t e = 0; e < table.edges.size(); ++e) {
      if (table.uses(e).size() != 1) {
        continue;
      }
      const int r = boundary.find(table.edges[e].first);
      if (!root_seen[static_cast<size_t>(r)]) {
        root_seen[static_cast<size_t>(r)] = 1;
        ++result.num_boundary_loops;
      }
    }
  }
}

void count_components(const PolygonMesh& mesh, const std::vector<char>& face_ok,
                      MeshValidation& result) {
  // Components: faces joined through shared vertices, i.e. union the corners of every face.
  {
    std::unordered_map<int, int> faces_per_root;
    for (int root : face_components(mesh, face_ok)) {
      if (root >= 0) {
        ++faces_per_root[root];
      }
    }
    result.num_components = static_cast<int>(faces_per_root.size());
    for (const auto& [root, count] : faces_per_root) {
      result.component_faces.push_back(count);
    }
    std::sort(result.component_faces.begin(), result.component_faces.end(), std::greater<>());
  }
}

void note_non_manifold_vertices(const PolygonMesh& mesh, const std::vector<char>& face_ok,
                                const EdgeTable& table, int max_examples, MeshValidation& result) {
  const int nv = mesh.num_vertices();
  const int nf = mesh.num_faces();
  // Non-manifold vertices: around each vertex, join the faces that share an edge at the vertex and
  // count the groups. Each edge (v, w) joins all faces using it in the per-vertex sets of v and of
  // w; a vertex-local union-find over "face slots" (vertex, incident face) does this in one pass.
  {
    // Incident faces of every vertex, each face listed once per vertex (CSR): one pass counts,
    // the second fills.
    std::vector<int> last_face(static_cast<size_t>(nv), -1);
    auto for_each_incidence = [&](auto&& visit) {
      std::fill(last_face.begin(), last_face.end(), -1);
      for (int f = 0; f < nf; ++f) {
        if (!face_ok[static_cast<size_t>(f)]) {
          continue;
        }
        for (int v : mesh.face(f)) {
          if (last_face[static_cast<size_t>(v)] != f) {
            last_face[static_cast<size_t>(v)] = f;
            visit(v, f);
          }
        }
      }
    };
    std::vector<int> start(static_cast<size_t>(nv) + 1, 0);
    for_each_incidence([&](int v, int) { ++start[static_cast<size_t>(v) + 1]; });
    for (int v = 0; v < nv; ++v) {
      start[static_cast<size_t>(v) + 1] += start[static_cast<size_t>(v)];
    }
    std::vector<int> incident(static_cast<size_t>(start.back()));
    std::vector<int> fill(start.begin(), start.end() - 1);
    for_each_incidence(
        [&](int v, int f) { incident[static_cast<size_t>(fill[static_cast<size_t>(v)]++)] = f; });
    // Slot of face f at vertex v: its position in v's (ascending) incident list.
    auto slot = [&](int v, int f) {
      const auto begin = incident.begin() + start[static_cast<size_t>(v)];
      const auto end = incident.begin() + start[static_cast<size_t>(v) + 1];
      return static_cast<int>(std::lower_bound(begin, end, f) - incident.begin());
    };
    DisjointSets fans(static_cast<int>(incident.size()));
    for (size_t e = 0; e < table.edges.size(); ++e) {
      const auto uses = table.uses(e);
      for (size_t i = 1; i < uses.size(); ++i) {
        for (int v : {table.edges[e].first, table.edges[e].second}) {
          fans.unite(slot(v, uses[0].face), slot(v, uses[i].face));
        }
      }
    }
    for (int v = 0; v < nv; ++v) {
      const int b = start[static_cast<size_t>(v)];
      const int e = start[static_cast<size_t>(v) + 1];
      for (int s = b + 1; s < e; ++s) {
        if (fans.find(s) != fans.find(b)) {
          note(result.non_manifold_vertices, v, max_examples);
          break;
        }
      }
    }
  }
}

}  // namespace

MeshValidation validate_mesh(const PolygonMesh& mesh, const ValidationOptions& options) {
  const int max_examples = std::max(0, options.max_examples);
  MeshValidation result;
  const int nv = mesh.num_vertices();
  const int nf = mesh.num_faces();
  result.num_vertices = nv;
  result.num_faces = nf;

  for (int v = 0; v < nv; ++v) {
    if (!mesh.positions[static_cast<size_t>(v)].allFinite()) {
      note(result.non_finite_vertices, v, max_examples);
    }
  }

  std::vector<char> face_ok(static_cast<size_t>(nf), 1);
  std::vector<char> referenced(static_cast<size_t>(nv), 0);
  std::vector<int> sorted;
  for (int f = 0; f < nf; ++f) {
    if (!face_is_wellformed(mesh, f)) {
      face_ok[static_cast<size_t>(f)] = 0;
      note(result.malformed_faces, f, max_examples);
      continue;
    }
    const auto face = mesh.face(f);
    for (int v : face) {
      referenced[static_cast<size_t>(v)] = 1;
    }
    sorted.assign(face.begin(), face.end());
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
      note(result.repeated_index_faces, f, max_examples);
      continue;  // its area is not looked at: the two findings are disjoint
    }
    bool finite = true;
    for (int v : face) {
      finite = finite && mesh.positions[static_cast<size_t>(v)].allFinite();
    }
    if (finite && is_zero_area(mesh, f, options.zero_area_relative_tolerance)) {
      note(result.zero_area_faces, f, max_examples);
    }
  }
  int num_referenced = 0;
  for (int v = 0; v < nv; ++v) {
    if (referenced[static_cast<size_t>(v)]) {
      ++num_referenced;
    } else {
      note(result.unreferenced_vertices, v, max_examples);
    }
  }

  const EdgeTable table = build_edges(mesh, face_ok);
  result.num_edges = static_cast<int>(table.edges.size());
  note_edge_findings(table, nv, max_examples, result);
  count_components(mesh, face_ok, result);
  note_non_manifold_vertices(mesh, face_ok, table, max_examples, result);

  if (result.non_manifold_edges.count == 0) {
    std::vector<char> flip;
    result.orientable = solve_orientation(mesh, face_ok, table, flip);
  }
  result.euler_characteristic =
      num_referenced - result.num_edges + (nf - result.malformed_faces.count);
  if (result.is_oriented_manifold()) {
    const int twice_genus =
        2 * result.num_components - result.num_boundary_loops - result.euler_characteristic;
    result.genus = twice_genus >= 0 && twice_genus % 2 == 0 ? twice_genus / 2 : -1;
  }
  return result;
}

namespace {

/// Keeps the faces with keep[f] != 0, with their corner attributes and materials, in order.
void keep_faces(PolygonMesh& mesh, const std::vector<char>& keep) {
  const bool uv = mesh.has_texcoords();
  const bool nrm = mesh.has_normals();
  const bool mat = !mesh.face_materials.empty();
  const bool col = mesh.has_face_colors();
  std::vector<Eigen::Vector3f> colors;
  std::vector<int> offsets{0};
  std::vector<int> vertices;
  std::vector<int> uvs;
  std::vector<int> normals;
  std::vector<int> materials;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    if (!keep[static_cast<size_t>(f)]) {
      continue;
    }
    const auto b = static_cast<size_t>(mesh.face_offsets[static_cast<size_t>(f)]);
    const auto e = static_cast<size_t>(mesh.face_offsets[static_cast<size_t>(f) + 1]);
    for (size_t c = b; c < e; ++c) {
      vertices.push_back(mesh.face_vertices[c]);
      if (uv) {
        uvs.push_back(mesh.corner_texcoords[c]);
      }
      if (nrm) {
        normals.push_back(mesh.corner_normals[c]);
      }
    }
    offsets.push_back(static_cast<int>(vertices.size()));
    if (mat) {
      materials.push_back(mesh.face_materials[static_cast<size_t>(f)]);
    }
    if (col) {
      colors.push_back(mesh.face_colors[static_cast<size_t>(f)]);
    }
  }
  if (offsets.size() == 1) {
    offsets.clear();
  }
  mesh.face_offsets = std::move(offsets);
  mesh.face_vertices = std::move(vertices);
  mesh.corner_texcoords = std::move(uvs);
  mesh.corner_normals = std::move(normals);
  mesh.face_materials = std::move(materials);
  mesh.face_colors = std::move(colors);
}

/// Reverses face f's orientation, keeping its first corner first (so that a quad's ptex
/// parameterisation keeps its origin): corners 0 1 2 3 become 0 3 2 1.
void flip_face(PolygonMesh& mesh, int f) {
  const auto b = static_cast<size_t>(mesh.face_offsets[static_cast<size_t>(f)]) + 1;
  const auto e = static_cast<size_t>(mesh.face_offsets[static_cast<size_t>(f) + 1]);
  auto reverse = [&](std::vector<int>& corners) {
    if (!corners.empty()) {
      std::reverse(corners.begin() + static_cast<std::ptrdiff_t>(b),
                   corners.begin() + static_cast<std::ptrdiff_t>(e));
    }
  };
  reverse(mesh.face_vertices);
  reverse(mesh.corner_texcoords);
  reverse(mesh.corner_normals);
}

/// Removes the vertices no face uses; returns how many. Creases and corners on removed vertices go
/// too.
int remove_unreferenced(PolygonMesh& mesh) {
  const int nv = mesh.num_vertices();
  std::vector<int> remap(static_cast<size_t>(nv), -1);
  for (int v : mesh.face_vertices) {
    remap[static_cast<size_t>(v)] = 0;
  }
  int next = 0;
  for (int v = 0; v < nv; ++v) {
    if (remap[static_cast<size_t>(v)] == 0) {
      remap[static_cast<size_t>(v)] = next;
      mesh.positions[static_cast<size_t>(next)] = mesh.positions[static_cast<size_t>(v)];
      if (mesh.has_vertex_colors()) {
        mesh.vertex_colors[static_cast<size_t>(next)] = mesh.vertex_colors[static_cast<size_t>(v)];
      }
      ++next;
    }
  }
  if (next == nv) {
    return 0;
  }
  mesh.positions.resize(static_cast<size_t>(next));
  if (mesh.has_vertex_colors()) {
    mesh.vertex_colors.resize(static_cast<size_t>(next));
  }
  for (int& v : mesh.face_vertices) {
    v = remap[static_cast<size_t>(v)];
  }
  auto gone = [&](int v) { return v < 0 || v >= nv || remap[static_cast<size_t>(v)] < 0; };
  std::erase_if(mesh.creases, [&](const Crease& c) { return gone(c.v0) || gone(c.v1); });
  for (Crease& c : mesh.creases) {
    c.v0 = remap[static_cast<size_t>(c.v0)];
    c.v1 = remap[static_cast<size_t>(c.v1)];
  }
  std::erase_if(mesh.corners, [&](const std::pair<int, double>& c) { return gone(c.first); });
  for (auto& c : mesh.corners) {
    c.first = remap[static_cast<size_t>(c.first)];
  }
  return nv - next;
}

bool has_repeated_index(const PolygonMesh& mesh, int f, std::vector<int>& scratch) {
  const auto face = mesh.face(f);
  scratch.assign(face.begin(), face.end());
  std::sort(scratch.begin(), scratch.end());
  return std::adjacent_find(scratch.begin(), scratch.end()) != scratch.end();
}

}  // namespace

namespace {

/// Keeps the component with the most faces (ties: the one with the lowest face index).
void keep_largest_component(PolygonMesh& mesh, RepairResult& result) {
  const std::vector<int> component = face_components(mesh, {});
  std::unordered_map<int, int> count;
  std::unordered_map<int, int> first_face;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int r = component[static_cast<size_t>(f)];
    ++count[r];
    first_face.try_emplace(r, f);
  }
  int best = -1;
  for (const auto& [root, n] : count) {
    if (best < 0 || n > count[best] || (n == count[best] && first_face[root] < first_face[best])) {
      best = root;
    }
  }
  if (count.size() > 1) {
    std::vector<char> keep(static_cast<size_t>(mesh.num_faces()));
    for (int f = 0; f < mesh.num_faces(); ++f) {
      keep[static_cast<size_t>(f)] = component[static_cast<size_t>(f)] == best ? 1 : 0;
    }
    result.removed_components = static_cast<int>(count.size()) - 1;
    result.removed_component_faces = mesh.num_faces() - count[best];
    keep_faces(mesh, keep);
    result.actions.push_back("kept the largest of " + std::to_string(count.size()) +
                             " components, removing " +
                             std::to_string(result.removed_component_faces) + " faces");
  }
}

}  // namespace

RepairResult repair_mesh(PolygonMesh& mesh, const RepairOptions& options) {
  RepairResult result;
  const MeshValidation before = validate_mesh(mesh, options.validation);
  if (before.malformed_faces.count > 0) {
    throw InvalidInputError(options.name,
                            finding_text(before.malformed_faces,
                                         "malformed faces (< 3 corners or index out of "
                                         "range); cannot repair"));
  }
  const int nf0 = mesh.num_faces();

  if (options.remove_degenerate_faces &&
      (before.repeated_index_faces.count > 0 || before.zero_area_faces.count > 0)) {
    std::vector<char> keep(static_cast<size_t>(nf0), 1);
    std::vector<int> scratch;
    for (int f = 0; f < nf0; ++f) {
      if (has_repeated_index(mesh, f, scratch)) {
        keep[static_cast<size_t>(f)] = 0;
        ++result.removed_repeated_index_faces;
      } else if (is_zero_area(mesh, f, options.validation.zero_area_relative_tolerance)) {
        keep[static_cast<size_t>(f)] = 0;
        ++result.removed_zero_area_faces;
      }
    }
    keep_faces(mesh, keep);
    if (result.removed_repeated_index_faces) {
      result.actions.push_back("removed " + std::to_string(result.removed_repeated_index_faces) +
                               " faces with a repeated vertex index");
    }
    if (result.removed_zero_area_faces) {
      result.actions.push_back("removed " + std::to_string(result.removed_zero_area_faces) +
                               " zero-area faces");
    }
  }

  if (options.keep_largest_component && mesh.num_faces() > 0) {
    keep_largest_component(mesh, result);
  }

  if (options.fix_winding) {
    const std::vector<char> all(static_cast<size_t>(mesh.num_faces()), 1);
    const EdgeTable table = build_edges(mesh, all);
    bool inconsistent = false;
    for (size_t e = 0; e < table.edges.size(); ++e) {
      const auto uses = table.uses(e);
      if (uses.size() == 2 && uses[0].forward == uses[1].forward) {
        inconsistent = true;
      }
      // An edge used by more faces is consistent only if its uses alternate; leave that to
      // validation.
    }
    if (inconsistent) {
      std::vector<char> flip;
      if (solve_orientation(mesh, all, table, flip)) {
        for (int f = 0; f < mesh.num_faces(); ++f) {
          if (flip[static_cast<size_t>(f)]) {
            flip_face(mesh, f);
            ++result.flipped_faces;
          }
        }
        result.actions.push_back("flipped " + std::to_string(result.flipped_faces) +
                                 " faces to make the winding consistent");
      } else {
        result.winding_unfixable = true;
      }
    }
  }

  if (options.remove_unreferenced_vertices) {
    result.removed_vertices = remove_unreferenced(mesh);
    if (result.removed_vertices) {
      result.actions.push_back("removed " + std::to_string(result.removed_vertices) +
                               " unreferenced vertices");
    }
  }
  result.after = validate_mesh(mesh, options.validation);
  return result;
}

namespace {

// The first malformed face with its defect, e.g. "face 3 refers to vertex 42, which does not
// exist".
std::string malformed_example(const PolygonMesh& mesh, const IndexFindings& malformed) {
  if (malformed.examples.empty()) {
    return "";
  }
  const int f = malformed.examples.front();
  if (mesh.face_size(f) < 3) {
    return "; face " + std::to_string(f) + " has fewer than 3 corners";
  }
  for (int v : mesh.face(f)) {
    if (v < 0 || v >= mesh.num_vertices()) {
      return "; face " + std::to_string(f) + " refers to vertex " + std::to_string(v) +
             ", which does not exist";
    }
  }
  return "";
}

}  // namespace

std::string manifold_problem(const PolygonMesh& mesh, const MeshValidation& v,
                             const ManifoldRequirements& requirements) {
  if (!requirements.allow_no_faces && mesh.num_faces() == 0) {
    return "the mesh is empty (no faces)";
  }
  if (v.malformed_faces.count) {
    return finding_text(v.malformed_faces,
                        "malformed faces (< 3 corners or vertex index out of range)") +
           malformed_example(mesh, v.malformed_faces);
  }
  if (v.non_finite_vertices.count) {
    return finding_text(v.non_finite_vertices,
                        "vertices with a non-finite (NaN or infinite) coordinate");
  }
  if (v.non_manifold_edges.count) {
    return finding_text(v.non_manifold_edges, "non-manifold edges (used by more than two faces)");
  }
  if (v.non_manifold_vertices.count) {
    return finding_text(v.non_manifold_vertices,
                        "non-manifold vertices (the faces around them form no single fan)");
  }
  if (v.repeated_index_faces.count) {
    return finding_text(v.repeated_index_faces, "faces with a repeated vertex index") +
           " (repair_mesh removes them)";
  }
  if (v.inconsistent_edges.count) {
    return finding_text(v.inconsistent_edges, "edges whose two faces disagree in orientation") +
           (v.orientable ? " (repair_mesh flips faces to fix this)"
                         : "; the mesh is not orientable");
  }
  if (!requirements.allow_zero_area_faces && v.zero_area_faces.count) {
    return finding_text(v.zero_area_faces, "zero-area faces") + " (repair_mesh removes them)";
  }
  if (!requirements.allow_several_components && v.num_components > 1) {
    return std::to_string(v.num_components) +
           " connected components where one is required (repair_mesh can keep the largest)";
  }
  if (!requirements.allow_boundary && v.num_boundary_edges > 0) {
    return std::to_string(v.num_boundary_loops) + " boundary loops (" +
           std::to_string(v.num_boundary_edges) +
           " boundary edges) where a closed mesh is required";
  }
  if (!requirements.allow_unreferenced_vertices && v.unreferenced_vertices.count) {
    return finding_text(v.unreferenced_vertices, "unreferenced vertices") +
           " (repair_mesh removes them)";
  }
  return "";
}

void require_valid_manifold(const PolygonMesh& mesh, const std::string& name,
                            const ManifoldRequirements& requirements) {
  const std::string problem =
      manifold_problem(mesh, validate_mesh(mesh, requirements.validation), requirements);
  if (!problem.empty()) {
    throw InvalidInputError(name, problem);
  }
}

SanitizeResult sanitize_mesh(PolygonMesh& mesh, const std::string& name,
                             const RepairOptions& repair,
                             const ManifoldRequirements& requirements) {
  RepairOptions options = repair;
  options.name = name;
  SanitizeResult result;
  result.repair = repair_mesh(mesh, options);
  for (const std::string& action : result.repair.actions) {
    result.warnings.push_back(name + ": " + action);
  }
  require_valid_manifold(mesh, name, requirements);
  return result;
}

}  // namespace elastic
