#pragma once
/// \file
/// `PtexDomain`: the parameter domain of a ptex face, the one home of its geometry. Every module
/// that reasons about (u, v) inside a face (the limit surface's walk and adjacency, the projector's
/// Newton iteration, seeds and clamps) asks this header instead of re-deriving corners, edges or
/// the centre.
///
/// The domain is the unit square (Catmull-Clark) or the unit triangle u, v >= 0, u + v <= 1
/// (Loop); see surface_point.h for how ptex faces sit on the control mesh.
///
// clang-format off
/// Corners and edges, in the order of the control face's corners; edge k runs from corner k to
/// corner k + 1 (mod n):
///
///   square:   corner 0 (0,0)   1 (1,0)   2 (1,1)   3 (0,1)
///             edge   0 v = 0   1 u = 1   2 v = 1   3 u = 0
///   triangle: corner 0 (0,0)   1 (1,0)   2 (0,1)
///             edge   0 v = 0   1 u + v = 1         2 u = 0
// clang-format on
///
/// Each edge is also a half-plane n . (u, v) >= offset with inward unit normal n (`DomainEdge`),
/// so `inside_distance(k, uv)` is the Euclidean distance from uv to edge k's line in (u, v) units,
/// positive inside.
///
/// The one nudge: where a computation cannot use a point on a face's corner or edge (walk() cannot
/// leave through a corner; du x dv vanishes at some extraordinary corners), it moves the point a
/// fixed distance towards the face centre, `towards_centre(p, distance)`, with one of the two
/// distances below.

#include <Eigen/Core>
#include <array>
#include <cmath>

#include "elastic/surface/surface_point.h"

namespace elastic {

/// One edge of a ptex domain as a half-plane: n . (u, v) >= offset inside.
struct DomainEdge {
  Eigen::Vector2d normal;    ///< inward unit normal
  double offset;             ///< n . (u, v) >= offset inside
  Eigen::Vector2d tangent;   ///< unit vector along the edge (sign: see the table in ptex_domain.h)
  Eigen::Vector2d midpoint;  ///< the edge's midpoint, on no other edge
};

/// Distance (ptex units) a point on a corner or edge is moved inside so that walk() starts off the
/// corner and leaves through an edge: far below any step the Newton iteration takes, far above
/// round-off of (u, v).
inline constexpr double kInsideNudge = 1e-9;
/// Distance (ptex units) a point is moved off a singular parameterisation (du x dv = 0 at some
/// extraordinary corners) to evaluate a normal or curvature there: both are continuous, so this
/// changes them by O(1e-6) relative, and du x dv is resolved well above round-off.
inline constexpr double kSingularNudge = 1e-6;

class PtexDomain {
 public:
  /// The unit triangle (Loop) when `triangle`, else the unit square (Catmull-Clark).
  explicit constexpr PtexDomain(bool triangle) : triangle_(triangle) {}

  bool triangle() const { return triangle_; }
  /// Corners (= edges) of the domain: 3 or 4.
  int num_corners() const { return triangle_ ? 3 : 4; }

  /// Corner k in (u, v).
  Eigen::Vector2d corner(int k) const {
    const auto& c = triangle_ ? kTriangleCorners[static_cast<size_t>(k)]
                              : kSquareCorners[static_cast<size_t>(k)];
    return {c[0], c[1]};
  }
  /// Point at parameter t along edge k (t = 0 at corner k, t = 1 at corner k + 1).
  Eigen::Vector2d edge_point(int k, double t) const {
    const Eigen::Vector2d a = corner(k);
    const Eigen::Vector2d b = corner((k + 1) % num_corners());
    return a + t * (b - a);
  }
  /// Parameter t of the projection of uv onto edge k's line (edge_point's inverse on the edge).
  double edge_parameter(int k, const Eigen::Vector2d& uv) const {
    const Eigen::Vector2d a = corner(k);
    const Eigen::Vector2d b = corner((k + 1) % num_corners());
    return (uv - a).dot(b - a) / (b - a).squaredNorm();
  }
  /// Edge k as a half-plane.
  const DomainEdge& edge(int k) const {
    return triangle_ ? triangle_edges()[static_cast<size_t>(k)]
                     : square_edges()[static_cast<size_t>(k)];
  }
  /// Signed distance from uv to edge k's line, positive inside: n . uv - offset.
  double inside_distance(int k, const Eigen::Vector2d& uv) const {
    const DomainEdge& e = edge(k);
    return e.normal.dot(uv) - e.offset;
  }
  /// Number of edges within `tolerance` of uv (inside distance at most `tolerance`): 2 or more
  /// on a corner.
  int edges_within(const Eigen::Vector2d& uv, double tolerance) const {
    int count = 0;
    for (int k = 0; k < num_corners(); ++k) {
      count += inside_distance(k, uv) <= tolerance;
    }
    return count;
  }

  /// True when uv lies in the domain, within `tolerance` in u and v (and u + v for the
  /// triangle). False for NaN.
  bool contains(const Eigen::Vector2d& uv, double tolerance = 0.0) const {
    if (!(uv.x() >= -tolerance && uv.y() >= -tolerance)) {
      return false;
    }
    if (triangle_) {
      return uv.x() + uv.y() <= 1.0 + tolerance;
    }
    return uv.x() <= 1.0 + tolerance && uv.y() <= 1.0 + tolerance;
  }
  /// The domain point for a uv slightly outside it (round-off): u and v clamped to [0, 1], and for
  /// the triangle a point beyond the hypotenuse pulled back onto it along the ray from the origin.
  Eigen::Vector2d clamp(Eigen::Vector2d uv) const {
    uv = uv.cwiseMax(0.0).cwiseMin(1.0);
    if (triangle_) {
      const double s = uv.x() + uv.y();
      if (s > 1.0) {
        uv /= s;
      }
    }
    return uv;
  }
  SurfacePoint clamp(const SurfacePoint& p) const {
    const Eigen::Vector2d uv = clamp(p.uv());
    return {p.face, uv.x(), uv.y()};
  }

  /// The centre: (1/2, 1/2) for the square, the centroid (1/3, 1/3) for the triangle.
  Eigen::Vector2d centre() const {
    const double c = triangle_ ? 1.0 / 3.0 : 0.5;
    return {c, c};
  }
  /// The one nudge: p moved `distance` (ptex units) straight towards the face centre, in the same
  /// face (kInsideNudge or kSingularNudge; see the file comment). p must not be the centre.
  SurfacePoint towards_centre(const SurfacePoint& p, double distance) const {
    const Eigen::Vector2d c = centre();
    const Eigen::Vector2d direction = Eigen::Vector2d(c.x() - p.u, c.y() - p.v).normalized();
    return {p.face, p.u + distance * direction.x(), p.v + distance * direction.y()};
  }

 private:
  static constexpr std::array<std::array<double, 2>, 4> kSquareCorners{
      {{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
  static constexpr std::array<std::array<double, 2>, 3> kTriangleCorners{{{0, 0}, {1, 0}, {0, 1}}};
  // sqrt(1/2) to the last bit (the literal rounds to the correctly rounded std::sqrt(0.5)).
  static constexpr double kHalfSqrt2 = 0.70710678118654752440;

  static const std::array<DomainEdge, 4>& square_edges() {
    static const std::array<DomainEdge, 4> edges{{
        {{0.0, 1.0}, 0.0, {1.0, 0.0}, {0.5, 0.0}},
        {{-1.0, 0.0}, -1.0, {0.0, 1.0}, {1.0, 0.5}},
        {{0.0, -1.0}, -1.0, {1.0, 0.0}, {0.5, 1.0}},
        {{1.0, 0.0}, 0.0, {0.0, 1.0}, {0.0, 0.5}},
    }};
    return edges;
  }
  static const std::array<DomainEdge, 3>& triangle_edges() {
    static const std::array<DomainEdge, 3> edges{{
        {{0.0, 1.0}, 0.0, {1.0, 0.0}, {0.5, 0.0}},
        {{-kHalfSqrt2, -kHalfSqrt2}, -kHalfSqrt2, {-kHalfSqrt2, kHalfSqrt2}, {0.5, 0.5}},
        {{1.0, 0.0}, 0.0, {0.0, 1.0}, {0.0, 0.5}},
    }};
    return edges;
  }

  bool triangle_;
};

}  // namespace elastic
