// --max-image-pixels through the real binary: a PNG bomb given as --source-image is refused from
// its header, with exit 65, in well under a second and without the process ever using 100 MB; the
// message gives the size, the limit and the flag; the flag raises or lowers the limit.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "png_bomb.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

struct MeasuredRun {
  int code = -1;
  double seconds = 0.0;
  double peak_mb = 0.0;  ///< the child's peak resident memory
  std::string err;
};

/// Runs `elastic args...` (stderr to a file) and measures its wall time and peak memory.
MeasuredRun run_measured(const std::vector<std::string>& args, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  std::vector<std::string> text = {ELASTIC_CLI};
  text.insert(text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : text) argv.push_back(a.data());
  argv.push_back(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const pid_t child = ::fork();
  if (child == 0) {
    const int null_fd = ::open("/dev/null", O_RDWR);
    const int err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(null_fd, 0);
    ::dup2(null_fd, 1);
    ::dup2(err_fd, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  int status = 0;
  rusage usage{};
  ::wait4(child, &status, 0, &usage);
  MeasuredRun run;
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  run.peak_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;
  std::ifstream in(err);
  std::stringstream s;
  s << in.rdbuf();
  run.err = s.str();
  return run;
}

TEST(CliImageLimits, PngBombAsSourceImageIsRefusedAtOnce) {
  const fs::path dir = test::scratch_dir("cli_png_bomb");
  const fs::path bomb = dir / "bomb.png";
  test::write_zero_grey_png(bomb, 20000, 20000);
  const MeasuredRun run = run_measured(
      {"map", "--source-image", bomb.string(), "--target",
       test::project_mesh("cap_quads.obj").string(), "--report", (dir / "r.json").string()},
      dir);
  EXPECT_EQ(run.code, 65) << run.err;
  EXPECT_LT(run.seconds, 1.0 * test::kTimeScale);
  // Decoding would need 400 MB for the grey bytes alone (the issue measured 8.45 GB).
  EXPECT_LT(run.peak_mb, 100.0 + test::kExtraMegabytes);
  EXPECT_EQ(run.err.rfind("elastic: " + bomb.string() +
                              ": image of 20000 x 20000 = 400000000 "
                              "pixels is larger than the limit of 67108864 pixels; raise it with "
                              "--max-image-pixels\n",
                          0),
            0u)
      << run.err;
  EXPECT_FALSE(fs::exists(dir / "r.json"));
}

TEST(CliImageLimits, FlagSetsTheLimit) {
  const fs::path dir = test::scratch_dir("cli_image_limit_flag");
  const fs::path image = dir / "small.png";
  test::write_zero_grey_png(image, 40, 25);  // 1000 pixels
  const std::vector<std::string> base = {"map",
                                         "--source-image",
                                         image.string(),
                                         "--target",
                                         test::project_mesh("cap_quads.obj").string(),
                                         "--particles",
                                         "100"};
  std::vector<std::string> lowered = base;
  lowered.insert(lowered.end(), {"--max-image-pixels", "999"});
  const MeasuredRun refused = run_measured(lowered, dir);
  EXPECT_EQ(refused.code, 65) << refused.err;
  EXPECT_NE(refused.err.find("40 x 25 = 1000 pixels is larger than the limit of 999 pixels"),
            std::string::npos)
      << refused.err;
  std::vector<std::string> exact = base;
  exact.insert(exact.end(), {"--max-image-pixels", "1000"});
  EXPECT_EQ(run_measured(exact, dir).code, 0);
  std::vector<std::string> zero = base;
  zero.insert(zero.end(), {"--max-image-pixels", "0"});
  EXPECT_EQ(run_measured(zero, dir).code, 64);  // not a positive number: a usage error
}

}  // namespace
}  // namespace elastic
