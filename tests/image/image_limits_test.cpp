// Images are bounded by their total pixel count, checked from the header before decoding: a valid
// PNG of 20000 x 20000 zeros (a few MB on disk, 400 MB as grey bytes, 6.4 GB as `Image`) is refused
// at once, without allocating its pixels; the limit can be raised; the message gives the size, the
// limit and how to raise it.

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <chrono>
#include <string>

#include "elastic/core/error.h"
#include "elastic/image/image.h"
#include "png_bomb.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

/// Peak resident memory of this process so far, in MB.
double peak_rss_mb() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KB on Linux
}

TEST(ImageLimits, HandMadePngDecodesToItsSizeAndZeros) {
  // The generator the bomb test relies on, checked by stb's decoder on a small instance (odd sizes,
  // so that the run of zeros does not end on a multiple of 258).
  const fs::path dir = test::scratch_dir("image_limits_small");
  test::write_zero_grey_png(dir / "zeros.png", 301, 77);
  const ImageInfo info = read_image_info(dir / "zeros.png");
  EXPECT_EQ(info.width, 301);
  EXPECT_EQ(info.height, 77);
  EXPECT_EQ(info.channels, 1);
  const Image image = read_image(dir / "zeros.png");
  ASSERT_EQ(image.width, 301);
  ASSERT_EQ(image.height, 77);
  for (const Eigen::Vector4f& p : image.pixels) {
    ASSERT_EQ(p, Eigen::Vector4f(0, 0, 0, 1));
  }
}

TEST(ImageLimits, PngBombIsRefusedFromItsHeaderBeforeDecoding) {
  const fs::path dir = test::scratch_dir("image_limits_bomb");
  const fs::path bomb = dir / "bomb.png";
  test::write_zero_grey_png(bomb, 20000, 20000);
  ASSERT_LT(fs::file_size(bomb), 5u << 20);  // a few MB on disk
  const double rss_before = peak_rss_mb();
  const auto start = std::chrono::steady_clock::now();
  try {
    read_image(bomb);
    FAIL() << "a 400-megapixel image was decoded";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(e.input(), bomb.string());
    EXPECT_NE(e.problem().find("20000 x 20000 = 400000000 pixels"), std::string::npos)
        << e.problem();
    EXPECT_NE(e.problem().find("limit of 67108864 pixels"), std::string::npos) << e.problem();
    EXPECT_NE(e.problem().find("ImageReadOptions::max_pixels"), std::string::npos) << e.problem();
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Decoding alone would allocate 400 MB of grey bytes (and 1.6 GB as RGBA): the peak grows by
  // less than 100 MB only if nothing was decoded. Reading the header takes microseconds.
  EXPECT_LT(peak_rss_mb() - rss_before, 100.0);
  EXPECT_LT(seconds, 1.0 * test::kTimeScale);
  // The same from the header-only entry point, with the name a tool gives its flag.
  try {
    read_image_info(bomb,
                    {.max_pixels = kDefaultMaxImagePixels, .limit_name = "--max-image-pixels"});
    FAIL() << "accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(e.problem().find("raise it with --max-image-pixels"), std::string::npos)
        << e.problem();
  }
  // With the limit raised, the header passes (the pixels are not decoded here).
  const ImageInfo info = read_image_info(bomb, {.max_pixels = 400'000'000});
  EXPECT_EQ(info.width, 20000);
}

TEST(ImageLimits, LimitIsInclusiveAndMustBePositive) {
  const fs::path dir = test::scratch_dir("image_limits_edge");
  test::write_zero_grey_png(dir / "z.png", 40, 25);  // 1000 pixels
  EXPECT_EQ(read_image(dir / "z.png", {.max_pixels = 1000}).width, 40);
  EXPECT_THROW(read_image(dir / "z.png", {.max_pixels = 999}), InvalidInputError);
  EXPECT_THROW(read_image(dir / "z.png", {.max_pixels = 0}), InvalidInputError);
  // 8192 x 8192 is exactly the default limit.
  EXPECT_EQ(kDefaultMaxImagePixels, std::int64_t{8192} * 8192);
}

// JPEGs found by tests/fuzz/image_fuzzer.cpp: a Huffman table of more than 256 codes (4080, and
// one cut short by the end of the file) made stb_image write past its 257-entry table. Refused by
// name before stb sees them; a good JPEG of the same corpus still reads.
TEST(ImageLimits, JpegHuffmanTablesOfMoreThan256CodesAreRefused) {
  const fs::path corpus = fs::path(ELASTIC_MESHES_DIR).parent_path() / "tests/fuzz/corpus/image";
  for (const char* name :
       {"jpeg_huffman_table_of_4080_codes.jpg", "jpeg_huffman_table_cut_short.jpg",
        "jpeg_huffman_table_after_fill_bytes.jpg"}) {
    try {
      read_image(corpus / name);
      FAIL() << name << " was read";
    } catch (const InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("Huffman table"), std::string::npos) << e.what();
    }
  }
  const Image good = read_image(corpus / "rgb_5x3.jpg");
  EXPECT_EQ(good.width, 5);
  EXPECT_EQ(good.height, 3);
}

TEST(ImageLimits, PngWithAnEmptyIdatBeforeItsDataDecodes) {
  // A valid 3 x 2 grey PNG whose first IDAT chunk is empty (the format allows it): stb_image copies
  // that chunk into its unallocated buffer, memcpy(NULL, ..., 0), undefined behaviour that the
  // image fuzzer found (fuzz.image.regression runs this file under UBSan). read_image leaves
  // empty IDATs out, so the file decodes to its pixels, grey 10 x + y at column x, row y.
  const fs::path file = fs::path(ELASTIC_MESHES_DIR).parent_path() /
                        "tests/fuzz/corpus/image/png_empty_idat_before_data.png";
  const Image image = read_image(file);
  ASSERT_EQ(image.width, 3);
  ASSERT_EQ(image.height, 2);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 3; ++x) {
      const float grey = static_cast<float>(10 * x + y) / 255.0f;
      EXPECT_EQ(image.at(x, y), Eigen::Vector4f(grey, grey, grey, 1.0f)) << x << "," << y;
    }
  }
}

}  // namespace
}  // namespace elastic
