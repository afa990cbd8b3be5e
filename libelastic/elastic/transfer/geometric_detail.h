#pragma once
/// \file
/// Cut-and-paste of geometry: the source's detail relative to its smooth base surface, expressed
/// in local frames of the base, re-applied on the target through the map.
///
/// Choice of base (the design decision): the base is the smooth surface the mapping was computed
/// on, i.e. the limit surface of the source control mesh, and the detail is a separate polygon mesh
/// lying over it (a scan, a sculpted copy, a finely displaced copy of the source). Each detail
/// vertex x gets the base point b = the closest point on the base limit surface (the magnet of
/// §4.4), and its offset is x - b expressed in the base frame (t1, t2, n) at b. Because b is a
/// point of the source surface, the Mapping carries it to the target (q = forward(b)) and the
/// offset is re-applied there through the map's differential (transfer/tangent_frames.h):
///
///     y = q + T(b -> q) (x - b),
///
/// T sending the source normal to the target limit normal and tangential components through the
/// map (stretched with it, or only rotated: an option). For a closest-point base the offset is
/// along the base normal (x - b is normal to the surface at b), so the detail's height over the
/// base is kept exactly and its footprint follows the map; tangential offsets occur only where b
/// lies on the base's boundary.
///
/// Why not a membrane base built from the detail itself (a Laplacian or biharmonic fill of the
/// detail region with its boundary fixed): its points are not points of a mapped surface, so
/// carrying them to the target would need a second map (membrane -> source) whose distortion adds
/// to the paste's. Mapping the smooth base keeps the elastic map free of the detail's bumps (a
/// bumpy region has more area than its footprint, and the elastic map would spread the bump out).
/// Where only a detailed mesh exists, its smoothed copy (any fairing with the boundary kept) is the
/// base to map; the detail then rides on it through this file.
///
/// Limits: the detail must lie within the base's reach (closer than its medial axis: offsets
/// smaller than the radius of curvature), or the closest point jumps between sheets; detail
/// vertices whose base point maps outside the target region are dropped with their faces.

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "elastic/mapping/mapping.h"
#include "elastic/mesh/polygon_mesh.h"
#include "elastic/projection/closest_point.h"
#include "elastic/transfer/tangent_frames.h"

namespace elastic {

struct DetailOptions {
  /// Name used in error messages (usually the detail mesh's file).
  std::string name = "detail";
};

/// A detail mesh expressed over its base surface.
struct DetailField {
  PolygonMesh mesh;                       ///< the detail mesh as given (connectivity, attributes)
  std::vector<SurfacePoint> base_points;  ///< #V closest point of each vertex on the base
  std::vector<Eigen::Vector3d> base_positions;  ///< #V their limit positions
  /// #V offsets x - b in the base frame at b: components (t1, t2, n) of surface_frame(base, b).
  std::vector<Eigen::Vector3d> local_offsets;
  int on_base_boundary = 0;  ///< vertices whose base point is on the base's boundary curve
  double max_height = 0.0;   ///< largest |offset|
};

/// Expresses `detail` over the projector's surface (the mapping's source surface).
/// \throws InvalidInputError (naming options.name) for a mesh without vertices or with a
///         non-finite position; NumericalError where the base has no tangent frame.
DetailField extract_detail(const SurfaceProjector& base, const PolygonMesh& detail,
                           const DetailOptions& options = {});

struct PasteDetailOptions {
  /// How tangential offsets follow the map: Stretch (with J, default) or Rotation (lengths kept).
  /// Normal offsets (heights) are kept in both.
  VectorTransport tangential = VectorTransport::Stretch;
  /// Multiplies every offset (0 flattens the detail onto the target, 1 pastes it as it is).
  double scale = 1.0;
  /// Name used in error messages.
  std::string name = "detail";
};

struct PasteDetailResult {
  /// The detail's faces whose corners all landed inside the target region, with the pasted
  /// positions (vertices keep their indices; unused ones sit at their base point's image or, when
  /// outside, at the origin). Texture coordinates, materials, vertex and face colours are kept;
  /// the detail's normals are dropped (they belong to the source's orientation).
  PolygonMesh mesh;
  std::vector<SurfacePoint> target_points;  ///< #V images q of the base points (unset: outside)
  std::vector<char> inside;                 ///< #V 1 when the base point mapped inside the region
  int outside = 0;                          ///< vertices whose base point maps outside
  int dropped_faces = 0;                    ///< faces dropped because a corner is outside
};

/// Pastes `field` onto the target through `mapping` (from the field's base surface) and
/// `differential` (the same map's triangles; its source surface must be the field's base).
/// \throws InvalidInputError (naming options.name) when the scale is not finite.
PasteDetailResult paste_detail(const DetailField& field, const Mapping& mapping,
                               const MapDifferential& differential,
                               const PasteDetailOptions& options = {});

/// The detail applied to target samples (e.g. the refined target region of
/// transfer/target_samples.h) instead of carried as its own mesh: sample i at target point
/// `target_points[i]` (position `target_positions[i]`) whose source is `sources[i]` (the inverse
/// map's Location, on the base) moves to
///
///     y_i = x_i + scale * T(p_i -> q_i) o(p_i),
///
/// where o(p) is the detail's offset interpolated at the source point p: the detail faces are laid
/// on the base through their vertices' base points (the "footprint", fan-triangulated), p's
/// position is located in it (nearest footprint triangle, by a uniform grid over the triangles),
/// and the corners' world offsets x - b are blended with p's barycentric coordinates there. For a
/// detail that is a height field over the base this is linear interpolation of its heights.
/// Samples whose source lies off the footprint (farther than `footprint_tolerance` times the mean
/// footprint edge) keep their position; samples flagged in `pinned` (e.g.
/// TargetSamples::on_boundary, to stay watertight with the surface around) too.
struct DetailSamplesResult {
  std::vector<Eigen::Vector3d> positions;  ///< #S displaced positions
  std::vector<char> covered;               ///< #S 1 where the detail was applied
  int covered_count = 0;                   ///< samples the detail moved
  int without_source = 0;                  ///< samples whose Location is not inside
  double max_displacement = 0.0;           ///< largest |y - x|
};

struct DetailSamplesOptions {
  /// Tangential offsets: Stretch or Rotation, as in PasteDetailOptions.
  VectorTransport tangential = VectorTransport::Stretch;
  /// Multiplies every offset.
  double scale = 1.0;
  /// A source point farther from the footprint than this times the mean footprint edge length is
  /// off the detail.
  double footprint_tolerance = 0.5;
  /// Name used in error messages.
  std::string name = "detail";
};

/// \throws InvalidInputError (naming options.name) when the sizes disagree (`pinned` may be
///         empty) or the scale is not finite.
DetailSamplesResult paste_detail_on_samples(const DetailField& field,
                                            const MapDifferential& differential,
                                            std::span<const SurfacePoint> target_points,
                                            std::span<const Eigen::Vector3d> target_positions,
                                            std::span<const Mapping::Location> sources,
                                            std::span<const char> pinned = {},
                                            const DetailSamplesOptions& options = {});

}  // namespace elastic
