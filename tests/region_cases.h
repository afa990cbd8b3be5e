#pragma once
// Shared by the region, flattening and layout tests: a rectangle bent around the unit cylinder,
// whose unrolling every conformal flattening must give, and a star whose sides run through two
// welded copies of a tessellation vertex.

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <vector>

#include "elastic/regions/region.h"
#include "elastic/regions/region_spec.h"

namespace elastic::test {

/// A rectangle bent around the unit cylinder, the vertices of a grid at angles i * step and
/// heights j * height, each quad split in two. Every quad is planar (a chord x height rectangle),
/// so the triangles unroll isometrically onto the plane, where the columns lie one chord apart.
struct BentRectangle {
  Region region;
  std::vector<Eigen::Vector2d> unrolled;  ///< #V the isometric unrolling, (i * chord, j * height)
  int origin = 0;                         ///< the vertex at (i, j) = (0, 0)
  int along = 0;                          ///< the vertex at (columns, 0)
};

/// The boundary runs counter-clockwise in the unrolled plane, as the triangles do.
inline BentRectangle bent_rectangle(int columns = 12, int rows = 7, double step = 0.15,
                                    double height = 0.09) {
  BentRectangle out;
  Region& region = out.region;
  const double chord = 2.0 * std::sin(step / 2.0);
  for (int j = 0; j <= rows; ++j) {
    for (int i = 0; i <= columns; ++i) {
      region.positions.emplace_back(std::cos(i * step), std::sin(i * step), j * height);
      out.unrolled.emplace_back(i * chord, j * height);
    }
  }
  region.points.resize(region.positions.size());
  const auto id = [columns](int i, int j) { return j * (columns + 1) + i; };
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < columns; ++i) {
      region.triangles.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      region.triangles.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  }
  for (int i = 0; i < columns; ++i) {
    region.boundary.push_back(id(i, 0));
  }
  for (int j = 0; j < rows; ++j) {
    region.boundary.push_back(id(columns, j));
  }
  for (int i = columns; i > 0; --i) {
    region.boundary.push_back(id(i, rows));
  }
  for (int j = rows; j > 0; --j) {
    region.boundary.push_back(id(0, j));
  }
  out.origin = id(0, 0);
  out.along = id(columns, 0);
  return out;
}

/// A five-pointed star (tips of 36 degrees, inner radius 0.38 x 0.8) on the plane z = 0, centred at
/// (0, -0.05): cut from make_plane's 32 x 32 quads at the CLI's tessellation, its sides run through
/// two welded copies of a tessellation vertex, a zero-area triangle in the region.
inline RegionSpec welded_star() {
  RegionSpec spec;
  spec.kind = RegionSpec::Kind::Points;
  for (int k = 0; k < 10; ++k) {
    const double angle = std::numbers::pi / 2 + std::numbers::pi * k / 5;
    const double r = (k % 2 == 0) ? 0.8 : 0.38 * 0.8;
    spec.points.emplace_back(r * std::cos(angle), -0.05 + r * std::sin(angle), 0.0);
  }
  return spec;
}

}  // namespace elastic::test
