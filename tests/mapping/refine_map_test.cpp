// Refining a relaxed map: subdivide the grid, place the new particles, relax briefly (end of §4.3).
#include "elastic/mapping/refine_map.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "elastic/core/error.h"
#include "elastic/mapping/map_regions.h"
#include "elastic/regions/region_spec.h"
#include "elastic/shapes/procedural_shapes.h"
#include "rigid_motion.h"

namespace elastic {
namespace {

Eigen::Isometry3d some_rigid_motion() {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.rotate(Eigen::AngleAxisd(-0.4, Eigen::Vector3d(2, -1, 1).normalized()));
  m.pretranslate(Eigen::Vector3d(-0.5, 0.8, 1.5));
  return m;
}

// A disk on the plane onto the same disk on a rigidly moved copy.
struct RigidCase {
  const Eigen::Isometry3d motion = some_rigid_motion();
  const PolygonMesh plane = make_plane({.faces = ShapeFaces::Quads, .resolution = 8});
  LimitSurface source_surface{plane};
  LimitSurface target_surface{test::moved(plane, motion)};
  SurfaceProjector source{source_surface}, target{target_surface};
  Region from, to;
  RigidCase() {
    RegionSpec spec = parse_region_spec("disk:0.1,0.05,0,0.6");
    spec.anchor = Eigen::Vector3d(1, 0, 0);
    RegionSpec moved_spec = spec;
    moved_spec.center = motion * spec.center;
    moved_spec.anchor = motion * *spec.anchor;
    from = make_region(source, spec);
    to = make_region(target, moved_spec);
  }
};

// The energy's zero is the rigid motion, and refinement must keep it: the new particles' source
// positions are wherever the source disk map put them, and the refined map must be the rigid
// motion of *those* positions, to 1e-8 of the region's size (diameter 1.2; the brief relaxation
// stops at a relative gradient of 1e-6 of a start that is already within the coarse grid's
// interpolation error, and the boundary correspondence is exact up to the cut's round-off).
TEST(RefineMap, RigidMotionStaysRigidThroughMapRegions) {
  const RigidCase c;
  MapOptions options;
  options.sampling.layout.particles = 250;
  options.subdivisions = 1;
  const MapResult result = map_regions(c.source, c.from, c.target, c.to, options);
  const ParticleGrid& grid = result.sampling.grid;
  ASSERT_EQ(result.subdivisions, 1);
  ASSERT_EQ(result.subdivision_levels.size(), 1u);
  const RefinementLevel& level = result.subdivision_levels[0];
  EXPECT_EQ(level.particles_before, result.sampled_particles);
  EXPECT_EQ(level.particles_after, grid.num_particles());
  EXPECT_GT(grid.num_particles(), 3 * result.sampled_particles);  // V + E + quads ~ 4 V
  EXPECT_TRUE(result.relaxation.converged) << to_string(result.relaxation.reason);
  EXPECT_TRUE(result.coarse_relaxation.converged);
  EXPECT_EQ(result.coarse_relaxation.positions.cols(), result.sampled_particles);
  EXPECT_EQ(result.relaxation.folded_faces, 0);
  EXPECT_EQ(result.relaxation.initial_folded_faces, 0);

  const Eigen::Matrix3Xd expected = c.motion * grid.source_positions();
  const double error = (result.relaxation.positions - expected).colwise().norm().maxCoeff();
  EXPECT_LT(error, 1e-8) << "largest deviation from the rigid motion";
  EXPECT_LT(result.relaxation.length_energy, 1e-14);

  // Everything returned describes the refined grid.
  EXPECT_EQ(result.relaxation.positions.cols(), grid.num_particles());
  EXPECT_EQ(result.naive.positions.cols(), grid.num_particles());
  EXPECT_EQ(result.sampling.statistics.particles, grid.num_particles());
  size_t triangles = 0;
  for (const auto fh : grid.mesh.faces()) triangles += grid.mesh.valence(fh) - 2;
  EXPECT_EQ(result.mapping.triangles().size(), triangles);
  // The mapping of a refined-grid particle's source point is its own target position (a grid
  // vertex maps exactly; 1e-9: the magnet's tolerance).
  const int probe = grid.num_particles() - 1;  // a face particle, new in the refinement
  const Mapping::Location there = result.mapping.forward(grid.source_points[probe]);
  ASSERT_TRUE(there.inside);
  EXPECT_LT((there.position - result.relaxation.positions.col(probe)).norm(), 1e-9);
}

// Plane disk -> cap: a map with real distortion.
struct CapCase {
  LimitSurface source_surface{make_plane({.resolution = 8})};
  LimitSurface target_surface{make_cap({.resolution = 12})};
  SurfaceProjector source{source_surface}, target{target_surface};
  Region from = make_region(source, parse_region_spec("disk:0,0,0,0.9"));
  Region to = make_region(target, parse_region_spec("boundary"));
};

MapResult coarse_map(const CapCase& c, long particles) {
  MapOptions options;
  options.sampling.layout.particles = particles;
  options.sampling.adaptive = false;
  return map_regions(c.source, c.from, c.target, c.to, options);
}

TEST(RefineMap, PlaneOntoCapKeepsZeroFoldsAndBoundedEnergy) {
  const CapCase c;
  const MapResult coarse = coarse_map(c, 300);
  ASSERT_TRUE(coarse.relaxation.converged) << to_string(coarse.relaxation.reason);
  ASSERT_EQ(coarse.relaxation.folded_faces, 0);
  const RefineMapResult refined = refine_map(coarse.sampling.grid, coarse.relaxation, c.source,
                                             *coarse.source_disk, c.target, *coarse.target_disk);
  const RelaxationResult& r = refined.relaxation;
  const ParticleGrid& grid = refined.grid;
  ASSERT_EQ(r.positions.cols(), grid.num_particles());
  EXPECT_EQ(r.initial_folded_faces, 0);  // the midpoint placement of a fold-free map
  EXPECT_EQ(r.folded_faces, 0);
  EXPECT_TRUE(r.converged) << to_string(r.reason);
  EXPECT_LT(r.boundary_residual, 1e-12);
  EXPECT_LE(r.iterations, 200);
  EXPECT_EQ(refined.iterations, r.iterations);
  ASSERT_EQ(refined.levels.size(), 1u);
  EXPECT_EQ(refined.levels[0].folded_faces, 0);
  EXPECT_EQ(refined.levels[0].particles_after, grid.num_particles());

  // On the target surface.
  for (int i = 0; i < grid.num_particles(); ++i) {
    EXPECT_LT((c.target_surface.position(r.points[i]) - r.positions.col(i)).norm(), 1e-9) << i;
  }
  // New boundary particles on the target curve at their parameter: the target point is the limit
  // surface point under the curve's chord at that parameter, off the chord by at most its sagitta,
  // c^2 / (8 R) for a chord of length c on a boundary of curvature radius R >= c: below c / 8.
  const SurfaceCurve curve = c.to.boundary_curve();
  for (size_t k = 1; k < grid.boundary_loop.size(); k += 2) {
    // (at the correspondence the map chose: turned by its boundary offset)
    const SurfaceCurve::Location at =
        curve.locate(grid.boundary_parameter[k] + coarse.boundary_offset);
    const double chord =
        (curve.positions[(at.segment + 1) % curve.size()] - curve.positions[at.segment]).norm();
    EXPECT_LT((r.positions.col(grid.boundary_loop[k]) - at.position).norm(), chord / 8) << k;
  }

  // Energy per spring does not blow up. Halving the spacing halves each spring's length error at
  // the same strain, so the length energy per spring should drop to about 1/4 (the strain field is
  // the same continuum map's); allow 1/2 for the discretisation's change of the strain.
  const double coarse_per_spring =
      coarse.relaxation.length_energy / static_cast<double>(coarse.sampling.grid.springs.size());
  const double fine_per_spring = r.length_energy / static_cast<double>(grid.springs.size());
  EXPECT_GT(coarse_per_spring, 0.0);
  EXPECT_LT(fine_per_spring, 0.5 * coarse_per_spring)
      << "coarse " << coarse_per_spring << " fine " << fine_per_spring;
  // The brief relaxation lowered the energy of the placement.
  EXPECT_LE(r.length_energy + r.angular_energy, r.initial_energy);
}

TEST(RefineMap, IsDeterministicAndLevelsCompose) {
  const CapCase c;
  const MapResult coarse = coarse_map(c, 120);
  RefineMapOptions options;
  options.levels = 2;
  const RefineMapResult a = refine_map(coarse.sampling.grid, coarse.relaxation, c.source,
                                       *coarse.source_disk, c.target, *coarse.target_disk, options);
  const RefineMapResult b = refine_map(coarse.sampling.grid, coarse.relaxation, c.source,
                                       *coarse.source_disk, c.target, *coarse.target_disk, options);
  EXPECT_EQ(a.relaxation.positions, b.relaxation.positions);
  EXPECT_EQ(a.grid.source_positions(), b.grid.source_positions());
  ASSERT_EQ(a.levels.size(), 2u);
  EXPECT_EQ(a.levels[0].particles_before, coarse.sampling.grid.num_particles());
  EXPECT_EQ(a.levels[1].particles_before, a.levels[0].particles_after);
  EXPECT_EQ(a.levels[1].particles_after, a.grid.num_particles());
  EXPECT_EQ(a.grid.mesh.n_faces(), 16 * coarse.sampling.grid.mesh.n_faces());
  EXPECT_EQ(a.iterations, a.levels[0].iterations + a.levels[1].iterations);
  EXPECT_EQ(a.relaxation.folded_faces, 0);

  // Zero levels: the input unchanged.
  options.levels = 0;
  const RefineMapResult same =
      refine_map(coarse.sampling.grid, coarse.relaxation, c.source, *coarse.source_disk, c.target,
                 *coarse.target_disk, options);
  EXPECT_EQ(same.relaxation.positions, coarse.relaxation.positions);
  EXPECT_EQ(same.grid.num_particles(), coarse.sampling.grid.num_particles());
  EXPECT_TRUE(same.levels.empty());
}

TEST(RefineMap, RejectsInconsistentInput) {
  const CapCase c;
  const MapResult coarse = coarse_map(c, 80);
  RelaxationResult truncated = coarse.relaxation;
  truncated.positions.conservativeResize(3, truncated.positions.cols() - 1);
  EXPECT_THROW(refine_map(coarse.sampling.grid, truncated, c.source, *coarse.source_disk, c.target,
                          *coarse.target_disk),
               InvalidInputError);
  RefineMapOptions faithful;
  faithful.relaxation.solver = SolverKind::Faithful;
  EXPECT_THROW(refine_map(coarse.sampling.grid, coarse.relaxation, c.source, *coarse.source_disk,
                          c.target, *coarse.target_disk, faithful),
               InvalidInputError);
  MapOptions negative;
  negative.subdivisions = -1;
  EXPECT_THROW(map_regions(c.source, c.from, c.target, c.to, negative), InvalidInputError);
}

}  // namespace
}  // namespace elastic
