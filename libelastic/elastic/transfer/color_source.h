#pragma once
/// \file
/// Colour on the source surface: what a colour transfer reads at a source SurfacePoint.
///
/// Three kinds of source:
///  - **Texture**: the control mesh's texture coordinates (regions/texture_coordinates.h), spread
///    over the limit surface, index an image (the control mesh's material `map_Kd`, or an image
///    given explicitly). An image on a plane (regions/image_source.h) is this case: the plane's
///    texture coordinates index the image. Lookup is bilinear (image/image.h), repeating outside
///    [0,1] as OBJ textures do.
///  - **Vertex colours** of the control mesh (PolygonMesh::vertex_colors).
///  - **Vertex scalars**: one value per control vertex, shown as a grey ramp from `lo` (black) to
///    `hi` (white).
///
/// Per-vertex values are interpolated at a SurfacePoint over its control face's corners in the
/// ptex domain (surface_point.h), the same interpolation as texture coordinates use
/// (control_vertex_weights): barycentric over a Loop triangle ((1-u-v) c0 + u c1 + v c2); bilinear
/// over a Catmull-Clark quad (corners 0..3 at (0,0), (1,0), (1,1), (0,1)); bilinear over sub-face i
/// of an n-gon, whose corners carry c_i, (c_i + c_{i+1})/2, the mean of all corners, and
/// (c_{i-1} + c_i)/2. It is continuous across control edges and linear precision holds: a field
/// linear in the control vertices' positions is reproduced exactly wherever the limit surface is
/// the same affine image of the ptex domain as the control face (a planar grid of parallelograms).
/// The interpolation is of the control values, not of the limit surface: near an extraordinary
/// vertex the colour sits where the control net puts it, not where the limit surface moves.

#include <Eigen/Core>
#include <filesystem>
#include <utility>
#include <vector>

#include "elastic/image/image.h"
#include "elastic/surface/limit_surface.h"

namespace elastic {

/// Weights of control vertices whose combination gives a per-vertex quantity at p (see the file
/// comment). Weights sum to 1; at most 2 n + 1 entries for an n-gon, vertices may repeat.
std::vector<std::pair<int, double>> control_vertex_weights(const LimitSurface& surface,
                                                           const SurfacePoint& p);

/// A per-vertex scalar interpolated at p. `values` has one entry per control vertex.
/// \throws InvalidInputError naming the surface when values has the wrong size.
double interpolate_vertex_scalar(const LimitSurface& surface, const std::vector<double>& values,
                                 const SurfacePoint& p);

enum class ColorSourceKind { Texture, VertexColors, VertexScalars };

/// A colour field on a source limit surface. Holds a reference to the surface (which must outlive
/// it) and owns its image or values. Queries are const and thread-safe.
class ColorSource {
 public:
  ColorSource() = default;

  ColorSourceKind kind() const { return kind_; }
  const LimitSurface& surface() const { return *surface_; }
  /// The texture (Texture kind; empty otherwise) and the file it came from (may be empty).
  const Image& image() const { return image_; }
  const std::filesystem::path& image_path() const { return image_path_; }

  /// RGBA colour at a source point (alpha from the texture; 1 for vertex colours and scalars).
  Eigen::Vector4f color(const SurfacePoint& p) const;
  /// Texture coordinate at a source point (Texture kind only; (0,0) otherwise).
  Eigen::Vector2d texcoord(const SurfacePoint& p) const;

  /// The control mesh's texture coordinates index `image` (or, when `image` is empty, the image of
  /// the control mesh's first material with a `map_Kd`, read with read_image).
  /// \throws InvalidInputError naming the surface when it has no texture coordinates or no
  ///         material texture; IoError / InvalidInputError from read_image (with `read_options`).
  static ColorSource texture(const LimitSurface& surface, const std::filesystem::path& image = {},
                             const ImageReadOptions& read_options = {});
  /// The same with an image already in memory (`path` only names it).
  static ColorSource texture(const LimitSurface& surface, Image image,
                             std::filesystem::path path = {});
  /// The control mesh's per-vertex colours. \throws InvalidInputError when it has none.
  static ColorSource vertex_colors(const LimitSurface& surface);
  /// Per-vertex scalars as a grey ramp from lo (black) to hi (white), clamped.
  /// \throws InvalidInputError when values does not have one entry per control vertex, a value
  ///         is not finite, or hi <= lo.
  static ColorSource vertex_scalars(const LimitSurface& surface, std::vector<double> values,
                                    double lo, double hi);

 private:
  const LimitSurface* surface_ = nullptr;
  ColorSourceKind kind_ = ColorSourceKind::Texture;
  Image image_;
  std::filesystem::path image_path_;
  std::vector<double> values_;
  double lo_ = 0.0;
  double hi_ = 1.0;
};

}  // namespace elastic
