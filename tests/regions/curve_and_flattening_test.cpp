// SurfaceCurve arithmetic on hand-made polylines, and region flattening (Floater disk map, LSCM).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <numbers>

#include "elastic/projection/closest_point.h"
#include "elastic/regions/region_flattening.h"
#include "elastic/regions/region_spec.h"
#include "elastic/shapes/procedural_shapes.h"
#include "region_cases.h"
#include "rigid_motion.h"

namespace elastic {
namespace {

constexpr double kPi = std::numbers::pi;

/// The square with corners (0,0), (2,0), (2,2), (0,2): perimeter 8.
SurfaceCurve square() {
  SurfaceCurve c;
  c.positions = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}};
  c.points.resize(4);
  return c;
}

TEST(SurfaceCurve, LengthAndArcLengths) {
  const SurfaceCurve c = square();
  EXPECT_DOUBLE_EQ(c.length(), 8.0);
  EXPECT_EQ(c.arc_lengths(), (std::vector<double>{0, 2, 4, 6}));
}

TEST(SurfaceCurve, LocateWrapsAndStartsAtTheAnchor) {
  SurfaceCurve c = square();
  auto loc = c.locate(0.3125);  // 2.5 along: segment 1, a quarter in
  EXPECT_EQ(loc.segment, 1);
  EXPECT_NEAR(loc.t, 0.25, 1e-15);
  EXPECT_TRUE(loc.position.isApprox(Eigen::Vector3d(2, 0.5, 0)));
  loc = c.locate(1.9375);  // wraps to 0.9375: 7.5 along the closing chord
  EXPECT_EQ(loc.segment, 3);
  EXPECT_TRUE(loc.position.isApprox(Eigen::Vector3d(0, 0.5, 0)));
  c.anchor = 0.5;  // s = 0 at (2, 2)
  EXPECT_TRUE(c.locate(0.0).position.isApprox(Eigen::Vector3d(2, 2, 0)));
  EXPECT_TRUE(c.locate(0.125).position.isApprox(Eigen::Vector3d(1, 2, 0)));
}

TEST(SurfaceCurve, NearestArcParameter) {
  const SurfaceCurve c = square();
  EXPECT_NEAR(c.nearest_arc_parameter({3, 1, 0}), 3.0 / 8.0, 1e-15);
  EXPECT_NEAR(c.nearest_arc_parameter({-1, 1.5, 5}), 6.5 / 8.0, 1e-15);
  // Round trip with locate.
  for (double s : {0.05, 0.4, 0.77}) {
    EXPECT_NEAR(c.nearest_arc_parameter(c.locate(s).position), s, 1e-12);
  }
}

struct Surface {
  std::unique_ptr<LimitSurface> surface;
  std::unique_ptr<SurfaceProjector> projector;
  explicit Surface(const PolygonMesh& mesh, int res) {
    surface = std::make_unique<LimitSurface>(mesh);
    ProjectionOptions o;
    o.tessellation.resolution = res;
    projector = std::make_unique<SurfaceProjector>(*surface, o);
  }
};

RegionSpec disk(const Eigen::Vector3d& c, double r) {
  RegionSpec spec;
  spec.kind = RegionSpec::Kind::Disk;
  spec.center = c;
  spec.radius = r;
  return spec;
}

/// Floater's map of a disk of radius `radius` around the point of `s` (a sphere) nearest
/// (0.3, 0.8, 0.5), into `region`; expected to be a disk map without folds.
RegionFlattening sphere_disk_map(const Surface& s, double radius, Region& region) {
  region = make_region(*s.projector, disk(s.projector->closest({0.3, 0.8, 0.5}).position, radius));
  RegionFlattening flat = flatten_region(region);
  EXPECT_EQ(flat.method, FlatteningMethod::Disk);
  EXPECT_EQ(flat.folded_triangles, 0);
  return flat;
}

/// 1 for the region's boundary vertices.
std::vector<char> boundary_mask(const Region& region) {
  std::vector<char> on_boundary(static_cast<size_t>(region.num_vertices()), 0);
  for (int v : region.boundary) {
    on_boundary[static_cast<size_t>(v)] = 1;
  }
  return on_boundary;
}

TEST(RegionFlattening, DiskMapIsBijectiveWithBoundaryOnTheCircleByArcLength) {
  const Surface s(make_sphere({.faces = ShapeFaces::Quads, .resolution = 6}), 6);
  Region region;
  const RegionFlattening flat = sphere_disk_map(s, 0.9, region);
  const SurfaceCurve curve = region.boundary_curve();
  const auto cum = curve.arc_lengths();
  for (size_t k = 0; k < region.boundary.size(); ++k) {
    const Eigen::Vector2d p = flat.uv[static_cast<size_t>(region.boundary[k])];
    const double angle = 2.0 * kPi * (cum[k] / curve.length() - region.anchor);
    EXPECT_NEAR(p.x(), std::cos(angle), 1e-12);
    EXPECT_NEAR(p.y(), std::sin(angle), 1e-12);
  }
  // Interior vertices strictly inside the disk.
  const std::vector<char> on_boundary = boundary_mask(region);
  for (size_t v = 0; v < flat.uv.size(); ++v) {
    if (!on_boundary[v]) {
      EXPECT_LT(flat.uv[v].norm(), 1.0);
    }
  }
}

// A region with more interior vertices than the mean-value system's direct-solve limit (4,096;
// above it the system is solved iteratively, region_flattening.cpp): the flattening satisfies
// Floater's equations sum_j w_ij (uv_i - uv_j) = 0 at every interior vertex, with the weights
// computed here from the angles themselves (acos of the edge directions, not the code's
// half-angle tangent formula), to a residual far below the map's own scale.
TEST(RegionFlattening, LargeDiskMapSatisfiesTheMeanValueEquations) {
  const Surface s(make_sphere({.faces = ShapeFaces::Quads, .resolution = 6}), 28);
  Region region;
  const RegionFlattening flat = sphere_disk_map(s, 1.2, region);
  const std::vector<char> on_boundary = boundary_mask(region);
  ASSERT_GT(region.num_vertices() - static_cast<int>(region.boundary.size()), 4096);
  std::vector<Eigen::Vector2d> sum(flat.uv.size(), Eigen::Vector2d::Zero());
  std::vector<double> weights(flat.uv.size(), 0.0);
  for (const Eigen::Vector3i& t : region.triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto i = static_cast<size_t>(t[k]);
      const auto j = static_cast<size_t>(t[(k + 1) % 3]), l = static_cast<size_t>(t[(k + 2) % 3]);
      const Eigen::Vector3d eij = region.positions[j] - region.positions[i];
      const Eigen::Vector3d eil = region.positions[l] - region.positions[i];
      if (eij.norm() == 0.0 || eil.norm() == 0.0 || eij.cross(eil).norm() == 0.0) {
        continue;
      }
      const double angle = std::acos(std::clamp(eij.normalized().dot(eil.normalized()), -1.0, 1.0));
      for (const auto& [other, e] : {std::pair{j, eij}, std::pair{l, eil}}) {
        const double w = std::tan(angle / 2.0) / e.norm();
        sum[i] += w * (flat.uv[i] - flat.uv[other]);
        weights[i] += w;
      }
    }
  }
  double worst = 0.0;
  for (size_t v = 0; v < flat.uv.size(); ++v) {
    if (!on_boundary[v] && weights[v] > 0.0) {
      worst = std::max(worst, sum[v].norm() / weights[v]);  // a displacement in disk units
    }
  }
  EXPECT_LT(worst, 1e-9);
}

/// The largest distance of `to` from the best similarity of `from`, to ~ a from + b (points as
/// complex numbers), fitted by least squares; `scale` = |a|. A reflection (to ~ a conj(from) + b)
/// is not a similarity here and leaves a residual of the points' size.
double similarity_residual(const std::vector<Eigen::Vector2d>& from,
                           const std::vector<Eigen::Vector2d>& to, double& scale) {
  using C = std::complex<double>;
  const auto n = static_cast<double>(from.size());
  const auto z_of = [&](size_t v) { return C(from[v].x(), from[v].y()); };
  const auto w_of = [&](size_t v) { return C(to[v].x(), to[v].y()); };
  C mz = 0.0, mw = 0.0;
  for (size_t v = 0; v < from.size(); ++v) {
    mz += z_of(v);
    mw += w_of(v);
  }
  mz /= n;
  mw /= n;
  C num = 0.0;
  double den = 0.0;
  for (size_t v = 0; v < from.size(); ++v) {
    num += std::conj(z_of(v) - mz) * (w_of(v) - mw);
    den += std::norm(z_of(v) - mz);
  }
  const C a = num / den;
  double worst = 0.0;
  for (size_t v = 0; v < from.size(); ++v) {
    worst = std::max(worst, std::abs((w_of(v) - mw) - a * (z_of(v) - mz)));
  }
  scale = std::abs(a);
  return worst;
}

/// The same for a planar region's flattening against its points' (x, y) (the region lies in z = 0).
double similarity_residual(const Region& region, const RegionFlattening& flat, double& scale) {
  std::vector<Eigen::Vector2d> xy;
  xy.reserve(region.positions.size());
  for (const Eigen::Vector3d& p : region.positions) {
    xy.emplace_back(p.x(), p.y());
  }
  return similarity_residual(xy, flat.uv, scale);
}

// A planar region's conformal flattening: fold-free and a similarity (its identity has zero
// conformal energy, so the residual is solver round-off), scaled to the 3D area with the
// orientation kept (|a| = 1, a rotation, not conj).
void expect_conformal_flattening_is_a_similarity(const Region& region) {
  const RegionFlattening flat = flatten_region(region, {.method = FlatteningMethod::Conformal});
  EXPECT_EQ(flat.method, FlatteningMethod::Conformal);
  EXPECT_EQ(flat.folded_triangles, 0);
  double scale = 0.0;
  EXPECT_LT(similarity_residual(region, flat, scale), 1e-8);
  EXPECT_NEAR(scale, 1.0, 1e-8);
}

TEST(RegionFlattening, ConformalMapOfAPlanarRegionIsASimilarity) {
  const Surface s(make_plane({.faces = ShapeFaces::Quads, .resolution = 6}), 6);
  expect_conformal_flattening_is_a_similarity(make_region(*s.projector, disk({0.2, 0.1, 0}, 0.6)));
}

// A flat region, turned and moved off the coordinate planes, is flattened by its own plane's
// coordinates: an isometry to round-off (every edge keeps its 3D length to 1e-12 of the region's
// size, where the conformal solve left about 5e-10), counter-clockwise, with no fold.
TEST(RegionFlattening, ConformalMapOfAFlatRegionIsItsIsometryExactly) {
  const Eigen::Isometry3d motion = test::rigid_motion();
  const Surface s(test::moved(make_plane({.faces = ShapeFaces::Quads, .resolution = 6}), motion),
                  6);
  const Region region =
      make_region(*s.projector, disk(motion * Eigen::Vector3d(0.2, 0.1, 0.0), 0.6));
  const RegionFlattening flat = flatten_region(region, {.method = FlatteningMethod::Conformal});
  EXPECT_EQ(flat.method, FlatteningMethod::Conformal);
  EXPECT_EQ(flat.folded_triangles, 0);
  double worst = 0.0;
  for (const Eigen::Vector3i& t : region.triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<size_t>(t[k]), b = static_cast<size_t>(t[(k + 1) % 3]);
      const double in_3d = (region.positions[a] - region.positions[b]).norm();
      const double in_2d = (flat.uv[a] - flat.uv[b]).norm();
      worst = std::max(worst, std::abs(in_3d - in_2d));
    }
  }
  EXPECT_LT(worst, 1e-12 * 1.2);
}

// A developable region off every plane, where the conformal solve runs (the planar shortcut refuses
// it): a rectangle bent around the unit cylinder (region_cases.h), whose unrolling has zero
// conformal energy, and the minimiser must be it up to a similarity, scaled to
// the 3D area (|a| = 1) and not mirrored. Written independently of the solver: a sign error in the
// area term makes the minimiser a reflection, which folds every triangle and falls back to the
// disk map.
TEST(RegionFlattening, ConformalMapOfABentRectangleIsItsUnrolling) {
  const test::BentRectangle strip = test::bent_rectangle();
  const Region& region = strip.region;
  const std::vector<Eigen::Vector2d>& unrolled = strip.unrolled;
  const RegionFlattening flat = flatten_region(region, {.method = FlatteningMethod::Conformal});
  EXPECT_EQ(flat.method, FlatteningMethod::Conformal);
  EXPECT_EQ(flat.folded_triangles, 0);
  double scale = 0.0;
  EXPECT_LT(similarity_residual(unrolled, flat.uv, scale), 1e-9);
  EXPECT_NEAR(scale, 1.0, 1e-9);
}

// A star whose sides run through two welded copies of a tessellation vertex (a zero-area triangle
// in the region, as on meshes/plane_quads.obj at the CLI's tessellation): the zero-area triangle
// has no conformal energy, and must not keep its area term either, or the minimiser opens it and
// distorts the whole map (measured before the fix: stretch 0.26-1.29 along the boundary, which
// crossed itself, and the grid layout failed).
TEST(RegionFlattening, ConformalMapIgnoresZeroAreaTriangles) {
  const auto mesh = make_plane({.faces = ShapeFaces::Quads, .resolution = 32});
  const LimitSurface surface(mesh);
  const SurfaceProjector projector(surface);
  const Region region = make_region(projector, test::welded_star());
  int zero_area = 0;
  for (const Eigen::Vector3i& t : region.triangles) {
    const Eigen::Vector3d a =
        region.positions[static_cast<size_t>(t[1])] - region.positions[static_cast<size_t>(t[0])];
    const Eigen::Vector3d b =
        region.positions[static_cast<size_t>(t[2])] - region.positions[static_cast<size_t>(t[0])];
    zero_area += a.cross(b).squaredNorm() == 0.0 ? 1 : 0;
  }
  ASSERT_GE(zero_area, 1) << "the case needs a zero-area triangle to test anything";
  expect_conformal_flattening_is_a_similarity(region);
}

}  // namespace
}  // namespace elastic
