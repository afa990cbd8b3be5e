#pragma once
/// \file
/// Height transfer (Fig. 8 of the paper: "instead of color, we associate a height with each
/// point"): a height per target sample, read from the source (a height image looked up with the
/// source texture coordinates, or a per-vertex scalar), becomes a displacement along the TARGET
/// limit normal,
///
///     x' = x + scale * w(x) * h * n(x),
///
/// where x and n(x) are the sample's limit position and unit limit normal on the target (the
/// normal side of the target surface, limit_surface.h), and w is an optional falloff weight that
/// rises from 0 on the region's boundary to 1 at distance `falloff_width` inside it, so the
/// displaced region meets the surrounding surface without a crack or a cliff. w is the C1
/// smoothstep 3 t^2 - 2 t^3 of t = d / falloff_width, d being the distance to the boundary (see
/// boundary_distance()).
///
/// Heights are in the units the caller chooses; `scale` turns them into the target's length units
/// (e.g. image values in [0, 1] times a relief depth in model units).
///
/// On a painted target (painted_surface.h) the heights come per refined region vertex from its
/// source point: sample_heights_from_image() and sample_heights_from_colors(); and
/// displace_painted_surface() moves the region of the painted mesh (the displaced mesh of
/// `elastic paste --height`, transfer/paste.h).

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "elastic/image/image.h"
#include "elastic/surface/limit_surface.h"
#include "elastic/transfer/color_source.h"
#include "elastic/transfer/painted_surface.h"
#include "elastic/transfer/target_samples.h"

namespace elastic {

/// Which image channel carries the height.
enum class HeightChannel {
  Luminance,  ///< Rec. 709 luma 0.2126 R + 0.7152 G + 0.0722 B of the stored values
  Red,
  Green,
  Blue,
  Alpha
};

/// Rec. 709 luma of an RGBA colour's stored values, 0.2126 R + 0.7152 G + 0.0722 B (alpha
/// ignored): the height a luminance reads.
inline double luminance(const Eigen::Vector4f& rgba) {
  return 0.2126 * static_cast<double>(rgba[0]) + 0.7152 * static_cast<double>(rgba[1]) +
         0.0722 * static_cast<double>(rgba[2]);
}

struct HeightImageOptions {
  /// The channel read as height.
  HeightChannel channel = HeightChannel::Luminance;
  /// The channel value that means height 0: h = value - zero_level (0.5 for images whose mid grey
  /// is the surface, with darker values carving in).
  double zero_level = 0.0;
  /// Lookups outside [0,1]^2: clamp to the edge, or tile the image.
  ImageWrap wrap = ImageWrap::Clamp;
};

/// One height per texture coordinate: the chosen channel of the bilinear sample (image/image.h,
/// v up) minus zero_level. \throws InvalidInputError when the image is empty or a coordinate is
/// not finite (naming "height image").
std::vector<double> heights_from_image(const Image& image, std::span<const Eigen::Vector2d> uv,
                                       const HeightImageOptions& options = {});

/// One height per vertex of a refined target region: `image` (heights_from_image with `options`)
/// looked up at the texture coordinate of the vertex's source point on `source` (the surface the
/// samples' sources lie on); NaN for vertices without a source.
/// \throws InvalidInputError naming the source when it has no texture coordinates; as
///         heights_from_image.
std::vector<double> sample_heights_from_image(const TargetSamples& samples,
                                              const LimitSurface& source, const Image& image,
                                              const HeightImageOptions& options = {});

/// One height per vertex of a refined target region: the luminance() of the source colour at the
/// vertex's source point minus `zero_level`; NaN for vertices without a source.
std::vector<double> sample_heights_from_colors(const TargetSamples& samples,
                                               const ColorSource& colors, double zero_level = 0.0);

struct DisplacementOptions {
  /// Multiplies every height (height units -> target length units).
  double scale = 1.0;
  /// > 0: displacement ramps up from 0 on the boundary to full at this distance (target length
  /// units) inside the region. 0: no falloff.
  double falloff_width = 0.0;
  /// Boundary vertices never move, whatever their height, so the region stays watertight with the
  /// surface around it (with falloff they have w = 0 anyway).
  bool pin_boundary = true;
  /// Name used in error messages.
  std::string name = "displacement";
};

struct DisplacementResult {
  std::vector<Eigen::Vector3d> positions;  ///< #V displaced positions
  std::vector<double> weights;             ///< #V falloff weight w in [0, 1] actually applied
  /// #V distance to the boundary (0 on it); only computed within falloff_width (beyond it:
  /// +infinity), empty without falloff.
  std::vector<double> boundary_distance;
  int boundary_vertices = 0;      ///< vertices on a boundary edge of the triangle mesh
  int skipped = 0;                ///< vertices with a non-finite height (NaN: no source), not moved
  double max_displacement = 0.0;  ///< largest |x' - x|
};

/// Displaces a triangle mesh (#V positions, #V unit normals, #V heights, #T counter-clockwise
/// triangles; e.g. TargetSamples of transfer/target_samples.h) along its normals. Boundary
/// vertices are those on edges used by one triangle. A NaN height leaves its vertex in place
/// (counted in `skipped`), for samples without a source.
/// \throws InvalidInputError (naming options.name) when the sizes disagree, a triangle names a
///         missing vertex, a position or normal is not finite, a height is infinite, or an option
///         is out of range (scale not finite, falloff_width negative).
DisplacementResult displace_along_normals(std::span<const Eigen::Vector3d> positions,
                                          std::span<const Eigen::Vector3d> normals,
                                          std::span<const double> heights,
                                          std::span<const Eigen::Vector3i> triangles,
                                          const DisplacementOptions& options = {});

/// A painted target with its region displaced.
struct DisplacedPaintedSurface {
  /// #V positions of the painted mesh (PaintedSurface::positions): the region's vertices displaced,
  /// the rest as painted.
  std::vector<Eigen::Vector3d> positions;
  DisplacementResult displacement;  ///< the region's displacement (per refined region vertex)
};

/// Displaces the refined region of `painted` (its TargetSamples: positions, limit normals,
/// triangles) along the target normals by `heights` (one per region vertex, e.g.
/// sample_heights_from_image) with displace_along_normals, and puts the moved vertices into the
/// painted mesh's positions. Write it with make_target_mesh(painted, positions) (the target's own
/// texture coordinates and materials on the displaced positions).
/// \throws InvalidInputError as displace_along_normals.
DisplacedPaintedSurface displace_painted_surface(const PaintedSurface& painted,
                                                 std::span<const double> heights,
                                                 const DisplacementOptions& options = {});

/// Distance from every vertex to the boundary of a triangle mesh (the union of its boundary edges):
/// Euclidean distance to the nearest boundary edge, where "nearest" is found by propagating the
/// closest boundary edge from vertex to vertex in order of distance (Dijkstra on the mesh's edges,
/// a discrete Voronoi propagation). It is exact where each boundary edge's region of nearest
/// points is connected on the mesh, which holds for a disk whose width is well above its edge
/// length; in a chordal sense on curved meshes (3D distance, not geodesic: the two agree to
/// relative O((d * curvature)^2)). Vertices farther than `max_distance` stay at +infinity.
std::vector<double> boundary_distance(std::span<const Eigen::Vector3d> positions,
                                      std::span<const Eigen::Vector3i> triangles,
                                      double max_distance);

}  // namespace elastic
