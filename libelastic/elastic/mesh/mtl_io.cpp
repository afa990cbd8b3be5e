// Wavefront MTL material libraries: `newmtl`, `Kd`, `map_Kd` (with its options); everything else
// (Ka, Ks, Ns, illum, nvdiffrec's `bsdf`, ...) is ignored.

#include <algorithm>
#include <filesystem>

#include "elastic/mesh/default_material.h"
#include "elastic/mesh/detail/io_common.h"

namespace elastic::detail {

namespace {

/// `map_Kd [-option args...] file`: skips the options (each "-name" followed by its numeric or
/// on/off arguments) and returns the file name, which may contain spaces.
std::string_view texture_file(std::string_view rest) {
  rest = trim(rest);
  while (!rest.empty() && rest.front() == '-') {
    std::string_view probe = rest;
    const std::string_view option = next_token(probe);
    rest = probe;
    // Arguments: numbers, on/off, or a single channel letter for -imfchan / a word for -type.
    const bool word_argument = option == "-imfchan" || option == "-type";
    for (;;) {
      std::string_view look = rest;
      const std::string_view arg = next_token(look);
      double number = 0.0;
      if (arg.empty()) {
        break;
      }
      if (parse_double(arg, number) || arg == "on" || arg == "off" || word_argument) {
        rest = look;
        if (word_argument) {
          break;
        }
        continue;
      }
      break;
    }
    rest = trim(rest);
  }
  return rest;
}

}  // namespace

bool read_mtl(const std::filesystem::path& path, std::vector<Material>& materials) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return false;
  }
  const std::string text = read_whole_file(path);
  LineScanner scanner(text, path);
  std::string_view line;
  Material* current = nullptr;
  while (scanner.next(line)) {
    std::string_view rest = line;
    const std::string_view keyword = next_token(rest);
    if (keyword.empty() || keyword.front() == '#') {
      continue;
    }
    if (keyword == "newmtl") {
      materials.emplace_back();
      current = &materials.back();
      current->name = std::string(trim(rest));
    } else if (current == nullptr) {
      continue;  // statements before the first newmtl belong to no material
    } else if (keyword == "Kd") {
      std::string_view probe = rest;
      if (next_token(probe) == "spectral" || trim(rest).starts_with("xyz")) {
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        current->diffuse[k] = expect_double(rest, scanner, "Kd value");
      }
      if (!current->diffuse.allFinite()) {
        scanner.fail("Kd value is NaN or infinite");
      }
    } else if (keyword == "map_Kd") {
      std::string file(texture_file(rest));
      if (file.empty()) {
        scanner.fail("map_Kd without a file name");
      }
      std::replace(file.begin(), file.end(), '\\', '/');
      const std::filesystem::path texture(file);
      current->diffuse_texture =
          texture.is_absolute() ? texture : (path.parent_path() / texture).lexically_normal();
    }
  }
  return true;
}

std::string write_mtl(const PolygonMesh& mesh, const std::filesystem::path& mtl_path) {
  std::string out = "# written by libelastic\n";
  const std::filesystem::path folder = std::filesystem::absolute(mtl_path).parent_path();
  // Faces without a material are written under `usemtl default` (write_obj): define it.
  std::vector<Material> materials = mesh.materials;
  const bool unassigned = mesh.face_materials.size() != static_cast<size_t>(mesh.num_faces()) ||
                          std::any_of(mesh.face_materials.begin(), mesh.face_materials.end(),
                                      [](int m) { return m < 0; });
  if (unassigned && std::none_of(materials.begin(), materials.end(),
                                 [](const Material& m) { return m.name == "default"; })) {
    materials.push_back(default_material());
  }
  for (const Material& m : materials) {
    out += "newmtl " + m.name + "\nKd";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_number(out, m.diffuse[k]);
    }
    out += '\n';
    if (!m.diffuse_texture.empty()) {
      // Relative to the .mtl's folder when the texture is on the same file system tree.
      std::filesystem::path texture =
          std::filesystem::absolute(m.diffuse_texture).lexically_normal();
      const std::filesystem::path relative = texture.lexically_relative(folder);
      if (!relative.empty()) {
        texture = relative;
      }
      out += "map_Kd " + texture.generic_string() + "\n";
    }
  }
  return out;
}

}  // namespace elastic::detail
