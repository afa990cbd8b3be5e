// The planar grid (sampling/planar_grid.h) on polygons with sharp tips and reflex notches: stars
// with inner radius ratios 0.38, 0.3 and 0.2, an L and a comb, each as its bare vertices and
// resampled at the lattice step like boundary particles, for several steps and lattice offsets.
// Every property is checked with code written here, independently of the library.

#include "elastic/sampling/planar_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "elastic/core/error.h"

namespace elastic {
namespace {

using Polygon = std::vector<Eigen::Vector2d>;

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}
double signed_area(const Polygon& p) {
  double a = 0.0;
  for (size_t k = 0; k < p.size(); ++k) a += cross(p[k], p[(k + 1) % p.size()]);
  return 0.5 * a;
}

/// A star with `tips` tips of outer radius 1 and inner radius `ratio`, counter-clockwise.
Polygon star(double ratio, int tips = 5) {
  Polygon p;
  for (int k = 0; k < 2 * tips; ++k) {
    const double angle = std::numbers::pi / 2 + std::numbers::pi * k / tips;
    const double r = (k % 2 == 0) ? 1.0 : ratio;
    p.emplace_back(r * std::cos(angle), r * std::sin(angle));
  }
  return p;
}

/// An L: the square [0,2]^2 without [1,2]x[1,2] (a 270 degree reflex corner at (1,1)), centred.
Polygon l_shape() {
  return {{-1, -1}, {1, -1}, {1, 0}, {0, 0}, {0, 1}, {-1, 1}};
}

/// A comb: a spine along the bottom and four teeth, separated by deep slots (reflex corners at
/// the bottom of each slot).
Polygon comb() {
  const int teeth = 4;
  const double w = 2.0 / (2 * teeth - 1);  // teeth and slots of equal width
  Polygon p{{-1.0, -1.0}, {1.0, -1.0}};
  for (int t = teeth - 1; t >= 0; --t) {
    const double x0 = -1.0 + 2 * t * w, x1 = x0 + w;
    if (t < teeth - 1) p.emplace_back(x1, -0.4);  // bottom of the slot to the right
    p.emplace_back(x1, 1.0);
    p.emplace_back(x0, 1.0);
    if (t > 0) p.emplace_back(x0, -0.4);
  }
  return p;
}

/// The polygon resampled at equal arc length with step about h, as the grid layout places boundary
/// particles (the corners themselves are generally not samples: the samples cut across tips).
Polygon resample(const Polygon& p, double h) {
  std::vector<double> cum{0.0};
  for (size_t k = 0; k < p.size(); ++k)
    cum.push_back(cum.back() + (p[(k + 1) % p.size()] - p[k]).norm());
  const double length = cum.back();
  const int m = std::max(3, static_cast<int>(std::lround(length / h)));
  Polygon out;
  size_t seg = 0;
  for (int k = 0; k < m; ++k) {
    const double s = length * k / m;
    while (cum[seg + 1] < s) ++seg;
    const double t = (s - cum[seg]) / (cum[seg + 1] - cum[seg]);
    out.push_back((1.0 - t) * p[seg] + t * p[(seg + 1) % p.size()]);
  }
  return out;
}

double segment_distance(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                        const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  const auto point_segment = [](const Eigen::Vector2d& p, const Eigen::Vector2d& s0,
                                const Eigen::Vector2d& s1) {
    const Eigen::Vector2d e = s1 - s0;
    const double t = std::clamp((p - s0).dot(e) / e.squaredNorm(), 0.0, 1.0);
    return (s0 + t * e - p).norm();
  };
  const double o1 = cross(b - a, c - a), o2 = cross(b - a, d - a);
  const double o3 = cross(d - c, a - c), o4 = cross(d - c, b - c);
  if (((o1 > 0) != (o2 > 0)) && ((o3 > 0) != (o4 > 0))) return 0.0;  // proper crossing
  return std::min({point_segment(a, c, d), point_segment(b, c, d), point_segment(c, a, b),
                   point_segment(d, a, b)});
}

bool inside(const Polygon& poly, const Eigen::Vector2d& x) {  // crossing number
  bool in = false;
  for (size_t k = 0; k < poly.size(); ++k) {
    const Eigen::Vector2d &p = poly[k], &q = poly[(k + 1) % poly.size()];
    if ((p.y() > x.y()) != (q.y() > x.y()) &&
        x.x() < p.x() + (x.y() - p.y()) / (q.y() - p.y()) * (q.x() - p.x())) {
      in = !in;
    }
  }
  return in;
}

struct Checked {
  bool laid_out = false;
  int band_points = 0;
};

/// Lays out `poly` at step h and offset, and checks every guarantee of planar_grid.h.
Checked check_layout(const Polygon& poly, double h, const Eigen::Vector2d& offset,
                     const std::string& what, int delaunay_rounds = 4) {
  SCOPED_TRACE(what);
  const PlanarLatticeOptions options;
  const PlanarLattice lattice = select_lattice_cells(poly, h, offset, options);
  if (lattice.points == 0) return {};  // the step is too coarse for any cell
  const PlanarGrid grid = build_planar_grid(
      poly, lattice, PlanarGridOptions{.name = "test polygon", .delaunay_rounds = delaunay_rounds});
  const int m = static_cast<int>(poly.size());
  const int interior = grid.interior_points();
  EXPECT_EQ(grid.boundary_points, m);
  EXPECT_EQ(static_cast<int>(grid.points.size()), interior + m);
  for (int k = 0; k < m; ++k) EXPECT_EQ(grid.points[interior + k], poly[k]);

  // Every face is counter-clockwise with positive area; no face has only boundary corners.
  std::vector<std::vector<int>> faces;
  for (const Eigen::Vector4i& q : grid.quads) faces.push_back({q[0], q[1], q[2], q[3]});
  for (const Eigen::Vector3i& t : grid.triangles) faces.push_back({t[0], t[1], t[2]});
  double area = 0.0;
  int frozen = 0, negative = 0;
  for (const std::vector<int>& f : faces) {
    double a = 0.0;
    bool all_boundary = true;
    for (size_t c = 0; c < f.size(); ++c) {
      a += 0.5 * cross(grid.points[f[c]], grid.points[f[(c + 1) % f.size()]]);
      all_boundary = all_boundary && f[c] >= interior;
    }
    if (f.size() == 3) {
      // Orientation from the triangle's own edges (no cancellation against the origin).
      const Eigen::Vector2d &p = grid.points[f[0]], &q = grid.points[f[1]], &r = grid.points[f[2]];
      negative += cross(q - p, r - p) > 0.0 ? 0 : 1;
    } else {
      negative += a > 0.0 ? 0 : 1;
      EXPECT_NEAR(a, h * h, 1e-9 * h * h);
    }
    frozen += all_boundary ? 1 : 0;
    area += a;
  }
  EXPECT_EQ(negative, 0) << "faces with non-positive area";
  EXPECT_EQ(frozen, 0) << "faces whose every corner is a boundary point";
  // Quads and band tile the polygon exactly: each interior edge is used once in each direction,
  // and the edges used once are exactly the polygon's (with positive faces, a disk whose boundary
  // is the polygon covers it exactly once). The area sum is then equal up to round-off: ~1e4
  // terms, each with a relative error of a few ulp, stay far below 1e-10 of the area.
  std::map<std::pair<int, int>, int> directed;
  for (const std::vector<int>& f : faces) {
    for (size_t c = 0; c < f.size(); ++c) ++directed[{f[c], f[(c + 1) % f.size()]}];
  }
  int bad_edges = 0, boundary_edges = 0;
  for (const auto& [e, count] : directed) {
    if (count != 1) ++bad_edges;
    if (directed.count({e.second, e.first})) continue;
    const bool polygon_edge = e.first >= interior && e.second >= interior &&
                              (e.second - interior) == (e.first - interior + 1) % m;
    if (polygon_edge) {
      ++boundary_edges;
    } else {
      ++bad_edges;
    }
  }
  EXPECT_EQ(bad_edges, 0);
  EXPECT_EQ(boundary_edges, m);
  EXPECT_NEAR(area, signed_area(poly), 1e-10 * signed_area(poly));
  // Euler characteristic of a disk.
  std::set<std::pair<int, int>> undirected;
  for (const auto& [e, count] : directed)
    undirected.insert({std::min(e.first, e.second), std::max(e.first, e.second)});
  EXPECT_EQ(static_cast<long>(grid.points.size()) - static_cast<long>(undirected.size()) +
                static_cast<long>(faces.size()),
            1);

  // The outline: one loop of distinct lattice points, strictly inside the polygon with a margin of
  // (clearance - 1/2) h from it.
  const std::set<int> distinct(grid.outline.begin(), grid.outline.end());
  EXPECT_EQ(distinct.size(), grid.outline.size());
  double margin = 1e300;
  for (size_t k = 0; k < grid.outline.size(); ++k) {
    const int a = grid.outline[k], b = grid.outline[(k + 1) % grid.outline.size()];
    EXPECT_LT(a, grid.lattice_points);
    EXPECT_TRUE(inside(poly, grid.points[a]));
    for (int e = 0; e < m; ++e) {
      margin = std::min(
          margin, segment_distance(grid.points[a], grid.points[b], poly[e], poly[(e + 1) % m]));
    }
  }
  EXPECT_GE(margin, (options.clearance - 0.5) * h * (1.0 - 1e-9));
  return {true, grid.band_points};
}

void check_polygon(const Polygon& polygon, const std::string& name, int expect_laid_out) {
  ASSERT_GT(signed_area(polygon), 0.0) << name << " must be counter-clockwise";
  const Eigen::Vector2d offsets[] = {{0.0, 0.0}, {0.5, 0.5}, {0.25, 0.25}, {0.125, 0.375}};
  int laid_out = 0;
  for (const double h : {0.2, 0.1, 0.05, 0.021}) {
    for (const Eigen::Vector2d& f : offsets) {
      for (const bool resampled : {false, true}) {
        const Polygon poly = resampled ? resample(polygon, h) : polygon;
        const std::string what = name + (resampled ? " resampled" : " bare") +
                                 ", h = " + std::to_string(h) + ", offset " +
                                 std::to_string(f.x()) + "," + std::to_string(f.y());
        laid_out += check_layout(poly, h, f * h, what).laid_out ? 1 : 0;
      }
    }
  }
  // All but the coarsest steps fit cells in every shape (a test that lays out nothing would pass).
  EXPECT_GE(laid_out, expect_laid_out) << name;
}

TEST(PlanarGrid, StarsWithSharpTipsLayOutValidly) {
  for (const double ratio : {0.38, 0.3, 0.2}) {
    check_polygon(star(ratio), "star " + std::to_string(ratio), 24);
  }
}

TEST(PlanarGrid, ReflexNotchesLayOutValidly) {
  check_polygon(l_shape(), "L", 32);
  check_polygon(comb(), "comb", 24);
}

// Resampled like boundary particles, a star's tips hold boundary points beyond the reach of the
// lattice: the band's Delaunay triangles there have every corner on the boundary until free points
// are added. Without any Delaunay round, the last resort (splitting each such triangle at its
// centroid) must give the same guarantees on its own.
TEST(PlanarGrid, SharpTipsGetFreePoints) {
  for (const double ratio : {0.38, 0.2}) {
    const Polygon poly = resample(star(ratio), 0.05);
    const std::string name = "resampled star " + std::to_string(ratio);
    const Checked delaunay = check_layout(poly, 0.05, Eigen::Vector2d::Zero(), name);
    ASSERT_TRUE(delaunay.laid_out);
    EXPECT_GE(delaunay.band_points, 5) << name << ": at least one free point per tip";
    const Checked split =
        check_layout(poly, 0.05, Eigen::Vector2d::Zero(), name + ", split only", 0);
    ASSERT_TRUE(split.laid_out);
    EXPECT_GE(split.band_points, 5) << name;
  }
}

TEST(PlanarGrid, SelfCrossingBoundaryIsAClearError) {
  Polygon fine = resample({{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}, 0.05);
  std::swap(fine[10], fine[60]);  // two boundary particles swapped: the polygon crosses itself
  const PlanarLattice lattice = select_lattice_cells(fine, 0.05, Eigen::Vector2d::Zero());
  ASSERT_GT(lattice.points, 0);
  try {
    build_planar_grid(fine, lattice, PlanarGridOptions{.name = "--source-region"});
    FAIL() << "expected an error";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("--source-region"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("crosses itself"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace elastic
