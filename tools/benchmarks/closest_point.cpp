// Closest-point queries per second on the limit surface of a torus (procedural quad control mesh,
// 32 segments around), whose projector tessellation has about 10k, 100k and 1M triangles.
//
//   BM_Build           projector construction (tessellation, grid nodes, Embree BVH)
//   BM_Cold            global queries (BVH seed + Newton) for points within 0.02 of the surface
//   BM_Warm            particles: every point moves by ~1e-3 per sweep and is projected with its
//                      previous answer as the hint (the solver's use)
//   BM_WarmBatched     the same through the batched form (TBB, all threads of the default arena)
//   BM_ColdBatched     cold queries through the batched form
//
// items_per_second is queries per CPU-second. The single-query benchmarks run on one thread.

#include "elastic/projection/closest_point.h"

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "elastic/shapes/procedural_shapes.h"

namespace {

using elastic::ClosestPoint;
using elastic::SurfacePoint;

constexpr int kParticles = 20000;

struct Fixture {
  std::unique_ptr<elastic::LimitSurface> surface;
  std::unique_ptr<elastic::SurfaceProjector> projector;
  std::vector<Eigen::Vector3d> points;  // query points near the surface
  std::vector<Eigen::Vector3d> steps;   // per-particle displacement per sweep
};

elastic::ProjectionOptions projection_options(long triangles) {
  elastic::ProjectionOptions options;
  options.tessellation.target_triangles = triangles;
  return options;
}

const elastic::LimitSurface& torus() {
  static const elastic::LimitSurface surface = [] {
    elastic::ShapeOptions shape;
    shape.faces = elastic::ShapeFaces::Quads;
    shape.resolution = 32;
    elastic::LimitSurfaceOptions options;
    options.name = "torus";
    return elastic::LimitSurface(elastic::make_torus(shape), options);
  }();
  return surface;
}

Fixture& fixture(long triangles) {
  static std::map<long, Fixture> cache;
  auto it = cache.find(triangles);
  if (it != cache.end()) return it->second;
  Fixture& f = cache[triangles];
  const elastic::LimitSurface& surface = torus();
  f.projector = std::make_unique<elastic::SurfaceProjector>(surface, projection_options(triangles));
  std::mt19937 rng(2024);
  std::uniform_int_distribution<int> face(0, surface.num_faces() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0), offset(-0.02, 0.02), step(-1e-3, 1e-3);
  for (int i = 0; i < kParticles; ++i) {
    const SurfacePoint p{face(rng), unit(rng), unit(rng)};
    const elastic::SurfaceDerivatives d = surface.derivatives(p);
    f.points.push_back(d.position + offset(rng) * d.du.cross(d.dv).normalized());
    f.steps.emplace_back(step(rng), step(rng), step(rng));
  }
  return f;
}

void BM_Build(benchmark::State& state) {
  const elastic::LimitSurface& surface = torus();
  for (auto _ : state) {
    elastic::SurfaceProjector projector(surface, projection_options(state.range(0)));
    benchmark::DoNotOptimize(projector.tessellation().triangles.size());
    state.counters["triangles"] = static_cast<double>(projector.tessellation().triangles.size());
  }
}

void BM_Cold(benchmark::State& state) {
  Fixture& f = fixture(state.range(0));
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.projector->closest(f.points[i]));
    i = (i + 1) % f.points.size();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
  state.counters["triangles"] = static_cast<double>(f.projector->tessellation().triangles.size());
}

// Particles oscillate: sweep k moves every point by +step or -step, so they stay near the surface.
void BM_Warm(benchmark::State& state) {
  Fixture& f = fixture(state.range(0));
  std::vector<Eigen::Vector3d> xs = f.points;
  std::vector<ClosestPoint> answers(xs.size());
  f.projector->closest(xs, answers);
  std::vector<SurfacePoint> hints(xs.size());
  for (size_t i = 0; i < xs.size(); ++i) hints[i] = answers[i].point;
  size_t i = 0;
  double sign = 1.0;
  for (auto _ : state) {
    xs[i] += sign * f.steps[i];
    const ClosestPoint c = f.projector->closest(xs[i], hints[i]);
    hints[i] = c.point;
    benchmark::DoNotOptimize(c);
    if (++i == xs.size()) {
      i = 0;
      sign = -sign;
    }
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

void BM_WarmBatched(benchmark::State& state) {
  Fixture& f = fixture(state.range(0));
  std::vector<Eigen::Vector3d> xs = f.points;
  std::vector<ClosestPoint> answers(xs.size());
  f.projector->closest(xs, answers);
  std::vector<SurfacePoint> hints(xs.size());
  double sign = 1.0;
  for (auto _ : state) {
    for (size_t i = 0; i < xs.size(); ++i) {
      hints[i] = answers[i].point;
      xs[i] += sign * f.steps[i];
    }
    f.projector->closest(xs, answers, hints);
    sign = -sign;
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(xs.size()));
}

void BM_ColdBatched(benchmark::State& state) {
  Fixture& f = fixture(state.range(0));
  std::vector<ClosestPoint> answers(f.points.size());
  for (auto _ : state) f.projector->closest(f.points, answers);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(f.points.size()));
}

}  // namespace

BENCHMARK(BM_Build)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK(BM_Cold)->Arg(10000)->Arg(100000)->Arg(1000000);
BENCHMARK(BM_Warm)->Arg(10000)->Arg(100000)->Arg(1000000);
// The batched forms run on several threads: time them by the CPU time of the whole process (summed
// over threads), so items_per_second is queries per CPU-second and comparable with the
// single-thread figures whatever the machine's load; their wall-clock rate on T idle cores is up to
// T times it.
BENCHMARK(BM_WarmBatched)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();
BENCHMARK(BM_ColdBatched)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();

BENCHMARK_MAIN();
