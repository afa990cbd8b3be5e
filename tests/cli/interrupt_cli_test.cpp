// Interrupted runs of the real binary leave no temporary files: SIGINT in the middle of a write
// removes the temporary before the process dies (the tool's handler), and the temporary a SIGKILL
// leaves behind is removed by the next run that writes into the folder. No destination is ever
// left truncated.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "elastic/core/atomic_file.h"
#include "elastic/mesh/mesh_io.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

/// Forks `elastic args...` (stdout and stderr to /dev/null). The child waits until `release` is
/// called before it execs, so the parent can prepare files named after its PID.
class Child {
 public:
  explicit Child(const std::vector<std::string>& args) {
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error("pipe");
    std::vector<std::string> text = {ELASTIC_CLI};
    text.insert(text.end(), args.begin(), args.end());
    pid_ = ::fork();
    if (pid_ == 0) {
      ::close(fds[1]);
      char go = 0;
      if (::read(fds[0], &go, 1) != 1) ::_exit(126);
      const int null_fd = ::open("/dev/null", O_RDWR);
      ::dup2(null_fd, 0);
      ::dup2(null_fd, 1);
      ::dup2(null_fd, 2);
      std::vector<char*> argv;
      for (std::string& a : text) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    ::close(fds[0]);
    go_ = fds[1];
  }
  ~Child() {
    if (pid_ > 0 && !reaped_) {
      ::kill(pid_, SIGKILL);
      wait();
    }
    if (go_ >= 0) ::close(go_);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  pid_t pid() const { return pid_; }
  void release() {
    const char go = 1;
    ASSERT_EQ(::write(go_, &go, 1), 1);
    ::close(go_);
    go_ = -1;
  }
  /// The wait status.
  int wait() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    reaped_ = true;
    return status;
  }
  /// True if the child has ended (then `status` is its wait status).
  bool ended(int& status) {
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      reaped_ = true;
      return true;
    }
    return false;
  }

 private:
  pid_t pid_ = -1;
  int go_ = -1;
  bool reaped_ = false;
};

std::vector<std::string> temporaries_in(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator(dir)) {
    long long pid = 0;
    if (parse_temporary_name(entry.path().filename().string(), pid)) {
      found.push_back(entry.path().filename().string());
    }
  }
  return found;
}

TEST(CliInterrupt, SigintInTheMiddleOfAWriteRemovesTheTemporary) {
  // The child's first atomic write goes to plane_quads.obj.tmp.<PID>.0. A FIFO put there before
  // the child starts holds it in the middle of that write for as long as the test wants: once its
  // first bytes arrive, the child is writing, and the FIFO's buffer is full soon after.
  const fs::path dir = test::scratch_dir("cli_sigint");
  Child child({"shapes", "--only", "plane", "--faces", "quad", "--resolution", "200", "--out",
               dir.string()});
  const fs::path tmp = dir / ("plane_quads.obj.tmp." + std::to_string(child.pid()) + ".0");
  ASSERT_EQ(::mkfifo(tmp.c_str(), 0644), 0);
  child.release();
  const int reader = ::open(tmp.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  pollfd wait_for_data{reader, POLLIN, 0};
  ASSERT_EQ(::poll(&wait_for_data, 1, 20000), 1) << "the child never started writing";
  char first[16];
  ASSERT_GT(::read(reader, first, sizeof(first)), 0);
  EXPECT_EQ(std::string(first, 1), "#");  // the OBJ writer's first line, "# written by ..."

  ASSERT_EQ(::kill(child.pid(), SIGINT), 0);
  const int status = child.wait();
  ::close(reader);
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), SIGINT);  // the handler re-raised the signal
  EXPECT_FALSE(fs::exists(fs::symlink_status(tmp))) << "the temporary is still there";
  EXPECT_TRUE(temporaries_in(dir).empty());
  EXPECT_FALSE(fs::exists(dir / "plane_quads.obj"));  // never completed: not there at all
}

TEST(CliInterrupt, TemporaryOfAKilledRunIsRemovedByTheNextRun) {
  // SIGKILL cannot be handled: kill a run while its temporary exists (polled; a few tries, as the
  // write may finish between two looks), then run again into the same folder.
  const fs::path dir = test::scratch_dir("cli_sigkill");
  const std::vector<std::string> big = {"shapes",       "--only", "plane", "--faces",   "quad",
                                        "--resolution", "700",    "--out", dir.string()};
  std::vector<std::string> left;
  for (int attempt = 0; attempt < 5 && left.empty(); ++attempt) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    Child child(big);
    child.release();
    const auto start = std::chrono::steady_clock::now();
    int status = 0;
    while (!child.ended(status) &&
           std::chrono::steady_clock::now() - start < std::chrono::seconds(60)) {
      if (!temporaries_in(dir).empty()) {
        ::kill(child.pid(), SIGKILL);
        child.wait();
        break;
      }
      ::usleep(200);
    }
    left = temporaries_in(dir);
    // A killed run never leaves a partial destination: it is there complete, or not at all.
    if (fs::exists(dir / "plane_quads.obj")) {
      EXPECT_EQ(read_mesh(dir / "plane_quads.obj").mesh.num_faces(), 700 * 700);
    }
  }
  ASSERT_FALSE(left.empty()) << "no run was caught with a temporary in 5 tries";

  // The next run into the folder (a small one) removes the dead run's temporary.
  Child next(
      {"shapes", "--only", "plane", "--faces", "quad", "--resolution", "4", "--out", dir.string()});
  next.release();
  const int status = next.wait();
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_TRUE(temporaries_in(dir).empty()) << left.front() << " is still there";
  EXPECT_EQ(read_mesh(dir / "plane_quads.obj").mesh.num_faces(), 16);
}

}  // namespace
}  // namespace elastic
