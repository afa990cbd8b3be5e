// A first program with libelastic: map a disk of a plane onto a spherical cap with least
// distortion, then ask the mapping where a source point lands. Built and run by the test suite
// (tests/CMakeLists.txt), quoted by docs/getting-started.md.
#include <elastic/mapping/map_regions.h>
#include <elastic/regions/region_spec.h>
#include <elastic/shapes/procedural_shapes.h>

#include <cstdio>

int main() {
  using namespace elastic;
  // [example]
  // 1. Two smooth surfaces: the limit surfaces of procedural control meshes (any mesh read with
  //    read_mesh() works the same way).
  const LimitSurface plane(make_plane());
  const LimitSurface cap(make_cap());
  const SurfaceProjector source(plane);  // the magnet: closest point on the limit surface
  const SurfaceProjector target(cap);

  // 2. Regions, given as on the command line: a geodesic disk, and the cap's own boundary.
  const Region from = make_region(source, parse_region_spec("disk:0,0,0,0.9"));
  const Region to = make_region(target, parse_region_spec("boundary"));

  // 3. Sample, place, relax.
  MapOptions options;
  options.sampling.layout.particles = 2000;
  const MapResult result = map_regions(source, from, target, to, options);
  const RelaxationResult& relaxed = result.relaxation;
  std::printf("%d particles, %ld iterations, converged: %s, folds: %d, length energy %.4g\n",
              result.sampling.grid.num_particles(), relaxed.iterations,
              relaxed.converged ? "yes" : "no", relaxed.folded_faces, relaxed.length_energy);

  // 4. Query the map: where does the plane's centre land on the cap?
  const ClosestPoint centre = source.closest(Eigen::Vector3d(0, 0, 0));
  const Mapping::Location there = result.mapping.forward(centre.point);
  if (there.inside) {
    std::printf("centre -> (%.4f, %.4f, %.4f)\n", there.position.x(), there.position.y(),
                there.position.z());
  }
  // [example]
  return relaxed.converged && relaxed.folded_faces == 0 && there.inside ? 0 : 1;
}
