// Mapping benchmark: Mapping::forward for a million source points of the plane -> cap map (grid.off
// disk of radius 0.45 onto the whole hemisphere.off, 2,000 particles), in parallel chunks of 1,024
// points as the Python binding runs it (tools/python/benchmarks/forward_1m.py times the binding on
// the same points and prints the ratio). The points: a Vogel spiral of N points in the disk of
// radius 0.44, put on the plane's limit surface by the closest-point query (not timed).
//
//   bench_mapping --benchmark_filter=ForwardMillion

#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "elastic/mapping/map_regions.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/region_spec.h"
#include "loaded_surface.h"

namespace {

using namespace elastic;

using Loaded = bench::LoadedSurface;

/// The benchmark's source points: a Vogel spiral of n points in the disk of radius 0.44 about
/// (0.5, 0.5, 0) (the golden angle between consecutive points, radius 0.44 sqrt((i + 0.5) / n)).
std::vector<Eigen::Vector3d> spiral(long n) {
  std::vector<Eigen::Vector3d> points(static_cast<std::size_t>(n));
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (long i = 0; i < n; ++i) {
    const double r = 0.44 * std::sqrt((static_cast<double>(i) + 0.5) / static_cast<double>(n));
    const double theta = golden * static_cast<double>(i);
    points[static_cast<std::size_t>(i)] = {0.5 + r * std::cos(theta), 0.5 + r * std::sin(theta),
                                           0.0};
  }
  return points;
}

void ForwardMillion(benchmark::State& state) {
  const Loaded plane(ELASTIC_SHARED_MESHES_DIR "/grid.off");
  const Loaded cap(ELASTIC_SHARED_MESHES_DIR "/hemisphere.off");
  const Region source = make_region(*plane.projector, parse_region_spec("disk:0.5,0.5,0,0.45"));
  const Region target = make_region(*cap.projector, parse_region_spec("boundary"));
  MapOptions options;
  options.sampling.layout.particles = 2000;
  const MapResult map = map_regions(*plane.projector, source, *cap.projector, target, options);
  const std::vector<Eigen::Vector3d> xs = spiral(state.range(0));
  std::vector<ClosestPoint> found(xs.size());
  plane.projector->closest(xs, found);
  std::vector<SurfacePoint> points(found.size());
  for (std::size_t i = 0; i < found.size(); ++i) {
    points[i] = found[i].point;
  }
  std::vector<Mapping::Location> out(points.size());
  for (auto _ : state) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          out[i] = map.mapping.forward(points[i]);
                        }
                      });
    benchmark::DoNotOptimize(out.data());
  }
  long inside = 0;
  for (const auto& l : out) {
    inside += l.inside ? 1 : 0;
  }
  state.counters["inside"] = static_cast<double>(inside);
}
BENCHMARK(ForwardMillion)->Arg(1'000'000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
