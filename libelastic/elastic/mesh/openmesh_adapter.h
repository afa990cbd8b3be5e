#pragma once
/// \file
/// Conversion between PolygonMesh and OpenMesh's halfedge polygon mesh, with double-precision
/// points. This is the only public header that includes OpenMesh.
///
/// Numbering: vertex i of the PolygonMesh is OpenMesh vertex handle i and face f is face handle f,
/// both ways (for meshes without deleted elements). Each face's halfedge_handle() is set to the
/// halfedge that ends at the face's first corner, so that `fh_range(f)` / `fv_range(f)` list the
/// corners in the PolygonMesh order, starting with the same corner (the ptex parameterisation of
/// OpenSubdiv depends on it).
///
/// Texture coordinates follow OpenMesh's convention: the coordinate of face f's corner at vertex v
/// is stored on the halfedge of f that points to v.

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <string>

#include "elastic/mesh/polygon_mesh.h"

namespace elastic {

/// Traits: double-precision points and normals, per-halfedge 2D texture coordinates, status flags
/// on all elements (so that consumers can delete and garbage-collect).
struct HalfedgeMeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  using TexCoord2D = OpenMesh::Vec2d;
  VertexAttributes(OpenMesh::Attributes::Normal | OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::TexCoord2D | OpenMesh::Attributes::PrevHalfedge |
                     OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Normal | OpenMesh::Attributes::Status);
};

/// The library's halfedge mesh type.
using HalfedgeMesh = OpenMesh::PolyMesh_ArrayKernelT<HalfedgeMeshTraits>;

struct ToOpenMeshOptions {
  /// Name of the mesh in error messages.
  std::string name = "mesh";
  /// Copy per-corner texture coordinates to halfedge texture coordinates (when the mesh has them).
  bool texcoords = true;
  /// Compute face and vertex normals (OpenMesh's update_normals) after building.
  bool compute_normals = true;
};

/// Builds the halfedge mesh of `mesh`.
/// \throws InvalidInputError naming `options.name` when the mesh cannot be a halfedge mesh:
///         malformed faces, non-finite positions, faces with a repeated vertex, non-manifold
///         edges or vertices, or inconsistently oriented faces (repair_mesh() fixes the last one),
///         worded by manifold_problem(). OpenMesh would otherwise print "complex edge" and
///         silently drop faces.
HalfedgeMesh to_openmesh(const PolygonMesh& mesh, const ToOpenMeshOptions& options = {});

struct FromOpenMeshOptions {
  /// Export halfedge texture coordinates as corner texture coordinates (identical values are
  /// shared).
  bool texcoords = true;
  /// Export the vertex normals (one per vertex) as corner normals, when the mesh has them.
  bool normals = false;
};

/// The PolygonMesh of a halfedge mesh. Deleted elements (status flags) are skipped and the rest
/// renumbered in order; isolated vertices are kept.
PolygonMesh from_openmesh(const HalfedgeMesh& mesh, const FromOpenMeshOptions& options = {});

}  // namespace elastic
