// Regression tests for the reproducers in ../shared/repro (found by fuzzing the readers and by
// hand; its README says what each did before): every one is refused with an InvalidInputError that
// names the file and the problem, or read with a documented repair and a warning, well within a
// second. Then the same hazards in the forms the reproducers do not cover: binary PLY, list lengths
// and element counts beyond the file's size, non-finite values in every format, and writers that
// would produce a file that does not read back.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Reads `path` in a child process and reports whether it finished within `seconds` (the child is
/// killed otherwise), so that a reader that hangs fails the test instead of hanging it.
bool reads_within(const fs::path& path, double seconds) {
  const pid_t child = ::fork();
  if (child == 0) {
    try {
      read_mesh(path);
    } catch (...) {
    }
    ::_exit(0);
  }
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  while (::waitpid(child, &status, WNOHANG) == 0) {
    if (seconds_since(start) > seconds) {
      ::kill(child, SIGKILL);
      ::waitpid(child, &status, 0);
      return false;
    }
    ::usleep(2000);
  }
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

/// Expects reading `path` to throw an InvalidInputError whose input is the path, whose message
/// names the file, and whose problem contains every one of `phrases`; and to do so within a
/// second.
void expect_refused(const fs::path& path, std::initializer_list<const char*> phrases) {
  SCOPED_TRACE(path.filename().string());
  ASSERT_TRUE(reads_within(path, 5.0)) << "the reader did not finish within 5 s";
  const auto start = std::chrono::steady_clock::now();
  try {
    read_mesh(path);
    ADD_FAILURE() << "accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(e.input(), path.string());
    EXPECT_NE(std::string(e.what()).find(path.filename().string()), std::string::npos) << e.what();
    for (const char* phrase : phrases) {
      EXPECT_NE(e.problem().find(phrase), std::string::npos)
          << "'" << phrase << "' not in: " << e.problem();
    }
  }
  // Every reproducer is a few hundred bytes; a second is the contract, the read takes microseconds.
  EXPECT_LT(seconds_since(start), 1.0 * test::kTimeScale);
}

TEST(Repro, PlyListCountNanIsRefused) {
  ELASTIC_REQUIRE_SHARED_REPRO(path, "ply-ascii-listcount-nan.ply");
  expect_refused(path, {"line 14", "nan", "uchar"});
}

TEST(Repro, PlyListCount1e300IsRefused) {
  ELASTIC_REQUIRE_SHARED_REPRO(path, "ply-ascii-listcount-1e300.ply");
  expect_refused(path, {"line 14", "1e300", "uchar"});
}

TEST(Repro, PlyOtherElementNanIsRefused) {
  ELASTIC_REQUIRE_SHARED_REPRO(path, "ply-ascii-otherelement-nan.ply");
  expect_refused(path, {"line 18", "nan", "element 'edge'"});
}

TEST(Repro, PlyVertexListNegative1e300IsRefused) {
  ELASTIC_REQUIRE_SHARED_REPRO(path, "ply-ascii-vertexlist-neg1e300.ply");
  expect_refused(path, {"line 11", "-1e300", "element 'vertex'"});
}

TEST(Repro, PlyFractionalCountIsRefused) {
  ELASTIC_REQUIRE_SHARED_REPRO(path, "ply-ascii-fractional-count.ply");
  expect_refused(path, {"line 14", "3.9", "whole number"});
}

TEST(Repro, PlyFractionalIndexIsRefused) {
  ELASTIC_REQUIRE_SHARED_REPRO(path, "ply-ascii-fractional-index.ply");
  expect_refused(path, {"line 14", "1.7", "whole number"});
}

TEST(Repro, PlyNanTexcoordIsRefused) {
  ELASTIC_REQUIRE_SHARED_REPRO(path, "ply-nan-texcoord-accepted.ply");
  expect_refused(path, {"line 12", "vertex 0", "texture coordinate"});
}

TEST(Repro, StoffNanTexcoordIsRefused) {
  ELASTIC_REQUIRE_SHARED_REPRO(path, "off-stoff-nan-texcoord-accepted.off");
  expect_refused(path, {"line 3", "texture coordinate"});
}

TEST(Repro, StlFacetWithoutEndloopIsRefused) {
  ELASTIC_REQUIRE_SHARED_REPRO(path, "stl-ascii-missing-endloop-silently-drops-facet.stl");
  expect_refused(path, {"line 28", "endloop"});
}

TEST(Repro, StlCoordinateBeyondFloatIsRefusedAtRead) {
  ELASTIC_REQUIRE_SHARED_REPRO(path, "stl-1e39-binary-write-unreadable.stl");
  expect_refused(path, {"line 5", "range of float"});
}

TEST(Repro, PlyElementWithoutPropertiesAndHugeCountIsSkippedInstantly) {
  // 2^63 - 1 rows without properties: they hold no bytes in either encoding, so the element is
  // skipped at once, with a warning, and the rest of the file is read.
  ELASTIC_REQUIRE_SHARED_REPRO(path, "ply-hang-empty-element-huge-count.ply");
  ASSERT_TRUE(reads_within(path, 5.0)) << "the reader hangs";
  const auto start = std::chrono::steady_clock::now();
  const MeshReadResult r = read_mesh(path);
  EXPECT_LT(seconds_since(start), 1.0 * test::kTimeScale);
  EXPECT_EQ(r.mesh.num_vertices(), 3);
  ASSERT_EQ(r.mesh.num_faces(), 1);
  EXPECT_EQ(r.mesh.positions[2], Eigen::Vector3d(0, 1, 0));
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("'junk' has 9223372036854775807 rows but no properties"),
            std::string::npos)
      << r.warnings[0];
}

// ---- The same hazards beyond the reproducers -------------------------------------------------

class ReaderLimits : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::scratch_dir("reader_limits"); }
  fs::path file(const std::string& name, const std::string& bytes) const {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  fs::path dir_;
};

/// Little-endian bytes of a value.
template <class T>
std::string le(T value) {
  std::string bytes(sizeof(T), '\0');
  std::memcpy(bytes.data(), &value, sizeof(T));
  return bytes;
}

/// A binary little-endian PLY: `header_elements` (each "element ...\nproperty ...\n") then the
/// data bytes.
std::string binary_ply(const std::string& header_elements, const std::string& data) {
  return "ply\nformat binary_little_endian 1.0\n" + header_elements + "end_header\n" + data;
}

/// One triangle: three float vertices and one face with a uchar count and int indices.
std::string triangle_data() {
  std::string data;
  for (const float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) data += le(c);
  data += le(static_cast<std::uint8_t>(3));
  for (const std::int32_t i : {0, 1, 2}) data += le(i);
  return data;
}

const char* const kTriangleHeader =
    "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\n";

TEST_F(ReaderLimits, BinaryPlyEmptyElementWithHugeCountIsSkippedInstantly) {
  const fs::path path =
      file("empty_element.ply",
           binary_ply("element junk 2147483648\n" + std::string(kTriangleHeader), triangle_data()));
  ASSERT_TRUE(reads_within(path, 5.0));
  const MeshReadResult r = read_mesh(path);
  EXPECT_EQ(r.mesh.num_faces(), 1);
  EXPECT_EQ(r.warnings.size(), 1u);
}

TEST_F(ReaderLimits, ElementCountsBeyondTheRemainingBytesAreRefusedBeforeReading) {
  // 2^31 rows of one uchar each cannot fit in the 51 bytes that follow the header: refused at
  // once, as a truncated file, instead of reading (or reserving) row by row.
  const std::string header =
      std::string(kTriangleHeader) + "element edge 2147483648\nproperty uchar flag\n";
  const fs::path path = file("huge_count.ply", binary_ply(header, triangle_data()));
  ASSERT_TRUE(reads_within(path, 5.0));
  try {
    read_mesh(path);
    FAIL() << "accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(e.input(), path.string());
    EXPECT_NE(e.problem().find("truncated file: element 'edge' declares 2147483648 rows"),
              std::string::npos)
        << e.problem();
  }
  // The same in ASCII, where a row takes at least two bytes per property.
  const fs::path ascii = file("huge_count_ascii.ply",
                              "ply\nformat ascii 1.0\nelement vertex 1000000\nproperty float x\n"
                              "property float y\nproperty float z\nend_header\n0 0 0\n");
  try {
    read_mesh(ascii);
    FAIL() << "accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(e.problem().find("declares 1000000 rows of at least 6 bytes"), std::string::npos)
        << e.problem();
  }
}

TEST_F(ReaderLimits, ListLengthsBeyondTheRemainingBytesAreRefused) {
  // A uint list length of 4e9 in a file of a few dozen bytes.
  std::string data;
  for (const float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) data += le(c);
  data += le(static_cast<std::uint32_t>(4000000000u));
  for (const std::int32_t i : {0, 1, 2}) data += le(i);
  const fs::path path =
      file("long_list.ply",
           binary_ply("element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 1\nproperty list uint int vertex_indices\n",
                      data));
  try {
    read_mesh(path);
    FAIL() << "accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(e.problem().find("has 4000000000 items"), std::string::npos) << e.problem();
  }
}

TEST_F(ReaderLimits, FractionalAndNonFiniteIndicesInFloatTypesAreRefused) {
  // Binary PLY allows an index list of floats: 1.5 and NaN are not indices.
  for (const float bad : {1.5f, std::numeric_limits<float>::quiet_NaN(), 3e9f}) {
    std::string data;
    for (const float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) data += le(c);
    data += le(static_cast<std::uint8_t>(3));
    for (const float i : {0.f, bad, 2.f}) data += le(i);
    const fs::path path =
        file("float_index.ply",
             binary_ply("element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                        "element face 1\nproperty list uchar float vertex_indices\n",
                        data));
    EXPECT_THROW(read_mesh(path), InvalidInputError) << bad;
  }
  // Whole numbers in a float type are indices like any other.
  std::string data;
  for (const float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) data += le(c);
  data += le(static_cast<std::uint8_t>(3));
  for (const float i : {0.f, 1.f, 2.f}) data += le(i);
  const fs::path good =
      file("float_index_ok.ply",
           binary_ply("element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 1\nproperty list uchar float vertex_indices\n",
                      data));
  EXPECT_EQ(read_mesh(good).mesh.face_vertices, (std::vector<int>{0, 1, 2}));
}

TEST_F(ReaderLimits, AsciiPlyValuesMustFitTheirDeclaredType) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  // A float beyond float's range, a uchar of 256, a negative uchar.
  for (const char* rows : {"0 0 0 1 2 3\n1e39 0 0 1 2 3\n0 1 0 1 2 3\n3 0 1 2\n",
                           "0 0 0 1 2 3\n1 0 0 256 2 3\n0 1 0 1 2 3\n3 0 1 2\n",
                           "0 0 0 1 2 3\n1 0 0 -1 2 3\n0 1 0 1 2 3\n3 0 1 2\n"}) {
    const fs::path path = file("range.ply", head + rows);
    try {
      read_mesh(path);
      ADD_FAILURE() << "accepted: " << rows;
    } catch (const InvalidInputError& e) {
      EXPECT_NE(e.problem().find("line 14"), std::string::npos) << e.problem();
      EXPECT_NE(e.problem().find("range of"), std::string::npos) << e.problem();
    }
  }
  // Whole numbers written as reals ("3.0", "2e0") are still whole numbers.
  const MeshReadResult r =
      read_mesh(file("whole.ply", head + "0 0 0 1 2 3\n1 0 0 255 0 3\n0 1 0 1 2 3\n3.0 0 1 2e0\n"));
  EXPECT_EQ(r.mesh.face_vertices, (std::vector<int>{0, 1, 2}));
  EXPECT_FLOAT_EQ(r.mesh.vertex_colors[1][0], 1.0f);
}

TEST_F(ReaderLimits, NonFiniteAttributesAreRefusedInEveryFormat) {
  const std::string ply_head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  EXPECT_THROW(read_mesh(file("n.ply", ply_head + "0 0 0 0 0 1\n1 0 0 0 nan 1\n0 1 0 0 0 1\n"
                                                  "3 0 1 2\n")),
               InvalidInputError);
  EXPECT_THROW(read_mesh(file("n.off",
                              "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 inf\n0 1 0 0 0 1\n"
                              "3 0 1 2\n")),
               InvalidInputError);
  EXPECT_THROW(read_mesh(file("c.off",
                              "COFF\n3 1 0\n0 0 0 1 1 1\n1 0 0 nan 1 1\n0 1 0 1 1 1\n"
                              "3 0 1 2\n")),
               InvalidInputError);
  EXPECT_THROW(read_mesh(file("c.obj",
                              "v 0 0 0 1 1 1\nv 1 0 0 1e39 1 1\nv 0 1 0 1 1 1\n"
                              "f 1 2 3\n")),
               InvalidInputError);
  EXPECT_THROW(
      read_mesh(file("s.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nt crease 2/1/0 0 1 nan\n")),
      InvalidInputError);
  file("bad.mtl", "newmtl m\nKd 1 nan 1\n");
  try {
    read_mesh(file("m.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n"));
    FAIL() << "accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(e.input(), (dir_ / "bad.mtl").string());
    EXPECT_NE(e.problem().find("line 2"), std::string::npos) << e.problem();
  }
}

TEST_F(ReaderLimits, StlLoopsMustBeClosed) {
  for (const char* text :
       {"solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endfacet\nendsolid s\n",
        "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "outer loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n",
        "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endsolid s\n"}) {
    EXPECT_THROW(read_mesh(file("open.stl", text)), InvalidInputError) << text;
  }
}

// ---- Writers: nothing is written that does not read back -------------------------------------

PolygonMesh triangle() {
  PolygonMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.add_face({0, 1, 2});
  return m;
}

TEST(WriterLimits, StlRefusesCoordinatesBeyondFloat) {
  const fs::path dir = test::scratch_dir("writer_limits_stl");
  PolygonMesh m = triangle();
  m.positions[1].x() = 1e39;  // finite as a double, infinite as STL's float
  for (const bool binary : {false, true}) {
    MeshWriteOptions options;
    options.binary = binary;
    const fs::path path = dir / (binary ? "b.stl" : "a.stl");
    try {
      write_mesh(path, m, options);
      ADD_FAILURE() << "written";
    } catch (const InvalidInputError& e) {
      EXPECT_EQ(e.input(), path.string());
      EXPECT_NE(e.problem().find("vertex 1"), std::string::npos) << e.problem();
    }
    EXPECT_FALSE(fs::exists(path));
  }
  // The largest float is written and reads back exactly.
  m.positions[1].x() = static_cast<double>(std::numeric_limits<float>::max());
  MeshWriteOptions options;
  options.binary = true;
  write_mesh(dir / "max.stl", m, options);
  EXPECT_EQ(read_mesh(dir / "max.stl").mesh.positions[1].x(), m.positions[1].x());
}

TEST(WriterLimits, NonFiniteAttributesAreNotWritten) {
  const fs::path dir = test::scratch_dir("writer_limits_attributes");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const float nanf = std::numeric_limits<float>::quiet_NaN();
  PolygonMesh uv = triangle();
  uv.texcoords = {{0, 0}, {1, nan}, {0, 1}};
  uv.corner_texcoords = {0, 1, 2};
  PolygonMesh normals = triangle();
  normals.normals = {{0, 0, 1}, {0, 0, inf}, {0, 0, 1}};
  normals.corner_normals = {0, 1, 2};
  PolygonMesh colors = triangle();
  colors.vertex_colors = {{1, 1, 1}, {1, nanf, 1}, {1, 1, 1}};
  PolygonMesh crease = triangle();
  crease.creases.push_back({0, 1, nan});
  for (const PolygonMesh* m : {&uv, &normals, &colors, &crease}) {
    for (const char* name : {"m.obj", "m.ply", "m.off"}) {
      EXPECT_THROW(write_mesh(dir / name, *m), InvalidInputError) << name;
      EXPECT_FALSE(fs::exists(dir / name)) << name;
    }
  }
}

}  // namespace
}  // namespace elastic
