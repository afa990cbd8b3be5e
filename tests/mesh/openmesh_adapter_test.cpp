// PolygonMesh <-> OpenMesh: topology counts known by construction, exact round trips, refusal of
// what a halfedge mesh cannot hold.

#include "elastic/mesh/openmesh_adapter.h"

#include <gtest/gtest.h>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"
#include "support.h"

namespace elastic {
namespace {

/// Unit cube, 6 quads, outward normals; corner c has texture coordinate (c, c / 2).
PolygonMesh textured_cube() {
  PolygonMesh m;
  for (int i = 0; i < 8; ++i) m.positions.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  m.add_face({0, 2, 3, 1});
  m.add_face({4, 5, 7, 6});
  m.add_face({0, 1, 5, 4});
  m.add_face({2, 6, 7, 3});
  m.add_face({0, 4, 6, 2});
  m.add_face({1, 3, 7, 5});
  for (int c = 0; c < 24; ++c) {
    m.texcoords.emplace_back(c, c / 2.0);
    m.corner_texcoords.push_back(c);
  }
  return m;
}

TEST(OpenMeshAdapter, CubeTopologyAndNormals) {
  const HalfedgeMesh om = to_openmesh(textured_cube());
  EXPECT_EQ(om.n_vertices(), 8u);
  EXPECT_EQ(om.n_faces(), 6u);
  EXPECT_EQ(om.n_edges(), 12u);
  for (const auto vh : om.vertices()) {
    EXPECT_EQ(om.valence(vh), 3u);
    EXPECT_FALSE(om.is_boundary(vh));
    // Vertex normals of a cube corner point along the diagonal away from the centre (exact up to
    // the rounding of averaging three unit vectors).
    const auto& p = om.point(vh);
    const OpenMesh::Vec3d outward = (p - OpenMesh::Vec3d(0.5, 0.5, 0.5)).normalized();
    EXPECT_NEAR((om.normal(vh) - outward).norm(), 0.0, 1e-12);
  }
  // Face normals are the axis directions: face 1 is z = 1.
  EXPECT_NEAR((om.normal(om.face_handle(1)) - OpenMesh::Vec3d(0, 0, 1)).norm(), 0.0, 1e-15);
}

TEST(OpenMeshAdapter, FacesKeepTheirFirstCornerAndTexcoords) {
  const PolygonMesh m = textured_cube();
  const HalfedgeMesh om = to_openmesh(m);
  for (int f = 0; f < m.num_faces(); ++f) {
    int k = 0;
    for (const auto h : om.fh_range(om.face_handle(static_cast<unsigned>(f)))) {
      const int corner = m.face_offsets[static_cast<size_t>(f)] + k;
      EXPECT_EQ(om.to_vertex_handle(h).idx(), m.face_vertices[static_cast<size_t>(corner)]);
      EXPECT_EQ(om.texcoord2D(h), OpenMesh::Vec2d(corner, corner / 2.0));
      ++k;
    }
    EXPECT_EQ(k, 4);
  }
}

TEST(OpenMeshAdapter, RoundTripIsExact) {
  const PolygonMesh m = textured_cube();
  const PolygonMesh back = from_openmesh(to_openmesh(m));
  EXPECT_EQ(back.positions, m.positions);
  EXPECT_EQ(back.face_offsets, m.face_offsets);
  EXPECT_EQ(back.face_vertices, m.face_vertices);
  EXPECT_EQ(back.texcoords, m.texcoords);  // all distinct, so one per corner in corner order
  EXPECT_EQ(back.corner_texcoords, m.corner_texcoords);
}

TEST(OpenMeshAdapter, SpotRoundTrip) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "spot.obj");
  const PolygonMesh m = read_mesh(path).mesh;
  const HalfedgeMesh om = to_openmesh(m);
  EXPECT_EQ(om.n_vertices(), 2930u);
  EXPECT_EQ(om.n_faces(), 5856u);
  EXPECT_EQ(om.n_edges(), 8784u);  // closed triangle mesh: E = 3F / 2
  const PolygonMesh back = from_openmesh(om);
  EXPECT_EQ(back.positions, m.positions);
  EXPECT_EQ(back.face_vertices, m.face_vertices);
  // UV values per corner survive (the pool is rebuilt by value).
  ASSERT_EQ(back.corner_texcoords.size(), m.corner_texcoords.size());
  for (size_t c = 0; c < m.corner_texcoords.size(); ++c) {
    ASSERT_EQ(back.texcoords[static_cast<size_t>(back.corner_texcoords[c])],
              m.texcoords[static_cast<size_t>(m.corner_texcoords[c])]);
  }
}

TEST(OpenMeshAdapter, BoundaryAndIsolatedVertices) {
  PolygonMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {5, 5, 5}};
  m.add_face({0, 1, 2});
  m.add_face({0, 2, 3});
  FromOpenMeshOptions with_normals;
  with_normals.normals = true;
  const HalfedgeMesh om = to_openmesh(m);
  EXPECT_EQ(om.n_vertices(), 5u);
  EXPECT_TRUE(om.is_isolated(om.vertex_handle(4)));
  EXPECT_TRUE(om.is_boundary(om.vertex_handle(1)));
  const PolygonMesh back = from_openmesh(om, with_normals);
  EXPECT_EQ(back.positions, m.positions);
  ASSERT_TRUE(back.has_normals());
  EXPECT_NEAR((back.normals[1] - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-15);
}

TEST(OpenMeshAdapter, DeletedElementsAreSkipped) {
  HalfedgeMesh om = to_openmesh(textured_cube());
  om.delete_face(om.face_handle(0), true);  // the z = 0 face; its vertices stay (used by others)
  const PolygonMesh back = from_openmesh(om);
  EXPECT_EQ(back.num_faces(), 5);
  EXPECT_EQ(back.num_vertices(), 8);
}

TEST(OpenMeshAdapter, RefusesWhatAHalfedgeMeshCannotHold) {
  {
    // Three triangles on one edge.
    PolygonMesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
    m.add_face({0, 1, 2});
    m.add_face({1, 0, 3});
    m.add_face({1, 0, 4});
    ToOpenMeshOptions options;
    options.name = "fin";
    try {
      to_openmesh(m, options);
      FAIL() << "accepted a non-manifold edge";
    } catch (const InvalidInputError& e) {
      EXPECT_EQ(e.input(), "fin");
      EXPECT_NE(e.problem().find("non-manifold edges"), std::string::npos) << e.what();
    }
  }
  {
    // Two faces disagreeing about orientation.
    PolygonMesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    m.add_face({0, 1, 2});
    m.add_face({0, 2, 3});
    m.face_vertices[4] = 3;
    m.face_vertices[5] = 2;  // (0, 3, 2): edge 0 -> 2 ... now 2 -> 0 twice
    EXPECT_THROW(to_openmesh(m), InvalidInputError);
  }
  {
    ELASTIC_REQUIRE_SHARED_MESH(path, "beetle.obj");
    EXPECT_THROW(to_openmesh(read_mesh(path).mesh), InvalidInputError);
  }
}

}  // namespace
}  // namespace elastic
