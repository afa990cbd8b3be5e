// The manifold policy has one wording: require_valid_manifold, the OpenMesh adapter and the limit
// surface report the same problem text for the same mesh (manifold_problem), naming the offending
// elements.
#include <gtest/gtest.h>

#include <string>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_validation.h"
#include "elastic/mesh/openmesh_adapter.h"
#include "elastic/surface/limit_surface.h"
#include "surface/surface_test_meshes.h"

namespace elastic {
namespace {

template <class F>
std::string problem_of(F&& make) {
  try {
    make();
  } catch (const InvalidInputError& e) {
    return e.problem();
  }
  return "(accepted)";
}

// Three triangles on the edge (0, 1), like pages of a book.
PolygonMesh book() {
  PolygonMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0, 1}};
  m.add_face({0, 1, 2});
  m.add_face({1, 0, 3});
  m.add_face({0, 1, 4});
  return m;
}

TEST(ManifoldPolicy, OneWordingForEveryConsumer) {
  const PolygonMesh mesh = book();
  const std::string expected = "1 non-manifold edges (used by more than two faces), e.g. (0, 1)";
  EXPECT_EQ(manifold_problem(mesh, validate_mesh(mesh)), expected);
  EXPECT_EQ(problem_of([&] { require_valid_manifold(mesh, "book"); }), expected);
  EXPECT_EQ(problem_of([&] { (void)to_openmesh(mesh); }),
            "cannot build a halfedge mesh: " + expected);
  EXPECT_EQ(problem_of([&] { LimitSurface s(mesh, {.name = "book"}); }), expected);
}

TEST(ManifoldPolicy, AMalformedFaceIsNamedWithItsDefect) {
  PolygonMesh mesh = test::cube();
  mesh.face_vertices[3] = 42;
  const std::string problem = manifold_problem(mesh, validate_mesh(mesh));
  EXPECT_NE(problem.find("face 0 refers to vertex 42, which does not exist"), std::string::npos)
      << problem;
  EXPECT_EQ(problem_of([&] { LimitSurface s(mesh); }), problem);
}

TEST(ManifoldPolicy, RequirementsRelaxWhatAConsumerCanCarry) {
  // Two separate quads with an unreferenced vertex: the tools' policy refuses it, the halfedge
  // adapter and the limit surface carry it.
  PolygonMesh two = test::quad_grid(1, 1, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const PolygonMesh other = test::quad_grid(1, 1, {3, 0, 0}, {1, 0, 0}, {0, 1, 0});
  for (const Eigen::Vector3d& p : other.positions) two.positions.push_back(p);
  two.add_face({4, 5, 7, 6});
  two.positions.emplace_back(9, 9, 9);
  const MeshValidation v = validate_mesh(two);
  EXPECT_EQ(manifold_problem(two, v),
            "2 connected components where one is required (repair_mesh can keep the largest)");
  ManifoldRequirements carry;
  carry.allow_several_components = true;
  EXPECT_EQ(manifold_problem(two, v, carry),
            "1 unreferenced vertices, e.g. 8 (repair_mesh removes them)");
  carry.allow_unreferenced_vertices = true;
  EXPECT_EQ(manifold_problem(two, v, carry), "");
  EXPECT_NO_THROW((void)to_openmesh(two));
  EXPECT_NO_THROW(LimitSurface s(two));
  // No faces: empty for the limit surface, an empty halfedge mesh for the adapter.
  EXPECT_EQ(problem_of([&] { LimitSurface s(PolygonMesh{}); }), "the mesh is empty (no faces)");
  EXPECT_NO_THROW((void)to_openmesh(PolygonMesh{}));
}

}  // namespace
}  // namespace elastic
