#pragma once
/// \file
/// Writing a file so that a reader never sees a partial one and a good file is never replaced by a
/// broken one: the content goes to a temporary file in the same directory, which is renamed over
/// the destination only after everything was written and flushed successfully.

#include <filesystem>
#include <fstream>
#include <functional>

namespace elastic {

/// Calls `write(stream)` on a temporary file beside `path`, then renames it to `path`.
/// If `write` throws, or the stream fails, the temporary is removed and `path` is left untouched.
/// \throws IoError naming `path` when the temporary cannot be created, written or renamed.
/// \param binary open the stream in binary mode (no newline translation).
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ofstream&)>& write, bool binary = false);

}  // namespace elastic
