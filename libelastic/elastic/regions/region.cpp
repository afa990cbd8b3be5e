#include "elastic/regions/region.h"

#include <Eigen/Geometry>
#include <cstdint>
#include <unordered_map>

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

std::vector<BoundaryChord> Region::boundary_chords() const {
  const size_t n = boundary.size();
  std::vector<BoundaryChord> chords(n);
  if (n < 2) {
    return chords;
  }
  auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32U) |
           static_cast<std::uint32_t>(b);
  };
  // chord key -> k; a chord repeated in the loop (not a simple curve) keeps its first k, and the
  // others are copied from it below.
  std::unordered_map<std::uint64_t, size_t> chord_index;
  chord_index.reserve(n);
  for (size_t k = 0; k < n; ++k) {
    chord_index.try_emplace(key(boundary[k], boundary[(k + 1) % n]), k);
  }
  std::vector<BoundaryChord> reversed(n);
  for (int t = 0; t < num_triangles(); ++t) {
    const Eigen::Vector3i& tri = triangles[static_cast<size_t>(t)];
    for (int c = 0; c < 3; ++c) {
      const int d = (c + 1) % 3;
      if (auto it = chord_index.find(key(tri[c], tri[d])); it != chord_index.end()) {
        chords[it->second] = {t, c, d};
      }
      if (auto it = chord_index.find(key(tri[d], tri[c]));
          it != chord_index.end() && reversed[it->second].triangle < 0) {
        reversed[it->second] = {t, d, c};
      }
    }
  }
  for (size_t k = 0; k < n; ++k) {
    const size_t first = chord_index.at(key(boundary[k], boundary[(k + 1) % n]));
    chords[k] = chords[first].triangle >= 0 ? chords[first] : reversed[first];
  }
  return chords;
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
