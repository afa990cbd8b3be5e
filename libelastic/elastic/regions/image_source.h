#pragma once
/// \file
/// An image as the source of a mapping: a flat rectangle carrying the image, as the paper's user
/// paints a planar texture onto a curved surface (§1: "the user can draw on a more simplified
/// region, even a plane").
///
/// The plane is z = 0, centred at the origin, `width` wide along x and width * rows / columns tall
/// along y (the image's aspect is kept), its normal +z. Texture coordinates run from (0,0) at the
/// image's bottom-left corner to (1,1) at its top-right (OBJ/OpenGL convention: v up; row 0 of the
/// file is the top, v = 1). Its material's diffuse texture is the image, so everything downstream
/// (sampling keeps source UVs) knows the colour of every particle.
///
/// The region is either the whole image rectangle (the plane's boundary) or the ellipse inscribed
/// in it, drawn in texture space (a 256-gon, shrunk by `ellipse_margin` so that it does not touch
/// the boundary).

#include <filesystem>

#include "elastic/image/image.h"
#include "elastic/mesh/polygon_mesh.h"
#include "elastic/regions/region_spec.h"

namespace elastic {

enum class ImageRegionShape { Rectangle, Ellipse };

struct ImagePlaneOptions {
  /// Physical width of the image on the plane; the height follows the aspect ratio. > 0.
  double width = 2.0;
  /// Quads along the longer side of the plane (the other side gets a proportional count). 2..4096.
  int resolution = 32;
  /// Which region of the plane is the source: the rectangle or its inscribed ellipse.
  ImageRegionShape shape = ImageRegionShape::Rectangle;
  /// Relative shrink of the inscribed ellipse (fraction of the half-axes) so it stays off the
  /// boundary.
  double ellipse_margin = 1e-3;
};

struct ImagePlane {
  PolygonMesh mesh;    ///< the plane, with texture coordinates and the image as material
  RegionSpec region;   ///< `boundary` (rectangle) or a uv polygon (ellipse)
  int columns = 0;     ///< image width in pixels
  int rows = 0;        ///< image height in pixels
  double width = 0.0;  ///< physical size of the plane
  double height = 0.0;
};

/// Reads the image's size (only its header, checked against `read_options`, before any work; pass
/// the same read options to whatever later reads its pixels) and builds the plane carrying it.
/// \throws IoError when the file cannot be read; InvalidInputError when it is not an image stb can
///         decode (PNG, JPEG, BMP, TGA, ...), has more pixels than `read_options.max_pixels`, or
///         the options are out of range.
ImagePlane make_image_plane(const std::filesystem::path& image,
                            const ImagePlaneOptions& options = {},
                            const ImageReadOptions& read_options = {});

}  // namespace elastic
