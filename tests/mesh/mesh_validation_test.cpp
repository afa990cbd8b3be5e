// Validation counts against shared/meshes/README.md (an independent checker) and against small
// hand-built meshes whose answers are known by construction; repair and the manifold requirement.

#include "elastic/mesh/mesh_validation.h"

#include <gtest/gtest.h>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"
#include "support.h"

namespace elastic {
namespace {

/// Unit cube as 6 quads, counter-clockwise seen from outside (closed, genus 0).
PolygonMesh cube() {
  PolygonMesh m;
  for (int i = 0; i < 8; ++i) m.positions.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  m.add_face({0, 2, 3, 1});  // z = 0, normal -z
  m.add_face({4, 5, 7, 6});  // z = 1, +z
  m.add_face({0, 1, 5, 4});  // y = 0, -y
  m.add_face({2, 6, 7, 3});  // y = 1, +y
  m.add_face({0, 4, 6, 2});  // x = 0, -x
  m.add_face({1, 3, 7, 5});  // x = 1, +x
  return m;
}

/// A strip of n quads along x (a disc with one boundary loop).
PolygonMesh strip(int n) {
  PolygonMesh m;
  for (int i = 0; i <= n; ++i) {
    m.positions.emplace_back(i, 0, 0);
    m.positions.emplace_back(i, 1, 0);
  }
  for (int i = 0; i < n; ++i) m.add_face({2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1});
  return m;
}

TEST(Validation, BeetleMatchesTheReadme) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "beetle.obj");
  const MeshValidation v = validate_mesh(read_mesh(path).mesh);
  EXPECT_EQ(v.num_components, 2);
  EXPECT_EQ(v.non_manifold_edges.count, 47);
  EXPECT_EQ(v.num_boundary_loops, 23);
  EXPECT_EQ(v.non_manifold_edges.examples.size(), 10u);  // default max_examples
  EXPECT_FALSE(v.is_oriented_manifold());
  EXPECT_EQ(v.genus, -1);
  EXPECT_THROW(require_valid_manifold(read_mesh(path).mesh, "beetle.obj"), InvalidInputError);
}

TEST(Validation, NonmanifoldOsdShapesMatchTheReadme) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "osd_catmark_nonman_edges.obj");
  const PolygonMesh mesh = read_mesh(path).mesh;
  EXPECT_EQ(mesh.num_vertices(), 142);
  EXPECT_EQ(mesh.num_faces(), 85);
  const MeshValidation v = validate_mesh(mesh);
  EXPECT_EQ(v.num_components, 9);
  EXPECT_EQ(v.non_manifold_edges.count, 9);
  EXPECT_EQ(v.non_manifold_vertices.count, 1);
  EXPECT_EQ(v.repeated_index_faces.count, 14);
  EXPECT_EQ(v.inconsistent_edges.count, 6);
  EXPECT_EQ(v.unreferenced_vertices.count, 0);
  try {
    require_valid_manifold(mesh, "osd_catmark_nonman_edges.obj");
    FAIL() << "accepted a non-manifold mesh";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(e.input(), "osd_catmark_nonman_edges.obj");
    EXPECT_NE(e.problem().find("9 non-manifold edges"), std::string::npos) << e.what();
  }
}

TEST(Validation, CubeIsClosedGenusZero) {
  const MeshValidation v = validate_mesh(cube());
  EXPECT_TRUE(v.is_clean());
  EXPECT_EQ(v.num_edges, 12);
  EXPECT_EQ(v.euler_characteristic, 2);
  EXPECT_EQ(v.genus, 0);
  EXPECT_TRUE(v.orientable);
  EXPECT_TRUE(v.describe().empty());
}

TEST(Validation, StripIsADisc) {
  const MeshValidation v = validate_mesh(strip(3));
  EXPECT_TRUE(v.is_clean());
  EXPECT_EQ(v.num_boundary_edges, 8);
  EXPECT_EQ(v.num_boundary_loops, 1);
  EXPECT_EQ(v.euler_characteristic, 1);
  EXPECT_EQ(v.genus, 0);
}

// A Moebius strip: a strip of 4 quads whose ends are glued with a half twist. Non-orientable, so
// the winding cannot be repaired, and it has one boundary loop (twice as long as the strip).
TEST(Validation, MoebiusStripIsNotOrientable) {
  PolygonMesh m = strip(4);
  m.positions.resize(8);  // drop the last column (8, 9): the last quad wraps around twisted
  m.face_vertices[static_cast<size_t>(m.face_offsets[3]) + 1] = 1;  // (6, 8, 9, 7) -> (6, 1, 9, 7)
  m.face_vertices[static_cast<size_t>(m.face_offsets[3]) + 2] = 0;  //             -> (6, 1, 0, 7)
  const MeshValidation v = validate_mesh(m);
  EXPECT_EQ(v.non_manifold_edges.count, 0);
  EXPECT_EQ(v.non_manifold_vertices.count, 0);
  EXPECT_FALSE(v.orientable);
  EXPECT_EQ(v.num_boundary_loops, 1);
  EXPECT_EQ(v.num_boundary_edges, 8);
  PolygonMesh repaired = m;
  RepairOptions options;
  options.remove_degenerate_faces = false;  // the twisted quad is a planar bow tie of zero area
  const RepairResult r = repair_mesh(repaired, options);
  EXPECT_TRUE(r.winding_unfixable);
  EXPECT_EQ(r.flipped_faces, 0);
}

TEST(Validation, FlippedFaceIsFoundAndRepairedByMajority) {
  PolygonMesh m = cube();
  // Reverse face 2: its 4 edges are now each used twice in the same direction.
  std::reverse(m.face_vertices.begin() + m.face_offsets[2],
               m.face_vertices.begin() + m.face_offsets[3]);
  const MeshValidation v = validate_mesh(m);
  EXPECT_EQ(v.inconsistent_edges.count, 4);
  EXPECT_TRUE(v.orientable);
  EXPECT_EQ(v.genus, -1);
  EXPECT_THROW(require_valid_manifold(m, "cube"), InvalidInputError);
  const RepairResult r = repair_mesh(m);
  EXPECT_EQ(r.flipped_faces, 1);  // the one flipped face, not the five others
  EXPECT_TRUE(r.after.is_clean());
  // The repaired face keeps its first corner: it was 4 5 1 0 after reversal, now 4 0 1 5.
  const auto face = m.face(2);
  EXPECT_EQ(std::vector<int>(face.begin(), face.end()), (std::vector<int>{4, 0, 1, 5}));
}

TEST(Validation, TwoCubesTouchingAtAVertexMakeANonManifoldVertex) {
  PolygonMesh m = cube();
  const PolygonMesh c = cube();
  // Second cube shifted by (1,1,1) so that its vertex 0 coincides with the first cube's vertex 7.
  std::vector<int> remap(8);
  for (int i = 0; i < 8; ++i) {
    if (i == 0) {
      remap[0] = 7;
      continue;
    }
    remap[static_cast<size_t>(i)] = m.num_vertices();
    m.positions.push_back(c.positions[static_cast<size_t>(i)] + Eigen::Vector3d::Ones());
  }
  for (int f = 0; f < c.num_faces(); ++f) {
    std::vector<int> face;
    for (int v : c.face(f)) face.push_back(remap[static_cast<size_t>(v)]);
    m.add_face(face);
  }
  const MeshValidation v = validate_mesh(m);
  EXPECT_EQ(v.non_manifold_vertices.count, 1);
  ASSERT_EQ(v.non_manifold_vertices.examples.size(), 1u);
  EXPECT_EQ(v.non_manifold_vertices.examples[0], 7);
  EXPECT_EQ(v.non_manifold_edges.count, 0);
  EXPECT_EQ(v.num_components, 1);  // connected through the shared vertex
  EXPECT_EQ(v.genus, -1);
}

TEST(Validation, ThreeFacesOnAnEdgeMakeANonManifoldEdge) {
  PolygonMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  m.add_face({0, 1, 2});
  m.add_face({1, 0, 3});
  m.add_face({1, 0, 4});
  const MeshValidation v = validate_mesh(m);
  EXPECT_EQ(v.non_manifold_edges.count, 1);
  ASSERT_EQ(v.non_manifold_edges.examples.size(), 1u);
  EXPECT_EQ(v.non_manifold_edges.examples[0], std::make_pair(0, 1));
  EXPECT_EQ(v.non_manifold_vertices.count, 0);  // the three faces are joined through the edge
}

TEST(Validation, DegenerateFacesAndUnreferencedVerticesAreRepaired) {
  PolygonMesh m = strip(2);
  m.vertex_colors.assign(m.positions.size(), Eigen::Vector3f(0.5f, 0.5f, 0.5f));
  m.vertex_colors[5] = Eigen::Vector3f(1, 0, 0);
  m.positions.emplace_back(9, 9, 9);  // 6: unreferenced
  m.vertex_colors.emplace_back(0, 1, 0);
  m.positions.emplace_back(2, 0.5, 0);  // 7: on the segment from 4 to 5
  m.vertex_colors.emplace_back(0, 0, 1);
  m.add_face({2, 3, 3});  // repeated index
  m.add_face({4, 7, 5});  // collinear corners: zero area
  m.creases.push_back({4, 5, 2.0});
  m.creases.push_back({6, 0, 1.0});  // on the unreferenced vertex: goes with it
  m.corners.emplace_back(5, 3.0);
  const MeshValidation v = validate_mesh(m);
  EXPECT_EQ(v.repeated_index_faces.count, 1);
  EXPECT_EQ(v.zero_area_faces.count, 1);
  EXPECT_EQ(v.zero_area_faces.examples, std::vector<int>{3});
  EXPECT_EQ(v.unreferenced_vertices.examples, std::vector<int>{6});
  EXPECT_THROW(require_valid_manifold(m, "strip"), InvalidInputError);

  const RepairResult r = repair_mesh(m);
  EXPECT_EQ(r.removed_repeated_index_faces, 1);
  EXPECT_EQ(r.removed_zero_area_faces, 1);
  EXPECT_EQ(r.removed_vertices, 2);  // 6 and 7 (7 was used only by the zero-area face)
  EXPECT_TRUE(r.after.is_clean());
  EXPECT_EQ(m.num_faces(), 2);
  EXPECT_EQ(m.num_vertices(), 6);
  ASSERT_EQ(m.vertex_colors.size(), 6u);
  EXPECT_EQ(m.vertex_colors[5], Eigen::Vector3f(1, 0, 0));
  ASSERT_EQ(m.creases.size(), 1u);
  EXPECT_EQ(m.creases[0].v0, 4);
  ASSERT_EQ(m.corners.size(), 1u);
  EXPECT_EQ(m.corners[0].first, 5);
  EXPECT_NO_THROW(require_valid_manifold(m, "strip"));
}

TEST(Validation, SeveralComponentsNeedTheLargestComponentOption) {
  PolygonMesh m = strip(1);
  const int base = m.num_vertices();
  const PolygonMesh big = strip(3);
  for (const auto& p : big.positions) m.positions.push_back(p + Eigen::Vector3d(0, 0, 5));
  for (int f = 0; f < big.num_faces(); ++f) {
    std::vector<int> face;
    for (int v : big.face(f)) face.push_back(v + base);
    m.add_face(face);
  }
  const MeshValidation v = validate_mesh(m);
  EXPECT_EQ(v.num_components, 2);
  EXPECT_EQ(v.component_faces, (std::vector<int>{3, 1}));
  PolygonMesh copy = m;
  EXPECT_THROW(sanitize_mesh(copy, "two strips"), InvalidInputError);
  RepairOptions options;
  options.keep_largest_component = true;
  const SanitizeResult s = sanitize_mesh(m, "two strips", options);
  EXPECT_EQ(s.repair.removed_components, 1);
  EXPECT_EQ(s.repair.removed_component_faces, 1);
  EXPECT_EQ(s.repair.removed_vertices, 4);
  EXPECT_EQ(m.num_faces(), 3);
  EXPECT_EQ(m.positions[0], Eigen::Vector3d(0, 0, 5));
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_EQ(s.warnings[0].rfind("two strips: ", 0), 0u);
}

TEST(Validation, RepairKeepsCornerAttributesWithTheirFaces) {
  PolygonMesh m = cube();
  for (int c = 0; c < static_cast<int>(m.face_vertices.size()); ++c) {
    m.texcoords.emplace_back(c, -c);
    m.corner_texcoords.push_back(c);
  }
  m.face_materials = {0, 0, 1, 1, 0, 0};
  m.materials.resize(2);
  std::reverse(m.face_vertices.begin() + m.face_offsets[3],
               m.face_vertices.begin() + m.face_offsets[4]);
  std::reverse(m.corner_texcoords.begin() + m.face_offsets[3],
               m.corner_texcoords.begin() + m.face_offsets[4]);
  repair_mesh(m);
  // Each corner still carries the texcoord it was given: corner c of the original had texcoord c.
  const PolygonMesh original = cube();
  for (int f = 0; f < 6; ++f) {
    for (int c = m.face_offsets[f]; c < m.face_offsets[f + 1]; ++c) {
      const int t = m.corner_texcoords[static_cast<size_t>(c)];
      EXPECT_EQ(original.face_vertices[static_cast<size_t>(t)],
                m.face_vertices[static_cast<size_t>(c)]);
    }
  }
  EXPECT_EQ(m.face_materials, (std::vector<int>{0, 0, 1, 1, 0, 0}));
  EXPECT_TRUE(validate_mesh(m).is_clean());
}

TEST(Validation, MalformedFacesAreReportedNotFollowed) {
  PolygonMesh m = strip(1);
  m.add_face({0, 1, 17});
  const MeshValidation v = validate_mesh(m);
  EXPECT_EQ(v.malformed_faces.count, 1);
  EXPECT_EQ(v.num_edges, 4);
  EXPECT_THROW(repair_mesh(m), InvalidInputError);
  EXPECT_THROW(require_valid_manifold(m, "m"), InvalidInputError);
}

TEST(Validation, ClosedRequirement) {
  ManifoldRequirements closed;
  closed.allow_boundary = false;
  EXPECT_NO_THROW(require_valid_manifold(cube(), "cube", closed));
  EXPECT_THROW(require_valid_manifold(strip(2), "strip", closed), InvalidInputError);
}

TEST(Validation, NonFiniteVertices) {
  PolygonMesh m = cube();
  m.positions[3].x() = std::numeric_limits<double>::quiet_NaN();
  const MeshValidation v = validate_mesh(m);
  EXPECT_EQ(v.non_finite_vertices.examples, std::vector<int>{3});
  EXPECT_FALSE(v.is_clean());
  EXPECT_THROW(require_valid_manifold(m, "cube"), InvalidInputError);
}

TEST(Validation, RepairOfTheOsdShapes) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "osd_catmark_nonman_edges.obj");
  PolygonMesh mesh = read_mesh(path).mesh;
  const RepairResult r = repair_mesh(mesh);
  EXPECT_EQ(r.removed_repeated_index_faces, 14);
  // What repair cannot fix stays reported.
  EXPECT_GT(r.after.non_manifold_edges.count, 0);
  EXPECT_EQ(r.after.repeated_index_faces.count, 0);
  EXPECT_THROW(sanitize_mesh(mesh, "osd"), InvalidInputError);
}

}  // namespace
}  // namespace elastic
