#pragma once
/// \file
/// The default material: what a face without a material is given when a mesh is written with
/// materials (OBJ has no "no material" statement, and viewers then pick one of their own choice,
/// often the file's first material, e.g. a decal's).
///
/// It is named "default", a neutral grey `Kd 0.8 0.8 0.8` (the MTL format's own default diffuse),
/// without a texture. write_mesh (mesh_io.h) writes faces without a material of a mesh that has
/// materials under `usemtl default` and defines it in the .mtl; transfer/ outputs give it to every
/// face explicitly.

#include <filesystem>

#include "elastic/mesh/polygon_mesh.h"

namespace elastic {

/// The default material (see the file comment).
Material default_material();

/// Gives every face without a material (face_materials -1, or all faces when face_materials is
/// empty) the default material: the mesh's material named "default" when it has one, otherwise
/// default_material() appended. Returns the number of faces that were given it (0: unchanged).
int assign_default_material(PolygonMesh& mesh);

/// The texture (`map_Kd`) of the mesh's first material that has one; empty when none has. The
/// image a texture colour source reads by default, and the one a bake paints into.
std::filesystem::path first_diffuse_texture(const PolygonMesh& mesh);

}  // namespace elastic
