#pragma once
/// \file
/// Topological checks and safe repairs of a PolygonMesh, before it becomes a limit surface or an
/// OpenMesh.
///
/// Definitions (they match the independent checker that produced shared/meshes/README.md):
/// - An *edge* is an unordered vertex pair {a, b}, a != b, that appears as consecutive corners of a
///   face. A corner pair (a, a) of a face with a repeated index is no edge.
/// - A *non-manifold edge* is used by more than two faces.
/// - An *inconsistent edge* is used by exactly two faces that traverse it in the same direction:
///   the two faces disagree about the orientation. (Halfedge structures cannot hold it either, but
///   unlike a non-manifold edge it can be repaired by flipping faces.)
/// - A *non-manifold vertex*: the faces around it do not form one fan, i.e. they fall into more
///   than one group when faces sharing an edge at the vertex are joined (any shared edge joins,
///   also non-manifold ones, so a vertex on a non-manifold edge is not counted for that reason
///   alone). Two cones touching at their tips, or two boundary loops meeting at a vertex, make it
///   one.
/// - *Components* are the groups of faces connected through shared vertices.
/// - *Boundary edges* are used by exactly one face; *boundary loops* are the connected pieces of
///   the graph of boundary edges.
/// - Euler characteristic chi = V - E + F over referenced vertices; for an oriented manifold with
///   C components and b boundary loops the total genus is g = (2C - b - chi) / 2.
///
/// Policy (what a tool does with each finding; `sanitize_mesh()` implements it,
/// docs/file-formats.md repeats it). The wording of every error is `manifold_problem()`'s, which
/// `require_valid_manifold()`, `to_openmesh()` and `LimitSurface` share.
///
// clang-format off
/// | finding                                  | policy                                         |
/// |------------------------------------------|------------------------------------------------|
/// | unreferenced vertices                    | warning, removed                               |
/// | faces with a repeated vertex index       | warning, removed                               |
/// | zero-area faces                          | warning, removed                               |
/// | several components                       | error, unless `keep_largest_component` (warning) |
/// | inconsistent winding, orientable         | warning, faces flipped (the majority wins)     |
/// | inconsistent winding, not orientable     | error                                          |
/// | non-manifold edges / vertices            | error                                          |
/// | malformed faces (< 3 corners, bad index) | error (readers already reject them)            |
/// | NaN / infinite coordinates               | error (in the reader and here)                 |
// clang-format on

#include <string>
#include <utility>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"

namespace elastic {

struct ValidationOptions {
  /// How many offending indices each finding lists (its count is always complete).
  int max_examples = 10;
  /// A face is zero-area when |vector area| <= this * (sum of its squared edge lengths): a
  /// scale-free test, about 1e4 times double rounding, so that exactly collinear or coincident
  /// corners are caught while slivers that are merely thin are not.
  double zero_area_relative_tolerance = 1e-12;
};

/// A count and the first few offending vertex or face indices.
struct IndexFindings {
  int count = 0;
  std::vector<int> examples;
};

/// A count and the first few offending edges (vertex pairs, smaller index first).
struct EdgeFindings {
  int count = 0;
  std::vector<std::pair<int, int>> examples;
};

struct MeshValidation {
  int num_vertices = 0;
  int num_faces = 0;
  int num_edges = 0;  ///< distinct edges (see the file comment)

  IndexFindings malformed_faces;        ///< faces with < 3 corners or a vertex index out of range
  IndexFindings non_finite_vertices;    ///< vertices with a NaN or infinite coordinate
  IndexFindings repeated_index_faces;   ///< faces listing a vertex more than once
  IndexFindings zero_area_faces;        ///< other faces whose area is zero (see ValidationOptions)
  EdgeFindings non_manifold_edges;      ///< edges used by more than two faces
  EdgeFindings inconsistent_edges;      ///< edges used twice in the same direction
  IndexFindings non_manifold_vertices;  ///< vertices whose faces do not form one fan
  IndexFindings unreferenced_vertices;  ///< vertices used by no face

  int num_components = 0;            ///< face components connected through vertices
  std::vector<int> component_faces;  ///< number of faces of each component, largest first
  int num_boundary_edges = 0;
  int num_boundary_loops = 0;
  int euler_characteristic = 0;  ///< V - E + F over referenced vertices
  /// True when the faces can be oriented consistently (no Moebius strip), judged over the edges
  /// used by exactly two faces. Meaningless (false) when there are non-manifold edges.
  bool orientable = false;
  /// Total genus (2C - b - chi) / 2 when the mesh is an orientable manifold (no malformed,
  /// repeated-index or non-manifold findings); -1 otherwise.
  int genus = -1;

  /// No boundary edges.
  bool is_closed() const { return num_boundary_edges == 0; }
  /// Edge- and vertex-manifold, consistently oriented, no malformed or repeated-index faces.
  bool is_oriented_manifold() const;
  /// Nothing to report at all: an oriented manifold, one component, no zero-area faces, no
  /// unreferenced or non-finite vertices.
  bool is_clean() const;
  /// One line per finding ("47 non-manifold edges, e.g. (3, 17) (3, 18)"); empty when clean.
  std::vector<std::string> describe() const;
};

/// Checks a mesh. Never throws on bad topology: it reports it. Malformed faces are counted and left
/// out of every other finding.
MeshValidation validate_mesh(const PolygonMesh& mesh, const ValidationOptions& options = {});

struct RepairOptions {
  /// Name of the mesh in error messages (a file name, "source", "target").
  std::string name = "mesh";
  /// Remove vertices no face uses (renumbering the rest; creases and corners follow).
  bool remove_unreferenced_vertices = true;
  /// Remove faces that list a vertex twice, and zero-area faces.
  bool remove_degenerate_faces = true;
  /// Keep only the component with the most faces (ties: the one with the lowest face index).
  bool keep_largest_component = false;
  /// Flip faces so that every edge shared by two faces is traversed once in each direction, when
  /// the mesh is orientable. In each component the orientation of the majority of faces is kept.
  bool fix_winding = true;
  /// Passed to the validation that runs before and after.
  ValidationOptions validation;
};

struct RepairResult {
  int removed_repeated_index_faces = 0;
  int removed_zero_area_faces = 0;
  int removed_component_faces = 0;  ///< faces dropped with the smaller components
  int removed_components = 0;
  int flipped_faces = 0;
  int removed_vertices = 0;
  /// Winding could not be made consistent (non-orientable, or non-manifold edges in the way).
  bool winding_unfixable = false;
  /// One human-readable line per action taken.
  std::vector<std::string> actions;
  /// The validation of the repaired mesh.
  MeshValidation after;
};

/// Repairs what can be repaired without guessing: see RepairOptions. Attributes (texture
/// coordinates, normals, colours, materials, creases, corners) follow the faces and vertices they
/// belong to. \throws InvalidInputError when the mesh has malformed faces (nothing is changed
/// then).
RepairResult repair_mesh(PolygonMesh& mesh, const RepairOptions& options = {});

/// What a consumer of the mesh demands of it. The defaults are the tools' policy (the table above);
/// the halfedge adapter and the limit surface relax what they can represent.
struct ManifoldRequirements {
  /// Accept meshes with boundary edges.
  bool allow_boundary = true;
  /// Accept several components.
  bool allow_several_components = false;
  /// Accept zero-area faces (a limit surface tolerates them, a parameterisation may not).
  bool allow_zero_area_faces = false;
  /// Accept vertices no face uses (a halfedge mesh and a limit surface carry them along).
  bool allow_unreferenced_vertices = false;
  /// Accept a mesh without faces (an empty halfedge mesh is a valid one).
  bool allow_no_faces = false;
  ValidationOptions validation;
};

/// The manifold policy in words, the one wording every consumer uses: the first problem of `mesh`
/// (validated as `validation`) that `requirements` does not accept, or "" when there is none. An
/// oriented manifold is required always: no malformed faces (the first one is named with its
/// defect), no non-finite coordinates, no non-manifold edges or vertices, no faces with a repeated
/// vertex, consistent winding. The text names the offending indices and says when repair_mesh()
/// would fix the problem; it does not name the mesh (callers put it in front, as InvalidInputError
/// does).
std::string manifold_problem(const PolygonMesh& mesh, const MeshValidation& validation,
                             const ManifoldRequirements& requirements = {});

/// Throws unless the mesh is an oriented manifold meeting `requirements`, with no unreferenced or
/// non-finite vertices: manifold_problem() of validate_mesh(mesh).
/// \throws InvalidInputError "<name>: <first problem>", the problem naming the offending
///         indices and, when repair_mesh() would fix it, saying so.
void require_valid_manifold(const PolygonMesh& mesh, const std::string& name,
                            const ManifoldRequirements& requirements = {});

struct SanitizeResult {
  RepairResult repair;
  /// What was repaired, as warnings for the user ("beetle.obj: removed 3 unreferenced vertices").
  std::vector<std::string> warnings;
};

/// The policy of the table above in one call: repair what is repairable (reporting it as warnings),
/// then require_valid_manifold() on the result. \throws InvalidInputError naming `name` for what
/// cannot be repaired.
SanitizeResult sanitize_mesh(PolygonMesh& mesh, const std::string& name,
                             const RepairOptions& repair = {},
                             const ManifoldRequirements& requirements = {});

}  // namespace elastic
