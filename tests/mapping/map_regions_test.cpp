// The whole mapping pipeline: sample -> naive map -> relax -> queryable Mapping.
#include "elastic/mapping/map_regions.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/metrics/map_metrics.h"
#include "elastic/regions/region_spec.h"
#include "elastic/shapes/procedural_shapes.h"
#include "rigid_motion.h"
#include "support.h"

namespace elastic {
namespace {

// Two surfaces, their projectors and a region on each (specs as `elastic map` takes them).
struct TwoRegions {
  LimitSurface source_surface, target_surface;
  SurfaceProjector source, target;
  Region from, to;
  TwoRegions(const PolygonMesh& source_mesh, const PolygonMesh& target_mesh,
             const std::string& from_spec, const std::string& to_spec)
      : source_surface(source_mesh),
        target_surface(target_mesh),
        source(source_surface),
        target(target_surface),
        from(make_region(source, parse_region_spec(from_spec))),
        to(make_region(target, parse_region_spec(to_spec))) {}
};

// A disk on a plane mapped onto the same disk on a rigidly moved copy of the plane: the map must be
// the rigid motion (the zero of the length and angle energies; congruent regions, congruent
// anchors).
TEST(MapRegions, PlaneOntoRigidlyMovedCopyIsTheRigidMotion) {
  const PolygonMesh plane = make_plane({.faces = ShapeFaces::Quads, .resolution = 12});
  const Eigen::Isometry3d motion = test::rigid_motion();
  const LimitSurface source_surface(plane), target_surface(test::moved(plane, motion));
  const SurfaceProjector source(source_surface), target(target_surface);
  RegionSpec source_spec = parse_region_spec("disk:0.1,0.05,0,0.6");
  source_spec.anchor = Eigen::Vector3d(1, 0, 0);
  RegionSpec target_spec = source_spec;
  target_spec.center = motion * source_spec.center;
  target_spec.anchor = motion * *source_spec.anchor;
  const Region from = make_region(source, source_spec);
  const Region to = make_region(target, target_spec);

  MapOptions options;
  options.sampling.layout.particles = 400;
  const MapResult result = map_regions(source, from, target, to, options);
  ASSERT_TRUE(result.relaxation.converged) << to_string(result.relaxation.reason);
  EXPECT_EQ(result.relaxation.folded_faces, 0);
  const ParticleGrid& grid = result.sampling.grid;
  const Eigen::Matrix3Xd expected = motion * grid.source_positions();
  // 1e-8 of the region's size (diameter 1.2): the energy's zero is the rigid motion; the solver
  // stops at a relative gradient of 1e-6, and the boundary correspondence is exact up to the cut's
  // round-off.
  const double error = (result.relaxation.positions - expected).colwise().norm().maxCoeff();
  EXPECT_LT(error, 1e-8) << "largest deviation from the rigid motion";
  EXPECT_LT(result.relaxation.length_energy, 1e-14);
  EXPECT_NEAR(result.rest_scale, 1.0, 1e-9);
}

// Without anchors the correspondence's start is chosen (MapOptions::choose_offset): the whole
// 4 x 2 rectangle of a stretched plane onto a copy turned by 90 degrees about its centre. The
// automatic anchors both lie along world +x from the centre: the middle of a short side on the
// source, of a long side on the target, 3/12 of the perimeter apart. The offset that undoes this
// (a quarter of the boundary, one of the 24 candidates) makes the map the turn itself; keeping the
// anchors leaves a correspondence no relaxation with a fixed boundary can undo.
TEST(MapRegions, ChosenOffsetUndoesATurnWithoutAnchors) {
  PolygonMesh plane = make_plane({.faces = ShapeFaces::Quads, .resolution = 12});
  for (Eigen::Vector3d& p : plane.positions) {
    p.x() *= 2.0;
  }
  const Eigen::Isometry3d turn(Eigen::AngleAxisd(0.5 * std::acos(-1.0), Eigen::Vector3d::UnitZ()));
  const LimitSurface source_surface(plane), target_surface(test::moved(plane, turn));
  const SurfaceProjector source(source_surface), target(target_surface);
  const Region from = make_region(source, parse_region_spec("boundary"));
  const Region to = make_region(target, parse_region_spec("boundary"));
  ASSERT_FALSE(from.anchor_given);
  MapOptions options;
  options.sampling.layout.particles = 400;
  const MapResult result = map_regions(source, from, target, to, options);
  EXPECT_TRUE(result.offset_chosen);
  EXPECT_NEAR(std::min(result.boundary_offset, 1.0 - result.boundary_offset), 0.25, 1e-12);
  EXPECT_LT(result.offset_energy, 1e-6 * result.offset_energy_at_zero);
  ASSERT_TRUE(result.relaxation.converged) << to_string(result.relaxation.reason);
  const Eigen::Matrix3Xd expected = turn * result.sampling.grid.source_positions();
  EXPECT_LT((result.relaxation.positions - expected).colwise().norm().maxCoeff(), 1e-6);
  options.choose_offset = false;
  const MapResult kept = map_regions(source, from, target, to, options);
  EXPECT_FALSE(kept.offset_chosen);
  EXPECT_GT(kept.relaxation.length_energy, 1e3 * result.relaxation.length_energy + 1e-9);
}

// The whole plane square onto the whole cap (600 particles): the case of the two tests below.
struct SquareOntoCap {
  LimitSurface source_surface{make_plane({.resolution = 8})};
  LimitSurface target_surface{make_cap({.resolution = 16})};
  SurfaceProjector source{source_surface}, target{target_surface};
  Region from = make_region(source, parse_region_spec("boundary"));
  Region to = make_region(target, parse_region_spec("boundary"));
  MapOptions options = [] {
    MapOptions o;
    o.sampling.layout.particles = 600;
    return o;
  }();
};

// The whole plane square onto the cap: converges, no folds, boundary particles exactly where the
// arc-length correspondence put them, and relaxation lowers the energy of the naive map.
TEST(MapRegions, PlaneOntoCapConvergesWithoutFolds) {
  SquareOntoCap c;
  const LimitSurface& target_surface = c.target_surface;
  MapOptions& options = c.options;
  const MapResult result = map_regions(c.source, c.from, c.target, c.to, options);
  const RelaxationResult& r = result.relaxation;
  EXPECT_TRUE(r.converged) << to_string(r.reason);
  EXPECT_EQ(r.folded_faces, 0);
  EXPECT_LT(r.boundary_residual, 1e-12);
  EXPECT_LT(r.length_energy + r.angular_energy, r.initial_energy);
  EXPECT_NEAR(static_cast<double>(result.sampling.grid.num_particles()), 600.0, 30.0);
  // Every particle is on the target surface.
  for (int i = 0; i < result.sampling.grid.num_particles(); ++i) {
    EXPECT_LT((target_surface.position(r.points[i]) - r.positions.col(i)).norm(), 1e-9);
  }
}

// --boundary slide: the plane's square (four corners, where the fixed arc-length boundary forces
// the most distortion) onto the cap's round boundary. Every boundary particle stays on the target
// curve at its parameter (checked here against the disk map's curve point, not the solver's own
// residual), the particles keep their order along the curve, some do slide, and the energy ends
// below the fixed boundary's.
TEST(MapRegions, SlidingBoundaryStaysOnTheCurveInOrder) {
  SquareOntoCap c;
  const LimitSurface& target_surface = c.target_surface;
  MapOptions& options = c.options;
  const MapResult fixed = map_regions(c.source, c.from, c.target, c.to, options);
  options.relaxation.boundary = BoundaryMode::Slide;
  const MapResult slid = map_regions(c.source, c.from, c.target, c.to, options);
  const RelaxationResult& r = slid.relaxation;
  EXPECT_TRUE(r.converged) << to_string(r.reason);
  EXPECT_EQ(r.folded_faces, 0);
  EXPECT_EQ(r.boundary, BoundaryMode::Slide);
  const std::vector<int>& loop = slid.sampling.grid.boundary_loop;
  ASSERT_EQ(r.boundary_parameters.size(), loop.size());
  double moved = 0.0;
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const SurfacePoint at = slid.target_disk->boundary_point(r.boundary_parameters[k]);
    EXPECT_LT((target_surface.position(at) - r.positions.col(loop[k])).norm(), 1e-9) << k;
    // In order: the step to the next parameter (cyclically) is positive and short.
    const double next = r.boundary_parameters[(k + 1) % loop.size()];
    double gap = next - r.boundary_parameters[k];
    gap -= std::floor(gap);
    EXPECT_GT(gap, 0.0) << k;
    EXPECT_LT(gap, 0.1) << k;
    double shift = r.boundary_parameters[k] - slid.sampling.grid.boundary_parameter[k];
    shift -= std::round(shift);
    moved = std::max(moved, std::abs(shift));
  }
  EXPECT_GT(moved, 1e-3);
  EXPECT_LT(r.length_energy + r.angular_energy + r.barrier_energy,
            fixed.relaxation.length_energy + fixed.relaxation.angular_energy +
                fixed.relaxation.barrier_energy);
}

// The slide phase stops at RelaxationOptions::slide_tolerance (its own relative gradient), and the
// held phase still converges to the full tolerance: fewer slide iterations than a slide run to the
// full tolerance (slide_tolerance 0), an energy within 0.5% of that run's, the fixed boundary's
// beaten all the same, and a negative or NaN tolerance refused.
TEST(MapRegions, SlidePhaseStopsAtItsOwnTolerance) {
  SquareOntoCap c;
  MapOptions& options = c.options;
  const MapResult fixed = map_regions(c.source, c.from, c.target, c.to, options);
  options.relaxation.boundary = BoundaryMode::Slide;
  // The gradient tolerance alone: the settle stop (1e-5 per 20 iterations) ends both slides here.
  options.relaxation.slide_settle_tolerance = 0.0;
  options.relaxation.slide_tolerance = 0.0;
  const MapResult full = map_regions(c.source, c.from, c.target, c.to, options);
  options.relaxation.slide_tolerance = 1e-2;
  const MapResult loose = map_regions(c.source, c.from, c.target, c.to, options);
  const auto energy = [](const RelaxationResult& r) {
    return r.length_energy + r.angular_energy + r.barrier_energy;
  };
  ASSERT_TRUE(full.relaxation.converged) << to_string(full.relaxation.reason);
  ASSERT_TRUE(loose.relaxation.converged) << to_string(loose.relaxation.reason);
  EXPECT_EQ(loose.relaxation.boundary, BoundaryMode::Slide);
  EXPECT_EQ(loose.relaxation.slide_reason, StopReason::RelativeGradient);
  EXPECT_LT(loose.relaxation.slide_iterations, full.relaxation.slide_iterations);
  // The held phase converges by the full tolerance, or by round-off (docs/solvers.md: the energy no
  // longer changes and |P g| is within 1e-4 of the start's), far below the slide's 1e-2 either way.
  if (loose.relaxation.reason == StopReason::RoundOff) {
    EXPECT_LE(loose.relaxation.relative_gradient, options.relaxation.round_off_gradient_tolerance);
  } else {
    EXPECT_EQ(loose.relaxation.reason, StopReason::RelativeGradient);
    EXPECT_LE(loose.relaxation.relative_gradient, options.relaxation.relative_gradient_tolerance);
  }
  EXPECT_LT(energy(loose.relaxation), 1.005 * energy(full.relaxation));
  EXPECT_LT(energy(loose.relaxation), energy(fixed.relaxation));
  for (const double bad : {-1.0, std::numeric_limits<double>::quiet_NaN()}) {
    options.relaxation.slide_tolerance = bad;
    EXPECT_THROW(map_regions(c.source, c.from, c.target, c.to, options), InvalidInputError);
  }
}

// The correspondence's offset prefers a naive map that folds no face: the five-pointed star onto
// the cow's flank, where the least-energy offset folds faces at two tips (measured: 4 folded
// faces; from that start the solver stopped with a fold), and another candidate does not.
TEST(MapRegions, OffsetPrefersAFoldFreeNaiveMap) {
  ELASTIC_REQUIRE_SHARED_MESH(spot_path, "spot.obj");
  const LimitSurface source_surface(read_mesh(test::project_mesh("plane_quads.obj")).mesh);
  const LimitSurface target_surface(read_mesh(spot_path).mesh);
  const SurfaceProjector source(source_surface), target(target_surface);
  // The star of the robustness benchmark (tools/benchmarks/regions/, beside meshes/).
  const Region from = make_region(
      source, parse_region_spec(
                  "points:" +
                  test::project_mesh("../tools/benchmarks/regions/star_on_plane.txt").string()));
  const Region to = make_region(target, parse_region_spec("disk:0.358,-0.032,0.073,0.25"));
  MapOptions options;
  options.sampling.layout.particles = 2000;
  options.relaxation.max_iterations = 1;
  const MapResult result = map_regions(source, from, target, to, options);
  ASSERT_TRUE(result.offset_chosen);
  EXPECT_EQ(result.offset_folds, 0);
  EXPECT_EQ(result.relaxation.initial_folded_faces, 0);
  // Every candidate's naive energy, independently: the chosen one is not the least.
  const SpringSystem springs(result.sampling.grid,
                             {.stiffness = options.relaxation.stiffness,
                              .angular_stiffness = angular_stiffness(options.relaxation),
                              .rest_scale = result.rest_scale});
  RegionDiskMap turned = *result.target_disk;
  double least = std::numeric_limits<double>::infinity();
  for (int k = 0; k < options.offset_candidates; ++k) {
    turned.set_offset(static_cast<double>(k) / options.offset_candidates);
    least = std::min(
        least,
        springs.evaluate(naive_map(result.sampling.grid, *result.source_disk, turned).positions)
            .total());
  }
  EXPECT_GT(result.offset_energy, least);
}

// Forward then inverse returns near the start (both directions are the grid's affine map per
// triangle; they differ only by the magnet's step off the particles' chord planes on the cylinder,
// see mapping_test.cpp for the bound), and points outside the region answer "outside".
TEST(MapRegions, MappingAnswersBothWays) {
  const TwoRegions c(make_plane({.resolution = 8}), make_cylinder({.resolution = 24}),
                     "disk:0,0,0,0.5", "disk:0.5,0,0,0.5");
  const SurfaceProjector &source = c.source, &target = c.target;
  const LimitSurface& target_surface = c.target_surface;
  MapOptions options;
  options.sampling.layout.particles = 800;
  const MapResult result = map_regions(source, c.from, target, c.to, options);
  ASSERT_TRUE(result.relaxation.converged);
  const double spacing = result.sampling.statistics.spacing_median;

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(0.0, 6.283185307179586), radius(0.0, 0.4);
  int checked = 0;
  for (int k = 0; k < 200; ++k) {
    const double a = angle(rng), r = radius(rng);
    const ClosestPoint p = source.closest(Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0.0));
    const Mapping::Location there = result.mapping.forward(p.point);
    ASSERT_TRUE(there.inside) << "interior point " << k << " not mapped";
    EXPECT_LT((target_surface.position(there.point) - there.position).norm(), 1e-9);
    const Mapping::Location back = result.mapping.inverse(there.point);
    ASSERT_TRUE(back.inside);
    EXPECT_LT((back.position - p.position).norm(), 0.05 * spacing);
    ++checked;
  }
  EXPECT_EQ(checked, 200);
  // Outside the source disk, and outside the target disk.
  EXPECT_FALSE(result.mapping.forward(source.closest(Eigen::Vector3d(0.9, 0.9, 0)).point).inside);
  EXPECT_FALSE(result.mapping.inverse(target.closest(Eigen::Vector3d(-0.5, 0, 0)).point).inside);
}

// The distortion guard (MapOptions::distortion_guard). The procedural plane's disk onto the top of
// spot's back at 1,500 particles (a case of the robustness benchmark; at 1,000 the relaxed map is
// below its start since the solver's fold test became the report's, 2026-12-04): the length
// energy's minimum has a larger symmetric Dirichlet energy than the naive map it started from
// (measured here by the metrics module, not the guard's own E_sd), so the guard relaxes on with the
// distortion term, and the map it returns is less distorted at a bounded cost in length.
TEST(MapRegions, DistortionGuardRelaxesOnWhereLengthsTradedAngles) {
  ELASTIC_REQUIRE_SHARED_MESH(spot_path, "spot.obj");
  const TwoRegions c(read_mesh(test::project_mesh("plane_quads.obj")).mesh,
                     read_mesh(spot_path).mesh, "disk:0,0,0,0.8", "disk:0.181,0.946,-0.245,0.3");
  MapOptions options;
  options.sampling.layout.particles = 1500;
  options.distortion_guard = false;
  const MapResult plain = map_regions(c.source, c.from, c.target, c.to, options);
  options.distortion_guard = true;
  const MapResult guarded = map_regions(c.source, c.from, c.target, c.to, options);
  const auto measure = [&](const MapResult& r, const InitialMap& placement) {
    return measure_on_target(r.sampling.grid, c.target_surface, r.rest_scale, placement.positions,
                             placement.points);
  };
  const auto relaxed = [](const MapResult& r) {
    return InitialMap{r.relaxation.positions, r.relaxation.points, 0};
  };
  ASSERT_TRUE(plain.relaxation.converged);
  EXPECT_FALSE(plain.guard.checked);
  const MapMetrics naive = measure(plain, plain.naive);
  const MapMetrics before = measure(plain, relaxed(plain));
  const MapMetrics after = measure(guarded, relaxed(guarded));
  EXPECT_GT(before.symmetric_dirichlet, naive.symmetric_dirichlet);  // the guard's premise
  ASSERT_TRUE(guarded.guard.checked);
  ASSERT_TRUE(guarded.guard.taken);
  EXPECT_GT(guarded.guard.relaxed, guarded.guard.naive);
  EXPECT_LT(guarded.guard.guarded, guarded.guard.relaxed);
  EXPECT_GT(guarded.guard.iterations, 0);
  EXPECT_EQ(guarded.relaxation.iterations, plain.relaxation.iterations + guarded.guard.iterations);
  EXPECT_TRUE(guarded.relaxation.converged);
  EXPECT_EQ(after.folds, 0);
  // The guard removes most of what the relaxation added over its start (it does not promise to
  // beat the naive map: at 1,000 particles it did, at 1,500 it ends 0.04 above it).
  EXPECT_LT(after.symmetric_dirichlet - naive.symmetric_dirichlet,
            0.5 * (before.symmetric_dirichlet - naive.symmetric_dirichlet));
  EXPECT_LT(after.symmetric_dirichlet, before.symmetric_dirichlet - 0.1);
  // The trade: more length energy than the lengths' own minimum, not much more.
  EXPECT_GT(after.length_energy, before.length_energy);
  EXPECT_LT(after.length_energy, 1.25 * before.length_energy);
}

// Where the relaxed map is no more distorted than its start (a flat disk onto a sphere's cap), the
// guard measures and leaves the map exactly as it was; the paper's energy is never guarded.
TEST(MapRegions, DistortionGuardLeavesOtherMapsAlone) {
  const TwoRegions c(make_plane({.resolution = 8}),
                     read_mesh(test::project_mesh("sphere_quads.obj")).mesh, "disk:0,0,0,0.8",
                     "disk:0,0,1,0.8");
  MapOptions options;
  options.sampling.layout.particles = 600;
  const MapResult guarded = map_regions(c.source, c.from, c.target, c.to, options);
  EXPECT_TRUE(guarded.guard.checked);
  EXPECT_FALSE(guarded.guard.taken);
  EXPECT_EQ(guarded.guard.iterations, 0);
  EXPECT_LT(guarded.guard.relaxed, guarded.guard.naive);
  options.distortion_guard = false;
  const MapResult plain = map_regions(c.source, c.from, c.target, c.to, options);
  EXPECT_TRUE(guarded.relaxation.positions == plain.relaxation.positions);
  options.distortion_guard = true;
  options.relaxation.energy = EnergyKind::Paper;
  options.relaxation.max_iterations = 50;
  EXPECT_FALSE(map_regions(c.source, c.from, c.target, c.to, options).guard.checked);
}

}  // namespace
}  // namespace elastic
