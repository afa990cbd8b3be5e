#include "elastic/core/atomic_file.h"

#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <set>
#include <string>
#include <system_error>

#include "elastic/core/detail/signal_path_registry.h"
#include "elastic/core/error.h"

namespace elastic {

namespace {

/// The live temporaries (core/detail/signal_path_registry.h).
// Constant-initialised (no constructor runs at start-up), so a handler can use it at any time.
constinit core_detail::SignalPathRegistry<64> registry;

/// Registers a temporary for the duration of a write.
class RegisteredTemporary {
 public:
  explicit RegisteredTemporary(const std::filesystem::path& path)
      : slot_(registry.add(path.string())) {}
  ~RegisteredTemporary() { registry.release(slot_); }
  RegisteredTemporary(const RegisteredTemporary&) = delete;
  RegisteredTemporary& operator=(const RegisteredTemporary&) = delete;

 private:
  int slot_;
};

std::filesystem::path temporary_beside(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  std::filesystem::path tmp = path;
  tmp += ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
  return tmp;
}

/// Sweeps a folder for stale temporaries the first time this process writes into it (a folder of
/// many files, e.g. animation frames, is listed once per run, not once per file).
void sweep_once(const std::filesystem::path& folder) {
  static std::mutex mutex;
  static std::set<std::filesystem::path> swept;
  std::error_code ec;
  std::filesystem::path key = std::filesystem::weakly_canonical(folder, ec);
  if (ec) {
    key = folder;
  }
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (!swept.insert(key).second) {
      return;
    }
  }
  remove_stale_temporaries(folder);
}

bool all_digits_no_leading_zero(std::string_view text) {
  if (text.empty() || text.size() > 18 || (text.size() > 1 && text.front() == '0')) {
    return false;
  }
  for (const char c : text) {
    if (c < '0' || c > '9') {
      return false;
    }
  }
  return true;
}

}  // namespace

bool parse_temporary_name(const std::string& name, long long& pid) {
  // <name>.tmp.<PID>.<N>: split off N, then PID, then ".tmp".
  const std::string_view text(name);
  const size_t last_dot = text.rfind('.');
  if (last_dot == std::string_view::npos ||
      !all_digits_no_leading_zero(text.substr(last_dot + 1))) {
    return false;
  }
  const std::string_view head = text.substr(0, last_dot);
  const size_t pid_dot = head.rfind('.');
  if (pid_dot == std::string_view::npos) {
    return false;
  }
  const std::string_view pid_text = head.substr(pid_dot + 1);
  if (!all_digits_no_leading_zero(pid_text) || pid_text == "0") {
    return false;
  }
  const std::string_view stem = head.substr(0, pid_dot);
  if (!stem.ends_with(".tmp") || stem.size() == 4) {
    return false;
  }
  pid = std::stoll(std::string(pid_text));
  return true;
}

int remove_stale_temporaries(const std::filesystem::path& folder) noexcept {
  int removed = 0;
  try {
    std::error_code ec;
    const std::filesystem::path where = folder.empty() ? std::filesystem::path(".") : folder;
    for (std::filesystem::directory_iterator it(where, ec), end; !ec && it != end;
         it.increment(ec)) {
      long long pid = 0;
      std::error_code type_ec;
      if (!it->is_regular_file(type_ec) || it->is_symlink(type_ec) ||
          !parse_temporary_name(it->path().filename().string(), pid)) {
        continue;
      }
      if (pid == static_cast<long long>(::getpid()) || pid > 0x7fffffff) {
        continue;
      }
      // Dead: no such process. EPERM means it runs under another user: leave its file.
      if (::kill(static_cast<pid_t>(pid), 0) == -1 && errno == ESRCH) {
        std::error_code remove_ec;
        if (std::filesystem::remove(it->path(), remove_ec)) {
          ++removed;
        }
      }
    }
  } catch (...) {
    // Best effort: a sweep never makes a write fail.
  }
  return removed;
}

void remove_temporary_files_now() noexcept {
  registry.for_each_live([](const char* path) { ::unlink(path); });  // async-signal-safe
}

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ofstream&)>& write, bool binary) {
  sweep_once(path.parent_path());
  const std::filesystem::path tmp = temporary_beside(path);
  // Registered before it exists, so that no moment passes in which a signal would miss it.
  const RegisteredTemporary registered(tmp);
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
