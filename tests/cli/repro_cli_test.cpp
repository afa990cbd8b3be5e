// Every reproducer in ../shared/repro through the real binary: `elastic info FILE` exits 65 with
// one stderr line naming the file, within a second (or, for the one documented repair, exits 0 and
// reports the warning). The binary is run with a hard time limit, so a reader that hangs fails the
// test instead of hanging it.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

struct TimedRun {
  int code = -1;           ///< exit code, or 128 + signal
  bool timed_out = false;  ///< killed after the limit
  double seconds = 0.0;    ///< wall time
  std::string out;
  std::string err;
};

std::string slurp(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs `elastic args...` with stdout and stderr in files, killing it after `limit` seconds.
TimedRun run_elastic(const std::vector<std::string>& args, const fs::path& dir, double limit) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  std::vector<std::string> argv_text = {ELASTIC_CLI};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const pid_t child = ::fork();
  if (child == 0) {
    const int in_fd = ::open("/dev/null", O_RDONLY);
    const int out_fd = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(in_fd, 0);
    ::dup2(out_fd, 1);
    ::dup2(err_fd, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  TimedRun run;
  int status = 0;
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  while (::waitpid(child, &status, WNOHANG) == 0) {
    if (elapsed() > limit) {
      ::kill(child, SIGKILL);
      ::waitpid(child, &status, 0);
      run.timed_out = true;
      break;
    }
    ::usleep(1000);
  }
  run.seconds = elapsed();
  run.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  run.out = slurp(out);
  run.err = slurp(err);
  return run;
}

class ReproCli : public ::testing::TestWithParam<const char*> {};

TEST_P(ReproCli, InfoExits65WithinASecondNamingTheFile) {
  ELASTIC_REQUIRE_SHARED_REPRO(path, GetParam());
  const fs::path dir = test::scratch_dir("repro_cli");
  const TimedRun run = run_elastic({"info", path.string()}, dir, 5.0);
  ASSERT_FALSE(run.timed_out) << "still running after 5 s";
  EXPECT_EQ(run.code, 65) << run.err;
  EXPECT_LT(run.seconds, 1.0 * test::kTimeScale);
  // One line: "elastic: <path>: <problem>".
  EXPECT_EQ(run.err.rfind("elastic: " + path.string() + ": ", 0), 0u) << run.err;
  EXPECT_EQ(run.err.find('\n'), run.err.size() - 1) << run.err;
}

INSTANTIATE_TEST_SUITE_P(
    Repro, ReproCli,
    ::testing::Values("ply-ascii-listcount-nan.ply", "ply-ascii-listcount-1e300.ply",
                      "ply-ascii-otherelement-nan.ply", "ply-ascii-vertexlist-neg1e300.ply",
                      "ply-ascii-fractional-count.ply", "ply-ascii-fractional-index.ply",
                      "ply-nan-texcoord-accepted.ply", "off-stoff-nan-texcoord-accepted.off",
                      "stl-ascii-missing-endloop-silently-drops-facet.stl",
                      "stl-1e39-binary-write-unreadable.stl"),
    [](const ::testing::TestParamInfo<const char*>& param) {
      std::string name = fs::path(param.param).stem().string();
      for (char& c : name) {
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      }
      return name;
    });

TEST(ReproCliRepair, EmptyElementWithHugeCountIsSkippedWithAWarning) {
  // The documented repair (docs/file-formats.md): an element without properties holds no bytes,
  // so its 2^63 - 1 rows are skipped at once and the triangle after it is read.
  ELASTIC_REQUIRE_SHARED_REPRO(path, "ply-hang-empty-element-huge-count.ply");
  const fs::path dir = test::scratch_dir("repro_cli_repair");
  const TimedRun run = run_elastic({"info", path.string()}, dir, 5.0);
  ASSERT_FALSE(run.timed_out) << "still running after 5 s";
  EXPECT_EQ(run.code, 0) << run.err;
  EXPECT_LT(run.seconds, 1.0 * test::kTimeScale);
  EXPECT_NE(run.out.find("'junk' has 9223372036854775807 rows but no properties; skipped"),
            std::string::npos)
      << run.out;
}

}  // namespace
}  // namespace elastic
