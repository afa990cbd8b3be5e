// libFuzzer target for the image reader as the tool uses it (image/image.h): read_image_info
// (the header and the pixel limit), then read_image (stb_image's PNG, JPEG, BMP, TGA, ...
// decoders, compiled into this fuzzer so that they are instrumented too). Each input must either
// read or throw elastic::Error; an image that reads has the size its header gave and finite
// pixels in [0, 1]. The pixel limit is lowered so that no input may decode more than 2^20 pixels.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "elastic/core/error.h"
#include "elastic/image/image.h"
#include "fuzz_scratch.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = elastic::fuzz::write_scratch_file(data, size, ".img");
  const elastic::ImageReadOptions options{.max_pixels = std::int64_t{1} << 20,
                                          .limit_name = "--fuzz-limit"};
  try {
    const elastic::ImageInfo info = elastic::read_image_info(path, options);
    const elastic::Image image = elastic::read_image(path, options);
    if (image.width != info.width || image.height != info.height) std::abort();
    if (image.pixels.size() != static_cast<size_t>(image.width) * image.height) std::abort();
    for (const Eigen::Vector4f& p : image.pixels) {
      if (!(p.minCoeff() >= 0.0f && p.maxCoeff() <= 1.0f)) std::abort();
    }
  } catch (const elastic::Error&) {
    // A refusal with a message: the expected outcome for most inputs.
  }
  return 0;
}
