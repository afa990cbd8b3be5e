#include "elastic/regions/region.h"

#include <Eigen/Geometry>

namespace elastic {

SurfaceCurve Region::boundary_curve() const {
  SurfaceCurve curve;
  curve.points.reserve(boundary.size());
  curve.positions.reserve(boundary.size());
  for (int v : boundary) {
    curve.points.push_back(points[static_cast<size_t>(v)]);
    curve.positions.push_back(positions[static_cast<size_t>(v)]);
  }
  curve.anchor = anchor;
  return curve;
}

double Region::area() const {
  double total = 0.0;
  for (const Eigen::Vector3i& t : triangles) {
    const Eigen::Vector3d& a = positions[static_cast<size_t>(t[0])];
    total += 0.5 * (positions[static_cast<size_t>(t[1])] - a)
                       .cross(positions[static_cast<size_t>(t[2])] - a)
                       .norm();
  }
  return total;
}

SurfacePoint Region::point_in_triangle(int t, double b1, double b2) const {
  // (u, v) is affine over the triangle inside its ptex face, so the blend stays in the face's
  // domain.
  const auto& uv = triangle_uv[static_cast<size_t>(t)];
  const Eigen::Vector2d p = (1.0 - b1 - b2) * uv[0] + b1 * uv[1] + b2 * uv[2];
  return SurfacePoint{triangle_face[static_cast<size_t>(t)], p.x(), p.y()};
}

}  // namespace elastic
