// Boundary first flattening (regions/boundary_first_flattening.h) against answers it does not
// compute: the unrolling of a developable strip, the stereographic projection of a spherical cap,
// and the fallback of flatten_region where the method does not apply.

#include "elastic/regions/boundary_first_flattening.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "elastic/projection/closest_point.h"
#include "elastic/regions/region_flattening.h"
#include "elastic/regions/region_spec.h"
#include "elastic/shapes/procedural_shapes.h"
#include "region_cases.h"

namespace elastic {
namespace {

constexpr double kPi = std::numbers::pi;

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

int folds(const Region& region, const std::vector<Eigen::Vector2d>& uv) {
  int n = 0;
  for (const Eigen::Vector3i& t : region.triangles) {
    n += cross2(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]) <= 0.0 ? 1 : 0;
  }
  return n;
}

// A rectangle bent around the unit cylinder (region_cases.h, 12 x 7 planar quads): every
// interior angle sum is 2 pi and every boundary turn is the unrolled rectangle's, so the scale
// factor is 0 and the flattening is the unrolling itself, with vertex `first` at the origin and
// `second` on the positive x axis: a rigid motion of (i * chord, j * height), not a similarity.
TEST(BoundaryFirstFlattening, UnrollsABentRectangleExactly) {
  const test::BentRectangle strip = test::bent_rectangle();
  const Region& region = strip.region;
  const std::vector<Eigen::Vector2d>& unrolled = strip.unrolled;
  // Pins: the corner (0, 0) and the corner (columns, 0), so the unrolling needs no rotation.
  const auto uv = boundary_first_flattening(region, strip.origin, strip.along);
  ASSERT_TRUE(uv.has_value());
  double worst = 0.0;
  for (size_t v = 0; v < unrolled.size(); ++v) {
    worst = std::max(worst, ((*uv)[v] - unrolled[v]).norm());
  }
  EXPECT_LT(worst, 1e-12);
}

/// A spherical cap of the unit sphere, polar angles 0..theta0, built ring by ring: `rings` rings at
/// theta_j = j theta0 / rings with 6 j vertices each, consecutive rings zipped by angle.
struct Cap {
  Region region;
  std::vector<double> theta;  ///< #V polar angle of each vertex
};

Cap spherical_cap(double theta0, int rings) {
  Cap cap;
  Region& r = cap.region;
  r.positions.emplace_back(0.0, 0.0, 1.0);
  cap.theta.push_back(0.0);
  std::vector<int> first{0}, count{1};
  for (int j = 1; j <= rings; ++j) {
    const double th = theta0 * j / rings;
    first.push_back(r.num_vertices());
    count.push_back(6 * j);
    for (int k = 0; k < 6 * j; ++k) {
      const double phi = 2.0 * kPi * k / (6 * j);
      r.positions.emplace_back(std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi),
                               std::cos(th));
      cap.theta.push_back(th);
    }
  }
  r.points.resize(r.positions.size());
  for (int j = 1; j <= rings; ++j) {
    // Zip ring j - 1 (inner, n1 vertices) and ring j (outer, n2) in order of angle: each triangle
    // advances on the ring whose next vertex comes first (counter-clockwise seen from +z).
    const int n1 = count[j - 1], n2 = count[j];
    int a = 0, b = 0;
    while (a < n1 || b < n2) {
      const auto inner = [&](int k) { return first[j - 1] + (k % n1); };
      const auto outer = [&](int k) { return first[j] + (k % n2); };
      const double next_a = n1 == 1 ? 2.0 : static_cast<double>(a + 1) / n1;
      const double next_b = static_cast<double>(b + 1) / n2;
      if (b < n2 && (a >= n1 || n1 == 1 || next_b <= next_a)) {
        r.triangles.emplace_back(inner(a), outer(b), outer(b + 1));
        ++b;
      } else {
        r.triangles.emplace_back(inner(a), outer(b), inner(a + 1));
        ++a;
      }
      if (n1 == 1 && b == n2) {
        break;
      }
    }
  }
  for (int k = 0; k < count[rings]; ++k) {
    r.boundary.push_back(first[rings] + k);
  }
  return cap;
}

// The conformal maps of a round cap onto the plane that keep its boundary round are stereographic
// projections; the one that keeps the boundary length sends polar angle theta to radius
// c tan(theta / 2) with c tan(theta0 / 2) = sin(theta0), i.e. c = 2 cos^2(theta0 / 2). Each ring's
// mean radius about the pole's image is checked against it (discretisation error O(h^2): 16 rings
// leave about 0.1%), the rings' roundness, and the boundary's edge lengths (kept by u = 0).
TEST(BoundaryFirstFlattening, MapsASphericalCapByStereographicProjection) {
  constexpr double kTheta0 = 1.2;
  constexpr int kRings = 16;
  const Cap cap = spherical_cap(kTheta0, kRings);
  const Region& region = cap.region;
  const int n = region.num_vertices();
  const auto uv = boundary_first_flattening(region, region.boundary[0], region.boundary[48]);
  ASSERT_TRUE(uv.has_value());
  EXPECT_EQ(folds(region, *uv), 0);
  const double c = 2.0 * std::cos(kTheta0 / 2) * std::cos(kTheta0 / 2);
  const Eigen::Vector2d centre = (*uv)[0];
  std::vector<double> sum(kRings + 1, 0.0), lo(kRings + 1, 1e9), hi(kRings + 1, 0.0);
  std::vector<int> count(kRings + 1, 0);
  for (int v = 1; v < n; ++v) {
    const int j = static_cast<int>(std::lround(cap.theta[v] / kTheta0 * kRings));
    const double radius = ((*uv)[v] - centre).norm();
    sum[j] += radius;
    lo[j] = std::min(lo[j], radius);
    hi[j] = std::max(hi[j], radius);
    ++count[j];
  }
  const double boundary_radius = c * std::tan(kTheta0 / 2);
  for (int j = 1; j <= kRings; ++j) {
    const double expected = c * std::tan(kTheta0 * j / kRings / 2);
    EXPECT_NEAR(sum[j] / count[j], expected, 2e-3 * boundary_radius) << "ring " << j;
    EXPECT_LT(hi[j] - lo[j], 2e-3 * boundary_radius) << "ring " << j;
  }
  // The boundary's edges keep their 3D lengths (the closing correction is round-off here).
  const size_t nb = region.boundary.size();
  for (size_t k = 0; k < nb; ++k) {
    const int a = region.boundary[k], b = region.boundary[(k + 1) % nb];
    const double in_3d = (region.positions[a] - region.positions[b]).norm();
    EXPECT_NEAR(((*uv)[a] - (*uv)[b]).norm(), in_3d, 1e-9);
  }
}

// flatten_region with BoundaryFirst on a curved region uses it and scales it to the 3D area; on a
// region with a zero-area triangle (a weld on meshes like plane_quads at a coarse tessellation,
// where angle sums are undefined) it falls back to the least-squares conformal map and says so.
TEST(BoundaryFirstFlattening, FlattenRegionUsesItOrFallsBack) {
  const auto sphere = make_sphere({.faces = ShapeFaces::Quads, .resolution = 6});
  const LimitSurface surface(sphere);
  const SurfaceProjector projector(surface);
  RegionSpec spec;
  spec.kind = RegionSpec::Kind::Disk;
  spec.center = projector.closest({0.3, 0.8, 0.5}).position;
  spec.radius = 0.9;
  const Region region = make_region(projector, spec);
  const RegionFlattening flat = flatten_region(region, {.method = FlatteningMethod::BoundaryFirst});
  EXPECT_EQ(flat.method, FlatteningMethod::BoundaryFirst);
  EXPECT_EQ(flat.folded_triangles, 0);
  double area = 0.0;
  for (const Eigen::Vector3i& t : region.triangles) {
    area += 0.5 * cross2(flat.uv[t[1]] - flat.uv[t[0]], flat.uv[t[2]] - flat.uv[t[0]]);
  }
  EXPECT_NEAR(area, region.area(), 1e-9 * region.area());

  const auto plane = make_plane({.faces = ShapeFaces::Quads, .resolution = 32});
  const LimitSurface flat_surface(plane);
  const SurfaceProjector flat_projector(flat_surface);
  Region welded = make_region(flat_projector, test::welded_star());
  // Lift it off its plane so the planar shortcut does not answer first.
  for (Eigen::Vector3d& p : welded.positions) {
    p.z() = 0.3 * p.x() * p.x();
  }
  ASSERT_FALSE(boundary_first_flattening(welded, welded.boundary[0], welded.boundary[5]))
      << "the case needs a zero-area triangle to test anything";
  const RegionFlattening fallback =
      flatten_region(welded, {.method = FlatteningMethod::BoundaryFirst});
  EXPECT_EQ(fallback.method, FlatteningMethod::Conformal);
  EXPECT_EQ(fallback.folded_triangles, 0);
}

}  // namespace
}  // namespace elastic
