#include "elastic/image/image.h"

#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"

namespace elastic {

Image::Image(int width_, int height_, const Eigen::Vector4f& fill)
    : width(width_), height(height_) {
  if (width_ < 0 || height_ < 0) {
    throw InvalidInputError(
        "image", "negative size " + std::to_string(width_) + " x " + std::to_string(height_));
  }
  pixels.assign(static_cast<size_t>(width_) * static_cast<size_t>(height_), fill);
}

namespace {

/// Index along one axis after wrapping; `i` may be anywhere.
int wrap_index(int i, int n, ImageWrap wrap) {
  if (wrap == ImageWrap::Repeat) {
    const int r = i % n;
    return r < 0 ? r + n : r;
  }
  return std::clamp(i, 0, n - 1);
}

}  // namespace

Eigen::Vector4f sample(const Image& image, const Eigen::Vector2d& uv, ImageWrap wrap) {
  if (image.empty()) {
    return Eigen::Vector4f::Zero();
  }
  // Continuous pixel coordinates whose integer + 0.5 points are pixel centres (x right, y down).
  const double x = uv.x() * image.width - 0.5;
  const double y = (1.0 - uv.y()) * image.height - 0.5;
  if (!std::isfinite(x) || !std::isfinite(y)) {
    return Eigen::Vector4f::Zero();
  }
  // Clamp far-away coordinates before the integer conversion (the result is the same).
  const double xc = std::clamp(x, -4.0 * image.width, 5.0 * image.width);
  const double yc = std::clamp(y, -4.0 * image.height, 5.0 * image.height);
  const double fx = std::floor(xc), fy = std::floor(yc);
  const auto tx = static_cast<float>(xc - fx), ty = static_cast<float>(yc - fy);
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const int xa = wrap_index(x0, image.width, wrap), xb = wrap_index(x0 + 1, image.width, wrap);
  const int ya = wrap_index(y0, image.height, wrap), yb = wrap_index(y0 + 1, image.height, wrap);
  const Eigen::Vector4f top = (1.0f - tx) * image.at(xa, ya) + tx * image.at(xb, ya);
  const Eigen::Vector4f bottom = (1.0f - tx) * image.at(xa, yb) + tx * image.at(xb, yb);
  return (1.0f - ty) * top + ty * bottom;
}

namespace {

/// stb's reason for the last failure (it may have none).
std::string stb_reason() {
  const char* reason = stbi_failure_reason();
  return reason != nullptr && *reason != '\0' ? reason : "unknown reason";
}

/// Checks every Huffman table of a JPEG before stb sees it: a table of more than 256 codes makes
/// stb_image (the Debian 2022 version) write past its 257-entry size table (found by
/// tests/fuzz/image_fuzzer.cpp, three times with three ways around a marker walk). So the check
/// does not follow stb's parsing: in a file that starts like a JPEG (0xFF, fill bytes, SOI), every
/// DHT marker bytes 0xFF 0xC4 anywhere is read as stb would read a DHT segment there (tables of a
/// class byte and 16 counts, missing bytes as zeros, while the segment's length lasts). A valid
/// JPEG has these bytes only at its DHT segments (entropy-coded data stuffs every 0xFF), so it
/// passes; a file with them inside other data (e.g. an ICC profile) is checked there too, and
/// refused only if the bytes after them would be a table that overflows stb. \throws
/// InvalidInputError naming the file.
void check_jpeg_huffman_tables(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const auto next = [&in]() { return in.get(); };  // EOF: -1
  int c = next();
  if (c != 0xFF) return;
  while (c == 0xFF) c = next();
  if (c != 0xD8) return;
  int previous = c;
  for (c = next(); c >= 0; previous = c, c = next()) {
    if (previous != 0xFF || c != 0xC4) continue;
    const std::streampos resume = in.tellg();
    const int high = next(), low = next();
    long remaining = std::max(high, 0) * 256L + std::max(low, 0) - 2;
    while (remaining > 0) {
      next();  // table class and id
      long codes = 0;
      for (int i = 0; i < 16; ++i) codes += std::max(next(), 0);
      if (codes > 256) {
        throw InvalidInputError(path.string(),
                                "not a readable image (corrupt JPEG: a Huffman table of " +
                                    std::to_string(codes) + " codes, at most 256)");
      }
      in.ignore(codes);
      remaining -= 17 + codes;
      if (!in) break;
    }
    in.clear();
    in.seekg(resume);
    c = 0;  // not 0xFF: the scan goes on after this C4
  }
}

/// The bytes of a PNG file without its zero-length IDAT chunks, or nullopt when it has none (or is
/// not a PNG). The PNG format allows empty IDAT chunks, but stb_image (the Debian 2022 version)
/// copies an empty IDAT that comes before any data into its still unallocated buffer,
/// memcpy(NULL, ..., 0), undefined behaviour (found by tests/fuzz/image_fuzzer.cpp). An empty chunk
/// carries nothing, so leaving it out decodes the same image. The walk stops at the first chunk
/// that does not fit in the file; stb refuses such a file with its own reason.
std::optional<std::string> png_without_empty_idat(const std::filesystem::path& path) {
  static constexpr char kSignature[] = "\x89PNG\r\n\x1a\n";
  constexpr size_t kSignatureSize = sizeof(kSignature) - 1;
  std::ifstream in(path, std::ios::binary);
  std::string bytes(kSignatureSize, '\0');
  if (!in.read(bytes.data(), kSignatureSize) || bytes != std::string_view(kSignature)) {
    return std::nullopt;
  }
  // The rest by its size (GCC 12 warns on istreambuf_iterator's inlined null check, a false
  // positive of -Wnull-dereference).
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < static_cast<std::streamoff>(kSignatureSize)) {
    return std::nullopt;
  }
  bytes.resize(static_cast<size_t>(size));
  in.seekg(static_cast<std::streamoff>(kSignatureSize));
  if (!in.read(bytes.data() + kSignatureSize,
               static_cast<std::streamsize>(bytes.size() - kSignatureSize))) {
    return std::nullopt;
  }
  const auto big_endian = [&bytes](size_t at) {
    std::uint32_t value = 0;
    for (size_t i = 0; i < 4; ++i) value = (value << 8) | static_cast<unsigned char>(bytes[at + i]);
    return value;
  };
  std::string kept = bytes.substr(0, kSignatureSize);
  bool dropped = false;
  size_t at = kSignatureSize;
  while (bytes.size() - at >= 12) {  // length, type, data, CRC
    const std::uint32_t length = big_endian(at);
    if (length > bytes.size() - at - 12) break;
    const size_t chunk_size = 12 + size_t{length};
    if (length == 0 && bytes.compare(at + 4, 4, "IDAT") == 0) {
      dropped = true;
    } else {
      kept.append(bytes, at, chunk_size);
    }
    at += chunk_size;
  }
  if (!dropped) return std::nullopt;
  kept.append(bytes, at, std::string::npos);
  if (kept.size() > static_cast<size_t>(std::numeric_limits<int>::max())) {
    throw InvalidInputError(path.string(), "PNG file of more than 2 GiB with empty IDAT chunks");
  }
  return kept;
}

}  // namespace

ImageInfo read_image_info(const std::filesystem::path& path, const ImageReadOptions& options) {
  const std::string name = path.string();
  if (!(options.max_pixels > 0)) {
    throw InvalidInputError(options.limit_name,
                            "must be positive, got " + std::to_string(options.max_pixels));
  }
  if (!std::ifstream(path, std::ios::binary)) {
    throw IoError(name, "cannot open the image");
  }
  check_jpeg_huffman_tables(path);
  ImageInfo info;
  if (!stbi_info(name.c_str(), &info.width, &info.height, &info.channels) || info.width <= 0 ||
      info.height <= 0) {
    throw InvalidInputError(name, "not a readable image (" + stb_reason() + ")");
  }
  const std::int64_t pixels = std::int64_t{info.width} * std::int64_t{info.height};
  if (pixels > options.max_pixels) {
    throw InvalidInputError(name, "image of " + std::to_string(info.width) + " x " +
                                      std::to_string(info.height) + " = " + std::to_string(pixels) +
                                      " pixels is larger than the limit of " +
                                      std::to_string(options.max_pixels) +
                                      " pixels; raise it with " + options.limit_name);
  }
  return info;
}

Image read_image(const std::filesystem::path& path, const ImageReadOptions& options) {
  const std::string name = path.string();
  // The size comes from the header, before stb allocates anything for the pixels.
  read_image_info(path, options);
  int columns = 0, rows = 0, channels = 0;
  std::unique_ptr<stbi_uc, void (*)(void*)> data(nullptr, stbi_image_free);
  if (const std::optional<std::string> png = png_without_empty_idat(path)) {
    data.reset(stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(png->data()),
                                     static_cast<int>(png->size()), &columns, &rows, &channels, 4));
  } else {
    data.reset(stbi_load(name.c_str(), &columns, &rows, &channels, 4));
  }
  if (!data) {
    throw InvalidInputError(name, "not a readable image (" + stb_reason() + ")");
  }
  Image image(columns, rows);
  const stbi_uc* p = data.get();
  for (Eigen::Vector4f& pixel : image.pixels) {
    for (int k = 0; k < 4; ++k) {
      pixel[k] = static_cast<float>(*p++) / 255.0f;
    }
  }
  return image;
}

void write_png(const std::filesystem::path& path, const Image& image) {
  const std::string name = path.string();
  if (image.empty() || image.width <= 0 || image.height <= 0) {
    throw InvalidInputError(name, "cannot write an empty image");
  }
  bool opaque = true;
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    if (!image.pixels[i].allFinite()) {
      throw InvalidInputError(
          name, "pixel " + std::to_string(i % static_cast<size_t>(image.width)) + "," +
                    std::to_string(i / static_cast<size_t>(image.width)) + " is not finite");
    }
    if (image.pixels[i][3] < 1.0f) {
      opaque = false;
    }
  }
  const int channels = opaque ? 3 : 4;
  std::vector<unsigned char> bytes;
  bytes.reserve(image.pixels.size() * static_cast<size_t>(channels));
  for (const Eigen::Vector4f& pixel : image.pixels) {
    for (int k = 0; k < channels; ++k) {
      bytes.push_back(
          static_cast<unsigned char>(std::lround(std::clamp(pixel[k], 0.0f, 1.0f) * 255.0f)));
    }
  }
  // stb encodes through a callback; collect the PNG in memory, then write it atomically.
  std::string png;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                               static_cast<size_t>(size));
  };
  if (!stbi_write_png_to_func(append, &png, image.width, image.height, channels, bytes.data(),
                              image.width * channels) ||
      png.empty()) {
    throw IoError(name, "PNG encoding failed", IoError::Direction::Write);
  }
  write_file_atomically(
      path,
      [&](std::ofstream& out) { out.write(png.data(), static_cast<std::streamsize>(png.size())); },
      true);
}

}  // namespace elastic
