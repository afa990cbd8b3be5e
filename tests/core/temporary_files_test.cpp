// Temporary files of write_file_atomically do not outlive their run: a signal handler can remove
// the live ones (remove_temporary_files_now), and stale ones of a dead process are removed by the
// next atomic write into their folder, while files that only look similar are kept.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <set>
#include <string>

#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

std::set<std::string> files_in(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename());
  return names;
}

void touch(const fs::path& path) {
  std::ofstream(path) << "partial";
}

/// The PID of a process that has ended (a child that exits at once, reaped).
pid_t dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

TEST(TemporaryFiles, NamePatternIsMatchedExactly) {
  long long pid = 0;
  EXPECT_TRUE(parse_temporary_name("painted.obj.tmp.1234.0", pid));
  EXPECT_EQ(pid, 1234);
  EXPECT_TRUE(parse_temporary_name("a.tmp.7.15", pid));
  EXPECT_EQ(pid, 7);
  for (const char* name :
       {"painted.obj", ".tmp.1234.0", "x.tmp.1234", "x.tmp.1234.", "x.tmp..0", "x.tmp.01234.0",
        "x.tmp.1234.00", "x.tmp.0.1", "x.tmp.12a4.0", "x.temp.1234.0", "x.tmp.1234.0.bak",
        "notes.tmp.txt", "x.tmp.1234567890123456789.0"}) {
    EXPECT_FALSE(parse_temporary_name(name, pid)) << name;
  }
}

TEST(TemporaryFiles, StaleTemporariesOfDeadProcessesAreRemovedByTheNextWrite) {
  const fs::path dir = test::scratch_dir("stale_temporaries");
  const std::string dead = std::to_string(dead_pid());
  const std::string alive = std::to_string(::getppid());      // the test runner: running
  touch(dir / ("painted.obj.tmp." + dead + ".0"));            // stale: removed
  touch(dir / ("report.json.tmp." + dead + ".17"));           // stale: removed
  touch(dir / ("colors.ply.tmp." + alive + ".3"));            // a running process's: kept
  touch(dir / ("notes.tmp." + dead));                         // not our pattern: kept
  touch(dir / ("painted.obj.tmp." + dead + ".0.bak"));        // not our pattern: kept
  fs::create_directory(dir / ("folder.tmp." + dead + ".1"));  // not a regular file: kept
  write_file_atomically(dir / "new.txt", [](std::ofstream& out) { out << "new"; });
  EXPECT_EQ(files_in(dir), (std::set<std::string>{
                               "new.txt", "colors.ply.tmp." + alive + ".3", "notes.tmp." + dead,
                               "painted.obj.tmp." + dead + ".0.bak", "folder.tmp." + dead + ".1"}));
  // The sweep runs once per folder and process; the function itself can be called again.
  touch(dir / ("late.obj.tmp." + dead + ".2"));
  EXPECT_EQ(remove_stale_temporaries(dir), 1);
  EXPECT_FALSE(fs::exists(dir / ("late.obj.tmp." + dead + ".2")));
}

TEST(TemporaryFiles, LiveTemporariesAreRemovedOnRequestAndTheWriteFails) {
  const fs::path dir = test::scratch_dir("live_temporaries");
  write_file_atomically(dir / "a.txt", [](std::ofstream& out) { out << "old"; });
  std::set<std::string> during;
  try {
    write_file_atomically(dir / "a.txt", [&](std::ofstream& out) {
      out << "new" << std::flush;
      EXPECT_EQ(files_in(dir).size(), 2u);  // a.txt and its temporary
      remove_temporary_files_now();         // what the tool's SIGINT handler calls
      during = files_in(dir);
    });
    FAIL() << "the write succeeded without its temporary";
  } catch (const IoError& e) {
    EXPECT_EQ(e.input(), (dir / "a.txt").string());
  }
  EXPECT_EQ(during, (std::set<std::string>{"a.txt"}));
  EXPECT_EQ(files_in(dir), (std::set<std::string>{"a.txt"}));
  std::ifstream in(dir / "a.txt");
  std::string content;
  in >> content;
  EXPECT_EQ(content, "old");
  // Finished writes are not registered any more: a later call removes nothing.
  remove_temporary_files_now();
  EXPECT_EQ(files_in(dir), (std::set<std::string>{"a.txt"}));
}

TEST(TemporaryFiles, ASignalHandlerRemovesTheTemporaryOfAnInterruptedWrite) {
  // In a child: a handler like the tool's, then SIGINT in the middle of a write. The child dies
  // of SIGINT, leaving the old file and no temporary.
  const fs::path dir = test::scratch_dir("signal_temporaries");
  write_file_atomically(dir / "a.txt", [](std::ofstream& out) { out << "old"; });
  const pid_t child = ::fork();
  if (child == 0) {
    struct sigaction action {};
    action.sa_handler = [](int signal_number) {
      remove_temporary_files_now();
      ::signal(signal_number, SIG_DFL);
      ::raise(signal_number);
    };
    ::sigaction(SIGINT, &action, nullptr);
    write_file_atomically(dir / "a.txt", [](std::ofstream& out) {
      out << "partial" << std::flush;
      ::raise(SIGINT);
    });
    ::_exit(0);  // not reached
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGINT);
  EXPECT_EQ(files_in(dir), (std::set<std::string>{"a.txt"}));
}

}  // namespace
}  // namespace elastic
