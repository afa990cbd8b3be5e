// Limit-surface evaluation throughput: position only, position + first + second derivatives, and
// curvature, at random points of control meshes whose default tessellation (resolution 8: 128
// triangles per quad) has about 10k, 100k and 1M triangles. These tori have only regular patches;
// the shared spot control mesh (pentagons, quads, triangles; when present) measures a mix with
// Gregory end caps. Also: construction and tessellation times. Reported as items_per_second.
#include "elastic/surface/limit_surface.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "elastic/mesh/mesh_io.h"
#include "elastic/surface/limit_tessellation.h"

namespace {

using elastic::LimitSurface;
using elastic::PolygonMesh;
using elastic::SurfacePoint;

PolygonMesh torus(int nu, int nv) {
  PolygonMesh mesh;
  const double pi = std::numbers::pi;
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const double a = 2 * pi * i / nu, b = 2 * pi * j / nv;
      mesh.positions.emplace_back((1.0 + 0.35 * std::cos(b)) * std::cos(a),
                                  (1.0 + 0.35 * std::cos(b)) * std::sin(a), 0.35 * std::sin(b));
    }
  }
  auto id = [&](int i, int j) { return (i % nu) * nv + j % nv; };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j)
      mesh.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  }
  return mesh;
}

/// Torus control meshes with ~80, ~800 and ~8200 quads (x 128 triangles at resolution 8).
const LimitSurface& surface(int size_index) {
  static std::unique_ptr<LimitSurface> cache[4];
  auto& s = cache[size_index];
  if (!s) {
    if (size_index == 3) {
      const std::filesystem::path spot =
          std::filesystem::path(ELASTIC_SHARED_MESHES_DIR) / "spot_control_mesh.obj";
      s = std::make_unique<LimitSurface>(
          std::filesystem::exists(spot) ? elastic::read_mesh(spot).mesh : torus(10, 8),
          elastic::LimitSurfaceOptions{.name = "spot"});
    } else {
      static constexpr int kSizes[3][2] = {{10, 8}, {40, 20}, {128, 64}};
      s = std::make_unique<LimitSurface>(torus(kSizes[size_index][0], kSizes[size_index][1]));
    }
  }
  return *s;
}

std::vector<SurfacePoint> random_points(const LimitSurface& s, size_t count) {
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> face(0, s.num_faces() - 1);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<SurfacePoint> out(count);
  for (auto& p : out) p = {face(rng), uni(rng), uni(rng)};
  return out;
}

void label(benchmark::State& state, const LimitSurface& s) {
  if (state.range(0) == 3) {
    state.SetLabel("spot control mesh (Gregory end caps)");
    return;
  }
  std::string text = "torus, ~";
  text += std::to_string(128L * s.control_mesh().num_faces() / 1000);
  text += "k triangles";
  state.SetLabel(text);
}

void BM_Position(benchmark::State& state) {
  const LimitSurface& s = surface(static_cast<int>(state.range(0)));
  const auto points = random_points(s, 1 << 16);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(s.position(points[i++ & (points.size() - 1)]));
  }
  state.SetItemsProcessed(state.iterations());
  label(state, s);
}

void BM_Derivatives(benchmark::State& state) {
  const LimitSurface& s = surface(static_cast<int>(state.range(0)));
  const auto points = random_points(s, 1 << 16);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(s.derivatives(points[i++ & (points.size() - 1)]));
  }
  state.SetItemsProcessed(state.iterations());
  label(state, s);
}

void BM_Curvature(benchmark::State& state) {
  const LimitSurface& s = surface(static_cast<int>(state.range(0)));
  const auto points = random_points(s, 1 << 16);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(s.curvature(points[i++ & (points.size() - 1)]));
  }
  state.SetItemsProcessed(state.iterations());
  label(state, s);
}

void BM_Build(benchmark::State& state) {
  static constexpr int kSizes[3][2] = {{10, 8}, {40, 20}, {128, 64}};
  const PolygonMesh mesh = torus(kSizes[state.range(0)][0], kSizes[state.range(0)][1]);
  for (auto _ : state) benchmark::DoNotOptimize(LimitSurface(mesh));
  state.SetItemsProcessed(state.iterations() * mesh.num_faces());  // control faces per second
}

void BM_Tessellate(benchmark::State& state) {
  const LimitSurface& s = surface(static_cast<int>(state.range(0)));
  long triangles = 0;
  for (auto _ : state) {
    const elastic::LimitTessellation t = elastic::tessellate(s, {.resolution = 8});
    triangles = static_cast<long>(t.triangles.size());
    benchmark::DoNotOptimize(t.positions.data());
  }
  state.SetItemsProcessed(state.iterations() * triangles);  // triangles per second
  label(state, s);
}

BENCHMARK(BM_Position)->DenseRange(0, 3);
BENCHMARK(BM_Derivatives)->DenseRange(0, 3);
BENCHMARK(BM_Curvature)->DenseRange(0, 3);
BENCHMARK(BM_Build)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Tessellate)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
