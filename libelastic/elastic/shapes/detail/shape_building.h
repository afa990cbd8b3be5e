#pragma once
/// \file
/// What the procedural shapes are built from, private to shapes/ (not installed): surfaces of
/// revolution swept from a profile (surface_of_revolution.cpp) and the sphere meshes
/// (sphere_meshes.cpp); procedural_shapes.cpp makes the public shapes from them.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <utility>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"
#include "elastic/shapes/procedural_shapes.h"

namespace elastic::shapes_detail {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// Multiplies every position by `scale`.
void apply_scale(PolygonMesh& mesh, double scale);
/// Reverses every face's corner order (flips its normal).
void reverse_faces(PolygonMesh& mesh);

// ---------------------------------------------------------------------------------------------------
// Profiles of surfaces of revolution.
//
// A profile is a plane curve t in [0,1] -> (r, z), r >= 0 the distance from the z axis. Sweeping it
// around z gives the surface point (r cos(theta), r sin(theta), z). Faces are first built with the
// corner order (ring i, angle j), (i, j+1), (i+1, j+1), (i+1, j): their normal is
// d/dtheta x d/dt = phi_hat x (r' r_hat + z' z_hat) = z' r_hat - r' z_hat, i.e. the profile's
// tangent (r', z') turned clockwise. A profile traversed with the solid on its left (bottom to top
// on the outside, outward from a bottom pole) therefore yields outward normals; `flip` reverses
// every face for a profile traversed the other way.

struct Profile {
  std::function<Eigen::Vector2d(double)> at;  ///< t in [0,1] -> (r, z); r(t) >= 0
  bool pole_at_start = false;                 ///< r(0) == 0: the surface closes at (0, z(0))
  bool closed = false;                        ///< at(0) == at(1): a closed curve (torus)
  bool flip = false;                          ///< reverse the faces (see above)
};

// A smooth curve through control points (r, z): cubic Hermite segments whose tangent directions are
// the bisectors of the adjacent chords and whose tangent lengths are the segment's chord length.
// This is tangent-continuous (G1), and scaling each segment's tangents by its own chord keeps the
// curve close to the control polygon where the points are unevenly spaced (no loops or overshoot,
// unlike uniform Catmull-Rom). When the first point is on the axis (a pole) its tangent is
// horizontal, so that the swept surface is smooth (tangent plane z = const) at the pole.
class HermiteProfile {
 public:
  explicit HermiteProfile(std::vector<Eigen::Vector2d> points) : points_(std::move(points)) {
    const size_t n = points_.size();
    tangents_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      Eigen::Vector2d d = Eigen::Vector2d::Zero();
      if (i > 0) {
        d += (points_[i] - points_[i - 1]).normalized();
      }
      if (i + 1 < n) {
        d += (points_[i + 1] - points_[i]).normalized();
      }
      tangents_[i] = d.normalized();
    }
    if (points_.front().x() == 0.0) {
      tangents_.front() = Eigen::Vector2d(1.0, 0.0);
    }
  }

  Eigen::Vector2d operator()(double t) const {
    const int segments = static_cast<int>(points_.size()) - 1;
    const double x = std::clamp(t, 0.0, 1.0) * segments;
    const int i = std::min(static_cast<int>(x), segments - 1);
    const double u = x - i;
    const double length = (points_[i + 1] - points_[i]).norm();
    const double u2 = u * u;
    const double u3 = u2 * u;
    const double h00 = 2 * u3 - 3 * u2 + 1;
    const double h10 = u3 - 2 * u2 + u;
    const double h01 = -2 * u3 + 3 * u2;
    const double h11 = u3 - u2;
    Eigen::Vector2d p = h00 * points_[i] + h10 * length * tangents_[i] + h01 * points_[i + 1] +
                        h11 * length * tangents_[i + 1];
    p.x() = std::max(p.x(), 0.0);  // the pole stays exactly on the axis
    return p;
  }

 private:
  std::vector<Eigen::Vector2d> points_;
  std::vector<Eigen::Vector2d> tangents_;
};

/// The surface of revolution of `profile` at options.resolution segments around the axis, with
/// triangles or quads as options.faces asks, scaled by options.scale.
PolygonMesh sweep(const Profile& profile, const ShapeOptions& options);

/// Quad sphere: a cube's faces as N x N grids (equal-angle map) projected onto the unit sphere.
PolygonMesh cube_sphere(int N);
/// Triangle sphere: the icosahedron subdivided k times, projected onto the unit sphere.
PolygonMesh icosphere(int k);

}  // namespace elastic::shapes_detail
