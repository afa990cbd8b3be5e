#pragma once
/// \file
/// Vectors across the map: tangent frames and the differential of the piecewise-linear map.
///
/// The relaxed particle grid defines the map triangle by triangle (mapping/mapping.h): inside grid
/// triangle t with source particles s0, s1, s2 and target particles x0, x1, x2 the map is the
/// affine map A(s) = x0 + J (s - s0), where J is the 3x3 matrix of rank 2 with
///
///     J (s1 - s0) = x1 - x0,   J (s2 - s0) = x2 - x0,   J m_s = 0,
///
/// m_s being the source triangle's unit normal: J = [x1-x0, x2-x0] [s1-s0, s2-s0]^+
/// (pseudo-inverse). J is the map's differential between the two triangle planes; Mapping::forward
/// composes it with the magnet, whose differential on the surface is the projection onto the target
/// tangent plane.
///
/// A vector v at a source point p (in world coordinates) is carried to the image point q by
///
///     T = R(m_t -> n_t) * (L + m_t m_s^T) * R(n_s -> m_s),
///
/// where n_s, n_t are the limit normals at p and q, m_s, m_t the triangles' normals, R(a -> b) the
/// minimal rotation taking unit vector a to b (about a x b), and L either J (VectorTransport::
/// Stretch) or J's rotation part from the polar decomposition J = R S in the triangle planes
/// (VectorTransport::Rotation). So:
/// - tangent vectors at p arrive tangent at q, the source normal arrives as the target normal:
///   bump and normal vectors expressed in a source frame (t, b, n) come out in the transported
///   frame (T t, T b, n_t); a world-space vector is transported, never copied;
/// - length policy: the tilt between the limit tangent plane and the chord plane of the grid
///   triangle (an angle of about spacing * curvature) is removed by rotations, which keep lengths,
///   not by projections, which would shorten vectors by cos(tilt). Stretch gives |T v| = |J R v|
///   for tangent v (the map's stretch, e.g. a vector field that should follow the paste's scaling)
///   and keeps the normal component unscaled; Rotation gives |T v| = |v| for every v (directions);
/// - a rigid map gives T = the rotation exactly (both modes), the identity map gives T = I;
/// - on a folded target triangle (orientation reversed against the target normal) T reverses the
///   tangent orientation, as the map does there; Rotation then uses the nearest reflection.
///
/// `MapDifferential` holds the particles' limit positions and each triangle's J; it references
/// the two limit surfaces (which must outlive it) for the limit normals. Const queries are
/// thread-safe.

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "elastic/mapping/map_regions.h"
#include "elastic/mapping/mapping.h"
#include "elastic/surface/limit_surface.h"

namespace elastic {

/// An orthonormal right-handed frame at a surface point: tangent x bitangent = normal.
struct TangentFrame {
  Eigen::Vector3d tangent = Eigen::Vector3d::UnitX();
  Eigen::Vector3d bitangent = Eigen::Vector3d::UnitY();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();

  /// Columns tangent, bitangent, normal (local -> world).
  Eigen::Matrix3d matrix() const;
  /// World vector of frame components (a, b, c): a t + b b + c n.
  Eigen::Vector3d to_world(const Eigen::Vector3d& local) const;
  /// Frame components of a world vector.
  Eigen::Vector3d to_local(const Eigen::Vector3d& world) const;
};

/// The frame with unit `normal` whose tangent is `tangent_hint` made orthogonal to it
/// (Gram-Schmidt) and normalised; bitangent = normal x tangent. \throws NumericalError when the
/// normal is zero or the hint is (nearly) parallel to it.
TangentFrame make_tangent_frame(const Eigen::Vector3d& normal, const Eigen::Vector3d& tangent_hint);

/// The limit surface's own frame at p: tangent = du / |du|, normal = du x dv normalised (the
/// surface's normal side, limit_surface.h), bitangent = normal x tangent. Note that ptex faces are
/// rotated against each other, so this frame jumps across ptex edges: use it for local work, and a
/// frame from texture coordinates or a transported frame for fields that must be continuous.
/// \throws NumericalError where du x dv vanishes (a singular parametrisation).
TangentFrame surface_frame(const LimitSurface& surface, const SurfacePoint& p);

/// The rotation by the smallest angle taking unit vector a to unit vector b (about a x b). For
/// a = -b (no unique answer) a half turn about an axis perpendicular to a.
Eigen::Matrix3d minimal_rotation(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

/// J of the affine map taking the source triangle (columns s0, s1, s2) to the target triangle
/// (columns x0, x1, x2): J (s_k - s0) = x_k - x0 and J m_s = 0 (see the file comment).
/// \throws NumericalError when the source triangle is degenerate (area ~ 0 relative to its edges).
Eigen::Matrix3d triangle_jacobian(const Eigen::Matrix3d& source, const Eigen::Matrix3d& target);

/// The rotation part of that map plus normal-to-normal: Q = B_t R B_s^T + m_t m_s^T, where B_s,
/// B_t are orthonormal bases of the two triangle planes and R is the 2x2 rotation nearest J in
/// them (polar decomposition), or the nearest reflection when J reverses orientation (det < 0).
/// \throws NumericalError for a degenerate source or target triangle.
Eigen::Matrix3d triangle_rotation(const Eigen::Matrix3d& source, const Eigen::Matrix3d& target);

/// How tangent vectors are carried (see the file comment).
enum class VectorTransport {
  Stretch,  ///< by the map's differential J: vectors stretch and shear with the paste
  Rotation  ///< by J's rotation part: directions; every vector keeps its length
};

class MapDifferential {
 public:
  MapDifferential() = default;
  /// \param source_points #P source surface points of the particles
  /// \param target_points #P relaxed target surface points of the particles
  /// \param triangles grid triangles (particle triples), as Mapping::triangles() lists them
  /// \throws InvalidInputError when the sizes disagree or a triangle names a missing particle.
  MapDifferential(const LimitSurface& source, const std::vector<SurfacePoint>& source_points,
                  const LimitSurface& target, const std::vector<SurfacePoint>& target_points,
                  const std::vector<Eigen::Vector3i>& triangles);
  /// From map_regions' result: the grid's source points, the relaxed points, the mapping's
  /// triangles. `source` and `target` are the surfaces the result was computed on.
  MapDifferential(const LimitSurface& source, const LimitSurface& target, const MapResult& result);

  int num_triangles() const { return static_cast<int>(triangles_.size()); }
  const LimitSurface& source_surface() const { return *source_; }
  const LimitSurface& target_surface() const { return *target_; }

  /// J of grid triangle t (3x3, maps source-plane vectors to target-plane vectors).
  /// \throws InvalidInputError for t out of range; NumericalError for a degenerate triangle.
  const Eigen::Matrix3d& jacobian(int t) const;
  /// True when grid triangle t's target is folded: its orientation, seen along the target limit
  /// normal at its centroid's nearest particle, is the reverse of the source's.
  bool folded(int t) const;
  /// The grid triangle nearest to a source position (by point-triangle distance to the source
  /// particle triangles; brute force, O(#triangles)); for locations without a triangle, e.g.
  /// boundary points matched by arc length.
  int nearest_triangle(const Eigen::Vector3d& source_position) const;

  /// T (see the file comment) carrying world vectors at source point `source` to target point
  /// `target` through grid triangle `triangle` (-1: nearest_triangle of the source position).
  /// \throws InvalidInputError for invalid points or triangle; NumericalError for a degenerate
  ///         triangle or a singular limit normal.
  Eigen::Matrix3d transport(const SurfacePoint& source, const SurfacePoint& target, int triangle,
                            VectorTransport mode = VectorTransport::Stretch) const;
  /// The same for a forward query: `source` and the Location Mapping::forward returned for it.
  Eigen::Matrix3d transport_forward(const SurfacePoint& source, const Mapping::Location& image,
                                    VectorTransport mode = VectorTransport::Stretch) const;
  /// The same for an inverse query: target point `target` and the Location Mapping::inverse
  /// returned for it (its `point` is on the source).
  Eigen::Matrix3d transport_inverse(const SurfacePoint& target, const Mapping::Location& preimage,
                                    VectorTransport mode = VectorTransport::Stretch) const;

  /// The source frame carried to the target: tangent T t made orthogonal to n_t and normalised,
  /// normal n_t. Components of a vector in `frame` equal its transported components in this frame
  /// under Rotation (exactly) and under Stretch for the normal component.
  TangentFrame transport_frame(const TangentFrame& frame, const SurfacePoint& source,
                               const SurfacePoint& target, int triangle,
                               VectorTransport mode = VectorTransport::Stretch) const;

 private:
  const LimitSurface* source_ = nullptr;
  const LimitSurface* target_ = nullptr;
  Eigen::Matrix3Xd source_positions_;
  Eigen::Matrix3Xd target_positions_;
  std::vector<SurfacePoint> target_points_;
  std::vector<Eigen::Vector3i> triangles_;
  std::vector<Eigen::Matrix3d> jacobians_;  // zero for degenerate triangles
  std::vector<Eigen::Matrix3d> rotations_;  // Q of triangle_rotation, zero for degenerate ones
  std::vector<char> degenerate_;
  std::vector<char> folded_;
  void check_triangle(int t) const;
};

struct VectorTransferOptions {
  /// Stretch (the map's differential) or Rotation (directions, lengths kept).
  VectorTransport mode = VectorTransport::Stretch;
  /// Name used in error messages.
  std::string name = "vectors";
};

struct VectorTransferResult {
  /// #S transported vectors: world vectors at the target points, or components in target_frames
  /// when those were given. Zero for samples without a source.
  std::vector<Eigen::Vector3d> vectors;
  int without_source = 0;  ///< samples whose Location is not `inside` (left zero)
  int folded = 0;          ///< samples carried through a folded grid triangle
};

/// Vectors at target samples (e.g. TargetSamples of transfer/target_samples.h): sample i lies at
/// `target_points[i]` and comes from `sources[i]` (Mapping::inverse of it; a Location with
/// triangle -1, e.g. a boundary point matched by arc length, uses the nearest grid triangle), where
/// the source field's value is `source_vectors[i]`. The vectors are world vectors, or components
/// in `source_frames[i]` when that is not empty; the results are world vectors, or components in
/// `target_frames[i]` when that is not empty.
/// \throws InvalidInputError (naming options.name) when the sizes disagree or a vector is not
///         finite; NumericalError when a sample's grid triangle is degenerate.
VectorTransferResult transfer_vectors(const MapDifferential& differential,
                                      std::span<const SurfacePoint> target_points,
                                      std::span<const Mapping::Location> sources,
                                      std::span<const Eigen::Vector3d> source_vectors,
                                      std::span<const TangentFrame> source_frames = {},
                                      std::span<const TangentFrame> target_frames = {},
                                      const VectorTransferOptions& options = {});

}  // namespace elastic
