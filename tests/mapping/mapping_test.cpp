// Mapping::forward / inverse: the relaxed grid's piecewise-linear map in 3D (affine on every grid
// triangle), composed with the magnet.
#include "elastic/mapping/mapping.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/mapping/map_regions.h"
#include "elastic/regions/region_spec.h"
#include "elastic/shapes/procedural_shapes.h"

namespace elastic {
namespace {

// A flat disk and a curved cap, mapped one onto the other in both directions: on the flat side the
// 3D position of a query *is* the barycentric combination it was made from, so the weights the
// mapping reports can be checked exactly (the disk maps' weights are not affine on a grid triangle
// and miss them by ~1e-3 of the spacing).
struct Pair {
  LimitSurface plane_surface{make_plane({.resolution = 8})};
  LimitSurface cap_surface{make_cap({.resolution = 12})};
  SurfaceProjector plane{plane_surface}, cap{cap_surface};
  Region plane_disk = make_region(plane, parse_region_spec("disk:0,0,0,0.6"));
  Region cap_region = make_region(cap, parse_region_spec("boundary"));
  MapResult plane_to_cap, cap_to_plane;

  Pair() {
    MapOptions options;
    options.sampling.layout.particles = 300;
    options.sampling.adaptive = false;
    plane_to_cap = map_regions(plane, plane_disk, cap, cap_region, options);
    cap_to_plane = map_regions(cap, cap_region, plane, plane_disk, options);
  }
};

class MappingTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { pair_ = std::make_unique<Pair>(); }
  static void TearDownTestSuite() { pair_.reset(); }
  static std::unique_ptr<Pair> pair_;
};
std::unique_ptr<Pair> MappingTest::pair_;

Eigen::Vector3d combination(const Eigen::Matrix3Xd& x, const Eigen::Vector3i& tri,
                            const Eigen::Vector3d& w) {
  return w[0] * x.col(tri[0]) + w[1] * x.col(tri[1]) + w[2] * x.col(tri[2]);
}

// Interior weights bounded away from the triangle's edges (>= 0.05), so the query is in exactly
// one grid triangle.
Eigen::Vector3d interior_weights(std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Eigen::Vector3d w(0.05 + unit(rng), 0.05 + unit(rng), 0.05 + unit(rng));
  return w / w.sum();
}

// The limit positions of the particles' source points: what the mapping interpolates. (The grid's
// own mesh points of boundary particles lie on the region's chord polyline, up to the
// tessellation's sagitta off the limit surface on the cap.)
Eigen::Matrix3Xd source_particles(const MapResult& result) {
  const ParticleGrid& grid = result.sampling.grid;
  const LimitSurface& surface = *result.source_disk->region().surface;
  Eigen::Matrix3Xd x(3, grid.num_particles());
  for (int i = 0; i < grid.num_particles(); ++i) x.col(i) = surface.position(grid.source_points[i]);
  return x;
}

// Longest 3D edge of the grid triangles with corners at the columns of x.
double longest_edge(const Eigen::Matrix3Xd& x, const std::vector<Eigen::Vector3i>& triangles) {
  double longest = 0.0;
  for (const Eigen::Vector3i& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      longest = std::max(longest, (x.col(t[(k + 1) % 3]) - x.col(t[k])).norm());
    }
  }
  return longest;
}

// A particle maps to exactly its partner (1e-9: the magnet's convergence; a particle is a corner of
// every grid triangle around it, so its weights are (1, 0, 0) up to round-off).
TEST_F(MappingTest, ParticlesMapToTheirPartners) {
  for (const MapResult* result : {&pair_->plane_to_cap, &pair_->cap_to_plane}) {
    ASSERT_TRUE(result->relaxation.converged) << to_string(result->relaxation.reason);
    ASSERT_EQ(result->relaxation.folded_faces, 0);
    const ParticleGrid& grid = result->sampling.grid;
    const Eigen::Matrix3Xd source = source_particles(*result);
    for (int i = 0; i < grid.num_particles(); ++i) {
      const Mapping::Location there = result->mapping.forward(grid.source_points[i]);
      ASSERT_TRUE(there.inside) << "particle " << i;
      EXPECT_LT((there.position - result->relaxation.positions.col(i)).norm(), 1e-9)
          << "particle " << i;
      const Mapping::Location back = result->mapping.inverse(result->relaxation.points[i]);
      ASSERT_TRUE(back.inside) << "particle " << i;
      EXPECT_LT((back.position - source.col(i)).norm(), 1e-9) << "particle " << i;
    }
  }
}

// On a flat query side, a point made as a barycentric combination of one grid triangle's
// particles is answered with exactly those weights in exactly that triangle, and lands at the same
// combination of the other side's particles put on the surface by the magnet. 1e-9: the weights
// are the solution of a 2x2 system on a well-shaped triangle (round-off ~1e-15) from a query
// position that the plane's projector returns to Newton's tolerance (1e-12 in (u, v)); the landing
// is the magnet's convergence. Disk-map weights miss by ~1e-3 of the spacing and fail this.
TEST_F(MappingTest, FlatSideWeightsAreTheGridTrianglesAffineCoordinates) {
  std::mt19937 rng(7);
  struct Direction {
    const MapResult* result;
    bool forward;
  };
  for (const Direction d :
       {Direction{&pair_->plane_to_cap, true}, Direction{&pair_->cap_to_plane, false}}) {
    const MapResult& result = *d.result;
    const Mapping& mapping = result.mapping;
    const Eigen::Matrix3Xd source = source_particles(result);
    const Eigen::Matrix3Xd& target = result.relaxation.positions;
    // The flat side is the query side; the other side is where the answer lands.
    const Eigen::Matrix3Xd& flat = d.forward ? source : target;
    const Eigen::Matrix3Xd& other = d.forward ? target : source;
    const std::vector<SurfacePoint>& other_points =
        d.forward ? result.relaxation.points : result.sampling.grid.source_points;
    const SurfaceProjector& flat_projector = pair_->plane;
    const SurfaceProjector& other_projector = pair_->cap;
    const auto& triangles = mapping.triangles();
    for (size_t t = 0; t < triangles.size(); ++t) {
      const Eigen::Vector3i& tri = triangles[t];
      const Eigen::Vector3d w = interior_weights(rng);
      const ClosestPoint query = flat_projector.closest(combination(flat, tri, w));
      const Mapping::Location loc =
          d.forward ? mapping.forward(query.point) : mapping.inverse(query.point);
      ASSERT_TRUE(loc.inside) << "triangle " << t;
      EXPECT_EQ(loc.triangle, static_cast<int>(t));
      EXPECT_LT((loc.barycentric - w).cwiseAbs().maxCoeff(), 1e-9)
          << "triangle " << t << (d.forward ? " forward" : " inverse") << ": weights "
          << loc.barycentric.transpose() << ", made with " << w.transpose();
      const ClosestPoint expected =
          other_projector.closest(combination(other, tri, w), other_points[tri[0]]);
      EXPECT_LT((loc.position - expected.position).norm(), 1e-9) << "triangle " << t;
    }
  }
}

// inverse(forward(p)) returns to p. Both directions are the same affine map of each grid triangle,
// so the only loss is the magnet's step between a grid triangle's plane and the curved cap: a point
// of the plane lies delta <= h^2 kappa / 6 from the surface (sagitta over the circumradius
// h / sqrt(3)), and the magnet moves it along the surface normal, which is tilted from the plane's
// normal by theta <~ h kappa; the tangential part, delta sin(theta) <= h^3 kappa^2 / 10, is what
// the other direction's plane weights see and carry back, scaled by the map's stretch. Tolerance
// h^3 kappa^2 / 4 (kappa = 1 on the unit cap, h = the longest grid edge on the cap) allows a
// stretch of 2.5 (the cap is ~2.2 times the disk's size). Measured: 0.02 and 0.05 h^3; the disk
// maps' weights came back only to 0.27 and 0.44 h^3 and fail this.
TEST_F(MappingTest, RoundTripIsExactUpToTheCapsSagitta) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(0.0, 6.283185307179586), radius(0.0, 0.55);
  {
    const MapResult& result = pair_->plane_to_cap;
    const double h = longest_edge(result.relaxation.positions, result.mapping.triangles());
    const double tolerance = 0.25 * h * h * h;
    double worst = 0.0;
    for (int k = 0; k < 200; ++k) {
      const double a = angle(rng), r = radius(rng);
      const ClosestPoint p =
          pair_->plane.closest(Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0.0));
      const Mapping::Location there = result.mapping.forward(p.point);
      ASSERT_TRUE(there.inside) << "interior point " << k << " not mapped";
      const Mapping::Location back = result.mapping.inverse(there.point);
      ASSERT_TRUE(back.inside) << "image of interior point " << k << " not mapped back";
      worst = std::max(worst, (back.position - p.position).norm());
    }
    EXPECT_LT(worst, tolerance) << "plane -> cap -> plane, h = " << h;
  }
  {
    // The cap's side as the query side: the same bound, the sagitta now on the query's way in.
    const MapResult& result = pair_->cap_to_plane;
    const Eigen::Matrix3Xd source = source_particles(result);
    const double h = longest_edge(source, result.mapping.triangles());
    const double tolerance = 0.25 * h * h * h;
    double worst = 0.0;
    std::uniform_real_distribution<double> polar(0.0, 1.2);
    for (int k = 0; k < 200; ++k) {
      const double a = angle(rng), theta = polar(rng);
      const ClosestPoint p = pair_->cap.closest(Eigen::Vector3d(
          std::sin(theta) * std::cos(a), std::sin(theta) * std::sin(a), std::cos(theta)));
      const Mapping::Location there = result.mapping.forward(p.point);
      ASSERT_TRUE(there.inside) << "interior point " << k << " not mapped";
      const Mapping::Location back = result.mapping.inverse(there.point);
      ASSERT_TRUE(back.inside) << "image of interior point " << k << " not mapped back";
      worst = std::max(worst, (back.position - p.position).norm());
    }
    EXPECT_LT(worst, tolerance) << "cap -> plane -> cap, h = " << h;
  }
}

// Above an interior grid edge on the curved side the two triangles' planes leave a gap or overlap
// (the grid bends there), so the query's projection can fall outside both; the answer must still be
// the edge's point: the image of the cap's point above a target edge's midpoint is the source
// edge's midpoint, to the same sagitta-times-tilt bound as the round trip (h^3 kappa^2 / 4, see
// above).
TEST_F(MappingTest, AboveAGridEdgeTheInverseIsContinuous) {
  const MapResult& result = pair_->plane_to_cap;
  const Eigen::Matrix3Xd source = source_particles(result);
  const Eigen::Matrix3Xd& target = result.relaxation.positions;
  const auto& triangles = result.mapping.triangles();
  const double h = longest_edge(target, triangles);
  std::set<std::pair<int, int>> directed;
  for (const Eigen::Vector3i& t : triangles) {
    for (int k = 0; k < 3; ++k) directed.emplace(t[k], t[(k + 1) % 3]);
  }
  int checked = 0, on_edge = 0;
  for (const auto& [a, b] : directed) {
    if (a > b || directed.count({b, a}) == 0) continue;  // each interior edge once
    const ClosestPoint q = pair_->cap.closest(0.5 * (target.col(a) + target.col(b)),
                                              result.relaxation.points[static_cast<size_t>(a)]);
    const Mapping::Location back = result.mapping.inverse(q.point);
    ASSERT_TRUE(back.inside) << "edge " << a << "-" << b;
    EXPECT_LT((back.position - 0.5 * (source.col(a) + source.col(b))).norm(), 0.25 * h * h * h)
        << "edge " << a << "-" << b;
    on_edge += back.barycentric.minCoeff() == 0.0 ? 1 : 0;  // clamped onto the edge
    ++checked;
  }
  EXPECT_GT(checked, 300);
  RecordProperty("clamped_onto_edge", on_edge);
  RecordProperty("interior_edges", checked);
}

// "Outside" means outside the region: points of the plane beyond the disk answer outside both
// ways. Just inside a boundary edge of the grid (1e-6 of its length, in its plane) is inside in 3D,
// whatever the disk maps say there, and is answered from that boundary triangle; just outside it
// is outside, or clamped onto the edge where the disk map has it inside.
TEST_F(MappingTest, OutsideTheRegionIsOutsideAndTheGridEdgeIsInside) {
  for (int k = 0; k < 16; ++k) {
    const double a = 0.39269908169872414 * k, r = 0.7 + 0.02 * k;
    const ClosestPoint p =
        pair_->plane.closest(Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0.0));
    EXPECT_FALSE(pair_->plane_to_cap.mapping.forward(p.point).inside) << "angle " << a;
    EXPECT_FALSE(pair_->cap_to_plane.mapping.inverse(p.point).inside) << "angle " << a;
  }

  const MapResult& result = pair_->plane_to_cap;
  const Eigen::Matrix3Xd source = source_particles(result);
  const auto& triangles = result.mapping.triangles();
  // Boundary edges: directed edges of the grid triangles whose reverse is in no triangle.
  std::set<std::pair<int, int>> directed;
  for (const Eigen::Vector3i& t : triangles) {
    for (int k = 0; k < 3; ++k) directed.emplace(t[k], t[(k + 1) % 3]);
  }
  int checked = 0, outside = 0, clamped = 0;
  for (size_t t = 0; t < triangles.size(); ++t) {
    const Eigen::Vector3i& tri = triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      if (directed.count({b, a}) > 0) continue;
      // Counter-clockwise seen from +z: the interior is on the left of a -> b.
      const Eigen::Vector3d edge = source.col(b) - source.col(a);
      const Eigen::Vector3d left = Eigen::Vector3d::UnitZ().cross(edge);
      const Eigen::Vector3d x = 0.5 * (source.col(a) + source.col(b)) + 1e-6 * left;
      const Mapping::Location loc = result.mapping.forward(pair_->plane.closest(x).point);
      ASSERT_TRUE(loc.inside) << "edge " << a << "-" << b;
      EXPECT_EQ(loc.triangle, static_cast<int>(t));
      EXPECT_GE(loc.barycentric.minCoeff(), -1e-9);
      ++checked;

      // Just outside the same edge (in the sliver between the chord and the boundary curve, or
      // outside the region where the two coincide): outside, or, where the disk map puts it inside
      // the grid, clamped onto this edge: weight 0 opposite it, 1/2 at its ends (up to the 1e-6
      // offset's component along the edge, which is 0 here).
      const Eigen::Vector3d y = 0.5 * (source.col(a) + source.col(b)) - 1e-6 * left;
      const Mapping::Location out = result.mapping.forward(pair_->plane.closest(y).point);
      if (!out.inside) {
        ++outside;
        continue;
      }
      ++clamped;
      EXPECT_EQ(out.triangle, static_cast<int>(t)) << "edge " << a << "-" << b;
      EXPECT_EQ(out.barycentric[(k + 2) % 3], 0.0) << "edge " << a << "-" << b;
      EXPECT_NEAR(out.barycentric[k], 0.5, 1e-9) << "edge " << a << "-" << b;
      EXPECT_NEAR(out.barycentric[(k + 1) % 3], 0.5, 1e-9) << "edge " << a << "-" << b;
    }
  }
  EXPECT_GT(checked, 20);
  EXPECT_EQ(outside + clamped, checked);
  RecordProperty("outside_beyond_edge", outside);
  RecordProperty("clamped_beyond_edge", clamped);
}

// A particle whose target point lies outside the target region is refused by the lowest such
// index, whatever the thread count (the constructor's loop runs in parallel).
TEST_F(MappingTest, ParticleOutsideTheTargetRegionIsNamedByItsLowestIndex) {
  const MapResult& result = pair_->cap_to_plane;  // target: the plane's disk of radius 0.6
  const int n = result.sampling.grid.num_particles();
  ASSERT_GT(n, 250);
  std::vector<SurfacePoint> points = result.relaxation.points;
  const SurfacePoint outside = pair_->plane.closest(Eigen::Vector3d(0.9, 0.9, 0.0)).point;
  points[static_cast<std::size_t>(n - 1)] = outside;
  points[static_cast<std::size_t>(n / 2)] = outside;
  points[7] = outside;
  try {
    const Mapping mapping(result.sampling.grid, pair_->cap, *result.source_disk, pair_->plane,
                          *result.target_disk, points);
    FAIL() << "a target point outside the region was accepted";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("particle 7 is outside the target region"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace elastic
