// StagedFolder (core/staged_folder.h): nothing appears in the destination before commit(), the
// whole set appears at commit() with the destination's other files kept, an unwound run leaves
// the destination as it was, and stale staging folders of dead processes are removed (or an old
// set put back) by the next StagedFolder of that destination.
#include "elastic/core/staged_folder.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "elastic/core/error.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

/// A PID that no process has: a child that has exited and been reaped.
long dead_pid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

TEST(StagedFolder, TheSetAppearsAtCommitWithTheOtherFilesKept) {
  const fs::path dir = test::scratch_dir("staged_commit");
  const fs::path out = dir / "out";
  fs::create_directories(out / "frames");
  write(out / "a.txt", "old a");
  write(out / "mine.txt", "the user's");
  write(out / "frames" / "old_frame.png", "old frame");
  write(out / "a.txt.tmp.999999999.0", "a dead run's temporary");
  {
    StagedFolder staged(out, "--out");
    EXPECT_EQ(staged.staging().parent_path(), fs::absolute(dir));
    write(staged.staging() / "a.txt", "new a");
    fs::create_directories(staged.staging() / "frames");
    write(staged.staging() / "frames" / "f0.png", "new frame");
    EXPECT_EQ(staged.final_path(staged.staging() / "frames" / "f0.png"),
              fs::absolute(out) / "frames" / "f0.png");
    EXPECT_EQ(read(out / "a.txt"), "old a");  // nothing moves before commit
    staged.commit();
  }
  EXPECT_EQ(read(out / "a.txt"), "new a");
  EXPECT_EQ(read(out / "mine.txt"), "the user's");
  EXPECT_EQ(read(out / "frames" / "f0.png"), "new frame");
  // A folder the run writes is the run's whole: an earlier run's extra frames would mix two sets.
  EXPECT_FALSE(fs::exists(out / "frames" / "old_frame.png"));
  EXPECT_FALSE(fs::exists(out / "a.txt.tmp.999999999.0"));
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1) << "a staging folder is left beside out";
}

TEST(StagedFolder, AnUnwoundRunLeavesTheDestinationAsItWas) {
  const fs::path dir = test::scratch_dir("staged_unwound");
  const fs::path out = dir / "out";
  fs::create_directories(out);
  write(out / "a.txt", "old a");
  try {
    StagedFolder staged(out);
    write(staged.staging() / "a.txt", "new a");
    throw std::runtime_error("the run fails");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(read(out / "a.txt"), "old a");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);
  // A new destination appears only at commit.
  {
    StagedFolder staged(dir / "fresh");
    write(staged.staging() / "b.txt", "b");
    EXPECT_FALSE(fs::exists(dir / "fresh"));
    staged.commit();
  }
  EXPECT_EQ(read(dir / "fresh" / "b.txt"), "b");
}

TEST(StagedFolder, StaleStagingIsRemovedAndAParkedOldSetPutBack) {
  const fs::path dir = test::scratch_dir("staged_stale");
  const long dead = dead_pid();
  const fs::path stale = dir / (".out.staging." + std::to_string(dead));
  fs::create_directories(stale / "frames");
  write(stale / "frames" / "half.png", "half written");
  const fs::path live = dir / (".out.staging." + std::to_string(::getppid()));  // running
  fs::create_directories(live);
  // A run killed between its two renames (no exchange) parked the old set.
  const fs::path parked = dir / (".out.old." + std::to_string(dead));
  fs::create_directories(parked);
  write(parked / "a.txt", "old a");
  EXPECT_EQ(remove_stale_staging(dir / "out"), 2);
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_EQ(read(dir / "out" / "a.txt"), "old a");
  fs::remove_all(live);
}

TEST(StagedFolder, DestinationsThatCannotBeAFolderAreRefusedByName) {
  const fs::path dir = test::scratch_dir("staged_refused");
  write(dir / "file", "x");
  try {
    StagedFolder staged(dir / "file", "--out");
    FAIL() << "an existing file was taken as the folder";
  } catch (const IoError& e) {
    EXPECT_EQ(e.direction(), IoError::Direction::Write);
    EXPECT_NE(std::string(e.what()).find("file"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("--out"), std::string::npos);
  }
  EXPECT_THROW(StagedFolder(fs::current_path()), IoError);
  EXPECT_THROW(check_output_file(dir / "missing" / "r.json", "--report"), IoError);
  EXPECT_THROW(check_output_file(dir, "--report"), IoError);
  EXPECT_NO_THROW(check_output_file(dir / "r.json", "--report"));
}

}  // namespace
}  // namespace elastic
