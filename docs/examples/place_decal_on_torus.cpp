// Placing a decal by a point, an angle and a size (a free boundary, no target curve): a disk of a
// plane onto the outer side of a torus, against the exponential-map decal on the same grid. Built
// and run by the test suite (tests/CMakeLists.txt), quoted by docs/transfer.md.
#include <elastic/baselines/decal_baseline.h>
#include <elastic/mapping/map_decal.h>
#include <elastic/metrics/map_metrics.h>
#include <elastic/regions/region_spec.h>
#include <elastic/shapes/procedural_shapes.h>

#include <cstdio>

int main() {
  using namespace elastic;
  // [example]
  const LimitSurface plane(make_plane());
  const LimitSurface torus(make_torus());
  const SurfaceProjector source(plane), target(torus);
  const Region disk = make_region(source, parse_region_spec("disk:0,0,0,0.5"));

  // Centre on the torus point closest to (1.35, 0, 0), up turned 30 degrees from the projected
  // world +Y, a third of the disk's own size.
  const DecalPlacement placement{.point = {1.35, 0, 0}, .angle_degrees = 30, .scale = 0.33};
  MapDecalOptions options;
  options.sampling.layout.particles = 1500;
  const MapDecalResult decal = map_decal(source, disk, target, placement, options);

  // The same grid placed by the exponential map, measured alike (sigma = the scale).
  const DecalBaselineResult expmap = exponential_map_decal(torus, decal.geometry);
  const ParticleGrid& grid = decal.map.sampling.grid;
  const MapMetrics ours = measure_on_target(
      grid, torus, placement.scale, decal.map.relaxation.positions, decal.map.relaxation.points);
  const MapMetrics theirs =
      measure_on_target(grid, torus, placement.scale, expmap.positions, expmap.points);
  std::printf("folds %d; length energy %.3g (exponential map %.3g); cut region area %.4f\n",
              ours.folds, ours.length_energy, theirs.length_energy, decal.target_region->area());
  // [example]
  return decal.map.relaxation.converged && ours.folds == 0 &&
                 ours.length_energy < theirs.length_energy
             ? 0
             : 1;
}
