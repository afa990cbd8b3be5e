// Tests of the procedural shapes against their definitions: topology (Euler characteristic,
// boundary loops, manifoldness, consistent and outward orientation), positions on the analytic
// surfaces, mesh quality, resolution, scale, and option validation. All checks are in
// mesh_checks.h, independent of the library's own mesh code.

#include "elastic/shapes/procedural_shapes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "elastic/core/error.h"
#include "shapes/mesh_checks.h"

namespace elastic {
namespace {

using test::analyse;
using test::MeshReport;

constexpr double kPi = std::numbers::pi;
constexpr double kDegree = kPi / 180.0;
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Expected {
  int euler;
  int loops;
  bool pole;  ///< a surface of revolution closed at a pole (quad disk or n-gon in the quad version)
};

const std::map<std::string, Expected>& expectations() {
  static const std::map<std::string, Expected> table{
      {"plane", {1, 1, false}}, {"cylinder", {0, 2, false}}, {"torus", {0, 0, false}},
      {"vase", {1, 1, true}},   {"goblet", {1, 1, true}},    {"cap", {1, 1, true}},
      {"sphere", {2, 0, false}}};
  return table;
}

ShapeOptions options_for(ShapeFaces faces, int resolution = 32) {
  ShapeOptions options;
  options.faces = faces;
  options.resolution = resolution;
  return options;
}

double radius(const Eigen::Vector3d& p) {
  return std::hypot(p.x(), p.y());
}

std::string faces_name(ShapeFaces faces) {
  return faces == ShapeFaces::Triangles ? "tris" : "quads";
}

// Structural checks every shape must pass at any resolution.
void expect_valid(const std::string& name, const PolygonMesh& mesh, const std::string& context) {
  SCOPED_TRACE(context);
  const Expected expected = expectations().at(name);
  const MeshReport report = analyse(mesh);
  EXPECT_GT(mesh.num_faces(), 0);
  EXPECT_EQ(report.unreferenced_vertices, 0);
  EXPECT_EQ(report.faces_with_repeated_corner, 0);
  EXPECT_EQ(report.non_manifold_edges, 0);
  EXPECT_EQ(report.inconsistent_edges, 0) << "faces not consistently oriented";
  EXPECT_EQ(report.non_manifold_vertices, 0);
  EXPECT_TRUE(report.boundary_is_manifold);
  EXPECT_EQ(report.components, 1);
  EXPECT_EQ(report.euler_characteristic(), expected.euler);
  EXPECT_EQ(static_cast<int>(report.boundary_loops.size()), expected.loops);

  // Outward orientation. The plane: every normal is +z. Everything else: closing the boundary loops
  // with fans gives a closed surface whose signed volume is positive iff the normals point outward.
  if (name == "plane") {
    for (int f = 0; f < mesh.num_faces(); ++f) EXPECT_GT(test::area_vector(mesh, f).z(), 0.0);
  } else {
    EXPECT_GT(test::closed_up_volume(mesh, report), 0.0);
  }
  // Surfaces of revolution (all but the plane): normals point away from the z axis on average.
  if (name != "plane") {
    double outward = 0.0;
    for (int f = 0; f < mesh.num_faces(); ++f) {
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (int v : mesh.face(f)) centre += mesh.positions[static_cast<size_t>(v)];
      const Eigen::Vector3d radial(centre.x(), centre.y(), 0.0);
      if (radial.norm() > 0.0) outward += test::area_vector(mesh, f).dot(radial.normalized());
    }
    EXPECT_GT(outward, 0.0);
  }

  // No degenerate or folded faces: every corner turns the same way as the face's normal (a convex,
  // non-degenerate polygon), with a corner angle of at least 5 degrees. The coarsest meshes (n = 3)
  // have the worst angles; 5 degrees is far from the 0 of a degenerate face.
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto face = mesh.face(f);
    const Eigen::Vector3d normal = test::area_vector(mesh, f);
    for (size_t c = 0; c < face.size(); ++c) {
      const Eigen::Vector3d& p = mesh.positions[static_cast<size_t>(face[c])];
      const Eigen::Vector3d a =
          mesh.positions[static_cast<size_t>(face[(c + 1) % face.size()])] - p;
      const Eigen::Vector3d b =
          mesh.positions[static_cast<size_t>(face[(c + face.size() - 1) % face.size()])] - p;
      EXPECT_GT(a.cross(b).dot(normal), 0.0) << "face " << f << " corner " << c;
    }
  }
  EXPECT_GT(test::min_corner_angle(mesh), 5.0 * kDegree);
  // No duplicated vertices (seams welded): all shapes have extent ~1, their edges are >= ~0.003.
  EXPECT_GT(test::min_vertex_distance(mesh), 1e-3);
}

class ShapeTest : public ::testing::TestWithParam<std::tuple<std::string, ShapeFaces>> {
 protected:
  std::string name() const { return std::get<0>(GetParam()); }
  ShapeFaces faces() const { return std::get<1>(GetParam()); }
};

TEST_P(ShapeTest, ValidAtDefaultResolution) {
  const PolygonMesh mesh = make_shape(name(), options_for(faces()));
  expect_valid(name(), mesh, name() + " " + faces_name(faces()));
  if (faces() == ShapeFaces::Triangles) {
    EXPECT_TRUE(mesh.is_triangle_mesh());
  } else {
    EXPECT_TRUE(mesh.is_quad_mesh()) << "an even resolution gives an all-quad mesh";
  }
  // Small enough to commit: the default resolution stays within ~4k faces.
  EXPECT_LE(mesh.num_faces(), 4500);
}

TEST_P(ShapeTest, ValidAtCoarseAndOddResolutions) {
  for (int resolution : {3, 4, 5, 6, 7, 8, 10, 13}) {
    const PolygonMesh mesh = make_shape(name(), options_for(faces(), resolution));
    expect_valid(name(), mesh,
                 name() + " " + faces_name(faces()) + " n=" + std::to_string(resolution));
    if (faces() == ShapeFaces::Triangles) {
      EXPECT_TRUE(mesh.is_triangle_mesh());
    } else {
      // Quads, except at a pole for odd n: one central n-gon (an odd boundary cannot bound quads).
      int non_quads = 0;
      for (int f = 0; f < mesh.num_faces(); ++f) {
        if (mesh.face_size(f) != 4) {
          ++non_quads;
          EXPECT_EQ(mesh.face_size(f), resolution);
        }
      }
      const bool ngon = expectations().at(name()).pole && resolution % 2 != 0;
      EXPECT_EQ(non_quads, ngon ? 1 : 0) << "n=" << resolution;
    }
  }
}

TEST_P(ShapeTest, ValidAtFinerResolution) {
  const PolygonMesh mesh = make_shape(name(), options_for(faces(), 66));
  expect_valid(name(), mesh, name() + " n=66");
}

TEST_P(ShapeTest, ScaleMultipliesPositions) {
  ShapeOptions options = options_for(faces(), 12);
  const PolygonMesh unit = make_shape(name(), options);
  options.scale = 2.5;
  const PolygonMesh scaled = make_shape(name(), options);
  ASSERT_EQ(scaled.num_vertices(), unit.num_vertices());
  EXPECT_EQ(scaled.face_vertices, unit.face_vertices);
  EXPECT_EQ(scaled.face_offsets, unit.face_offsets);
  for (int v = 0; v < unit.num_vertices(); ++v) {
    // One multiplication per coordinate: equal up to the last bit's rounding.
    EXPECT_LE((scaled.positions[v] - 2.5 * unit.positions[v]).norm(), 1e-15);
  }
}

TEST_P(ShapeTest, NamedConstructorMatchesMakeShape) {
  using Maker = PolygonMesh (*)(const ShapeOptions&);
  static const std::map<std::string, Maker> makers{
      {"plane", make_plane},  {"cylinder", make_cylinder}, {"torus", make_torus},
      {"vase", make_vase},    {"goblet", make_goblet},     {"cap", make_cap},
      {"sphere", make_sphere}};
  const ShapeOptions options = options_for(faces(), 9);
  const PolygonMesh a = make_shape(name(), options);
  const PolygonMesh b = makers.at(name())(options);
  EXPECT_EQ(a.face_vertices, b.face_vertices);
  EXPECT_EQ(a.positions, b.positions);
}

std::string param_name(const ::testing::TestParamInfo<ShapeTest::ParamType>& info) {
  return std::get<0>(info.param) + "_" + faces_name(std::get<1>(info.param));
}

INSTANTIATE_TEST_SUITE_P(AllShapes, ShapeTest,
                         ::testing::Combine(::testing::Values("plane", "cylinder", "torus", "vase",
                                                              "goblet", "cap", "sphere"),
                                            ::testing::Values(ShapeFaces::Triangles,
                                                              ShapeFaces::Quads)),
                         param_name);

TEST(ShapeNames, ListsEveryShape) {
  const std::vector<std::string>& names = shape_names();
  EXPECT_EQ(
      std::set<std::string>(names.begin(), names.end()),
      (std::set<std::string>{"plane", "cylinder", "torus", "vase", "goblet", "cap", "sphere"}));
  EXPECT_EQ(names.size(), 7u);
}

// ---------------------------------------------------------------------------------------------------
// Positions on the analytic surfaces. Vertices are computed in closed form (sin, cos, one
// normalisation), so they are on the surface to a few ulps: 1e-12 leaves a wide margin.

constexpr double kOnSurface = 1e-12;

TEST(Plane, VerticesOnTheSquareAndCornersPresent) {
  for (ShapeFaces faces : {ShapeFaces::Triangles, ShapeFaces::Quads}) {
    const PolygonMesh mesh = make_plane(options_for(faces, 20));
    int corners = 0;
    for (const Eigen::Vector3d& p : mesh.positions) {
      EXPECT_EQ(p.z(), 0.0);
      EXPECT_LE(std::abs(p.x()), 1.0);
      EXPECT_LE(std::abs(p.y()), 1.0);
      corners += std::abs(p.x()) == 1.0 && std::abs(p.y()) == 1.0;
    }
    EXPECT_EQ(corners, 4);
    // Resolution = segments per side: the boundary has 4 N edges, the grid N^2 squares.
    const MeshReport report = analyse(mesh);
    ASSERT_EQ(report.boundary_loops.size(), 1u);
    EXPECT_EQ(report.boundary_loops[0].size(), 80u);
    EXPECT_EQ(mesh.num_faces(), faces == ShapeFaces::Quads ? 400 : 800);
    EXPECT_EQ(mesh.num_vertices(), 21 * 21);
  }
}

TEST(Cylinder, VerticesOnTheTubeAndRimsAtBothEnds) {
  for (ShapeFaces faces : {ShapeFaces::Triangles, ShapeFaces::Quads}) {
    const int n = 24;
    const PolygonMesh mesh = make_cylinder(options_for(faces, n));
    for (const Eigen::Vector3d& p : mesh.positions) {
      EXPECT_NEAR(radius(p), 0.5, kOnSurface);
      EXPECT_LE(std::abs(p.z()), 1.0);
    }
    const MeshReport report = analyse(mesh);
    ASSERT_EQ(report.boundary_loops.size(), 2u);
    std::set<double> rim_heights;
    for (const std::vector<int>& loop : report.boundary_loops) {
      EXPECT_EQ(static_cast<int>(loop.size()), n) << "resolution = segments around the axis";
      for (int v : loop) rim_heights.insert(mesh.positions[static_cast<size_t>(v)].z());
    }
    EXPECT_EQ(rim_heights, (std::set<double>{-1.0, 1.0}));
  }
}

TEST(Cylinder, VolumeMatchesTheInscribedPrism) {
  // Quads: every cross-section is the regular n-gon inscribed in the circle, so the capped mesh is
  // exactly a prism of volume (n/2) r^2 sin(2 pi / n) h.
  const int n = 32;
  const double r = 0.5;
  const double h = 2.0;
  const PolygonMesh quads = make_cylinder(options_for(ShapeFaces::Quads, n));
  const double prism = 0.5 * n * r * r * std::sin(2.0 * kPi / n) * h;
  EXPECT_NEAR(test::closed_up_volume(quads, analyse(quads)), prism, 1e-12);
  // Triangles: rings alternate by half a step, so the bands are antiprisms, convex and inscribed in
  // the cylinder (volume below pi r^2 h). Their deficit is second order in the angular step, like
  // the inscribed n-gon's (2 pi / n)^2 / 6; allow twice that.
  const PolygonMesh tris = make_cylinder(options_for(ShapeFaces::Triangles, n));
  const double cylinder = kPi * r * r * h;
  const double volume = test::closed_up_volume(tris, analyse(tris));
  EXPECT_LT(volume, cylinder);
  EXPECT_GT(volume, cylinder * (1.0 - 2.0 * std::pow(2.0 * kPi / n, 2) / 6.0));
}

TEST(Torus, VerticesAtMinorRadiusFromTheCoreCircle) {
  for (ShapeFaces faces : {ShapeFaces::Triangles, ShapeFaces::Quads}) {
    const int n = 28;
    const PolygonMesh mesh = make_torus(options_for(faces, n));
    int outer_equator = 0;
    for (const Eigen::Vector3d& p : mesh.positions) {
      EXPECT_NEAR(std::hypot(radius(p) - 1.0, p.z()), 0.35, kOnSurface);
      outer_equator += std::abs(radius(p) - 1.35) < kOnSurface;
    }
    // Resolution = segments around the z axis: the outer equator is one ring of n vertices.
    EXPECT_EQ(outer_equator, n);
    // Volume 2 pi^2 R r^2. Every ring has n vertices, so there are m = V / n rings around the tube.
    // The polyhedron's deficit is second order in both angular steps, like an inscribed polygon's
    // (2 pi / k)^2 / 6 for k sides; allow 1.5 times the sum (the rings are not evenly spaced).
    const int m = mesh.num_vertices() / n;
    ASSERT_EQ(m * n, mesh.num_vertices());
    const double exact = 2.0 * kPi * kPi * 0.35 * 0.35;
    const double deficit = (std::pow(2.0 * kPi / m, 2) + std::pow(2.0 * kPi / n, 2)) / 6.0;
    const double volume = test::closed_up_volume(mesh, analyse(mesh));
    EXPECT_LT(volume, exact);
    EXPECT_GT(volume, exact * (1.0 - 1.5 * deficit)) << "m = " << m;
  }
}

TEST(Sphere, VerticesOnTheUnitSphere) {
  for (ShapeFaces faces : {ShapeFaces::Triangles, ShapeFaces::Quads}) {
    const PolygonMesh mesh = make_sphere(options_for(faces, 32));
    for (const Eigen::Vector3d& p : mesh.positions) EXPECT_NEAR(p.norm(), 1.0, kOnSurface);
    // Inscribed in the ball: the volume is less than 4 pi / 3, by the second-order chord deficit
    // (edges of ~11 degrees at n = 32: a few percent at most).
    const double volume = test::closed_up_volume(mesh, analyse(mesh));
    EXPECT_LT(volume, 4.0 * kPi / 3.0);
    EXPECT_GT(volume, 0.95 * 4.0 * kPi / 3.0);
  }
}

TEST(Sphere, ResolutionCountsSegmentsAroundTheEquator) {
  // Quads: a cube with N = n / 4 segments per edge (equator 4 N = n): 6 N^2 faces, valence 3 at the
  // 8 cube corners and 4 elsewhere. Triangles: frequency k = round(n atan(2) / (2 pi)) icosahedron,
  // 20 k^2 faces, valence 5 at the 12 icosahedron vertices and 6 elsewhere.
  for (int n : {8, 32, 64}) {
    const PolygonMesh quads = make_sphere(options_for(ShapeFaces::Quads, n));
    const int N = n / 4;
    EXPECT_EQ(quads.num_faces(), 6 * N * N);
    std::map<int, int> quad_valences;
    for (int v : test::valences(quads)) ++quad_valences[v];
    EXPECT_EQ(quad_valences[3], 8);
    EXPECT_EQ(quad_valences[4], quads.num_vertices() - 8);

    const PolygonMesh tris = make_sphere(options_for(ShapeFaces::Triangles, n));
    const int k = static_cast<int>(std::lround(n * std::atan(2.0) / (2.0 * kPi)));
    EXPECT_EQ(tris.num_faces(), 20 * k * k);
    std::map<int, int> tri_valences;
    for (int v : test::valences(tris)) ++tri_valences[v];
    EXPECT_EQ(tri_valences[5], 12);
    EXPECT_EQ(tri_valences[6], tris.num_vertices() - 12);
  }
}

TEST(Cap, VerticesOnTheUnitSphereWithinSeventyFiveDegrees) {
  for (ShapeFaces faces : {ShapeFaces::Triangles, ShapeFaces::Quads}) {
    const int n = 32;
    const PolygonMesh mesh = make_cap(options_for(faces, n));
    bool pole = false;
    for (const Eigen::Vector3d& p : mesh.positions) {
      EXPECT_NEAR(p.norm(), 1.0, kOnSurface);
      EXPECT_LE(std::atan2(radius(p), p.z()), 75.0 * kDegree + kOnSurface);
      pole = pole || (radius(p) == 0.0 && p.z() == 1.0);
    }
    EXPECT_TRUE(pole)
        << "the cap is closed at the pole (n = 32: the quad disk has a centre vertex)";
    const MeshReport report = analyse(mesh);
    ASSERT_EQ(report.boundary_loops.size(), 1u);
    EXPECT_EQ(static_cast<int>(report.boundary_loops[0].size()), n);
    for (int v : report.boundary_loops[0]) {
      EXPECT_NEAR(std::atan2(radius(mesh.positions[v]), mesh.positions[v].z()), 75.0 * kDegree,
                  kOnSurface);
    }
    // Signed volume of the capped mesh vs the spherical segment of height h = 1 - cos 75:
    // pi h^2 (3 - h) / 3, less the inscribed polyhedron's second-order deficit (a few percent).
    const double h = 1.0 - std::cos(75.0 * kDegree);
    const double segment = kPi * h * h * (3.0 - h) / 3.0;
    const double volume = test::closed_up_volume(mesh, report);
    EXPECT_LT(volume, segment);
    EXPECT_GT(volume, 0.9 * segment);
  }
}

// ---------------------------------------------------------------------------------------------------
// Vase and goblet: they must look like one. Radii are read off the vertices per height band.

struct RadialProfile {
  double z_min = kInf;
  double z_max = -kInf;
  /// Largest vertex radius with z in [lo, hi].
  std::function<double(double, double)> max_radius;
};

RadialProfile radial_profile(const PolygonMesh& mesh) {
  RadialProfile profile;
  for (const Eigen::Vector3d& p : mesh.positions) {
    profile.z_min = std::min(profile.z_min, p.z());
    profile.z_max = std::max(profile.z_max, p.z());
  }
  profile.max_radius = [&mesh](double lo, double hi) {
    double r = 0.0;
    for (const Eigen::Vector3d& p : mesh.positions) {
      if (p.z() >= lo && p.z() <= hi) r = std::max(r, radius(p));
    }
    return r;
  };
  return profile;
}

TEST(Vase, BulgingBodyNeckAndFlaredLip) {
  for (ShapeFaces faces : {ShapeFaces::Triangles, ShapeFaces::Quads}) {
    SCOPED_TRACE(faces_name(faces));
    const PolygonMesh mesh = make_vase(options_for(faces, 32));
    const RadialProfile profile = radial_profile(mesh);
    const double height = profile.z_max - profile.z_min;
    EXPECT_GT(height, 1.0);
    const MeshReport report = analyse(mesh);
    ASSERT_EQ(report.boundary_loops.size(), 1u);
    // The mouth is the top: its vertices are the highest.
    double rim_radius = 0.0;
    for (int v : report.boundary_loops[0]) {
      EXPECT_EQ(mesh.positions[v].z(), profile.z_max);
      rim_radius = radius(mesh.positions[v]);
    }
    auto band = [&](double from, double to) {
      return profile.max_radius(profile.z_min + from * height, profile.z_min + to * height);
    };
    const double body = band(0.2, 0.45);
    const double neck = band(0.78, 0.85);
    EXPECT_GT(body, 2.0 * neck) << "body bulges well beyond the neck";
    EXPECT_GT(rim_radius, 1.3 * neck) << "the lip flares out from the neck";
    EXPECT_LT(rim_radius, body);
    // The bottom is closed and nearly flat: there are vertices on (or next to) the axis at the
    // bottom.
    double lowest_radius = kInf;
    for (const Eigen::Vector3d& p : mesh.positions) {
      if (p.z() <= profile.z_min + 0.01 * height)
        lowest_radius = std::min(lowest_radius, radius(p));
    }
    EXPECT_LT(lowest_radius, 0.05);
  }
}

TEST(Goblet, CupThinStemAndFootClosedUnderneath) {
  for (ShapeFaces faces : {ShapeFaces::Triangles, ShapeFaces::Quads}) {
    SCOPED_TRACE(faces_name(faces));
    const PolygonMesh mesh = make_goblet(options_for(faces, 32));
    const RadialProfile profile = radial_profile(mesh);
    const double height = profile.z_max - profile.z_min;
    const MeshReport report = analyse(mesh);
    ASSERT_EQ(report.boundary_loops.size(), 1u);
    for (int v : report.boundary_loops[0]) EXPECT_EQ(mesh.positions[v].z(), profile.z_max);
    auto band = [&](double from, double to) {
      return profile.max_radius(profile.z_min + from * height, profile.z_min + to * height);
    };
    const double foot = band(0.0, 0.06);
    const double stem = band(0.25, 0.35);
    const double cup = band(0.6, 1.0);
    EXPECT_GT(foot, 0.4);
    EXPECT_GT(cup, 0.4);
    EXPECT_LT(stem, 0.2 * std::min(foot, cup)) << "a thin stem";
    // The underside closes at the centre: vertices near the axis in the lowest band...
    double lowest_radius = kInf;
    for (const Eigen::Vector3d& p : mesh.positions) {
      if (p.z() <= profile.z_min + 0.05 * height)
        lowest_radius = std::min(lowest_radius, radius(p));
    }
    EXPECT_LT(lowest_radius, 0.05);
    // ... whose normals point down (outward from the foot), and the cup's wall normals point out.
    double underside = 0.0;
    for (int f = 0; f < mesh.num_faces(); ++f) {
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (int v : mesh.face(f)) centre += mesh.positions[v];
      centre /= static_cast<double>(mesh.face_size(f));
      if (radius(centre) < 0.3 && centre.z() < profile.z_min + 0.05)
        underside += test::area_vector(mesh, f).z();
    }
    EXPECT_LT(underside, 0.0);
  }
}

// ---------------------------------------------------------------------------------------------------
// Mesh quality: the triangle versions are triangulated for themselves, not split quads.

TEST(TriangleQuality, SurfacesOfRevolutionHaveNearEquilateralTriangles) {
  // Rings offset by half a step with rows sqrt(3)/2 of the edge apart: the cylinder's triangles are
  // nearly equilateral (splitting its near-square quads would give 45-degree corners), and every
  // interior vertex has valence 6.
  const PolygonMesh cylinder = make_cylinder(options_for(ShapeFaces::Triangles, 32));
  EXPECT_GT(test::min_corner_angle(cylinder), 55.0 * kDegree);
  const MeshReport report = analyse(cylinder);
  std::set<int> boundary;
  for (const auto& loop : report.boundary_loops) boundary.insert(loop.begin(), loop.end());
  const std::vector<int> valence = test::valences(cylinder);
  for (int v = 0; v < cylinder.num_vertices(); ++v)
    EXPECT_EQ(valence[v], boundary.count(v) ? 4 : 6);

  // The torus is a regular Loop mesh (all valence 6) whose triangles stay reasonable where the
  // conformal spacing meets the tube's curvature.
  const PolygonMesh torus = make_torus(options_for(ShapeFaces::Triangles, 32));
  for (int v : test::valences(torus)) EXPECT_EQ(v, 6);
  EXPECT_GT(test::min_corner_angle(torus), 40.0 * kDegree);

  // Vase and cap: fewer vertices per ring near the pole; no sliver triangles anywhere. The goblet's
  // foot edge bends through 180 degrees at a radius of curvature ~0.04 while its rings are 0.1
  // around: its triangles there are anisotropic by design (following the anisotropic curvature), 15
  // degrees.
  for (const char* name : {"vase", "cap"}) {
    const PolygonMesh mesh = make_shape(name, options_for(ShapeFaces::Triangles, 32));
    EXPECT_GT(test::min_corner_angle(mesh), 35.0 * kDegree) << name;
  }
  EXPECT_GT(test::min_corner_angle(make_goblet(options_for(ShapeFaces::Triangles, 32))),
            15.0 * kDegree);
}

TEST(QuadQuality, PoleDiskHasFourValenceThreeVertices) {
  // The quad disk at a pole is a grid whose 4 corners are the only extraordinary vertices (valence
  // 3); every other interior vertex has valence 4, every boundary vertex 3.
  for (const char* name : {"vase", "goblet", "cap"}) {
    for (int n : {8, 14, 32}) {
      const PolygonMesh mesh = make_shape(name, options_for(ShapeFaces::Quads, n));
      const MeshReport report = analyse(mesh);
      std::set<int> boundary(report.boundary_loops[0].begin(), report.boundary_loops[0].end());
      const std::vector<int> valence = test::valences(mesh);
      int extraordinary = 0;
      for (int v = 0; v < mesh.num_vertices(); ++v) {
        if (boundary.count(v)) {
          EXPECT_EQ(valence[v], 3);
        } else if (valence[v] != 4) {
          EXPECT_EQ(valence[v], 3);
          ++extraordinary;
        }
      }
      EXPECT_EQ(extraordinary, 4) << name << " n=" << n;
      EXPECT_GT(test::min_corner_angle(mesh), 20.0 * kDegree) << name << " n=" << n;
    }
  }
}

// ---------------------------------------------------------------------------------------------------
// Options

TEST(ShapeOptions, RejectsBadOptionsNamingThem) {
  auto expect_rejected = [](const std::string& name, const ShapeOptions& options,
                            const std::string& input) {
    try {
      (void)make_shape(name, options);
      ADD_FAILURE() << name << ": accepted bad " << input;
    } catch (const InvalidInputError& e) {
      EXPECT_EQ(e.input(), input);
    }
  };
  for (const std::string& name : shape_names()) {
    for (int resolution : {-1, 0, 2, 4097}) {
      ShapeOptions options;
      options.resolution = resolution;
      expect_rejected(name, options, "resolution");
    }
    for (double scale : {0.0, -1.0, std::nan(""), kInf}) {
      ShapeOptions options;
      options.scale = scale;
      expect_rejected(name, options, "scale");
    }
    ShapeOptions options;
    options.faces = static_cast<ShapeFaces>(7);
    expect_rejected(name, options, "faces");
  }
  EXPECT_THROW((void)make_shape("cube"), InvalidInputError);
  EXPECT_THROW((void)make_shape(""), InvalidInputError);
  EXPECT_THROW((void)make_shape("Plane"), InvalidInputError);
  // The extremes of the range are accepted.
  ShapeOptions smallest;
  smallest.resolution = 3;
  EXPECT_NO_THROW((void)make_shape("plane", smallest));
}

}  // namespace
}  // namespace elastic
