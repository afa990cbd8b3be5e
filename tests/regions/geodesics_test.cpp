// Geodesics on triangle meshes: the heat method's local distance and its reuse between sources,
// and the exact shortest paths of points: polygons' sides against the search among all triangles.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "elastic/regions/exact_geodesics.h"
#include "elastic/regions/heat_geodesics.h"
#include "elastic/regions/polygon_sides.h"
#include "elastic/regions/region_context.h"
#include "region_fixture.h"

namespace elastic {
namespace {

constexpr double kPi = std::numbers::pi;

// A flat grid mesh of (n + 1)^2 vertices on [-half, half]^2 at height z, appended to `positions`
// and `triangles` (two triangles per cell, counter-clockwise seen from +z).
void append_grid(int n, double half, double z, std::vector<Eigen::Vector3d>& positions,
                 std::vector<Eigen::Vector3i>& triangles) {
  const int base = static_cast<int>(positions.size());
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      positions.emplace_back(-half + 2.0 * half * j / n, -half + 2.0 * half * i / n, z);
    }
  }
  const auto v = [&](int i, int j) { return base + i * (n + 1) + j; };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      triangles.emplace_back(v(i, j), v(i, j + 1), v(i + 1, j + 1));
      triangles.emplace_back(v(i, j), v(i + 1, j + 1), v(i + 1, j));
    }
  }
}

// The disk's local heat distance: on a plane the geodesic distance is the Euclidean one, so within
// the reach it must match |x - c| to the heat method's error (a few edges near the source, O(h)
// beyond); vertices farther than twice the reach, and a second sheet 0.05 above the plane (inside
// the Euclidean ball but not connected to the source), get `far`; a reach that covers the mesh
// falls back to the whole mesh, bit for bit.
TEST(LocalGeodesics, PlaneDistanceWithinReachAndFarBeyond) {
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::Vector3i> tri;
  const int n = 80;
  const double half = 1.0, h = 2.0 * half / n, reach = 0.3, far = 10.0;
  append_grid(n, half, 0.0, x, tri);
  const int sheet = static_cast<int>(x.size());
  append_grid(8, 0.2, 0.05, x, tri);
  // The source at the plane's centre vertex (row 40, column 40): corner 0 of that cell's triangle.
  const regions_detail::MeshLocation source{2 * (40 * n + 40), Eigen::Vector3d(1.0, 0.0, 0.0)};
  ASSERT_LT(x[static_cast<size_t>(tri[static_cast<size_t>(source.triangle)][0])].norm(), 1e-12);
  const Eigen::VectorXd d =
      regions_detail::local_geodesic_distance(x, tri, source, reach, far, "plane");
  int within = 0, beyond = 0;
  for (int v = 0; v < sheet; ++v) {
    const double r = x[static_cast<size_t>(v)].norm();
    if (r <= reach) {
      EXPECT_NEAR(d[v], r, 2.0 * h) << v;
      ++within;
    } else if (r > 2.0 * reach + 2.0 * h) {
      EXPECT_EQ(d[v], far) << v;
      ++beyond;
    }
  }
  EXPECT_GT(within, 400);
  EXPECT_GT(beyond, 4000);
  for (int v = sheet; v < static_cast<int>(x.size()); ++v) {
    EXPECT_EQ(d[v], far) << "vertex " << v << " of the unconnected sheet";
  }
  const Eigen::VectorXd whole =
      regions_detail::local_geodesic_distance(x, tri, source, 5.0, far, "plane");
  const Eigen::VectorXd reference = regions_detail::HeatGeodesics(x, tri, "plane").distance(source);
  EXPECT_EQ((whole - reference).cwiseAbs().maxCoeff(), 0.0);
}

// HeatGeodesics::distance_reusing (the Poisson operator factored once, the pin by bordering) gives
// distance()'s answer (a factorisation pinned at each source) to round-off, for a pin at the
// factored vertex 0 and elsewhere, on an open mesh with a second, unconnected sheet.
TEST(LocalGeodesics, ReusedPoissonFactorisationGivesTheSameDistance) {
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::Vector3i> tri;
  append_grid(24, 1.0, 0.0, x, tri);
  append_grid(4, 0.2, 0.05, x, tri);
  const regions_detail::HeatGeodesics heat(x, tri, "plane");
  for (const regions_detail::MeshLocation& source :
       {regions_detail::MeshLocation{0, Eigen::Vector3d(0.8, 0.1, 0.1)},
        regions_detail::MeshLocation{2 * (12 * 24 + 12), Eigen::Vector3d(0.2, 0.5, 0.3)},
        regions_detail::MeshLocation{2 * (3 * 24 + 20) + 1, Eigen::Vector3d(0.1, 0.1, 0.8)}}) {
    const Eigen::VectorXd reference = heat.distance(source);
    const Eigen::VectorXd reused = heat.distance_reusing(source);
    EXPECT_LT((reused - reference).cwiseAbs().maxCoeff(), 1e-9) << source.triangle;
    EXPECT_GT(reference.maxCoeff(), 1.0);
  }
}

// LocalHeatCache: a source dragged along the plane in steps of 0.025 with reach 0.29 keeps its
// part (a ball of 2 * 1.25 * 0.29 around the first source) while the new ball of 0.58 fits in it,
// 0.145 of travel (five steps), and the distance is still |x - c| within the reach, `far` off the
// part, and the second sheet `far`. A moved mesh builds its part again.
TEST(LocalGeodesics, CachedPartFollowsADraggedSource) {
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::Vector3i> tri;
  const int n = 80;
  const double h = 2.0 / n, reach = 0.29, far = 10.0;
  append_grid(n, 1.0, 0.0, x, tri);
  const int sheet = static_cast<int>(x.size());
  append_grid(8, 0.2, 0.05, x, tri);
  regions_detail::LocalHeatCache cache;
  for (int step = 0; step <= 10; ++step) {
    // Vertex (row 40, column 40 + step) sits at (step h, 0, 0); steps of h = 0.025.
    const regions_detail::MeshLocation source{2 * (40 * n + 40 + step),
                                              Eigen::Vector3d(1.0, 0.0, 0.0)};
    const Eigen::Vector3d c = x[static_cast<size_t>(tri[static_cast<size_t>(source.triangle)][0])];
    ASSERT_NEAR(c.x(), step * h, 1e-12);
    const Eigen::VectorXd d = cache.distance(x, tri, source, reach, far, "plane");
    for (int v = 0; v < sheet; ++v) {
      const double r = (x[static_cast<size_t>(v)] - c).norm();
      if (r <= reach) {
        EXPECT_NEAR(d[v], r, 2.0 * h) << "step " << step << " vertex " << v;
      } else if ((x[static_cast<size_t>(v)] - Eigen::Vector3d(step < 6 ? 0.0 : 6 * h, 0, 0))
                     .norm() > 2.0 * 1.25 * reach + 2.0 * h) {
        EXPECT_EQ(d[v], far) << "step " << step << " vertex " << v;
      }
    }
    for (int v = sheet; v < static_cast<int>(x.size()); ++v) {
      EXPECT_EQ(d[v], far);
    }
    // Five steps on the first part; the sixth builds the second, which holds the rest.
    EXPECT_EQ(cache.builds(), step < 6 ? 1 : 2) << "step " << step;
  }
  for (Eigen::Vector3d& p : x) {
    p.z() += 0.1;
  }
  const regions_detail::MeshLocation last{2 * (40 * n + 50), Eigen::Vector3d(1.0, 0.0, 0.0)};
  const Eigen::VectorXd moved = cache.distance(x, tri, last, reach, far, "plane");
  EXPECT_EQ(cache.builds(), 3);
  EXPECT_NEAR(moved[40 * (n + 1) + 60], 0.25, 2.0 * h);
}

/// Each side of polygon_sides() against the exact shortest path among all the triangles, and the
/// band each side was found in.
std::vector<regions_detail::SideBand> expect_sides_are_shortest(
    const Fixture& fx, const std::vector<Eigen::Vector3d>& polygon) {
  const LimitTessellation& tess = fx.projector->tessellation();
  const RegionOptions options;
  const regions_detail::RegionContext ctx(*fx.projector, options);
  std::vector<regions_detail::MeshLocation> corners;
  corners.reserve(polygon.size());
  for (const Eigen::Vector3d& x : polygon) {
    corners.push_back(ctx.project(x, "corner"));
  }
  const std::vector<regions_detail::PolygonSide> sides =
      regions_detail::polygon_sides(tess.positions, tess.triangles, corners, "sides");
  std::vector<int> everything(tess.triangles.size());
  std::iota(everything.begin(), everything.end(), 0);
  regions_detail::ExactGeodesics whole(tess.positions, tess.triangles, "whole");
  std::vector<regions_detail::SideBand> bands;
  EXPECT_EQ(sides.size(), corners.size());
  for (size_t i = 0; i < sides.size(); ++i) {
    const regions_detail::GeodesicPath truth =
        whole.path(corners[i], corners[(i + 1) % corners.size()], everything);
    const regions_detail::GeodesicPath& side = sides[i].path;
    EXPECT_NEAR(side.length, truth.length, 1e-12 * truth.length) << "side " << i;
    EXPECT_EQ(side.nodes.size(), truth.nodes.size()) << "side " << i;
    for (size_t k = 0; k < std::min(side.nodes.size(), truth.nodes.size()); ++k) {
      EXPECT_EQ(side.nodes[k].segment_triangle, truth.nodes[k].segment_triangle) << "side " << i;
    }
    bands.push_back(sides[i].band);
  }
  return bands;
}

// The sides of points: polygons (polygon_sides.h) are the shortest paths on the whole surface,
// whichever band served them: the chord's (a small circle's sides, a triangle on a plane), the band
// enclosing the path a chord's band gave (a cap's sides of 120 degrees, longer than the chord's
// bound), or the heat method's (a side of nearly 180 degrees, whose chord's bands fall in two
// pieces). The reference is CGAL's exact shortest path among all the triangles. (A case where the
// chord's band gives a path other than the shortest, a side over a ridge with a gap, has a window
// of a few edges; the counts of each band check the order of the steps instead.)
TEST(PolygonSides, AreTheShortestPathsOnTheWholeSurface) {
  using regions_detail::SideBand;
  const auto count = [](const std::vector<SideBand>& bands, SideBand b) {
    return std::count(bands.begin(), bands.end(), b);
  };
  const Fixture fx(make_sphere({.faces = ShapeFaces::Quads, .resolution = 12}), 6);
  const Eigen::Vector3d centre = Eigen::Vector3d(0.3, 0.5, 0.8).normalized();
  const Eigen::Vector3d a = centre.cross(Eigen::Vector3d::UnitX()).normalized();
  const Eigen::Vector3d b = centre.cross(a);
  std::vector<Eigen::Vector3d> circle;
  for (int k = 0; k < 16; ++k) {
    const double t = 2.0 * kPi * k / 16.0;
    circle.push_back(fx.on_surface(centre + 0.6 * (std::cos(t) * a + std::sin(t) * b)));
  }
  EXPECT_EQ(count(expect_sides_are_shortest(fx, circle), SideBand::Chord), 16);
  const std::vector<SideBand> cap =
      expect_sides_are_shortest(fx, {fx.on_surface({1, 0, 0.3}), fx.on_surface({-0.5, 0.87, 0.3}),
                                     fx.on_surface({-0.5, -0.87, 0.3})});
  EXPECT_EQ(count(cap, SideBand::Enclosing), 3);
  // On a finer sphere (the certificate's room, two edges, is smaller), a side between nearly
  // antipodal points.
  const Fixture fine(make_sphere({.faces = ShapeFaces::Quads, .resolution = 16}), 8);
  const std::vector<SideBand> far = expect_sides_are_shortest(
      fine,
      {fine.on_surface({1, 0, 0}), fine.on_surface({-1, 0.05, 0}), fine.on_surface({0, -1, 0.6})});
  EXPECT_EQ(count(far, SideBand::Heat), 1);
  // The inner equator of a torus, where the surface is a saddle.
  const Fixture torus(make_torus({.faces = ShapeFaces::Quads, .resolution = 12}), 4);
  expect_sides_are_shortest(torus,
                            {torus.on_surface({0.65, 0, 0}), torus.on_surface({0, 0.65, 0}),
                             torus.on_surface({-0.65, 0, 0}), torus.on_surface({0, -0.65, 0})});
  const Fixture plane(plane_mesh(), 4);
  EXPECT_EQ(
      count(expect_sides_are_shortest(plane, {{-0.7, -0.6, 0}, {0.7, -0.5, 0}, {0.1, 0.7, 0}}),
            SideBand::Chord),
      3);
}

}  // namespace
}  // namespace elastic
