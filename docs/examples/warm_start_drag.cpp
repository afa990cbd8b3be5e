// A target region dragged over a sphere, the map warm-started at every step from the last one
// (what a picker does while the user drags): no new sampling, no offset search, the relaxed
// placement carried onto the moved region. Built and run by the test suite (tests/CMakeLists.txt),
// quoted by docs/api.md.
#include <elastic/mapping/map_regions.h>
#include <elastic/regions/region_spec.h>
#include <elastic/shapes/procedural_shapes.h>

#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <string>

int main() {
  using namespace elastic;
  const LimitSurface plane(make_plane()), sphere(make_sphere());
  const SurfaceProjector source(plane), target(sphere);
  const Region from = make_region(source, parse_region_spec("disk:0,0,0,0.8"));
  MapOptions options;
  options.sampling.layout.particles = 2000;
  options.relaxation.boundary = BoundaryMode::Slide;
  bool ok = true;
  // [example]
  // Each map references its target region: keep every region alive as long as its map.
  std::deque<Region> regions;
  std::unique_ptr<MapResult> map;
  // The disk cuts share the heat method's factorisations of the neighbourhood.
  RegionCache cache;
  for (int step = 0; step <= 5; ++step) {
    const double tilt = 0.04 * step;  // the disk's centre moves 0.04 radians per step
    regions.push_back(
        make_region(target,
                    parse_region_spec("disk:" + std::to_string(std::sin(tilt)) + ",0," +
                                      std::to_string(std::cos(tilt)) + ",0.5"),
                    {.cache = &cache}));
    // The first map is cold; every later one starts from the one before (the same `from`).
    map = std::make_unique<MapResult>(
        map ? map_regions(source, from, target, regions.back(), *map, options)
            : map_regions(source, from, target, regions.back(), options));
    const RelaxationResult& r = map->relaxation;
    std::printf("step %d: %s, %ld iterations, converged: %s, folds: %d\n", step,
                map->warm_started ? "warm" : "cold", r.iterations, r.converged ? "yes" : "no",
                r.folded_faces);
    ok = ok && r.converged && r.folded_faces == 0;
  }
  // [example]
  return ok ? 0 : 1;
}
