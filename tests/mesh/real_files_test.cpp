// Reading the public test meshes of ../shared/meshes: the counts are those of
// shared/meshes/README.md (computed by an independent checker) or read off the files with grep/wc.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>

#include "elastic/mesh/mesh_io.h"
#include "elastic/mesh/mesh_validation.h"
#include "support.h"

namespace elastic {
namespace {

TEST(RealFiles, SpotHasSeamUvsAndAResolvableTexture) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "spot.obj");
  const MeshReadResult r = read_mesh(path);
  EXPECT_EQ(r.mesh.num_vertices(), 2930);
  EXPECT_EQ(r.mesh.num_faces(), 5856);
  EXPECT_TRUE(r.mesh.is_triangle_mesh());
  EXPECT_EQ(r.mesh.texcoords.size(), 3225u);
  ASSERT_TRUE(r.mesh.has_texcoords());
  EXPECT_EQ(r.mesh.corner_texcoords.size(), r.mesh.face_vertices.size());
  ASSERT_EQ(r.mesh.materials.size(), 1u);
  EXPECT_EQ(r.mesh.materials[0].name, "initialShadingGroup");
  EXPECT_EQ(r.mesh.materials[0].diffuse_texture.filename(), "spot_texture.png");
  EXPECT_TRUE(std::filesystem::exists(r.mesh.materials[0].diffuse_texture));
  ASSERT_EQ(r.mesh.face_materials.size(), 5856u);
  EXPECT_TRUE(std::all_of(r.mesh.face_materials.begin(), r.mesh.face_materials.end(),
                          [](int m) { return m == 0; }));
  // README: u in [-0.052, 0.989], v in [0.111, 1.0007] (3 decimals given, hence the 1e-3 slack).
  double umin = 1e9, umax = -1e9, vmin = 1e9, vmax = -1e9;
  for (const auto& t : r.mesh.texcoords) {
    umin = std::min(umin, t.x());
    umax = std::max(umax, t.x());
    vmin = std::min(vmin, t.y());
    vmax = std::max(vmax, t.y());
  }
  EXPECT_NEAR(umin, -0.052, 1e-3);
  EXPECT_NEAR(umax, 0.989, 1e-3);
  EXPECT_NEAR(vmin, 0.111, 1e-3);
  EXPECT_NEAR(vmax, 1.0007, 1e-4);
  EXPECT_TRUE(r.warnings.empty());
  const MeshValidation v = validate_mesh(r.mesh);
  EXPECT_TRUE(v.is_clean());
  EXPECT_TRUE(v.is_closed());
  EXPECT_EQ(v.genus, 0);
  EXPECT_EQ(v.euler_characteristic, 2);
}

TEST(RealFiles, BobIsAClosedGenusOneTorusWithTexture) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "bob_tri.obj");
  const MeshReadResult r = read_mesh(path);
  EXPECT_EQ(r.mesh.num_vertices(), 5344);
  EXPECT_EQ(r.mesh.num_faces(), 10688);
  EXPECT_EQ(r.mesh.texcoords.size(), 5647u);
  ASSERT_EQ(r.mesh.materials.size(), 1u);
  EXPECT_TRUE(std::filesystem::exists(r.mesh.materials[0].diffuse_texture));
  const MeshValidation v = validate_mesh(r.mesh);
  EXPECT_TRUE(v.is_clean());
  EXPECT_TRUE(v.is_closed());
  EXPECT_EQ(v.genus, 1);
}

TEST(RealFiles, CamelheadWithCrlfLineEnds) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "camelhead.off");
  const MeshReadResult r = read_mesh(path);
  EXPECT_EQ(r.mesh.num_vertices(), 11381);
  EXPECT_EQ(r.mesh.num_faces(), 22704);
  // First vertex of the file: "-0.105873 0.121359 0.0271172" (CR must not leak into the last
  // number).
  EXPECT_EQ(r.mesh.positions[0].z(), 0.0271172);
  const MeshValidation v = validate_mesh(r.mesh);
  EXPECT_TRUE(v.is_clean());
  EXPECT_EQ(v.num_boundary_loops, 1);
  EXPECT_EQ(v.genus, 0);
}

TEST(RealFiles, PawnWithMultiSpaceFieldsAndCreaseTags) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "osd_catmark_pawn.obj");
  const MeshReadResult r = read_mesh(path);
  EXPECT_EQ(r.mesh.num_vertices(), 601);
  EXPECT_EQ(r.mesh.num_faces(), 588);
  EXPECT_TRUE(r.mesh.is_quad_mesh());
  EXPECT_EQ(r.mesh.texcoords.size(), 4u);
  // grep -c '^t crease' gives 120, each with one vertex pair; the first is "2/1/0 9 584 6.000000".
  ASSERT_EQ(r.mesh.creases.size(), 120u);
  EXPECT_EQ(r.mesh.creases[0].v0, 9);
  EXPECT_EQ(r.mesh.creases[0].v1, 584);
  EXPECT_EQ(r.mesh.creases[0].sharpness, 6.0);
  EXPECT_TRUE(r.mesh.corners.empty());
  EXPECT_TRUE(r.warnings.empty());
  const MeshValidation v = validate_mesh(r.mesh);
  EXPECT_TRUE(v.is_clean());
  EXPECT_EQ(v.num_boundary_loops, 1);
  EXPECT_EQ(v.genus, 0);
}

TEST(RealFiles, OffFilesFromPmp) {
  {
    ELASTIC_REQUIRE_SHARED_MESH(path, "hemisphere.off");
    const MeshReadResult r = read_mesh(path);
    EXPECT_EQ(r.mesh.num_vertices(), 1861);
    EXPECT_EQ(r.mesh.num_faces(), 3600);
    const MeshValidation v = validate_mesh(r.mesh);
    EXPECT_TRUE(v.is_clean());
    EXPECT_EQ(v.num_boundary_loops, 1);
    // A cap of the unit sphere, z >= 0.098: every vertex on the sphere (file has 6 decimals).
    for (const auto& p : r.mesh.positions) {
      EXPECT_NEAR(p.norm(), 1.0, 1e-5);
      EXPECT_GE(p.z(), 0.098 - 1e-6);
    }
  }
  {
    ELASTIC_REQUIRE_SHARED_MESH(path, "fandisk_quads.off");
    const MeshReadResult r = read_mesh(path);
    EXPECT_EQ(r.mesh.num_vertices(), 766);
    EXPECT_EQ(r.mesh.num_faces(), 764);
    EXPECT_TRUE(r.mesh.is_quad_mesh());
    const MeshValidation v = validate_mesh(r.mesh);
    EXPECT_TRUE(v.is_clean());
    EXPECT_TRUE(v.is_closed());
    EXPECT_EQ(v.genus, 0);
  }
  {
    ELASTIC_REQUIRE_SHARED_MESH(path, "grid.off");
    const MeshReadResult r = read_mesh(path);
    EXPECT_EQ(r.mesh.num_vertices(), 145);
    EXPECT_EQ(r.mesh.num_faces(), 256);
    const MeshValidation v = validate_mesh(r.mesh);
    EXPECT_TRUE(v.is_clean());
    EXPECT_EQ(v.num_boundary_loops, 1);
    for (const auto& p : r.mesh.positions) EXPECT_EQ(p.z(), 0.0);
  }
}

// The README's topology column for every clean mesh: closed or number of boundary loops, and genus.
TEST(RealFiles, CleanMeshesMatchTheReadme) {
  struct Expected {
    const char* name;
    int vertices;
    int faces;
    int boundary_loops;
    int genus;
  };
  const Expected expected[] = {
      {"spot_control_mesh.obj", 188, 180, 0, 0},
      {"bunny.obj", 3301, 6598, 0, 0},
      {"armadillo.obj", 14587, 29170, 0, 0},
      {"nefertiti-lowres.obj", 35002, 70000, 0, 0},
      {"decimated-max.obj", 5272, 10540, 0, 0},
      {"fandisk.off", 6475, 12946, 0, 0},
      {"torus.obj", 2304, 4608, 0, 1},
      {"osd_catmark_torus.obj", 32, 32, 0, 1},
      {"osd_catmark_cube.obj", 8, 6, 0, 0},
      {"wavy_vase_open_low_res.obj", 1750, 3312, 2, 0},
      {"cylinder.obj", 48, 64, 2, 0},
      {"hand_lowres.obj", 810, 1602, 1, 0},
      {"mountain.obj", 25600, 50562, 1, 0},
  };
  for (const Expected& e : expected) {
    const std::filesystem::path path = test::shared_mesh(e.name);
    if (path.empty()) continue;
    SCOPED_TRACE(e.name);
    const MeshReadResult r = read_mesh(path);
    EXPECT_EQ(r.mesh.num_vertices(), e.vertices);
    EXPECT_EQ(r.mesh.num_faces(), e.faces);
    const MeshValidation v = validate_mesh(r.mesh);
    EXPECT_TRUE(v.is_clean()) << ::testing::PrintToString(v.describe());
    EXPECT_EQ(v.num_boundary_loops, e.boundary_loops);
    EXPECT_EQ(v.genus, e.genus);
    EXPECT_NO_THROW(require_valid_manifold(r.mesh, e.name));
  }
}

TEST(RealFiles, CubeHasTexcoordsAndNormals) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "osd_catmark_cube.obj");
  const MeshReadResult r = read_mesh(path);
  EXPECT_EQ(r.mesh.texcoords.size(), 14u);
  EXPECT_EQ(r.mesh.normals.size(), 24u);
  EXPECT_TRUE(r.mesh.has_texcoords());
  EXPECT_TRUE(r.mesh.has_normals());
}

TEST(RealFiles, UnusedOsdTagsAreReported) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "osd_catmark_nonman_edges.obj");
  const MeshReadResult r = read_mesh(path);
  // The file's one `t interpolateboundary 1/0/0 1` line is not kept, and says so.
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("interpolateboundary"), std::string::npos);
  EXPECT_TRUE(r.mesh.creases.empty());
  EXPECT_EQ(r.mesh.texcoords.size(), 158u);
}

TEST(RealFiles, BeetleLoadsDespiteItsMissingMaterialLibrary) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "beetle.obj");
  const MeshReadResult r = read_mesh(path);
  EXPECT_EQ(r.mesh.num_vertices(), 1148);
  EXPECT_EQ(r.mesh.num_faces(), 2053);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings[0].find("VWBugMesh002.mtl"), std::string::npos);
}

// Loading speed matters for the CLI; this is not a timed test (no assertion on the time), the time
// is printed so that a regression shows in the log.
TEST(RealFiles, LargestObjLoads) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "nefertiti-lowres.obj");
  const auto start = std::chrono::steady_clock::now();
  const MeshReadResult r = read_mesh(path);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.mesh.num_faces(), 70000);
  RecordProperty("load_ms", std::to_string(ms));
  std::printf("nefertiti-lowres.obj (70000 faces) loaded in %.1f ms\n", ms);
}

}  // namespace
}  // namespace elastic
