// Sampling benchmarks: grid layout (sample_region without adaptive sampling) and layout plus
// curvature-adaptive sampling (eqs. 6-8) on the boundary region of the procedural cap (a spherical
// cap: constant curvature, so the adaptive iteration is Laplacian smoothing of the grid on the
// sphere). Timed: the sampling call; the surface, magnet and region are built once. Counters:
// particles, adaptive_iterations (not "iterations": Google Benchmark's own key), converged (1/0),
// largest last move (in mean spring lengths), rejected moves.
//
//   bench_sampling --benchmark_filter=Adaptive

#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "elastic/projection/closest_point.h"
#include "elastic/regions/region_spec.h"
#include "elastic/sampling/sample_region.h"
#include "elastic/shapes/procedural_shapes.h"
#include "elastic/surface/limit_surface.h"

namespace {

using namespace elastic;

struct Cap {
  std::unique_ptr<LimitSurface> surface;
  std::unique_ptr<SurfaceProjector> projector;
  Region region;
  Cap() {
    const ShapeOptions shape{.faces = ShapeFaces::Quads, .resolution = 32, .scale = 1.0};
    surface = std::make_unique<LimitSurface>(make_cap(shape));
    projector = std::make_unique<SurfaceProjector>(*surface);
    region = make_region(*projector, parse_region_spec("boundary"));
  }
};

const Cap& cap() {
  static const Cap instance;
  return instance;
}

void report(benchmark::State& state, const SampleRegionResult& result) {
  state.counters["particles"] = result.grid.num_particles();
  state.counters["adaptive_iterations"] = result.sampling.iterations;
  state.counters["converged"] = result.sampling.converged ? 1.0 : 0.0;
  state.counters["max_move"] = result.sampling.max_move;
  state.counters["rejected"] = static_cast<double>(result.sampling.rejected_moves);
}

void BM_Layout(benchmark::State& state) {
  SampleRegionOptions options;
  options.layout.particles = state.range(0);
  options.adaptive = false;
  SampleRegionResult result;
  for (auto _ : state) {
    result = sample_region(cap().region, *cap().projector, options);
    benchmark::DoNotOptimize(result.grid.num_particles());
  }
  report(state, result);
}
BENCHMARK(BM_Layout)
    ->Name("Layout")
    ->Arg(5775)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Adaptive(benchmark::State& state) {
  SampleRegionOptions options;
  options.layout.particles = state.range(0);
  SampleRegionResult result;
  for (auto _ : state) {
    result = sample_region(cap().region, *cap().projector, options);
    benchmark::DoNotOptimize(result.grid.num_particles());
  }
  report(state, result);
}
BENCHMARK(BM_Adaptive)
    ->Name("Adaptive")
    ->Arg(2000)
    ->Arg(5775)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
