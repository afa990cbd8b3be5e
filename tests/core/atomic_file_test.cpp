#include "elastic/core/atomic_file.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

#include "elastic/core/error.h"
#include "support.h"

namespace elastic {
namespace {

std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(AtomicFile, WritesContent) {
  const auto dir = test::scratch_dir("atomic_writes");
  write_file_atomically(dir / "a.txt", [](std::ofstream& out) { out << "hello\n"; });
  EXPECT_EQ(read_all(dir / "a.txt"), "hello\n");
}

TEST(AtomicFile, FailingWriterLeavesOldFileAndNoTemporary) {
  const auto dir = test::scratch_dir("atomic_keeps");
  write_file_atomically(dir / "a.txt", [](std::ofstream& out) { out << "good"; });
  EXPECT_THROW(write_file_atomically(dir / "a.txt",
                                     [](std::ofstream& out) {
                                       out << "partial";
                                       throw std::runtime_error("writer failed");
                                     }),
               std::runtime_error);
  EXPECT_EQ(read_all(dir / "a.txt"), "good");
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1);
}

TEST(AtomicFile, UnwritableDirectoryIsIoErrorNamingThePath) {
  const std::filesystem::path path = "/nonexistent-dir-elastic/x.obj";
  try {
    write_file_atomically(path, [](std::ofstream& out) { out << "x"; });
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_EQ(e.input(), path.string());
    EXPECT_NE(std::string(e.what()).find("cannot create"), std::string::npos);
  }
}

TEST(Error, MessageNamesInputAndProblem) {
  const InvalidInputError e("mesh.obj", "face 3 has vertex index 17 out of range");
  EXPECT_STREQ(e.what(), "mesh.obj: face 3 has vertex index 17 out of range");
  EXPECT_EQ(e.problem(), "face 3 has vertex index 17 out of range");
}

}  // namespace
}  // namespace elastic
