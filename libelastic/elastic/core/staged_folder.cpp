#include "elastic/core/staged_folder.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>

#include "elastic/core/atomic_file.h"
#include "elastic/core/detail/signal_path_registry.h"
#include "elastic/core/error.h"

namespace elastic {

namespace {

namespace fs = std::filesystem;

/// The uncommitted staging folders of this process (core/detail/signal_path_registry.h);
/// constant-initialised, so a handler can use it at any time.
constinit core_detail::SignalPathRegistry<8> staging_registry;

/// The record getdents64 fills (linux/dirent.h's linux_dirent64).
struct DirectoryEntry64 {
  ino64_t d_ino;
  off64_t d_off;
  unsigned short d_reclen;
  unsigned char d_type;
  char d_name[1];
};

/// Removes `name` under the folder `parent_fd` and everything in it, with async-signal-safe system
/// calls only. Removing entries while reading a folder may skip some, so a folder is read again
/// until a pass removes nothing. Depth is bounded (the staging folders are two levels deep).
void remove_tree_at(int parent_fd, const char* name, int depth) noexcept {
  const int fd = ::openat(parent_fd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) {
    ::unlinkat(parent_fd, name, 0);
    return;
  }
  if (depth < 8) {
    for (int pass = 0; pass < 64; ++pass) {
      alignas(8) char buffer[2048];
      bool removed = false;
      ::lseek(fd, 0, SEEK_SET);
      for (;;) {
        const long bytes = ::syscall(SYS_getdents64, fd, buffer, sizeof buffer);
        if (bytes <= 0) break;
        for (long offset = 0; offset < bytes;) {
          const auto* entry = reinterpret_cast<const DirectoryEntry64*>(buffer + offset);
          offset += entry->d_reclen;
          const char* n = entry->d_name;
          if (n[0] == '.' && (n[1] == '\0' || (n[1] == '.' && n[2] == '\0'))) continue;
          if (entry->d_type == DT_DIR) {
            remove_tree_at(fd, n, depth + 1);
          } else {
            ::unlinkat(fd, n, 0);
          }
          removed = true;
        }
      }
      if (!removed) break;
    }
  }
  ::close(fd);
  ::unlinkat(parent_fd, name, AT_REMOVEDIR);
}

bool process_running(long long pid) {
  if (pid <= 0 || pid > 0x7fffffff) return false;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
}

/// The PID of `entry` when it is `<prefix><PID>` (decimal, no leading zero), else -1.
long long pid_after(const std::string& entry, const std::string& prefix) {
  if (entry.size() <= prefix.size() || entry.compare(0, prefix.size(), prefix) != 0) return -1;
  const std::string digits = entry.substr(prefix.size());
  if (digits.size() > 10 || digits[0] == '0') return -1;
  long long pid = 0;
  for (const char c : digits) {
    if (c < '0' || c > '9') return -1;
    pid = pid * 10 + (c - '0');
  }
  return pid;
}

/// `.<name><kind>`, built by appending (GCC 12 warns falsely about "literal" + string here).
std::string hidden_prefix(const fs::path& destination, const char* kind) {
  std::string prefix(".");
  prefix.append(destination.filename().string()).append(kind);
  return prefix;
}
std::string staging_prefix(const fs::path& destination) {
  return hidden_prefix(destination, ".staging.");
}
std::string old_prefix(const fs::path& destination) {
  return hidden_prefix(destination, ".old.");
}

/// Brings every entry of `from` that `to` lacks into `to`: folders recursively, files as hard
/// links (copies when a link fails, e.g. across file systems), symbolic links as links.
/// Temporaries of write_file_atomically are left behind (they go with the old set).
void carry_over(const fs::path& from, const fs::path& to) {
  for (const fs::directory_entry& entry : fs::directory_iterator(from)) {
    const std::string name = entry.path().filename().string();
    long long pid = 0;
    if (parse_temporary_name(name, pid)) continue;
    const fs::path target = to / name;
    std::error_code ec;
    if (fs::symlink_status(target, ec).type() != fs::file_type::not_found) {
      // The run wrote this name: its file, or its whole folder (frames/ of a run with fewer
      // frames must not keep an earlier run's last frames: that would be a mixture of two sets).
      continue;
    }
    if (entry.is_symlink()) {
      fs::copy_symlink(entry.path(), target);
    } else if (entry.is_directory()) {
      fs::create_directory(target);
      carry_over(entry.path(), target);
    } else if (entry.is_regular_file()) {
      fs::create_hard_link(entry.path(), target, ec);
      if (ec) fs::copy_file(entry.path(), target);
    }
  }
}

}  // namespace

StagedFolder::StagedFolder(fs::path destination, std::string name) : name_(std::move(name)) {
  std::error_code ec;
  destination_ = fs::absolute(destination, ec).lexically_normal();
  if (destination_.has_parent_path() && destination_.filename().empty()) {
    destination_ = destination_.parent_path();  // "out/" -> "out"
  }
  if (fs::is_symlink(destination_, ec)) destination_ = fs::canonical(destination_, ec);
  const std::string shown = destination.string();
  const fs::file_status status = fs::status(destination_, ec);
  if (fs::exists(status) && !fs::is_directory(status)) {
    throw IoError(shown, name_ + " must be a folder, and this is an existing file",
                  IoError::Direction::Write);
  }
  // The set is exchanged whole: the current folder (or one holding it) would vanish from under
  // the shell that runs us.
  const fs::path here = fs::weakly_canonical(fs::current_path(ec), ec);
  const fs::path there = fs::weakly_canonical(destination_, ec);
  const auto [end, rest] = std::mismatch(there.begin(), there.end(), here.begin(), here.end());
  if (end == there.end() || destination_ == destination_.root_path()) {
    throw IoError(shown, name_ + " is the current folder or holds it; give a folder of its own",
                  IoError::Direction::Write);
  }
  const fs::path parent = destination_.parent_path();
  fs::create_directories(parent, ec);
  if (ec) {
    throw IoError(
        shown, "cannot create the folder " + parent.string() + " (" + name_ + "): " + ec.message(),
        IoError::Direction::Write);
  }
  remove_stale_staging(destination_);
  staging_ = parent / (staging_prefix(destination_) + std::to_string(::getpid()));
  fs::remove_all(staging_, ec);
  if (!fs::create_directory(staging_, ec) || ec) {
    throw IoError(shown,
                  "cannot write into " + parent.string() + " (" + name_ +
                      "): " + (ec ? ec.message() : std::string("the staging folder exists")),
                  IoError::Direction::Write);
  }
  slot_ = staging_registry.add(staging_.string());
}

StagedFolder::~StagedFolder() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(staging_, ec);
  }
  staging_registry.release(slot_);
}

fs::path StagedFolder::final_path(const fs::path& staged) const {
  const fs::path relative = staged.lexically_relative(staging_);
  if (relative.empty() || *relative.begin() == "..") return staged;
  return destination_ / relative;
}

void StagedFolder::commit() {
  if (committed_) return;
  std::error_code ec;
  const std::string shown = destination_.string();
  const auto fail = [&](const std::string& what, int error) {
    throw IoError(shown, what + ": " + std::strerror(error), IoError::Direction::Write);
  };
  if (fs::is_directory(destination_, ec)) {
    try {
      carry_over(destination_, staging_);
    } catch (const fs::filesystem_error& e) {
      throw IoError(shown, "cannot carry its other files into the new set: " + e.code().message(),
                    IoError::Direction::Write);
    }
    if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, destination_.c_str(), RENAME_EXCHANGE) !=
        0) {
      const int error = errno;
      if (error != EINVAL && error != ENOSYS && error != ENOTSUP) {
        fail("cannot move the new set into place", error);
      }
      // No exchange on this file system: two renames, the old set parked under `.old.` between
      // them (put back by the next run if we die there).
      const fs::path old =
          destination_.parent_path() / (old_prefix(destination_) + std::to_string(::getpid()));
      fs::remove_all(old, ec);
      if (::rename(destination_.c_str(), old.c_str()) != 0) {
        fail("cannot move the old set aside", errno);
      }
      if (::rename(staging_.c_str(), destination_.c_str()) != 0) {
        const int e = errno;
        ::rename(old.c_str(), destination_.c_str());
        fail("cannot move the new set into place", e);
      }
      committed_ = true;
      fs::remove_all(old, ec);
      return;
    }
    // The staging path now holds the old set (still registered: a signal removes the rest).
    committed_ = true;
    fs::remove_all(staging_, ec);
    return;
  }
  if (::rename(staging_.c_str(), destination_.c_str()) != 0) {
    fail("cannot move the new set into place", errno);
  }
  committed_ = true;
}

void remove_staging_folders_now() noexcept {
  staging_registry.for_each_live([](const char* path) { remove_tree_at(AT_FDCWD, path, 0); });
}

int remove_stale_staging(const fs::path& destination) noexcept {
  int count = 0;
  try {
    std::error_code ec;
    const fs::path parent =
        destination.parent_path().empty() ? fs::path(".") : destination.parent_path();
    const std::string staging = staging_prefix(destination);
    const std::string old = old_prefix(destination);
    for (const fs::directory_entry& entry : fs::directory_iterator(parent, ec)) {
      const std::string name = entry.path().filename().string();
      const long long staging_pid = pid_after(name, staging);
      const long long old_pid = pid_after(name, old);
      const long long pid = staging_pid >= 0 ? staging_pid : old_pid;
      if (pid < 0 || process_running(pid)) continue;
      if (old_pid >= 0 && !fs::exists(destination, ec)) {
        fs::rename(entry.path(), destination, ec);  // the old complete set, put back
      } else {
        fs::remove_all(entry.path(), ec);
      }
      if (!ec) ++count;
    }
  } catch (...) {
    // Best effort: a folder we cannot read has nothing of ours to clean.
  }
  return count;
}

void check_output_file(const fs::path& path, const std::string& name) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  if (fs::is_directory(absolute, ec)) {
    throw IoError(path.string(), "is a folder (" + name + " names a file)",
                  IoError::Direction::Write);
  }
  const fs::path folder = absolute.parent_path();
  if (!fs::is_directory(folder, ec)) {
    throw IoError(path.string(), "the folder " + folder.string() + " does not exist (" + name + ")",
                  IoError::Direction::Write);
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    throw IoError(path.string(),
                  "the folder " + folder.string() + " is not writable (" + name + ")",
                  IoError::Direction::Write);
  }
}

}  // namespace elastic
