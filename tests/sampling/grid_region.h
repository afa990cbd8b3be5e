#pragma once

#include <algorithm>
#include <cmath>
// Test helpers for the sampling tests: a height-field control mesh over [-1,1]^2 and a Region built
// by hand on its limit surface (independent of regions/make_region), so that the region's
// triangles, ptex parameters and boundary are known exactly.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <sstream>
#include <string>

#include "elastic/mesh/polygon_mesh.h"
#include "elastic/particles/particle_grid.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/region.h"
#include "elastic/surface/limit_surface.h"

namespace elastic::test {

/// An n x n quad control grid over [x0,x1] x [y0,y1] with z = height(x, y). Face f = j * n + i has
/// the corners (i,j), (i+1,j), (i+1,j+1), (i,j+1) (counter-clockwise, normal +z), so under
/// Catmull-Clark its ptex u runs along x and v along y.
inline PolygonMesh make_height_grid(int nx, int ny, double x0, double x1, double y0, double y1,
                                    const std::function<double(double, double)>& height) {
  PolygonMesh mesh;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const double x = x0 + (x1 - x0) * i / nx, y = y0 + (y1 - y0) * j / ny;
      mesh.positions.emplace_back(x, y, height(x, y));
    }
  }
  const auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i)
      mesh.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  }
  return mesh;
}

/// The whole limit surface of make_height_grid(nx, ny, ...) as a Region: each ptex face sampled
/// with res x res cells (two triangles each). Texture coordinates are ((x - x0)/(x1 - x0), (y -
/// y0)/(y1 - y0)) of the control grid, i.e. linear in the ptex parameters.
inline Region make_grid_region(const LimitSurface& surface, int nx, int ny, int res) {
  Region region;
  region.surface = &surface;
  const int gx = nx * res, gy = ny * res;
  const auto vid = [&](int I, int J) { return J * (gx + 1) + I; };
  for (int J = 0; J <= gy; ++J) {
    for (int I = 0; I <= gx; ++I) {
      const int i = std::min(I / res, nx - 1), j = std::min(J / res, ny - 1);
      const SurfacePoint p{j * nx + i, static_cast<double>(I - i * res) / res,
                           static_cast<double>(J - j * res) / res};
      region.points.push_back(p);
      region.positions.push_back(surface.position(p));
      region.texcoords.emplace_back(static_cast<double>(I) / gx, static_cast<double>(J) / gy);
    }
  }
  for (int J = 0; J < gy; ++J) {
    for (int I = 0; I < gx; ++I) {
      const int i = I / res, j = J / res, face = j * nx + i;
      const auto uv = [&](int a, int b) {
        return Eigen::Vector2d(static_cast<double>(a - i * res) / res,
                               static_cast<double>(b - j * res) / res);
      };
      region.triangles.emplace_back(vid(I, J), vid(I + 1, J), vid(I + 1, J + 1));
      region.triangle_face.push_back(face);
      region.triangle_uv.push_back({uv(I, J), uv(I + 1, J), uv(I + 1, J + 1)});
      region.triangles.emplace_back(vid(I, J), vid(I + 1, J + 1), vid(I, J + 1));
      region.triangle_face.push_back(face);
      region.triangle_uv.push_back({uv(I, J), uv(I + 1, J + 1), uv(I, J + 1)});
    }
  }
  // Counter-clockwise boundary loop seen from +z.
  for (int I = 0; I < gx; ++I) region.boundary.push_back(vid(I, 0));
  for (int J = 0; J < gy; ++J) region.boundary.push_back(vid(gx, J));
  for (int I = gx; I > 0; --I) region.boundary.push_back(vid(I, gy));
  for (int J = gy; J > 0; --J) region.boundary.push_back(vid(0, J));
  region.anchor = 0.0;
  return region;
}

/// Every face corner turns counter-clockwise around the surface normal at that corner, with a sine
/// bounded away from zero: no inverted and no degenerate face. Computed from the mesh and the
/// surface, independently of the library's own statistics.
inline void expect_valid_faces(const ParticleGrid& grid, const LimitSurface& surface,
                               double min_sine) {
  const Eigen::Matrix3Xd x = grid.source_positions();
  double smallest = 1.0;
  for (const auto f : grid.mesh.faces()) {
    std::vector<int> v;
    for (const auto vh : grid.mesh.fv_range(f)) v.push_back(vh.idx());
    const int n = static_cast<int>(v.size());
    ASSERT_GE(n, 3);
    for (int c = 0; c < n; ++c) {
      const Eigen::Vector3d normal = surface.curvature(grid.source_points[v[c]]).normal;
      const Eigen::Vector3d e1 = x.col(v[(c + 1) % n]) - x.col(v[c]);
      const Eigen::Vector3d e2 = x.col(v[(c + n - 1) % n]) - x.col(v[c]);
      ASSERT_GT(e1.norm(), 0.0);
      smallest = std::min(smallest, e1.cross(e2).dot(normal) / (e1.norm() * e2.norm()));
    }
  }
  EXPECT_GT(smallest, min_sine);
}

/// A "disk:X,Y,Z,R" region spec centred at the surface point nearest to `near` (control meshes of
/// convex shapes lie outside their limit surfaces, so a point of the ideal shape may be too far
/// from it).
inline std::string disk_spec(const SurfaceProjector& projector, const Eigen::Vector3d& near,
                             double radius) {
  const Eigen::Vector3d c = projector.closest(near).position;
  std::ostringstream out;
  out.precision(17);
  out << "disk:" << c.x() << "," << c.y() << "," << c.z() << "," << radius;
  return out.str();
}

/// Independent arc-length reference for boundary-placement tests: where `p` lies on the closed
/// polyline through the region's boundary vertices, computed from scratch (no library code).
struct PolylinePosition {
  double distance = 0.0;  ///< distance from p to the polyline
  double arc = 0.0;  ///< normalised arc length from boundary vertex 0 of p's foot point, in [0,1)
  double length = 0.0;  ///< length of the closed polyline
};
inline PolylinePosition polyline_position(const Region& region, const Eigen::Vector3d& p) {
  std::vector<Eigen::Vector3d> poly;
  for (const int v : region.boundary) poly.push_back(region.positions[v]);
  const int n = static_cast<int>(poly.size());
  std::vector<double> cumulative(n + 1, 0.0);
  for (int k = 0; k < n; ++k)
    cumulative[k + 1] = cumulative[k] + (poly[(k + 1) % n] - poly[k]).norm();
  PolylinePosition out;
  out.length = cumulative[n];
  int seg = 0;
  out.distance = 1e300;
  for (int e = 0; e < n; ++e) {
    const Eigen::Vector3d a = poly[e], d = poly[(e + 1) % n] - poly[e];
    const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
    const double dist = (a + t * d - p).norm();
    if (dist < out.distance) out.distance = dist, seg = e;
  }
  out.arc = (cumulative[seg] + (p - poly[seg]).norm()) / out.length;
  out.arc -= std::floor(out.arc);
  return out;
}

}  // namespace elastic::test
