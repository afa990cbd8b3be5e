#pragma once
/// \file
/// Writing a file so that a reader never sees a partial one and a good file is never replaced by a
/// broken one: the content goes to a temporary file in the same directory, which is renamed over
/// the destination only after everything was written and flushed successfully.
///
/// Temporary files are named `<destination>.tmp.<PID>.<N>` (PID of the writing process, N a
/// per-process counter). Two mechanisms keep them from outliving their run:
/// - every live temporary file is listed in a fixed-size registry that
///   remove_temporary_files_now() empties with async-signal-safe calls only, so a program's
///   SIGINT/SIGTERM handler can remove them before the process dies (the `elastic` tool installs
///   one; the library installs no handler);
/// - a process killed outright (SIGKILL, power loss) leaves its temporaries behind: the first
///   atomic write of a process into a folder removes the regular files there that match the
///   pattern exactly and whose PID is not a running process (kill(PID, 0) fails with ESRCH). A file
///   of a running process (including one of another user) is left alone. The PID test assumes the
///   folder is written from this machine and PID namespace: a folder shared with another host or
///   container could lose a temporary that is still being written there (that write then fails
///   with IoError; no finished file is touched).

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace elastic {

/// Calls `write(stream)` on a temporary file beside `path`, then renames it to `path`.
/// If `write` throws, or the stream fails, the temporary is removed and `path` is left untouched.
/// The first call for a folder removes stale temporaries of dead processes in it (see the file
/// comment).
/// \throws IoError naming `path` when the temporary cannot be created, written or renamed.
/// \param binary open the stream in binary mode (no newline translation).
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ofstream&)>& write, bool binary = false);

/// Removes (unlinks) every temporary file that write_file_atomically is writing at this moment.
/// Async-signal-safe: meant for a signal handler that then lets the signal end the process. Calls
/// in progress then fail with IoError (their temporary is gone) and leave their destination as it
/// was.
void remove_temporary_files_now() noexcept;

/// Whether `name` (a file name without folder) is a temporary of write_file_atomically:
/// `<non-empty name>.tmp.<PID>.<N>` with PID and N decimal numbers without leading zeros. On
/// success, `pid` is the PID it carries.
bool parse_temporary_name(const std::string& name, long long& pid);

/// Removes the stale temporaries in `folder`: files matching parse_temporary_name whose PID is
/// not a running process. Errors (an unreadable folder, a file removed meanwhile) are ignored.
/// \returns how many files were removed.
int remove_stale_temporaries(const std::filesystem::path& folder) noexcept;

}  // namespace elastic
