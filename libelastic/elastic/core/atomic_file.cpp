#include "elastic/core/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "elastic/core/error.h"

namespace elastic {

namespace {
std::filesystem::path temporary_beside(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  std::filesystem::path tmp = path;
  tmp += ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
  return tmp;
}
}  // namespace

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ofstream&)>& write, bool binary) {
  const std::filesystem::path tmp = temporary_beside(path);
  {
    std::ofstream out(tmp, binary ? std::ios::out | std::ios::binary : std::ios::out);
    if (!out) {
      throw IoError(path.string(), std::string("cannot create file: ") + std::strerror(errno),
                    IoError::Direction::Write);
    }
    try {
      write(out);
      out.flush();
    } catch (...) {
      out.close();
      std::error_code ignored;
      std::filesystem::remove(tmp, ignored);
      throw;
    }
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(tmp, ignored);
      throw IoError(path.string(), "write failed (disk full or I/O error)",
                    IoError::Direction::Write);
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw IoError(path.string(), "cannot replace file: " + ec.message(), IoError::Direction::Write);
  }
}

}  // namespace elastic
