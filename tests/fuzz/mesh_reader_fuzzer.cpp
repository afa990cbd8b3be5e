// libFuzzer target for one mesh reader, chosen at compile time by ELASTIC_FUZZ_FORMAT (obj, off,
// ply, stl, mtl). The readers get the bytes in memory (OBJ, OFF, PLY, STL), or through a
// temporary file (MTL, which is only read from a path). Every input must either read or throw
// elastic::Error; anything else (a crash, a sanitizer report, another exception, a hang) is a
// finding. What is read must also pass the writer's checks, since no reader may accept what the
// writers refuse.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/mesh/detail/io_common.h"
#include "elastic/mesh/mesh_io.h"

namespace {

std::filesystem::path scratch_file(const char* extension) {
  static const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("elastic_fuzz_" + std::to_string(::getpid()) + extension);
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace elastic;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::string format = ELASTIC_FUZZ_FORMAT;
  try {
    MeshReadResult result;
    const std::filesystem::path name = "fuzz." + format;
    if (format == "obj") {
      MeshReadOptions options;
      options.load_materials = false;  // an mtllib line would open files
      result = detail::read_obj(bytes, name, options);
    } else if (format == "off") {
      result = detail::read_off(bytes, name);
    } else if (format == "ply") {
      result = detail::read_ply(bytes, name);
    } else if (format == "stl") {
      result = detail::read_stl(bytes, name);
    } else if (format == "mtl") {
      const std::filesystem::path path = scratch_file(".mtl");
      std::ofstream(path, std::ios::binary)
          .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      std::vector<Material> materials;
      detail::read_mtl(path, materials);
      return 0;
    }
    if (result.mesh.num_faces() > 0) {
      // What a reader accepts, the writers must accept too.
      detail::check_writable(result.mesh, name);
      if (format == "stl") detail::check_stl_writable(result.mesh, name);
    }
  } catch (const Error&) {
    // A refusal with a message: the expected outcome for most inputs.
  }
  return 0;
}
