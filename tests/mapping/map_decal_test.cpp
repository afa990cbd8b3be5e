// Decals placed by a point, an angle and a size, with a free boundary (mapping/map_decal.h),
// against answers the code did not produce: on a plane the decal is the source itself rigidly
// placed at the given angle and scale; on a cylinder (developable) an isometry; on a sphere the
// relaxation beats the exponential map it starts from; a decal that cannot fit is refused with
// how much smaller it must be.
#include "elastic/mapping/map_decal.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "elastic/baselines/decal_baseline.h"
#include "elastic/core/error.h"
#include "elastic/metrics/map_metrics.h"
#include "elastic/regions/region_spec.h"
#include "elastic/shapes/procedural_shapes.h"

namespace elastic {
namespace {

struct Surfaces {
  LimitSurface source_surface, target_surface;
  SurfaceProjector source, target;
  Region region;
  Surfaces(const PolygonMesh& source_mesh, const PolygonMesh& target_mesh, const std::string& spec)
      : source_surface(source_mesh),
        target_surface(target_mesh),
        source(source_surface),
        target(target_surface),
        region(make_region(source, parse_region_spec(spec))) {}
};

MapDecalOptions options(long particles) {
  MapDecalOptions o;
  o.sampling.layout.particles = particles;
  return o;
}

TEST(MapDecal, OnAPlaneTheDecalIsTheSourceRigidlyPlaced) {
  Surfaces s(make_plane({.resolution = 8}), make_plane({.resolution = 10}),
             "disk:0.1,-0.05,0,0.35");
  const DecalPlacement placement{.point = {0.2, -0.1, 0.1}, .angle_degrees = 30.0, .scale = 1.5};
  const MapDecalResult r = map_decal(s.source, s.region, s.target, placement, options(600));
  ASSERT_TRUE(r.map.relaxation.converged) << to_string(r.map.relaxation.reason);
  EXPECT_EQ(r.map.relaxation.boundary, BoundaryMode::Free);
  const DecalGeometry& g = r.geometry;
  // The source frame on the plane z = 0 (normal +z) is (x, y); the target's, turned by 30 degrees.
  const double a = std::numbers::pi / 6.0;
  const Eigen::Vector3d right(std::cos(a), std::sin(a), 0), up(-std::sin(a), std::cos(a), 0);
  const Eigen::Vector3d centre(0.2, -0.1, 0.0);  // the closest point of the plane
  EXPECT_LT((g.target_centre_position - centre).norm(), 1e-12);
  const Eigen::Matrix3Xd source = r.map.sampling.grid.source_positions();
  double error = 0.0;
  for (Eigen::Index p = 0; p < source.cols(); ++p) {
    const Eigen::Vector3d d = source.col(p) - g.source_centre;
    const Eigen::Vector3d expected = centre + 1.5 * (d.x() * right + d.y() * up);
    error = std::max(error, (r.map.relaxation.positions.col(p) - expected).norm());
  }
  EXPECT_LT(error, 1e-8) << "largest deviation from the rigidly placed, scaled source";
  EXPECT_LT(r.map.relaxation.length_energy, 1e-14);
  EXPECT_NEAR(g.turned_degrees, 0.0, 1e-6);
  // The cut region is the decal: its area is 1.5^2 times the source region's, up to the chords.
  EXPECT_NEAR(r.target_region->area() / s.region.area(), 2.25, 2.25 * 0.01);
  // The queryable mapping: a particle's source point maps onto its target position.
  const int p = r.map.sampling.grid.boundary_loop[3];
  const Mapping::Location at = r.map.mapping.forward(r.map.sampling.grid.source_points[p]);
  ASSERT_TRUE(at.inside);
  EXPECT_LT((at.position - r.map.relaxation.positions.col(p)).norm(), 1e-9);
}

TEST(MapDecal, OnACylinderIsAnIsometry) {
  // A disk of radius 0.5 rolled onto a cylinder of radius ~0.5 wraps ~60% of the way around.
  Surfaces s(make_plane({.resolution = 8}), make_cylinder({.resolution = 32}), "disk:0,0,0,0.5");
  const DecalPlacement placement{.point = {0.6, 0.0, 0.1}, .angle_degrees = 20.0};
  const MapDecalResult r = map_decal(s.source, s.region, s.target, placement, options(800));
  ASSERT_TRUE(r.map.relaxation.converged);
  const MapMetrics m = measure_on_target(r.map.sampling.grid, s.target_surface, 1.0,
                                         r.map.relaxation.positions, r.map.relaxation.points);
  EXPECT_EQ(m.folds, 0);
  // Chords are shorter than arcs by (h k)^2 / 24 relative (h the spacing, k = 2): the length
  // energy is that squared, not zero; a visible distortion would be 1e-3 and more.
  EXPECT_LT(m.length_energy, 1e-6);
  EXPECT_LT(m.angle_error_max_deg, 0.5);
  EXPECT_NEAR(m.area_distortion, 0.0, 1e-2);
}

TEST(MapDecal, OnASphereTheRelaxationBeatsTheExponentialMap) {
  Surfaces s(make_plane({.resolution = 8}), make_sphere({.resolution = 48}), "disk:0,0,0,0.7");
  const DecalPlacement placement{.point = {0.3, 0.2, 1.0}, .angle_degrees = -45.0};
  const MapDecalResult r = map_decal(s.source, s.region, s.target, placement, options(1500));
  ASSERT_TRUE(r.map.relaxation.converged);
  const MapMetrics elastic = measure_on_target(r.map.sampling.grid, s.target_surface, 1.0,
                                               r.map.relaxation.positions, r.map.relaxation.points);
  const DecalBaselineResult expmap = exponential_map_decal(s.target_surface, r.geometry);
  EXPECT_EQ(expmap.stopped, 0);
  const MapMetrics baseline = measure_on_target(r.map.sampling.grid, s.target_surface, 1.0,
                                                expmap.positions, expmap.points);
  EXPECT_EQ(elastic.folds, 0);
  EXPECT_EQ(baseline.folds, 0);
  EXPECT_LT(elastic.length_energy, 0.8 * baseline.length_energy);
  EXPECT_LT(elastic.symmetric_dirichlet, baseline.symmetric_dirichlet);
  // The decal stays where it was put, turned as asked: the pinned pair, and the rest twisted by
  // a few degrees at most.
  for (const int p : {r.geometry.pinned, r.geometry.pinned_up}) {
    EXPECT_LT((r.map.relaxation.positions.col(p) - r.map.naive.positions.col(p)).norm(), 1e-12);
  }
  EXPECT_LT(std::abs(r.geometry.turned_degrees), 2.0);
}

TEST(MapDecal, RefusesADecalThatOverlapsItself) {
  // A disk of radius 1.2 on the torus's outer equator: around the tube (circumference 2.2) its
  // two sides meet on the inner equator, 1.1 away, and overlap there.
  Surfaces s(make_plane({.resolution = 8}), make_torus({.resolution = 32}), "disk:0,0,0,0.6");
  const DecalPlacement placement{.point = {1.35, 0.0, 0.0}, .scale = 2.0};
  try {
    map_decal(s.source, s.region, s.target, placement, options(600));
    FAIL() << "a decal wrapped onto itself was accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(e.input(), "--target-place");
    EXPECT_NE(std::string(e.what()).find("overlaps itself"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("SCALE at most"), std::string::npos) << e.what();
  }
}

TEST(MapDecal, RefusesADecalThatRunsOffTheSurface) {
  Surfaces s(make_plane({.resolution = 8}), make_plane({.resolution = 8}), "disk:0,0,0,0.5");
  const DecalPlacement placement{.point = {0.8, 0.0, 0.0}};
  try {
    map_decal(s.source, s.region, s.target, placement, options(300));
    FAIL() << "a decal beyond the surface's boundary was accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("runs off"), std::string::npos) << e.what();
    // 0.9 x 0.2 / 0.5, the last particles a little beyond the disk's radius 0.5
    EXPECT_NE(std::string(e.what()).find("SCALE at most about 0.3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(map_decal(s.source, s.region, s.target, {.point = {0, 0, 5}}, options(300)),
               InvalidInputError);  // far from the surface
  EXPECT_THROW(map_decal(s.source, s.region, s.target, {.scale = 0.0}, options(300)),
               InvalidInputError);
}

TEST(MapDecal, ParsesPlacements) {
  const DecalPlacement p = parse_decal_placement("1,2,3,45,0.5");
  EXPECT_EQ(p.point, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(p.angle_degrees, 45.0);
  EXPECT_EQ(p.scale, 0.5);
  EXPECT_EQ(parse_decal_placement("1,2,3").scale, 1.0);
  for (const char* bad : {"1,2", "1,2,3,4,5,6", "1,2,x", "1,2,3,0,0", "1,2,3,0,-1", "1,2,inf",
                          "1,,3", "1,2,3,", " "}) {
    EXPECT_THROW(parse_decal_placement(bad), InvalidInputError) << bad;
  }
}

}  // namespace
}  // namespace elastic
