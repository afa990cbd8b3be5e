#include "elastic/mesh/mesh_validation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <span>
#include <sstream>
#include <unordered_map>

#include "elastic/core/error.h"
#include "elastic/mesh/detail/mesh_topology.h"

namespace elastic {

namespace {
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
    lines.push_back(detail::finding_text(malformed_faces,
                                         "malformed faces (< 3 corners or index out of range)"));
  }
  if (non_finite_vertices.count) {
    lines.push_back(
        detail::finding_text(non_finite_vertices, "vertices with NaN/infinite coordinates"));
  }
  if (non_manifold_edges.count) {
    lines.push_back(
        detail::finding_text(non_manifold_edges, "non-manifold edges (used by > 2 faces)"));
  }
  if (non_manifold_vertices.count) {
    lines.push_back(detail::finding_text(
        non_manifold_vertices, "non-manifold vertices (faces around them form no single fan)"));
  }
  if (inconsistent_edges.count) {
    lines.push_back(detail::finding_text(
        inconsistent_edges, orientable ? "edges whose two faces disagree in orientation"
                                       : "edges whose two faces disagree in orientation (the mesh "
                                         "is not orientable)"));
  }
  if (repeated_index_faces.count) {
    lines.push_back(
        detail::finding_text(repeated_index_faces, "faces with a repeated vertex index"));
  }
  if (zero_area_faces.count) {
    lines.push_back(detail::finding_text(zero_area_faces, "zero-area faces"));
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
    lines.push_back(detail::finding_text(unreferenced_vertices, "unreferenced vertices"));
  }
  return lines;
}

namespace {

// Non-manifold and inconsistent edges, boundary edges, and boundary loops (the connected pieces of
// the graph of boundary edges).
void note_edge_findings(const detail::EdgeTable& table, int nv, int max_examples,
                        MeshValidation& result) {
  detail::DisjointSets boundary(nv);
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
    for (int root : detail::face_components(mesh, face_ok)) {
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
                                const detail::EdgeTable& table, int max_examples,
                                MeshValidation& result) {
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
    detail::DisjointSets fans(static_cast<int>(incident.size()));
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
    if (finite && detail::is_zero_area(mesh, f, options.zero_area_relative_tolerance)) {
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

  const detail::EdgeTable table = detail::build_edges(mesh, face_ok);
  result.num_edges = static_cast<int>(table.edges.size());
  note_edge_findings(table, nv, max_examples, result);
  count_components(mesh, face_ok, result);
  note_non_manifold_vertices(mesh, face_ok, table, max_examples, result);

  if (result.non_manifold_edges.count == 0) {
    std::vector<char> flip;
    result.orientable = detail::solve_orientation(mesh, face_ok, table, flip);
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
    return detail::finding_text(v.malformed_faces,
                                "malformed faces (< 3 corners or vertex index out of range)") +
           malformed_example(mesh, v.malformed_faces);
  }
  if (v.non_finite_vertices.count) {
    return detail::finding_text(v.non_finite_vertices,
                                "vertices with a non-finite (NaN or infinite) coordinate");
  }
  if (v.non_manifold_edges.count) {
    return detail::finding_text(v.non_manifold_edges,
                                "non-manifold edges (used by more than two faces)");
  }
  if (v.non_manifold_vertices.count) {
    return detail::finding_text(v.non_manifold_vertices,
                                "non-manifold vertices (the faces around them form no single fan)");
  }
  if (v.repeated_index_faces.count) {
    return detail::finding_text(v.repeated_index_faces, "faces with a repeated vertex index") +
           " (repair_mesh removes them)";
  }
  if (v.inconsistent_edges.count) {
    return detail::finding_text(v.inconsistent_edges,
                                "edges whose two faces disagree in orientation") +
           (v.orientable ? " (repair_mesh flips faces to fix this)"
                         : "; the mesh is not orientable");
  }
  if (!requirements.allow_zero_area_faces && v.zero_area_faces.count) {
    return detail::finding_text(v.zero_area_faces, "zero-area faces") +
           " (repair_mesh removes them)";
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
    return detail::finding_text(v.unreferenced_vertices, "unreferenced vertices") +
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
