// Baseline maps (LSCM, ARAP, DCM through CGAL): flattenings of planar regions against the analytic
// answer, maps between congruent and similar regions against the known motion, outside detection on
// a thin target, the shared boundary correspondence, errors and determinism.

#include "elastic/baselines/baseline_map.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <complex>
#include <memory>
#include <numbers>

#include "elastic/baselines/cgal_flattening.h"
#include "elastic/core/error.h"
#include "elastic/mapping/initial_map.h"
#include "elastic/regions/region_spec.h"
#include "elastic/sampling/sample_region.h"
#include "elastic/shapes/procedural_shapes.h"
#include "rigid_motion.h"
#include "support.h"

namespace elastic {
namespace {

constexpr BaselineKind kKinds[] = {BaselineKind::Lscm, BaselineKind::Arap, BaselineKind::Dcm};

/// A surface with its projector (the surface must outlive the projector and its regions).
struct Surface {
  std::unique_ptr<LimitSurface> surface;
  std::unique_ptr<SurfaceProjector> projector;
  explicit Surface(const PolygonMesh& mesh)
      : surface(std::make_unique<LimitSurface>(mesh)),
        projector(std::make_unique<SurfaceProjector>(*surface)) {}
};

PolygonMesh transformed(PolygonMesh mesh, const Eigen::Affine3d& motion) {
  for (Eigen::Vector3d& p : mesh.positions) p = motion * p;
  return mesh;
}

ParticleGrid sample(const Region& region, const SurfaceProjector& projector, long particles) {
  SampleRegionOptions options;
  options.layout.particles = particles;
  options.adaptive = false;
  return sample_region(region, projector, options).grid;
}

// The disk spec moved by `motion` (centre and anchor), so the two regions are congruent and their
// correspondences start at corresponding points.
RegionSpec disk_spec(const Eigen::Affine3d& motion, double radius) {
  RegionSpec spec = parse_region_spec("disk:0.1,0.05,0,0.6");
  spec.center = motion * spec.center;
  spec.radius = radius;
  spec.anchor = motion * Eigen::Vector3d(1, 0, 0);
  return spec;
}

double largest_deviation(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return (a - b).colwise().norm().maxCoeff();
}

// Flattening a planar region: LSCM's energy vanishes exactly on similarities and ARAP's on
// isometries, so with the area normalisation the flattening must be a rigid motion of (x, y).
// Checked by the least-squares rigid fit (complex form) and its largest residual.
TEST(CgalFlattening, PlanarRegionFlattensIsometrically) {
  const Surface plane(make_plane({.resolution = 10}));
  const Region region = make_region(*plane.projector, parse_region_spec("disk:0.1,0.05,0,0.6"));
  for (BaselineKind kind : {BaselineKind::Lscm, BaselineKind::Arap}) {
    // ARAP: 100 local/global iterations without the energy stop (tolerance 0); its linear
    // convergence is at 2e-9 after 50 iterations on this mesh, far below 1e-8 after 100.
    CgalFlatteningOptions options;
    options.arap_iterations = 100;
    options.arap_tolerance = 0.0;
    const CgalFlattening flat = flatten_region_cgal(region, kind, options);
    EXPECT_EQ(flat.flipped_triangles, 0) << to_string(kind);
    std::complex<double> xm = 0.0, um = 0.0;
    const double n = static_cast<double>(region.num_vertices());
    for (int v = 0; v < region.num_vertices(); ++v) {
      xm += std::complex<double>(region.positions[v].x(), region.positions[v].y()) / n;
      um += std::complex<double>(flat.uv[v].x(), flat.uv[v].y()) / n;
    }
    std::complex<double> cross = 0.0;
    for (int v = 0; v < region.num_vertices(); ++v) {
      cross +=
          std::conj(std::complex<double>(region.positions[v].x(), region.positions[v].y()) - xm) *
          (std::complex<double>(flat.uv[v].x(), flat.uv[v].y()) - um);
    }
    const std::complex<double> rotation = cross / std::abs(cross);
    double worst = 0.0;
    for (int v = 0; v < region.num_vertices(); ++v) {
      const std::complex<double> x(region.positions[v].x(), region.positions[v].y());
      worst = std::max(worst, std::abs(rotation * (x - xm) + um -
                                       std::complex<double>(flat.uv[v].x(), flat.uv[v].y())));
    }
    // The disk has diameter 1.2; 1e-8 leaves room for the solvers' round-off and ARAP's iteration.
    EXPECT_LT(worst, 1e-8) << to_string(kind);
  }
}

// A disk on a plane mapped onto the same disk on a rigidly moved copy: every method must give the
// rigid motion (congruent regions have congruent flattenings, and the alignment is exact), with
// nothing outside.
TEST(MapBaseline, RigidlyMovedCopyGivesTheRigidMotion) {
  const PolygonMesh mesh = make_plane({.resolution = 10});
  const Eigen::Affine3d motion = test::rigid_motion();
  const Surface source(mesh), target(transformed(mesh, motion));
  const Region from = make_region(*source.projector, disk_spec(Eigen::Affine3d::Identity(), 0.6));
  const Region to = make_region(*target.projector, disk_spec(motion, 0.6));
  const ParticleGrid grid = sample(from, *source.projector, 300);
  const Eigen::Matrix3Xd expected = motion * grid.source_positions();
  for (BaselineKind kind : kKinds) {
    const BaselineResult r =
        map_baseline(grid, *source.projector, from, *target.projector, to, {.kind = kind});
    EXPECT_EQ(r.kind, kind);
    EXPECT_EQ(r.num_outside, 0) << to_string(kind);
    // 1e-9 of a region of diameter 1.2: both flattenings are computed from the same numbers up to
    // the motion's round-off (1e-16), amplified only by the linear solvers' conditioning.
    EXPECT_LT(largest_deviation(r.positions, expected), 1e-9) << to_string(kind);
    EXPECT_NEAR(r.alignment_scale, 1.0, 1e-9) << to_string(kind);
    EXPECT_NEAR(std::remainder(r.alignment_rotation, 2 * std::numbers::pi), 0.0, 1e-9)
        << to_string(kind);
    EXPECT_LT(r.alignment_rms, 1e-9) << to_string(kind);
    EXPECT_GE(r.seconds, 0.0);
  }
}

// The same disk onto a copy of the plane scaled by 2 (and moved): the map is that similarity and
// the alignment reports its scale (flattenings carry their region's 3D area).
TEST(MapBaseline, ScaledDiskGivesTheScaling) {
  const PolygonMesh mesh = make_plane({.resolution = 10});
  Eigen::Affine3d similarity = Eigen::Affine3d::Identity();
  similarity.translate(Eigen::Vector3d(0.5, 0.25, -1.0)).scale(2.0);
  const Surface source(mesh), target(transformed(mesh, similarity));
  const Region from = make_region(*source.projector, disk_spec(Eigen::Affine3d::Identity(), 0.6));
  const Region to = make_region(*target.projector, disk_spec(similarity, 1.2));
  const ParticleGrid grid = sample(from, *source.projector, 300);
  const Eigen::Matrix3Xd expected = similarity * grid.source_positions();
  for (BaselineKind kind : kKinds) {
    const BaselineResult r =
        map_baseline(grid, *source.projector, from, *target.projector, to, {.kind = kind});
    EXPECT_EQ(r.num_outside, 0) << to_string(kind);
    // 2e-9: the 1e-9 of the rigid case at twice the size.
    EXPECT_LT(largest_deviation(r.positions, expected), 2e-9) << to_string(kind);
    EXPECT_NEAR(r.alignment_scale, 2.0, 1e-9) << to_string(kind);
  }
}

// A region onto itself, on a curved surface: the identity, and every target point where the
// source point was.
TEST(MapBaseline, IdenticalRegionsGiveTheIdentity) {
  const Surface cap(make_cap({.resolution = 12}));
  const Region region = make_region(*cap.projector, parse_region_spec("disk:0.2,0,1,0.5"));
  const ParticleGrid grid = sample(region, *cap.projector, 250);
  // The limit positions of the particles' source points (a boundary particle's grid position lies
  // on the boundary chord, within the tessellation's tolerance of the surface; its point is exact).
  Eigen::Matrix3Xd expected(3, grid.num_particles());
  for (int i = 0; i < grid.num_particles(); ++i) {
    expected.col(i) = cap.surface->position(grid.source_points[i]);
  }
  for (BaselineKind kind : kKinds) {
    const BaselineResult r =
        map_baseline(grid, *cap.projector, region, *cap.projector, region, {.kind = kind});
    EXPECT_EQ(r.num_outside, 0) << to_string(kind);
    // 1e-10: the same computation on both sides; only barycentric round-trips (1e-15) remain.
    EXPECT_LT(largest_deviation(r.positions, expected), 1e-10) << to_string(kind);

    EXPECT_NEAR(r.alignment_scale, 1.0, 1e-12) << to_string(kind);
    EXPECT_LT(r.alignment_rms, 1e-12) << to_string(kind);
  }
}

// Plane disk onto the cap: every particle on the target surface, and boundary particles exactly
// where the naive map (ElasticPaint's start, an independent implementation of the arc-length
// correspondence) puts them.
TEST(MapBaseline, SharesTheBoundaryCorrespondenceOfTheNaiveMap) {
  const Surface plane(make_plane({.resolution = 10})), cap(make_cap({.resolution = 12}));
  const Region from = make_region(*plane.projector, parse_region_spec("disk:0,0,0,0.8"));
  const Region to = make_region(*cap.projector, parse_region_spec("boundary"));
  const ParticleGrid grid = sample(from, *plane.projector, 300);
  const RegionDiskMap source_disk(from), target_disk(to);
  const InitialMap naive = naive_map(grid, source_disk, target_disk);
  for (BaselineKind kind : kKinds) {
    const BaselineResult r =
        map_baseline(grid, *plane.projector, from, *cap.projector, to, {.kind = kind});
    ASSERT_EQ(r.positions.cols(), grid.num_particles());
    ASSERT_EQ(r.points.size(), static_cast<size_t>(grid.num_particles()));
    ASSERT_EQ(r.outside.size(), static_cast<size_t>(grid.num_particles()));
    for (int i = 0; i < grid.num_particles(); ++i) {
      if (r.outside[i]) continue;
      ASSERT_TRUE(r.points[i].valid());
      // On the surface: the position is the limit point of the SurfacePoint (round-off only).
      EXPECT_LT((cap.surface->position(r.points[i]) - r.positions.col(i)).norm(), 1e-12);
    }
    for (int i : grid.boundary_loop) {
      // 1e-9: both locate the same arc length on the same polyline, summed in different orders.
      EXPECT_LT((r.positions.col(i) - naive.positions.col(i)).norm(), 1e-9) << to_string(kind);
      EXPECT_FALSE(r.outside[i]);
    }
    EXPECT_EQ(r.source_flipped_triangles, 0) << to_string(kind);
    EXPECT_EQ(r.target_flipped_triangles, 0) << to_string(kind);
  }
}

// Point-in-polygon by crossings, for an independent inside test in the plane z = 0.
bool inside_polygon(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p) {
  bool inside = false;
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

double distance_to_polyline(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    best = std::min(best, (a + t * (b - a) - p).norm());
  }
  return best;
}

// A round disk onto a thin rectangle (the whole boundary of a plane squashed to 2 x 0.3): the
// aligned disk sticks out of it, so some particles fall outside. They are flagged, carry no
// SurfacePoint and sit on the target boundary; every other particle is inside the rectangle
// (checked against the boundary polygon).
TEST(MapBaseline, ThinTargetPutsParticlesOutsideAndFlagsThem) {
  const PolygonMesh mesh = make_plane({.resolution = 10});
  const Surface plane(mesh);
  const Surface thin(transformed(mesh, Eigen::Affine3d(Eigen::Scaling(1.0, 0.15, 1.0))));
  const Region from = make_region(*plane.projector, parse_region_spec("disk:0,0,0,0.6"));
  const Region to = make_region(*thin.projector, parse_region_spec("boundary"));
  std::vector<Eigen::Vector2d> polygon;
  for (int v : to.boundary) polygon.push_back(to.positions[v].head<2>());
  const ParticleGrid grid = sample(from, *plane.projector, 300);
  for (BaselineKind kind : kKinds) {
    const BaselineResult r =
        map_baseline(grid, *plane.projector, from, *thin.projector, to, {.kind = kind});
    // LSCM and ARAP keep the disk round, so it sticks out of the rectangle; DCM maps both regions
    // onto circles, so it can only lose particles in the slivers between the two boundary polygons.
    if (kind != BaselineKind::Dcm) {
      EXPECT_GT(r.num_outside, 0) << to_string(kind);
    }
    int flagged = 0;
    for (int i = 0; i < grid.num_particles(); ++i) {
      const Eigen::Vector2d xy = r.positions.col(i).head<2>();
      EXPECT_NEAR(r.positions(2, i), 0.0, 1e-12);  // on the plane z = 0
      if (r.outside[i]) {
        ++flagged;
        EXPECT_FALSE(r.points[i].valid());
        EXPECT_FALSE(grid.is_boundary[i]);
        // The nearest flattened boundary point, mapped back: on the boundary polyline.
        EXPECT_LT(distance_to_polyline(polygon, xy), 1e-9);
      } else {
        EXPECT_TRUE(r.points[i].valid());
        // Inside the ellipse, or on its boundary (boundary particles), to round-off.
        EXPECT_TRUE(inside_polygon(polygon, xy) || distance_to_polyline(polygon, xy) < 1e-9)
            << to_string(kind) << " particle " << i;
      }
    }
    EXPECT_EQ(flagged, r.num_outside);
  }
}

TEST(MapBaseline, BadInputIsATypedErrorNamingIt) {
  const Surface plane(make_plane({.resolution = 8}));
  const Region region = make_region(*plane.projector, parse_region_spec("disk:0,0,0,0.6"));
  const ParticleGrid grid = sample(region, *plane.projector, 100);
  auto input_of = [](auto&& call) -> std::string {
    try {
      call();
    } catch (const InvalidInputError& e) {
      return e.input();
    }
    return "(no InvalidInputError)";
  };
  const ParticleGrid empty;
  EXPECT_EQ(
      input_of([&] { map_baseline(empty, *plane.projector, region, *plane.projector, region); }),
      "grid");
  Region no_boundary = region;
  no_boundary.boundary.clear();
  EXPECT_EQ(input_of([&] {
              map_baseline(grid, *plane.projector, region, *plane.projector, no_boundary);
            }),
            "target region");
  EXPECT_EQ(input_of([&] {
              map_baseline(grid, *plane.projector, no_boundary, *plane.projector, region);
            }),
            "source region");
  const Region nothing;
  EXPECT_EQ(
      input_of([&] { map_baseline(grid, *plane.projector, region, *plane.projector, nothing); }),
      "target region");
  EXPECT_EQ(input_of([&] { flatten_region_cgal(no_boundary, BaselineKind::Dcm, {.name = "--x"}); }),
            "--x");
  // A hole (the triangles around one interior vertex removed): two boundary loops, not a disk.
  Region holed = region;
  const int centre = holed.triangles[holed.triangles.size() / 2][0];
  ASSERT_EQ(std::count(holed.boundary.begin(), holed.boundary.end(), centre), 0);
  std::erase_if(holed.triangles,
                [&](const Eigen::Vector3i& t) { return (t.array() == centre).any(); });
  holed.triangle_face.resize(holed.triangles.size());
  holed.triangle_uv.resize(holed.triangles.size());
  EXPECT_EQ(input_of([&] { flatten_region_cgal(holed, BaselineKind::Lscm); }), "region");

  // ARAP refuses regions above its vertex limit instead of risking CGAL's quadratic post-processor:
  // a NumericalError (valid input this method cannot handle), naming the region.
  try {
    map_baseline(grid, *plane.projector, region, *plane.projector, region,
                 {.kind = BaselineKind::Arap, .arap_max_vertices = 10});
    ADD_FAILURE() << "no error above the ARAP vertex limit";
  } catch (const NumericalError& e) {
    EXPECT_EQ(e.input(), "source region");
  }

  for (BaselineKind kind : kKinds) EXPECT_EQ(parse_baseline_kind(to_string(kind)), kind);
  EXPECT_EQ(input_of([] { parse_baseline_kind("mvc", "--baseline"); }), "--baseline");
}

// Same inputs, same outputs, bit for bit (parallel composition writes per particle; CGAL is run on
// identically built meshes).
TEST(MapBaseline, Deterministic) {
  const Surface plane(make_plane({.resolution = 8})), cap(make_cap({.resolution = 12}));
  const Region from = make_region(*plane.projector, parse_region_spec("disk:0,0,0,0.8"));
  const Region to = make_region(*cap.projector, parse_region_spec("boundary"));
  const ParticleGrid grid = sample(from, *plane.projector, 300);
  for (BaselineKind kind : kKinds) {
    const BaselineResult a =
        map_baseline(grid, *plane.projector, from, *cap.projector, to, {.kind = kind});
    const BaselineResult b =
        map_baseline(grid, *plane.projector, from, *cap.projector, to, {.kind = kind});
    EXPECT_TRUE(a.positions == b.positions) << to_string(kind);
    EXPECT_EQ(a.points, b.points);
    EXPECT_EQ(a.outside, b.outside);
    EXPECT_EQ(a.alignment_rms, b.alignment_rms);
  }
}

}  // namespace
}  // namespace elastic
