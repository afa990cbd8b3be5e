#pragma once
// A scratch file per fuzzing process, for readers that take a path rather than bytes.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace elastic::fuzz {

/// Writes `size` bytes to this process's scratch file with `extension` and returns its path.
inline std::filesystem::path write_scratch_file(const std::uint8_t* data, std::size_t size,
                                                const char* extension) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("elastic_fuzz_" + std::to_string(::getpid()) + extension);
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace elastic::fuzz
