#include "elastic/regions/image_source.h"

#include <cmath>
#include <numbers>

#include "elastic/core/error.h"
#include "elastic/image/image.h"

namespace elastic {

ImagePlane make_image_plane(const std::filesystem::path& image, const ImagePlaneOptions& options,
                            const ImageReadOptions& read_options) {
  const std::string name = image.string();
  if (!(options.width > 0.0) || !std::isfinite(options.width)) {
    throw InvalidInputError(name, "image width must be finite and positive");
  }
  if (options.resolution < 2 || options.resolution > 4096) {
    throw InvalidInputError(name, "plane resolution must be between 2 and 4096");
  }
  if (!(options.ellipse_margin >= 0.0 && options.ellipse_margin < 0.5)) {
    throw InvalidInputError(name, "ellipse margin must be in [0, 0.5)");
  }
  // Only the header is read: an image beyond read_options.max_pixels is refused here, before any
  // work, rather than when its pixels are first needed.
  const ImageInfo info = read_image_info(image, read_options);
  const int columns = info.width;
  const int rows = info.height;

  ImagePlane plane;
  plane.columns = columns;
  plane.rows = rows;
  plane.width = options.width;
  plane.height = options.width * rows / columns;
  // Quads of about equal size: `resolution` along the longer side.
  const double longer = std::max(plane.width, plane.height);
  const int nx =
      std::max(1, static_cast<int>(std::lround(options.resolution * plane.width / longer)));
  const int ny =
      std::max(1, static_cast<int>(std::lround(options.resolution * plane.height / longer)));
  PolygonMesh& mesh = plane.mesh;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const double u = static_cast<double>(i) / nx, v = static_cast<double>(j) / ny;
      mesh.positions.emplace_back((u - 0.5) * plane.width, (v - 0.5) * plane.height, 0.0);
      mesh.texcoords.emplace_back(u, v);
    }
  }
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i;
      const int corners[4] = {a, a + 1, a + nx + 2, a + nx + 1};  // counter-clockwise seen from +z
      mesh.add_face(corners);
      mesh.corner_texcoords.insert(mesh.corner_texcoords.end(), corners, corners + 4);
    }
  }
  Material material;
  material.name = "image";
  material.diffuse = Eigen::Vector3d::Ones();
  material.diffuse_texture = std::filesystem::absolute(image);
  mesh.materials.push_back(material);
  mesh.face_materials.assign(mesh.num_faces(), 0);

  plane.region.text =
      options.shape == ImageRegionShape::Rectangle ? "image rectangle" : "image ellipse";
  if (options.shape == ImageRegionShape::Rectangle) {
    plane.region.kind = RegionSpec::Kind::Boundary;
  } else {
    // The inscribed ellipse is a circle of radius 1/2 around (1/2, 1/2) in texture space.
    plane.region.kind = RegionSpec::Kind::UvPolygon;
    const int n = 256;
    const double r = 0.5 * (1.0 - options.ellipse_margin);
    for (int k = 0; k < n; ++k) {
      const double a = 2.0 * std::numbers::pi * k / n;
      plane.region.uv_polygon.emplace_back(0.5 + r * std::cos(a), 0.5 + r * std::sin(a));
    }
  }
  return plane;
}

}  // namespace elastic
