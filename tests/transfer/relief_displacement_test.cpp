// Height transfer (Fig. 8): heights from images, displacement along the target limit normal,
// boundary distance and falloff (transfer/displacement.h).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "elastic/core/error.h"
#include "elastic/mapping/map_regions.h"
#include "elastic/regions/region_spec.h"
#include "elastic/regions/texture_coordinates.h"
#include "elastic/shapes/procedural_shapes.h"
#include "elastic/transfer/displacement.h"

namespace elastic {
namespace {

// The unit square [0,1]^2 in z = 0 as an n x n grid of vertices, two triangles per cell,
// counter-clockwise seen from +z.
struct Grid {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> triangles;
};

Grid square_grid(int n) {
  Grid g;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      g.positions.emplace_back(i / (n - 1.0), j / (n - 1.0), 0.0);
    }
  }
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i, b = a + 1, c = a + n + 1, d = a + n;
      g.triangles.emplace_back(a, b, c);
      g.triangles.emplace_back(a, c, d);
    }
  }
  return g;
}

double square_boundary_distance(const Eigen::Vector3d& p) {
  return std::min({p.x(), 1.0 - p.x(), p.y(), 1.0 - p.y()});
}

TEST(ReliefDisplacement, HeightsFromImageReadTheChosenChannel) {
  // A 4 x 2 image whose red channel is a ramp in x through the pixel centres, green constant,
  // alpha a ramp in y: bilinear lookup reproduces linear functions between pixel centres.
  Image image(4, 2);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) {
      image.at(x, y) = Eigen::Vector4f(static_cast<float>(x) / 4.0f, 0.5f, 0.25f,
                                       y == 0 ? 1.0f : 0.0f);  // top row opaque
    }
  }
  // Pixel centres: u = (x + 0.5) / 4, v = 1 - (y + 0.5) / 2.
  const std::vector<Eigen::Vector2d> uv = {{0.375, 0.75}, {0.5, 0.5}, {0.625, 0.25}};
  const std::vector<double> red =
      heights_from_image(image, uv, {.channel = HeightChannel::Red, .zero_level = 0.1});
  // Float storage: 1e-7 of the channel values.
  EXPECT_NEAR(red[0], 0.25 - 0.1, 1e-7);
  EXPECT_NEAR(red[1], 0.375 - 0.1, 1e-7);  // halfway between x = 1 and x = 2
  EXPECT_NEAR(red[2], 0.5 - 0.1, 1e-7);
  const std::vector<double> alpha =
      heights_from_image(image, uv, {.channel = HeightChannel::Alpha});
  EXPECT_NEAR(alpha[0], 1.0, 1e-7);
  EXPECT_NEAR(alpha[1], 0.5, 1e-7);
  EXPECT_NEAR(alpha[2], 0.0, 1e-7);
  // Luminance of (r, 0.5, 0.25) with Rec. 709 weights.
  const std::vector<double> luma = heights_from_image(image, uv);
  EXPECT_NEAR(luma[0], 0.2126 * 0.25 + 0.7152 * 0.5 + 0.0722 * 0.25, 1e-7);
  EXPECT_THROW(heights_from_image(Image(), uv), InvalidInputError);
  const std::vector<Eigen::Vector2d> bad = {{std::nan(""), 0.0}};
  EXPECT_THROW(heights_from_image(image, bad), InvalidInputError);
}

// The distance to a square's boundary is min(x, 1-x, y, 1-y).
TEST(ReliefDisplacement, BoundaryDistanceOfASquareIsAnalytic) {
  const Grid g = square_grid(21);
  const std::vector<double> d = boundary_distance(g.positions, g.triangles, 10.0);
  double worst = 0.0;
  for (size_t i = 0; i < g.positions.size(); ++i) {
    worst = std::max(worst, std::abs(d[i] - square_boundary_distance(g.positions[i])));
  }
  // The nearest side is propagated along grid edges from its own vertices; on a convex polygon
  // every vertex is reached from its nearest side, so distances are point-segment distances,
  // exact to round-off.
  EXPECT_LT(worst, 1e-14);
  // Beyond max_distance: infinity.
  const std::vector<double> near = boundary_distance(g.positions, g.triangles, 0.2);
  EXPECT_EQ(near[10 * 21 + 10], std::numeric_limits<double>::infinity());
  EXPECT_NEAR(near[3 * 21 + 10], 0.15, 1e-14);
}

// Constant height with a falloff: z = smoothstep(d / width) * h, 0 on the boundary, h beyond the
// falloff width.
TEST(ReliefDisplacement, FalloffRampsSmoothlyFromTheBoundary) {
  const Grid g = square_grid(21);
  const std::vector<Eigen::Vector3d> normals(g.positions.size(), Eigen::Vector3d::UnitZ());
  const std::vector<double> heights(g.positions.size(), 2.0);
  const DisplacementResult r = displace_along_normals(g.positions, normals, heights, g.triangles,
                                                      {.scale = 0.5, .falloff_width = 0.25});
  EXPECT_EQ(r.boundary_vertices, 80);
  for (size_t i = 0; i < g.positions.size(); ++i) {
    const double t = std::min(square_boundary_distance(g.positions[i]) / 0.25, 1.0);
    const double expected = t * t * (3.0 - 2.0 * t) * 0.5 * 2.0;
    EXPECT_NEAR(r.positions[i].z(), expected, 1e-14);
    EXPECT_EQ(r.positions[i].x(), g.positions[i].x());
  }
  EXPECT_NEAR(r.max_displacement, 1.0, 1e-15);

  // Without falloff, boundary vertices are still pinned (watertight) unless told otherwise.
  const DisplacementResult pinned =
      displace_along_normals(g.positions, normals, heights, g.triangles);
  const DisplacementResult free =
      displace_along_normals(g.positions, normals, heights, g.triangles, {.pin_boundary = false});
  EXPECT_EQ(pinned.positions[0].z(), 0.0);
  EXPECT_EQ(pinned.positions[22].z(), 2.0);
  EXPECT_EQ(free.positions[0].z(), 2.0);
  EXPECT_TRUE(pinned.boundary_distance.empty());
}

TEST(ReliefDisplacement, InvalidInputsAreRejected) {
  const Grid g = square_grid(3);
  const std::vector<Eigen::Vector3d> normals(g.positions.size(), Eigen::Vector3d::UnitZ());
  std::vector<double> heights(g.positions.size(), 1.0);
  const std::vector<double> short_heights(2, 1.0);
  EXPECT_THROW(displace_along_normals(g.positions, normals, short_heights, g.triangles),
               InvalidInputError);
  EXPECT_THROW(
      displace_along_normals(g.positions, normals, heights, g.triangles, {.falloff_width = -1.0}),
      InvalidInputError);
  std::vector<Eigen::Vector3i> bad = g.triangles;
  bad[0][1] = 99;
  EXPECT_THROW(displace_along_normals(g.positions, normals, heights, bad), InvalidInputError);
  heights[4] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(displace_along_normals(g.positions, normals, heights, g.triangles),
               InvalidInputError);
  // NaN: no source for that sample; it stays where it is.
  heights[4] = std::nan("");
  const DisplacementResult r = displace_along_normals(g.positions, normals, heights, g.triangles);
  EXPECT_EQ(r.skipped, 1);
  EXPECT_EQ(r.positions[4], g.positions[4]);
}

// Issue 6: a plane -> plane rigid map transfers a height field unchanged. The source plane carries
// UVs ((x+1)/2, (y+1)/2) and a height image that is a ramp in u; the target is a rigidly moved
// copy. Every target sample (the target region's vertices) looks its source up through the inverse
// map and is displaced along the TARGET normal; the result must be the rigidly moved displaced
// source, where the source's height is the analytic ramp at the sample's source point.
TEST(ReliefDisplacement, PlaneRigidMapTransfersAHeightFieldUnchanged) {
  PolygonMesh plane = make_plane({.faces = ShapeFaces::Quads, .resolution = 12});
  for (const Eigen::Vector3d& p : plane.positions) {
    plane.texcoords.emplace_back((p.x() + 1.0) / 2.0, (p.y() + 1.0) / 2.0);
  }
  plane.corner_texcoords = plane.face_vertices;
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  motion.pretranslate(Eigen::Vector3d(0.3, -1.2, 2.5));
  PolygonMesh moved_plane = plane;
  for (Eigen::Vector3d& p : moved_plane.positions) p = motion * p;

  const LimitSurface source_surface(plane), target_surface(moved_plane);
  const SurfaceProjector source(source_surface), target(target_surface);
  RegionSpec source_spec = parse_region_spec("disk:0.1,0.05,0,0.6");
  source_spec.anchor = Eigen::Vector3d(1, 0, 0);
  RegionSpec target_spec = source_spec;
  target_spec.center = motion * source_spec.center;
  target_spec.anchor = motion * *source_spec.anchor;
  const Region from = make_region(source, source_spec);
  const Region to = make_region(target, target_spec);
  MapOptions options;
  options.sampling.layout.particles = 400;
  const MapResult result = map_regions(source, from, target, to, options);
  ASSERT_TRUE(result.relaxation.converged);

  // A 256-texel ramp: pixel x holds (x + 0.5) / 256, so the bilinear lookup is u itself between
  // the first and last pixel centres.
  Image ramp(256, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 256; ++x) {
      const float value = (static_cast<float>(x) + 0.5f) / 256.0f;
      ramp.at(x, y) = Eigen::Vector4f(value, value, value, 1.0f);
    }
  }
  const int n = to.num_vertices();
  std::vector<Eigen::Vector3d> normals(static_cast<size_t>(n));
  std::vector<Eigen::Vector2d> uv(static_cast<size_t>(n), Eigen::Vector2d(0.5, 0.5));
  std::vector<Eigen::Vector3d> source_positions(static_cast<size_t>(n));
  std::vector<char> has_source(static_cast<size_t>(n), 0);
  for (int i = 0; i < n; ++i) {
    normals[static_cast<size_t>(i)] =
        target_surface.curvature(to.points[static_cast<size_t>(i)]).normal;
    const Mapping::Location back = result.mapping.inverse(to.points[static_cast<size_t>(i)]);
    if (!back.inside) continue;  // boundary slivers; pinned below anyway
    has_source[static_cast<size_t>(i)] = 1;
    uv[static_cast<size_t>(i)] = texture_coordinate(source_surface, back.point);
    source_positions[static_cast<size_t>(i)] = back.position;
  }
  std::vector<double> heights = heights_from_image(ramp, uv, {.channel = HeightChannel::Red});
  for (int i = 0; i < n; ++i) {
    if (!has_source[static_cast<size_t>(i)]) heights[static_cast<size_t>(i)] = std::nan("");
  }
  const double scale = 0.3;
  const DisplacementResult r =
      displace_along_normals(to.positions, normals, heights, to.triangles, {.scale = scale});

  std::vector<char> boundary(static_cast<size_t>(n), 0);
  for (const int v : to.boundary) boundary[static_cast<size_t>(v)] = 1;
  int compared = 0, without_source = 0;
  for (int i = 0; i < n; ++i) {
    const size_t k = static_cast<size_t>(i);
    if (boundary[k]) {
      EXPECT_EQ(r.positions[k], to.positions[k]);  // pinned: watertight with the outside
      continue;
    }
    if (!has_source[k]) {  // in a sliver between the grid's boundary chords and the curve
      ++without_source;
      continue;
    }
    const Eigen::Vector3d s = source_positions[k];
    const double h = (s.x() + 1.0) / 2.0;  // the ramp's value at the source point
    // The displacement is the source height along the rigidly rotated source normal. Float image
    // storage: ~6e-8 of u.
    EXPECT_LT((r.positions[k] - to.positions[k] -
               motion.linear() * (scale * h * Eigen::Vector3d::UnitZ()))
                  .norm(),
              1e-6)
        << "vertex " << i;
    // And the displaced sample is the rigidly moved displaced source: the inverse is the
    // particles' affine map on each grid triangle (mapping/mapping.h), rigid where the particles
    // are (to the solver's ~1e-8), so what is left is the float image storage as above (measured
    // 3e-8). (Interpolating in the disk maps' coordinates was off by 0.003 spacing.)
    const Eigen::Vector3d expected = motion * (s + scale * h * Eigen::Vector3d::UnitZ());
    EXPECT_LT((r.positions[k] - expected).norm(), 1e-6) << "vertex " << i;
    ++compared;
  }
  EXPECT_LT(without_source, n / 20);
  EXPECT_GT(compared, n / 2);
}

}  // namespace
}  // namespace elastic
