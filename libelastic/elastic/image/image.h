#pragma once
/// \file
/// `Image`: a plain RGBA raster as image files hold it, with PNG/JPEG/... reading (stb_image),
/// atomic PNG writing (stb_image_write) and bilinear lookup by texture coordinates.
///
/// Conventions (the same as OBJ texture coordinates):
/// - Pixels are stored row by row from the **top** row (as files store them); `at(x, y)` is column
///   x, row y from the top.
/// - A texture coordinate (u, v) in [0,1]^2 has v = 0 at the **bottom** of the image: pixel centres
///   are at u = (x + 0.5) / width, v = 1 - (y + 0.5) / height.
/// - Channel values are in [0, 1], exactly as stored (8-bit files map k to k / 255); no colour
///   management: sRGB files stay sRGB-encoded, and blending is done on the encoded values.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace elastic {

struct Image {
  int width = 0;
  int height = 0;
  /// width * height RGBA pixels, top row first.
  std::vector<Eigen::Vector4f> pixels;

  Image() = default;
  /// A width x height image filled with `fill`.
  Image(int width, int height, const Eigen::Vector4f& fill = Eigen::Vector4f(0, 0, 0, 1));

  bool empty() const { return pixels.empty(); }
  Eigen::Vector4f& at(int x, int y) {
    return pixels[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)];
  }
  const Eigen::Vector4f& at(int x, int y) const {
    return pixels[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)];
  }
};

/// How `sample()` treats texture coordinates outside [0,1].
enum class ImageWrap {
  Clamp,  ///< use the nearest edge pixel
  Repeat  ///< tile the image (OBJ's default for textures)
};

/// Bilinear lookup at texture coordinates (u, v) (v up, see the file comment).
Eigen::Vector4f sample(const Image& image, const Eigen::Vector2d& uv,
                       ImageWrap wrap = ImageWrap::Clamp);

/// Default of ImageReadOptions::max_pixels: 2^26 = 67,108,864 pixels ("64 megapixels"), so that
/// 8192 x 8192 passes. Decoded, such an image takes 256 MB as 8-bit RGBA and 1 GB as `Image`.
inline constexpr std::int64_t kDefaultMaxImagePixels = std::int64_t{1} << 26;

struct ImageReadOptions {
  /// Most pixels (width x height) an image may have, checked from the file's header before
  /// anything is decoded (a PNG of a few hundred KB can hold 400 million pixels). > 0.
  std::int64_t max_pixels = kDefaultMaxImagePixels;
  /// What the refusal names as the way to raise the limit (a tool puts its flag here).
  std::string limit_name = "ImageReadOptions::max_pixels";
};

/// What an image file's header says.
struct ImageInfo {
  int width = 0;
  int height = 0;
  int channels = 0;  ///< as stored: 1 grey, 2 grey-alpha, 3 RGB, 4 RGBA
};

/// Reads only the header of an image file and checks its size against `options.max_pixels`.
/// \throws IoError when the file cannot be opened; InvalidInputError when it is not a readable
///         image (naming the file and stb's reason) or has more pixels than the limit (giving the
///         size, the limit and `options.limit_name`).
ImageInfo read_image_info(const std::filesystem::path& path, const ImageReadOptions& options = {});

/// Reads an image file (PNG, JPEG, BMP, TGA, ...: whatever stb_image reads); grey and grey-alpha
/// become RGB(A), missing alpha is 1. The header is checked (read_image_info) before decoding.
/// \throws IoError when the file cannot be opened; InvalidInputError when it is not a readable
///         image (naming the file and stb's reason) or has more pixels than `options.max_pixels`.
Image read_image(const std::filesystem::path& path, const ImageReadOptions& options = {});

/// Writes a PNG (8-bit RGBA, or RGB when every alpha is 1) atomically: an existing file is replaced
/// only when the whole new file has been written. Values are clamped to [0,1] and rounded.
/// \throws IoError when the file cannot be written; InvalidInputError for an empty image or a
///         non-finite pixel (naming the path and the pixel).
void write_png(const std::filesystem::path& path, const Image& image);

}  // namespace elastic
