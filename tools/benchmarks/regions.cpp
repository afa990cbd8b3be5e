// Region cutting benchmark: make_region of a geodesic disk on bob_tri.obj (its limit tessellation
// has about 85k vertices), the cut the studio repeats at every step of a drag (docs/studio.md), at
// radii from a small decal to a third of the model. Loading is not timed.
//
//   BM_Disk/R   make_region("disk:C,R") for R = range / 100 (the model is about 1.6 long)

#include <benchmark/benchmark.h>

#include <memory>
#include <sstream>

#include "elastic/projection/closest_point.h"
#include "elastic/regions/region_spec.h"
#include "loaded_surface.h"

namespace {

using namespace elastic;

using Loaded = bench::LoadedSurface;

const Loaded& bob() {
  static const Loaded loaded(ELASTIC_SHARED_MESHES_DIR "/bob_tri.obj");
  return loaded;
}

void BM_Disk(benchmark::State& state) {
  const Loaded& target = bob();
  std::ostringstream spec;
  spec << "disk:0.452912,-0.0774533,0.230485," << static_cast<double>(state.range(0)) / 100.0;
  const RegionSpec parsed = parse_region_spec(spec.str());
  long triangles = 0;
  for (auto _ : state) {
    const Region region = make_region(*target.projector, parsed);
    triangles = region.num_triangles();
    benchmark::DoNotOptimize(region.positions.data());
  }
  state.counters["triangles"] = static_cast<double>(triangles);
}
BENCHMARK(BM_Disk)->Arg(5)->Arg(23)->Arg(50)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
