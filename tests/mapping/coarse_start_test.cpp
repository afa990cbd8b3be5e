// The multilevel start (MapOptions::coarse_start_above) and the prolonged map it starts from,
// against answers the code does not produce: the identity map, a turned boundary, the naive map
// and the cold map of the same regions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "elastic/core/error.h"
#include "elastic/mapping/initial_map.h"
#include "elastic/mapping/map_regions.h"
#include "elastic/regions/region_spec.h"
#include "elastic/shapes/procedural_shapes.h"
#include "mapping/disk_onto_sphere.h"

namespace elastic {
namespace {

using test::boundary_name;

// The plane disk onto the sphere's disk of radius 0.5 around +z, without the multilevel start
// unless a test sets it.
struct DiskOntoSphere : test::DiskOntoSphere {
  Region to = sphere_disk(0.0, 0.5);

  static MapOptions options(long particles, BoundaryMode boundary) {
    MapOptions o = test::DiskOntoSphere::options(boundary, particles);
    o.coarse_start_above = 0;
    return o;
  }
};

double spring_energy(const RelaxationResult& r) {
  return r.length_energy + r.angular_energy;
}

// The largest distance along the curve (a fraction of it, either way round) from a boundary
// particle's arc-length parameter to where the map put it: what the report's slide measures.
double largest_slide(const MapResult& map) {
  const std::vector<double>& from = map.sampling.grid.boundary_parameter;
  const std::vector<double>& to = map.relaxation.boundary_parameters;
  double largest = 0.0;
  for (std::size_t k = 0; k < from.size(); ++k) {
    const double d = to[k] - from[k];
    largest = std::max(largest, std::abs(d - std::round(d)));
  }
  return largest;
}

// A grid prolonged from itself is the map it was given: each particle is a corner of the
// triangles it is located in, so it keeps that corner's point.
TEST(ProlongedMap, FromTheSameGridIsTheGivenMap) {
  const DiskOntoSphere c;
  const MapResult cold =
      map_regions(c.source, c.from, c.target, c.to, c.options(800, BoundaryMode::Slide));
  const ParticleGrid& grid = cold.sampling.grid;
  std::vector<double> boundary;
  const InitialMap same =
      prolonged_map(grid, grid, cold.relaxation.points, cold.relaxation.boundary_parameters,
                    *cold.source_disk, *cold.target_disk, boundary);
  EXPECT_EQ(same.outside, 0);
  EXPECT_LT((same.positions - cold.relaxation.positions).colwise().norm().maxCoeff(), 1e-9);
  ASSERT_EQ(boundary.size(), grid.boundary_loop.size());
  for (std::size_t k = 0; k < boundary.size(); ++k) {
    const double s = cold.relaxation.boundary_parameters[k];
    EXPECT_NEAR(boundary[k] - std::floor(boundary[k]), s - std::floor(s), 1e-12) << k;
  }
  EXPECT_THROW(prolonged_map(grid, grid, cold.relaxation.points, {}, *cold.source_disk,
                             *cold.target_disk, boundary),
               InvalidInputError);
}

// A region mapped onto itself by the identity: the coarse map is the identity of the disk, so
// every particle of a finer grid lands on its own source point, and a boundary turned by a
// constant turns every finer boundary particle by the same constant.
TEST(ProlongedMap, IdentityAndTurnCarryOverExactly) {
  const DiskOntoSphere c;
  const RegionDiskMap disk(c.from);
  MapOptions options = c.options(300, BoundaryMode::Slide);
  const SampleRegionResult coarse = sample_region(c.from, c.source, options.sampling);
  options.sampling.layout.particles = 3000;
  const SampleRegionResult fine = sample_region(c.from, c.source, options.sampling);
  ASSERT_GT(fine.grid.num_particles(), 5 * coarse.grid.num_particles());

  std::vector<double> boundary;
  const InitialMap identity = prolonged_map(fine.grid, coarse.grid, coarse.grid.source_points,
                                            coarse.grid.boundary_parameter, disk, disk, boundary);
  EXPECT_EQ(identity.outside, 0);
  const Eigen::Matrix3Xd source = fine.grid.source_positions();
  for (int p = 0; p < fine.grid.num_particles(); ++p) {
    if (fine.grid.is_boundary[static_cast<std::size_t>(p)] == 0) {
      EXPECT_LT((identity.positions.col(p) - source.col(p)).norm(), 1e-9) << p;
    }
  }
  for (std::size_t k = 0; k < boundary.size(); ++k) {
    EXPECT_NEAR(boundary[k], fine.grid.boundary_parameter[k], 1e-12) << k;
  }

  // Turned by 0.05 of the boundary (in order: every coarse parameter by the same amount).
  std::vector<double> turned = coarse.grid.boundary_parameter;
  for (double& s : turned) {
    s += 0.05;
  }
  prolonged_map(fine.grid, coarse.grid, coarse.grid.source_points, turned, disk, disk, boundary);
  for (std::size_t k = 0; k < boundary.size(); ++k) {
    const double expected = fine.grid.boundary_parameter[k] + 0.05;
    EXPECT_NEAR(boundary[k] - std::floor(boundary[k]), expected - std::floor(expected), 1e-12) << k;
  }
}

class CoarseStart : public ::testing::TestWithParam<BoundaryMode> {};

// 3,000 particles from a relaxed map of 1/8 as many: converged and fold-free, at the cold map's
// energy (0.1%) with a fixed boundary, which stays at the naive map's arc-length positions to the
// bit, and with a sliding one, which slides on from where the coarse map slid it.
TEST_P(CoarseStart, ReachesTheColdMapsEnergy) {
  const DiskOntoSphere c;
  MapOptions options = c.options(3000, GetParam());
  const MapResult cold = map_regions(c.source, c.from, c.target, c.to, options);
  options.coarse_start_above = 1000;
  const MapResult multilevel = map_regions(c.source, c.from, c.target, c.to, options);
  ASSERT_TRUE(cold.relaxation.converged) << to_string(cold.relaxation.reason);
  EXPECT_TRUE(multilevel.relaxation.converged) << to_string(multilevel.relaxation.reason);
  EXPECT_EQ(multilevel.relaxation.folded_faces, 0);
  EXPECT_EQ(multilevel.relaxation.boundary, GetParam());
  EXPECT_EQ(multilevel.sampling.grid.num_particles(), cold.sampling.grid.num_particles());
  EXPECT_GT(multilevel.coarse_particles, 3000.0 / 8 * 0.95);
  EXPECT_LT(multilevel.coarse_particles, 3000.0 / 8 * 1.05);
  EXPECT_GT(multilevel.coarse_iterations, 0);
  EXPECT_GT(multilevel.seconds_coarse, 0.0);
  EXPECT_EQ(cold.coarse_particles, 0);
  EXPECT_NEAR(spring_energy(multilevel.relaxation), spring_energy(cold.relaxation),
              1e-3 * spring_energy(cold.relaxation));

  // `naive` is the grid's own naive map (the distortion guard's yardstick), at the offset the
  // coarse map chose: boundary particles at their source parameters on the target curve.
  const ParticleGrid& grid = multilevel.sampling.grid;
  for (std::size_t k = 0; k < grid.boundary_loop.size(); ++k) {
    const int p = grid.boundary_loop[k];
    const Eigen::Vector3d on_curve = c.sphere_surface.position(
        multilevel.target_disk->boundary_point(grid.boundary_parameter[k]));
    EXPECT_LT((multilevel.naive.positions.col(p) - on_curve).norm(), 1e-12) << k;
    if (GetParam() == BoundaryMode::Fixed) {
      EXPECT_EQ(multilevel.relaxation.positions.col(p), multilevel.naive.positions.col(p)) << k;
    }
  }
  if (GetParam() == BoundaryMode::Slide) {
    EXPECT_GT(multilevel.relaxation.slide_iterations, 0);
    EXPECT_EQ(multilevel.relaxation.boundary_parameters.size(), grid.boundary_loop.size());
    EXPECT_NEAR(multilevel.relaxation.boundary_slide, largest_slide(multilevel), 1e-15);
  }
}

// MapOptions::coarse_hold_above: a grid above it holds its sliding boundary where the coarse map
// slid it (no slide iteration of its own, the coarse slide's reason, the report's slide still
// measured from the arc-length correspondence), on this near-isometry at 0.3% of energy (1%
// allowed); a grid below it slides on.
TEST(CoarseStart, HoldsTheBoundaryOnlyAboveCoarseHoldAbove) {
  const DiskOntoSphere c;
  MapOptions options = c.options(3000, BoundaryMode::Slide);
  options.coarse_start_above = 1000;
  const MapResult slid = map_regions(c.source, c.from, c.target, c.to, options);
  options.coarse_hold_above = 0;
  const MapResult held = map_regions(c.source, c.from, c.target, c.to, options);
  EXPECT_TRUE(held.relaxation.converged) << to_string(held.relaxation.reason);
  EXPECT_EQ(held.relaxation.folded_faces, 0);
  EXPECT_EQ(held.relaxation.boundary, BoundaryMode::Slide);
  EXPECT_EQ(held.relaxation.slide_iterations, 0);
  EXPECT_EQ(held.relaxation.slide_reason, StopReason::RelativeGradient);
  EXPECT_NEAR(held.relaxation.boundary_slide, largest_slide(held), 1e-15);
  EXPECT_NEAR(spring_energy(held.relaxation), spring_energy(slid.relaxation),
              1e-2 * spring_energy(slid.relaxation));
  options.coarse_hold_above = 3500;  // above the grid: it slides
  EXPECT_GT(map_regions(c.source, c.from, c.target, c.to, options).relaxation.slide_iterations, 0);
  options.coarse_hold_above = -1;
  EXPECT_THROW(map_regions(c.source, c.from, c.target, c.to, options), InvalidInputError);
}

INSTANTIATE_TEST_SUITE_P(BothBoundaries, CoarseStart,
                         ::testing::Values(BoundaryMode::Slide, BoundaryMode::Fixed),
                         boundary_name);

// A carried start that does not settle (here: an iteration budget of 2) is not returned: the map
// relaxes again from the naive start, exactly as without the coarse map (no offset search, so both
// naive maps are the same), and the iterations tried count.
TEST(CoarseStart, UnsettledCarriedStartFallsBackToTheNaiveStart) {
  const DiskOntoSphere c;
  MapOptions options = c.options(3000, BoundaryMode::Slide);
  options.choose_offset = false;
  options.relaxation.max_iterations = 2;
  const MapResult cold = map_regions(c.source, c.from, c.target, c.to, options);
  options.coarse_start_above = 1000;
  const MapResult multilevel = map_regions(c.source, c.from, c.target, c.to, options);
  ASSERT_FALSE(cold.relaxation.converged);
  EXPECT_FALSE(multilevel.relaxation.converged);
  EXPECT_GT(multilevel.coarse_particles, 0);
  EXPECT_EQ(multilevel.relaxation.positions, cold.relaxation.positions);
  EXPECT_EQ(multilevel.relaxation.initial_energy, cold.relaxation.initial_energy);
  EXPECT_GT(multilevel.relaxation.iterations, cold.relaxation.iterations);
}

// Below the threshold, with the faithful solver or with subdivision, the map is the cold one to
// the bit; a negative threshold or a ratio below 2 is refused, naming the option.
TEST(CoarseStartInput, OnlyWhereItAppliesAndRefusesNonsense) {
  const DiskOntoSphere c;
  MapOptions options = c.options(1200, BoundaryMode::Slide);
  const MapResult cold = map_regions(c.source, c.from, c.target, c.to, options);
  options.coarse_start_above = 1300;
  const MapResult below = map_regions(c.source, c.from, c.target, c.to, options);
  EXPECT_EQ(below.coarse_particles, 0);
  EXPECT_EQ(below.relaxation.positions, cold.relaxation.positions);

  options.coarse_start_above = 100;
  options.relaxation.boundary = BoundaryMode::Fixed;
  options.subdivisions = 1;
  options.sampling.layout.particles = 300;
  EXPECT_EQ(map_regions(c.source, c.from, c.target, c.to, options).coarse_particles, 0);

  options.subdivisions = 0;
  options.coarse_start_above = -1;
  EXPECT_THROW(map_regions(c.source, c.from, c.target, c.to, options), InvalidInputError);
  options.coarse_start_above = 100;
  options.coarse_start_ratio = 1;
  try {
    map_regions(c.source, c.from, c.target, c.to, options);
    ADD_FAILURE() << "a ratio of 1 was accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("coarse start"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace elastic
