#include "elastic/transfer/output_folder.h"

#include <algorithm>
#include <fstream>
#include <system_error>
#include <utility>

#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"
#include "elastic/mesh/default_material.h"

namespace elastic {
namespace {

std::filesystem::path canonical_or_absolute(const std::filesystem::path& path) {
  std::error_code ec;
  std::filesystem::path c = std::filesystem::weakly_canonical(path, ec);
  if (ec) {
    c = std::filesystem::absolute(path).lexically_normal();
  }
  return c;
}

void check_bare_name(const std::string& name, const std::filesystem::path& dir) {
  const std::filesystem::path p(name);
  if (name.empty() || p.has_parent_path() || p.filename() != p || name == "." || name == "..") {
    throw InvalidInputError((dir / name).string(), "an output file needs a bare file name");
  }
}

}  // namespace

OutputFolder::OutputFolder(std::filesystem::path dir) : dir_(std::move(dir)) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) {
    throw IoError(dir_.string(), "cannot create the output folder: " + ec.message(),
                  IoError::Direction::Write);
  }
}

void OutputFolder::record(const std::filesystem::path& path) {
  if (std::find(files_.begin(), files_.end(), path) == files_.end()) {
    files_.push_back(path);
  }
}

std::filesystem::path OutputFolder::claim(const std::string& name) {
  check_bare_name(name, dir_);
  const auto it = names_.find(name);
  if (it != names_.end() && !it->second.empty()) {
    throw InvalidInputError((dir_ / name).string(),
                            "is already the copy of " + it->second.string() + " in this folder");
  }
  names_[name] = std::filesystem::path();
  return dir_ / name;
}

std::filesystem::path OutputFolder::copy_in(const std::filesystem::path& file) {
  const std::filesystem::path source = canonical_or_absolute(file);
  if (const auto it = copied_.find(source); it != copied_.end()) {
    return dir_ / it->second;
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(source, ec)) {
    throw IoError(file.string(), "no such file (needed by an output of " + dir_.string() + ")");
  }
  // Already in the folder (e.g. the output folder is the input's own, or a file this run wrote):
  // referenced where it is.
  if (canonical_or_absolute(dir_) == source.parent_path()) {
    const std::string name = source.filename().string();
    names_.emplace(name, std::filesystem::path());
    copied_[source] = name;
    record(dir_ / name);
    return dir_ / name;
  }
  // A free name: the input's own, or with _2, _3, ... before the extension.
  const std::string stem = source.stem().string(), extension = source.extension().string();
  std::string name = source.filename().string();
  for (int k = 2; names_.count(name) > 0; ++k) {
    name = stem;
    name.push_back('_');
    name.append(std::to_string(k));
    name.append(extension);
  }
  std::ifstream in(source, std::ios::binary);
  if (!in) {
    throw IoError(file.string(), "cannot open the file to copy it into " + dir_.string());
  }
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  std::string bytes(size > 0 ? static_cast<size_t>(size) : 0, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (size < 0 || !in) {
    throw IoError(file.string(), "cannot read the file to copy it into " + dir_.string());
  }
  std::filesystem::path destination = dir_ / name;
  write_file_atomically(
      destination,
      [&](std::ofstream& out) {
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      },
      true);
  names_[name] = source;
  copied_[source] = name;
  record(destination);
  return destination;
}

std::filesystem::path OutputFolder::write_image(const std::string& name, const Image& image) {
  std::filesystem::path path = claim(name);
  write_png(path, image);
  // A later copy_in of this very file (a material naming it) references it where it is.
  copied_[canonical_or_absolute(path)] = name;
  record(path);
  return path;
}

std::vector<std::filesystem::path> OutputFolder::write_obj(const std::string& name,
                                                           PolygonMesh mesh) {
  check_bare_name(name, dir_);
  assign_default_material(mesh);
  for (Material& m : mesh.materials) {
    if (m.diffuse_texture.empty()) {
      continue;
    }
    std::error_code ec;
    if (!std::filesystem::is_regular_file(m.diffuse_texture, ec)) {
      warnings_.push_back(m.diffuse_texture.string() + ": texture of material '" + m.name +
                          "' not found; " + name + " uses its Kd instead");
      m.diffuse_texture.clear();
      continue;
    }
    m.diffuse_texture = copy_in(m.diffuse_texture);
  }
  const std::filesystem::path obj = claim(name);
  std::filesystem::path mtl = obj;
  mtl.replace_extension(".mtl");
  claim(mtl.filename().string());
  MeshWriteOptions options;
  options.format = MeshFormat::Obj;
  elastic::write_mesh(obj, mesh, options);
  record(obj);
  record(mtl);
  return {obj, mtl};
}

std::filesystem::path OutputFolder::write_mesh(const std::string& name, const PolygonMesh& mesh,
                                               const MeshWriteOptions& options) {
  std::filesystem::path path = claim(name);
  elastic::write_mesh(path, mesh, options);
  record(path);
  return path;
}

}  // namespace elastic
