// The curvature measure averaged at the particle scale (curvature_field.h), and adaptive sampling
// on a surface whose pointwise curvature is noise at that scale.
#include "elastic/sampling/curvature_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "elastic/projection/closest_point.h"
#include "elastic/sampling/adaptive_sampling.h"
#include "elastic/sampling/grid_layout.h"
#include "grid_region.h"

namespace elastic {
namespace {

using test::make_grid_region;
using test::make_height_grid;

/// A deterministic value in [-1, 1] for control vertex (x, y): a scan's noise, the same on every
/// platform.
double noise(double x, double y) {
  const auto i = static_cast<std::uint64_t>(std::llround((x + 2.0) * 1000.0));
  const auto j = static_cast<std::uint64_t>(std::llround((y + 2.0) * 1000.0));
  std::uint64_t h = i * 0x9E3779B97F4A7C15ULL ^ (j + 0x632BE59BD9B4E019ULL) * 0xC2B2AE3D27D4EB4FULL;
  h ^= h >> 29U;
  h *= 0xBF58476D1CE4E5B9ULL;
  h ^= h >> 32U;
  return static_cast<double>(h % 2000001ULL) / 1000000.0 - 1.0;
}

/// A gentle dome with noise of amplitude `amplitude` on every control vertex of a 24 x 24 grid
/// over [-1,1]^2 (control spacing 1/12).
PolygonMesh noisy_dome(double amplitude) {
  return make_height_grid(24, 24, -1, 1, -1, 1, [amplitude](double x, double y) {
    return 0.3 * (1.0 - 0.5 * (x * x + y * y)) + amplitude * noise(x, y);
  });
}

/// Kernel average (1 - d^2 / (3 s)^2)^3 of the pointwise r over the region's vertices, by brute
/// force (every vertex tested, areas from the triangles): the reference for the indexed field.
double brute_force(const Region& region, const Eigen::Vector3d& x, double s) {
  std::vector<double> area(region.num_vertices(), 0.0);
  for (const Eigen::Vector3i& t : region.triangles) {
    const double a = (region.positions[t[1]] - region.positions[t[0]])
                         .cross(region.positions[t[2]] - region.positions[t[0]])
                         .norm() /
                     6.0;
    for (int k = 0; k < 3; ++k) area[t[k]] += a;
  }
  double num = 0.0, den = 0.0;
  for (int v = 0; v < region.num_vertices(); ++v) {
    const double d2 = (region.positions[v] - x).squaredNorm();
    if (d2 >= 9.0 * s * s) continue;
    const double g = std::pow(1.0 - d2 / (9.0 * s * s), 3);
    num += g * area[v] * CurvatureField::pointwise(*region.surface, region.points[v]);
    den += g * area[v];
  }
  return num / den;
}

TEST(CurvatureField, MatchesABruteForceKernelAverage) {
  const LimitSurface surface(noisy_dome(0.01));
  const Region region = make_grid_region(surface, 24, 24, 3);
  const double s = 0.15;
  const CurvatureField field(region, s);
  ASSERT_DOUBLE_EQ(field.radius(), s);  // above the tessellation's edges (1/36)
  for (const SurfacePoint q : {SurfacePoint{0, 0.5, 0.5}, SurfacePoint{300, 0.2, 0.7},
                               SurfacePoint{575, 0.9, 0.1}, SurfacePoint{287, 0.0, 0.0}}) {
    const Eigen::Vector3d x = surface.position(q);
    const double expected = brute_force(region, x, s);
    EXPECT_NEAR(field.at(x, q), expected, 1e-12 * expected) << "face " << q.face;
  }
}

TEST(CurvatureField, ZeroOnATiltedPlaneAndPointwiseAtRadiusZero) {
  const LimitSurface plane(
      make_height_grid(8, 8, -1, 1, -1, 1, [](double x, double y) { return 0.3 * x - 0.2 * y; }));
  const Region region = make_grid_region(plane, 8, 8, 4);
  const CurvatureField smooth(region, 0.3);
  const SurfacePoint q{27, 0.3, 0.6};
  EXPECT_NEAR(smooth.at(plane.position(q), q), 0.0, 1e-9);

  const LimitSurface dome(noisy_dome(0.01));
  const Region dome_region = make_grid_region(dome, 24, 24, 3);
  const CurvatureField pointwise(dome_region, 0.0);
  EXPECT_EQ(pointwise.radius(), 0.0);
  const SurfacePoint p{300, 0.25, 0.75};
  EXPECT_EQ(pointwise.at(dome.position(p), p), CurvatureField::pointwise(dome, p));
}

TEST(CurvatureField, NoiseAtTheControlScaleIsAveragedAway) {
  const LimitSurface surface(noisy_dome(0.01));
  const Region region = make_grid_region(surface, 24, 24, 3);
  const CurvatureField field(region, 0.15);  // about two control spacings
  // Relative spread (std / mean) of r over interior sample points, pointwise and averaged.
  const auto spread = [&](bool averaged) {
    double sum = 0.0, sum2 = 0.0;
    int n = 0;
    for (int j = 4; j < 20; ++j) {
      for (int i = 4; i < 20; ++i) {
        const SurfacePoint q{j * 24 + i, 0.37, 0.61};
        const double r =
            averaged ? field.at(surface.position(q), q) : CurvatureField::pointwise(surface, q);
        sum += r;
        sum2 += r * r;
        ++n;
      }
    }
    const double mean = sum / n;
    return std::sqrt(std::max(0.0, sum2 / n - mean * mean)) / mean;
  };
  const double raw = spread(false), averaged = spread(true);
  std::printf("relative spread of r: pointwise %.3f, averaged %.3f\n", raw, averaged);
  EXPECT_GT(raw, 0.3);  // the noise dominates the dome's own curvature (about 0.3)
  EXPECT_LT(averaged, raw / 4.0);
}

TEST(CurvatureField, AdaptiveSamplingSettlesOnANoisySurface) {
  // Control-scale noise 2.5x the dome's sag per spacing: the pointwise weights jump when a
  // particle moves by a fraction of the spacing. Averaged over a spacing, eq. 8 has a fixed point
  // the Newton steps reach.
  const LimitSurface surface(noisy_dome(0.01));
  const SurfaceProjector projector(surface);
  const Region region = make_grid_region(surface, 24, 24, 3);
  GridLayoutOptions layout;
  layout.particles = 400;
  const GridLayoutResult laid_out = layout_particle_grid(region, layout);
  AdaptiveSamplingOptions options;
  const AdaptiveSamplingResult averaged =
      adaptive_sampling(laid_out.grid, region, projector, options);
  EXPECT_TRUE(averaged.converged);
  EXPECT_LT(averaged.iterations, 15);
  test::expect_valid_faces(averaged.grid, surface, 0.0);
  options.curvature_radius = 0.0;
  const AdaptiveSamplingResult pointwise =
      adaptive_sampling(laid_out.grid, region, projector, options);
  std::printf("iterations: averaged %d (converged %d), pointwise %d (converged %d)\n",
              averaged.iterations, averaged.converged, pointwise.iterations, pointwise.converged);
  EXPECT_GT(pointwise.iterations, 5 * averaged.iterations);
}

}  // namespace
}  // namespace elastic
