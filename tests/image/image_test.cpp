#include "elastic/image/image.h"

#include <gtest/gtest.h>

#include <fstream>

#include "elastic/core/error.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

/// A 3 x 2 image whose channels encode their own pixel position (values on the 8-bit grid).
Image position_image() {
  Image image(3, 2);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 3; ++x) {
      image.at(x, y) = Eigen::Vector4f(static_cast<float>(x) * 51.0f / 255.0f,
                                       static_cast<float>(y) * 102.0f / 255.0f, 0.2f, 1.0f);
    }
  }
  return image;
}

TEST(Image, PngRoundTripIsExactOnTheByteGrid) {
  const fs::path dir = test::scratch_dir("image_round_trip");
  Image image = position_image();
  write_png(dir / "a.png", image);
  const Image back = read_image(dir / "a.png");
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.height, 2);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    EXPECT_LT((back.pixels[i] - image.pixels[i]).cwiseAbs().maxCoeff(), 0.5f / 255.0f) << i;
  }
  // Translucent pixels keep their alpha (RGBA PNG).
  image.at(1, 1)[3] = 128.0f / 255.0f;
  write_png(dir / "b.png", image);
  EXPECT_NEAR(read_image(dir / "b.png").at(1, 1)[3], 128.0f / 255.0f, 1e-6f);
}

TEST(Image, SampleHitsPixelCentresAndInterpolatesLinearly) {
  const Image image = position_image();
  // Pixel (x, y) centre is at u = (x + 0.5) / 3, v = 1 - (y + 0.5) / 2 (v up, rows from the top).
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 3; ++x) {
      const Eigen::Vector2d uv((x + 0.5) / 3.0, 1.0 - (y + 0.5) / 2.0);
      EXPECT_LT((sample(image, uv) - image.at(x, y)).cwiseAbs().maxCoeff(), 1e-6f);
    }
  }
  // Halfway between the centres of columns 0 and 1 in row 0: the mean of the two (red is linear).
  const Eigen::Vector4f mid = sample(image, {1.0 / 3.0, 0.75});
  EXPECT_NEAR(mid[0], 0.5f * (image.at(0, 0)[0] + image.at(1, 0)[0]), 1e-6f);
  // Clamp keeps edge values beyond [0,1]; repeat wraps around to the other side.
  EXPECT_LT((sample(image, {-3.0, 0.75}) - image.at(0, 0)).cwiseAbs().maxCoeff(), 1e-6f);
  EXPECT_LT((sample(image, {1.0 + 0.5 / 3.0, 0.75}, ImageWrap::Repeat) - image.at(0, 0))
                .cwiseAbs()
                .maxCoeff(),
            1e-6f);
}

TEST(Image, BadFilesAndImagesAreRefusedByName) {
  const fs::path dir = test::scratch_dir("image_errors");
  EXPECT_THROW(read_image(dir / "missing.png"), IoError);
  std::ofstream(dir / "junk.png") << "not a png";
  try {
    read_image(dir / "junk.png");
    FAIL() << "junk accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("junk.png"), std::string::npos) << e.what();
  }
  EXPECT_THROW(write_png(dir / "empty.png", Image()), InvalidInputError);
  // A non-finite pixel is refused and an existing good file is left untouched.
  write_png(dir / "good.png", position_image());
  Image bad = position_image();
  bad.at(2, 1)[0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(write_png(dir / "good.png", bad), InvalidInputError);
  EXPECT_EQ(read_image(dir / "good.png").width, 3);
}

}  // namespace
}  // namespace elastic
