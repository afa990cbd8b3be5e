#pragma once
/// \file
/// `OutputFolder`: the folder a paste writes into, kept self-contained and relocatable.
///
/// Every file a written OBJ needs lies in the folder itself and is referenced by its bare file
/// name (the .mtl beside the .obj names `map_Kd spot_texture.png`, never
/// `../../in/spot_texture.png` or an absolute path), so the folder can be moved, copied or zipped
/// and still opens in any viewer. Textures that come from the inputs (a target's own `map_Kd`, a
/// detail mesh's textures) are copied in byte for byte; images made by the run (the decal, the
/// bake) are written in. Every face of every OBJ gets a material: faces without one get the
/// documented default (mesh/default_material.h: `newmtl default`, `Kd 0.8 0.8 0.8`).
///
/// Names: a copied file keeps its bare name; a different file whose name is already taken in
/// this run (two inputs called `texture.png` in different folders, or an input named like a file
/// the run writes) gets `_2`, `_3`, ... before its extension. A file that already lies in the
/// folder is used where it is. Files left from an earlier run are overwritten. Every write is
/// atomic (core/atomic_file.h).
///
/// Not thread-safe (one writer per folder); the object only records names, it owns no files.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "elastic/image/image.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/mesh/polygon_mesh.h"

namespace elastic {

class OutputFolder {
 public:
  /// Creates the folder (and its parents) when missing.
  /// \throws IoError naming the folder when it cannot be created.
  explicit OutputFolder(std::filesystem::path dir);

  const std::filesystem::path& dir() const { return dir_; }

  /// The file `file` brought into the folder (see the file comment for names): returns its path
  /// in the folder. Copies each input once per run.
  /// \throws IoError naming `file` when it cannot be read, or the copy when it cannot be written.
  std::filesystem::path copy_in(const std::filesystem::path& file);

  /// Writes `image` as a PNG named `name` (a bare file name) in the folder; returns its path.
  /// \throws InvalidInputError when `name` is not a bare file name or was already given to a
  ///         copied input in this run; IoError / InvalidInputError from write_png.
  std::filesystem::path write_image(const std::string& name, const Image& image);

  /// Writes `mesh` as the OBJ `name` (a bare file name ending in .obj) with its .mtl beside it,
  /// standing alone: faces without a material get the default one (assign_default_material), and
  /// every material texture is brought in with copy_in (a texture file that does not exist is
  /// dropped from its material, which keeps its `Kd`, and named in warnings()). Returns the .obj
  /// and .mtl paths.
  /// \throws InvalidInputError for a bad name; IoError / InvalidInputError from write_mesh and
  ///         copy_in.
  std::vector<std::filesystem::path> write_obj(const std::string& name, PolygonMesh mesh);

  /// Writes any other mesh file (e.g. a PLY) named `name` in the folder; returns its path.
  std::filesystem::path write_mesh(const std::string& name, const PolygonMesh& mesh,
                                   const MeshWriteOptions& options = {});

  /// Every file written or copied in this run, in order, each once.
  const std::vector<std::filesystem::path>& files() const { return files_; }
  /// What was tolerated: missing texture files ("<file>: ...").
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  std::filesystem::path dir_;
  /// Bare name -> the input it was copied from (canonical), or empty for a file the run wrote.
  std::map<std::string, std::filesystem::path> names_;
  /// Canonical input -> its bare name in the folder.
  std::map<std::filesystem::path, std::string> copied_;
  std::vector<std::filesystem::path> files_;
  std::vector<std::string> warnings_;

  std::filesystem::path claim(const std::string& name);
  void record(const std::filesystem::path& path);
};

}  // namespace elastic
