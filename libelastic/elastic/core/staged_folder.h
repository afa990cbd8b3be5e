#pragma once
/// \file
/// `StagedFolder`: a set of output files that appears in its folder all at once, or not at all.
///
/// A command that writes several files (a paste's decal, colour PLY, heatmaps, previews and report)
/// writes them into a staging folder beside the destination, `<parent>/.<name>.staging.<PID>`, and
/// commit() moves the whole set into place with one atomic exchange of the two folders
/// (renameat2 with RENAME_EXCHANGE), then removes the old set. A run interrupted at any moment
/// leaves the destination as it was (the old complete set) or as the new run made it (the new
/// complete set), never a mixture.
///
/// - Files in the destination that the run does not write (the user's own, or an earlier run's
///   with other flags) are carried into the new set as hard links (copies where links fail), so a
///   commit never loses them; temporaries of write_file_atomically are not carried. A folder the
///   run writes (a paste's frames/) is the run's whole: nothing of the old folder of that name is
///   carried into it, so an earlier run's extra frames never mix with the new ones.
/// - Where the file system cannot exchange folders, commit() renames the destination to
///   `.<name>.old.<PID>`, the staging folder to the destination, and removes the old one; a run
///   killed between the two renames leaves the old set under the `.old.` name, which the next run
///   into that destination puts back.
/// - Staging and `.old.` folders of processes that no longer run (a SIGKILL, a power cut) are
///   removed (or, as above, put back) by the next StagedFolder of that destination. Those of a
///   running process are left alone (the PID test of core/atomic_file.h, with its caveat for
///   folders shared across machines).
/// - remove_staging_folders_now() removes the staging folders of this process with
///   async-signal-safe calls only, for a SIGINT handler (the `elastic` tool installs one).
///
///   StagedFolder out("pasted", "--out");       // checks and creates the staging folder, or throws
///   write_png(out.staging() / "decal.png", image);
///   out.commit();                               // the set appears in pasted/

#include <filesystem>
#include <string>

namespace elastic {

class StagedFolder {
 public:
  /// Checks `destination` and creates the staging folder beside it (and the destination's missing
  /// parents), after removing stale staging folders of dead runs. `name` is for messages (a flag,
  /// e.g. "--out").
  /// \throws IoError (Direction::Write) naming the destination when it exists and is not a folder,
  ///         is the current folder or holds it, or when its parent cannot be created or written.
  explicit StagedFolder(std::filesystem::path destination, std::string name = "output folder");
  /// Removes the staging folder when commit() was not reached (an exception unwinds the run).
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  /// Where the run writes its files (an empty folder at first).
  const std::filesystem::path& staging() const { return staging_; }
  /// Where the set goes (absolute).
  const std::filesystem::path& destination() const { return destination_; }
  /// The final path of `staged`, a path inside staging() (other paths are returned unchanged).
  std::filesystem::path final_path(const std::filesystem::path& staged) const;

  /// Carries the destination's other files in, then moves the set into place (see the file
  /// comment). At most once. \throws IoError naming the destination when a rename fails (the
  /// destination then keeps its old set).
  void commit();

 private:
  std::filesystem::path destination_;
  std::filesystem::path staging_;
  std::string name_;
  int slot_ = -1;  ///< registry slot for remove_staging_folders_now
  bool committed_ = false;
};

/// Removes every staging folder of this process that is not committed yet, with async-signal-safe
/// calls only (open, getdents64, unlinkat). Meant for a signal handler that then lets the signal
/// end the process.
void remove_staging_folders_now() noexcept;

/// Removes the stale staging folders beside `destination` (those of processes that no longer
/// run), and puts a stale `.old.` folder back when the destination is missing. Errors are ignored.
/// \returns how many folders were removed or put back.
int remove_stale_staging(const std::filesystem::path& destination) noexcept;

/// Checks, before any work, that a single output file can be created at `path`: its folder exists
/// and is writable, and `path` is not a folder. `name` is for messages (a flag, e.g. "--report").
/// \throws IoError (Direction::Write) naming `path`.
void check_output_file(const std::filesystem::path& path, const std::string& name);

}  // namespace elastic
