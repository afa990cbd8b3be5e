#include "elastic/regions/image_source.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>

#include "elastic/core/error.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/region_spec.h"
#include "elastic/surface/limit_surface.h"
#include "support.h"

namespace elastic {
namespace {

// A binary PPM image of the given size (stb reads PNM as well as PNG).
std::filesystem::path write_ppm(const std::filesystem::path& dir, int columns, int rows) {
  const std::filesystem::path path = dir / "image.ppm";
  std::ofstream out(path, std::ios::binary);
  out << "P6\n" << columns << ' ' << rows << "\n255\n";
  for (int k = 0; k < columns * rows * 3; ++k) out.put(static_cast<char>(k % 251));
  return path;
}

TEST(ImagePlane, KeepsAspectAndMapsCornersToTextureCorners) {
  const auto dir = test::scratch_dir("image_plane_aspect");
  const ImagePlane plane =
      make_image_plane(write_ppm(dir, 40, 10), {.width = 3.0, .resolution = 8});
  EXPECT_EQ(plane.columns, 40);
  EXPECT_EQ(plane.rows, 10);
  EXPECT_DOUBLE_EQ(plane.height, 0.75);
  ASSERT_TRUE(plane.mesh.has_texcoords());
  // Every vertex's texture coordinate is its position scaled into [0,1]^2.
  for (int f = 0; f < plane.mesh.num_faces(); ++f) {
    for (int k = 0; k < plane.mesh.face_size(f); ++k) {
      const int corner = plane.mesh.face_offsets[f] + k;
      const Eigen::Vector3d& p = plane.mesh.positions[plane.mesh.face_vertices[corner]];
      const Eigen::Vector2d& uv = plane.mesh.texcoords[plane.mesh.corner_texcoords[corner]];
      EXPECT_NEAR(uv.x(), p.x() / 3.0 + 0.5, 1e-15);
      EXPECT_NEAR(uv.y(), p.y() / 0.75 + 0.5, 1e-15);
    }
  }
  EXPECT_EQ(plane.mesh.materials.at(0).diffuse_texture,
            std::filesystem::absolute(dir / "image.ppm"));
}

TEST(ImagePlane, RectangleAndEllipseRegionsHaveTheRightAreas) {
  const auto dir = test::scratch_dir("image_plane_regions");
  const auto image = write_ppm(dir, 64, 32);
  for (const ImageRegionShape shape : {ImageRegionShape::Rectangle, ImageRegionShape::Ellipse}) {
    const ImagePlane plane =
        make_image_plane(image, {.width = 2.0, .resolution = 16, .shape = shape});
    const LimitSurface surface(plane.mesh);
    const SurfaceProjector projector(surface);
    const Region region = make_region(projector, plane.region);
    const double rectangle = plane.width * plane.height;
    if (shape == ImageRegionShape::Rectangle) {
      EXPECT_NEAR(region.area(), rectangle, 1e-9 * rectangle);
    } else {
      // pi/4 of the rectangle, less the 256-gon's deficit (sin(2pi/n) n/(2pi) ~ 1 - 1e-4) and the
      // 1e-3 margin (area factor (1 - 1e-3)^2).
      const double expected = std::numbers::pi / 4.0 * rectangle * std::pow(1.0 - 1e-3, 2);
      EXPECT_NEAR(region.area(), expected, 3e-4 * expected);
    }
  }
}

TEST(ImagePlane, BadInputsAreNamed) {
  const auto dir = test::scratch_dir("image_plane_bad");
  EXPECT_THROW(make_image_plane(dir / "missing.png"), IoError);
  { std::ofstream(dir / "not_an_image.png") << "hello"; }
  try {
    make_image_plane(dir / "not_an_image.png");
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("not_an_image.png"), std::string::npos);
  }
  const auto image = write_ppm(dir, 8, 8);
  EXPECT_THROW(make_image_plane(image, {.width = 0.0}), InvalidInputError);
  EXPECT_THROW(make_image_plane(image, {.width = std::nan("")}), InvalidInputError);
  EXPECT_THROW(make_image_plane(image, {.resolution = 1}), InvalidInputError);
}

TEST(ImagePlane, SharedPngReadsItsSize) {
  ELASTIC_REQUIRE_SHARED_MESH(png, "pmp_logo_512.png");
  const ImagePlane plane = make_image_plane(png);
  EXPECT_EQ(plane.columns, 512);
  EXPECT_EQ(plane.rows, 512);
  EXPECT_DOUBLE_EQ(plane.height, plane.width);
}

}  // namespace
}  // namespace elastic
