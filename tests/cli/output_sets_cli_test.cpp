// Whole output sets and early checks of the real binary: a paste killed (SIGINT or SIGKILL) while
// it writes leaves its --out folder holding the old complete set or the new complete set, never a
// mixture, and the next run leaves no staging folder or temporary behind; output paths that cannot
// be written, runs over the memory limit and a --seed without --jitter are refused before any work,
// with one `elastic:` line; map's --seed reproduces bit for bit and two seeds differ.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "elastic/core/atomic_file.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

struct CliResult {
  int code = -1;
  std::string err;
};

/// Runs `elastic args...` (stdout to /dev/null, stderr captured); `kill_when` (if set) is polled
/// while it runs and the child gets `signal` as soon as it returns true.
CliResult run(const std::vector<std::string>& args, const fs::path& err_file,
              const std::function<bool()>& kill_when = {}, int signal = SIGKILL) {
  std::vector<std::string> text = {ELASTIC_CLI};
  text.insert(text.end(), args.begin(), args.end());
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null_fd = ::open("/dev/null", O_RDWR);
    const int err_fd = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(null_fd, 0);
    ::dup2(null_fd, 1);
    ::dup2(err_fd, 2);
    std::vector<char*> argv;
    for (std::string& a : text) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  int status = 0;
  if (kill_when) {
    const auto start = std::chrono::steady_clock::now();
    while (::waitpid(pid, &status, WNOHANG) == 0) {
      if (kill_when() || std::chrono::steady_clock::now() - start > std::chrono::seconds(120)) {
        ::kill(pid, signal);
        ::waitpid(pid, &status, 0);
        break;
      }
      ::usleep(100);
    }
  } else {
    ::waitpid(pid, &status, 0);
  }
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream in(err_file);
  std::stringstream s;
  s << in.rdbuf();
  r.err = s.str();
  return r;
}

/// Every file of the folder (recursively) and its bytes, but the report, whose timings differ
/// from run to run (it is compared by its job instead).
std::map<std::string, std::string> contents(const fs::path& dir) {
  std::map<std::string, std::string> all;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file() || entry.path().filename() == "report.json") continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    all[fs::relative(entry.path(), dir).string()] = s.str();
  }
  return all;
}

/// The names of the files that differ between two folder contents (missing on either side or with
/// other bytes). gtest's own diff of two maps of megabyte strings takes gigabytes.
std::vector<std::string> differing(const std::map<std::string, std::string>& a,
                                   const std::map<std::string, std::string>& b) {
  std::vector<std::string> names;
  for (const auto& [name, bytes] : a) {
    const auto it = b.find(name);
    if (it == b.end() || it->second != bytes) names.push_back(name);
  }
  for (const auto& [name, bytes] : b) {
    if (a.find(name) == a.end()) names.push_back(name + " (only in the second)");
  }
  return names;
}

long particles_of_report(const fs::path& dir) {
  return nlohmann::json::parse(std::ifstream(dir / "report.json"))["job"]["particles"].get<long>();
}

/// Staging folders, `.old.` folders and temporaries beside or inside `dir`.
std::vector<std::string> leftovers(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator(dir.parent_path())) {
    const std::string name = entry.path().filename().string();
    std::string prefix(".");
    prefix.append(dir.filename().string()).append(".");  // (GCC 12 -Wrestrict: no "." + string)
    if (name.rfind(prefix, 0) == 0) found.push_back(name);
  }
  if (fs::exists(dir)) {
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      long long pid = 0;
      if (parse_temporary_name(entry.path().filename().string(), pid)) {
        found.push_back(entry.path().string());
      }
    }
  }
  return found;
}

std::vector<std::string> paste_args(const fs::path& emblem, long particles, const fs::path& out) {
  return {"paste",
          "-q",
          "--source-image",
          emblem.string(),
          "--target",
          test::project_mesh("cap_quads.obj").string(),
          "--target-region",
          "disk:0,0,1,0.5",
          "--particles",
          std::to_string(particles),
          "--threads",
          "1",
          "--min-vertices",
          "20000",
          "--preview",
          "--preview-size",
          "64",
          "--frames",
          "20",
          "--out",
          out.string()};
}

TEST(CliOutputSets, KilledPasteLeavesTheOldOrTheNewSetAndTheNextRunCleansUp) {
  const fs::path dir = test::scratch_dir("cli_output_sets");
  const fs::path emblem = dir / "emblem.png";
  const fs::path log = dir / "stderr.txt";
  ASSERT_EQ(run({"render", "--emblem", emblem.string(), "--size", "64", "--quiet"}, log).code, 0);
  // The two complete sets: the old (200 particles) and the new (300), each made undisturbed.
  const fs::path old_set = dir / "old", new_set = dir / "new";
  ASSERT_EQ(run(paste_args(emblem, 200, old_set), log).code, 0);
  ASSERT_EQ(run(paste_args(emblem, 300, new_set), log).code, 0);
  const auto old_files = contents(old_set), new_files = contents(new_set);
  ASSERT_FALSE(differing(old_files, new_files).empty());

  const fs::path out = dir / "out";
  int caught_writing = 0;
  for (const int signal : {SIGINT, SIGKILL, SIGINT, SIGKILL}) {
    fs::remove_all(out);
    fs::copy(old_set, out, fs::copy_options::recursive);
    // Kill the new run as soon as its staging folder holds a file: in the middle of writing.
    const auto writing = [&] {
      for (const auto& entry : fs::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        if (name.rfind(".out.staging.", 0) == 0 && !fs::is_empty(entry.path())) return true;
      }
      return false;
    };
    const CliResult killed = run(paste_args(emblem, 300, out), log, writing, signal);
    if (killed.code == 128 + signal) ++caught_writing;
    const auto now = contents(out);
    const bool is_old = now == old_files && particles_of_report(out) == 200;
    const bool is_new = now == new_files && particles_of_report(out) == 300;
    EXPECT_TRUE(is_old || is_new) << "signal " << signal << ": a mixture of the two sets";
    if (signal == SIGINT) {
      // The handler removed the staging folder before dying.
      EXPECT_TRUE(leftovers(out).empty()) << leftovers(out).front();
    }
    // The next run into the folder (its old set intact or replaced whole) cleans whatever a
    // SIGKILL left, and writes the new complete set.
    ASSERT_EQ(run(paste_args(emblem, 300, out), log).code, 0);
    EXPECT_TRUE(leftovers(out).empty()) << leftovers(out).front();
    const std::vector<std::string> diff = differing(contents(out), new_files);
    EXPECT_TRUE(diff.empty()) << "signal " << signal << ": " << diff.size()
                              << " files differ from the new set, first " << diff.front();
  }
  EXPECT_GE(caught_writing, 2) << "the runs ended before they could be killed while writing";
}

TEST(CliOutputSets, UnwritablePathsAreRefusedBeforeTheWork) {
  const fs::path dir = test::scratch_dir("cli_output_paths");
  const fs::path log = dir / "stderr.txt";
  const fs::path file = dir / "a_file";
  std::ofstream(file) << "not a folder\n";
  const std::vector<std::string> map = {"map",
                                        "--source",
                                        test::project_mesh("plane_quads.obj").string(),
                                        "--source-region",
                                        "disk:0,0,0,0.9",
                                        "--target",
                                        test::project_mesh("cap_quads.obj").string(),
                                        "--particles",
                                        "5000000",
                                        "--max-memory",
                                        "100000"};
  // 5 million particles would take minutes: each refusal below comes first, in well under that.
  const auto expect_refused = [&](std::vector<std::string> extra, int code,
                                  const std::string& names) {
    std::vector<std::string> args = map;
    args.insert(args.end(), extra.begin(), extra.end());
    const auto start = std::chrono::steady_clock::now();
    const CliResult r = run(args, log);
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(20)) << r.err;
    EXPECT_EQ(r.code, code) << r.err;
    EXPECT_EQ(r.err.rfind("elastic: ", 0), 0u) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line: " << r.err;
    EXPECT_NE(r.err.find(names), std::string::npos) << r.err;
  };
  expect_refused({"--out", file.string()}, 73, "a_file");
  expect_refused({"--report", (dir / "missing" / "r.json").string()}, 73, "missing");
  expect_refused({"--report", dir.string()}, 73, "cli_output_paths");
  // paste: --report into a missing folder, --out an existing file.
  std::vector<std::string> paste = {"paste",
                                    "--source-image",
                                    (dir / "none.png").string(),
                                    "--target",
                                    test::project_mesh("cap_quads.obj").string(),
                                    "--out",
                                    file.string()};
  CliResult r = run(paste, log);
  EXPECT_EQ(r.code, 73) << r.err;
  EXPECT_NE(r.err.find("a_file"), std::string::npos) << r.err;
  paste.back() = (dir / "out").string();
  paste.push_back("--report");
  paste.push_back((dir / "missing" / "r.json").string());
  r = run(paste, log);
  EXPECT_EQ(r.code, 73) << r.err;
  EXPECT_NE(r.err.find("missing"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
  EXPECT_TRUE(leftovers(dir / "out").empty());
}

TEST(CliOutputSets, MemoryEstimatesRefuseBeforeTheWorkAndNameTheFlag) {
  const fs::path dir = test::scratch_dir("cli_memory");
  const fs::path log = dir / "stderr.txt";
  const std::string cap = test::project_mesh("cap_quads.obj").string();
  // The default limit (at most 4096 MB) refuses 5 million particles on `sample` at once.
  auto start = std::chrono::steady_clock::now();
  CliResult r =
      run({"sample", "--mesh", cap, "--region", "disk:0,0,1,0.5", "--particles", "5000000"}, log);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  EXPECT_EQ(r.code, 65) << r.err;
  EXPECT_NE(r.err.find("--particles 5000000: needs about"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--max-memory"), std::string::npos) << r.err;
  // Small limits: map's particles times 4 per --subdivide level, paste's --resolution.
  r = run({"map", "--source", test::project_mesh("plane_quads.obj").string(), "--source-region",
           "disk:0,0,0,0.9", "--target", cap, "--particles", "2000", "--subdivide", "2",
           "--max-memory", "100"},
          log);
  EXPECT_EQ(r.code, 65) << r.err;
  EXPECT_NE(r.err.find("--subdivide 2"), std::string::npos) << r.err;
  r = run({"map", "--source", test::project_mesh("plane_quads.obj").string(), "--source-region",
           "disk:0,0,0,0.9", "--target", cap, "--particles", "2000", "--subdivide", "0",
           "--max-memory", "100", "--max-iterations", "5", "-q"},
          log);
  EXPECT_NE(r.code, 65) << r.err;  // 2000 particles alone fit in 100 MB
  const fs::path emblem = dir / "emblem.png";
  ASSERT_EQ(run({"render", "--emblem", emblem.string(), "--size", "32", "--quiet"}, log).code, 0);
  r = run({"paste", "--source-image", emblem.string(), "--target", cap, "--particles", "200",
           "--resolution", "64", "--max-memory", "300", "--out", (dir / "out").string()},
          log);
  EXPECT_EQ(r.code, 65) << r.err;
  EXPECT_NE(r.err.find("--target-tessellation 64"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
  // The paste's estimate needs only the target's control mesh: it refuses before any surface is
  // built, so a source that would not even read is never reached.
  const fs::path broken = dir / "broken.obj";
  std::ofstream(broken) << "v 0 0\nf 1 2 3\n";
  r = run({"paste", "--source", broken.string(), "--source-region", "disk:0,0,0,0.5", "--target",
           cap, "--particles", "200", "--resolution", "64", "--max-memory", "300", "--out",
           (dir / "out").string()},
          log);
  EXPECT_EQ(r.code, 65) << r.err;
  EXPECT_NE(r.err.find("--target-tessellation 64"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("broken.obj"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(CliOutputSets, MapSeedReproducesBitForBitAndTwoSeedsDiffer) {
  const fs::path dir = test::scratch_dir("cli_map_seed");
  const fs::path log = dir / "stderr.txt";
  const auto map = [&](const std::string& seed, const std::string& name) {
    const fs::path out = dir / name;
    const CliResult r = run(
        {"map", "-q", "--source", test::project_mesh("plane_quads.obj").string(), "--source-region",
         "disk:0,0,0,0.9", "--target", test::project_mesh("cap_quads.obj").string(), "--particles",
         "300", "--jitter", "0.2", "--seed", seed, "--threads", "1", "--out", out.string()},
        log);
    EXPECT_EQ(r.code, 0) << r.err;
    return contents(out);
  };
  const auto first = map("7", "a"), again = map("7", "b"), other = map("8", "c");
  ASSERT_EQ(first.size(), 3u);
  EXPECT_EQ(first, again);
  EXPECT_NE(first.at("source_grid.obj"), other.at("source_grid.obj"));
  // A seed without jitter would do nothing: refused, naming both flags.
  const CliResult r = run({"map", "--source", test::project_mesh("plane_quads.obj").string(),
                           "--target", test::project_mesh("cap_quads.obj").string(), "--seed", "3"},
                          log);
  EXPECT_EQ(r.code, 64) << r.err;
  EXPECT_NE(r.err.find("--seed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--jitter"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace elastic
