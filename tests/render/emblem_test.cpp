// The built-in emblem: size, determinism, the documented design at chosen points, anti-aliasing.
#include "elastic/image/emblem.h"

#include <gtest/gtest.h>

#include <set>
#include <tuple>

#include "elastic/core/error.h"

namespace elastic {
namespace {

/// The pixel containing the point (x, y) of the unit square (y down).
const Eigen::Vector4f& at(const Image& image, double x, double y) {
  return image.at(static_cast<int>(x * image.width), static_cast<int>(y * image.height));
}

TEST(Emblem, HasTheRequestedSizeAndIsDeterministic) {
  const Image a = make_emblem(64);
  EXPECT_EQ(a.width, 64);
  EXPECT_EQ(a.height, 64);
  const Image b = make_emblem(64);
  EXPECT_TRUE(a.pixels == b.pixels);
  EXPECT_EQ(make_emblem(33).width, 33);
}

TEST(Emblem, ShowsTheDocumentedDesign) {
  const Image image = make_emblem(128);
  std::set<std::tuple<int, int, int>> colours;
  for (const Eigen::Vector4f& p : image.pixels) {
    colours.emplace(static_cast<int>(p.x() * 255), static_cast<int>(p.y() * 255),
                    static_cast<int>(p.z() * 255));
  }
  EXPECT_GT(colours.size(), 50u);  // not constant: ring hues, letter, spring, anti-aliased edges
  // Corners lie outside the ring (radius 0.48 < distance 0.707): transparent.
  EXPECT_EQ(at(image, 0.01, 0.01).w(), 0.0f);
  EXPECT_EQ(at(image, 0.99, 0.99).w(), 0.0f);
  // Ring at radius 0.44: hue 0 (red) at the right, hue 0.5 (cyan) at the left.
  const Eigen::Vector4f right = at(image, 0.94, 0.5), left = at(image, 0.06, 0.5);
  EXPECT_EQ(right.w(), 1.0f);
  EXPECT_GT(right.x(), 0.8f);
  EXPECT_LT(right.y(), 0.4f);
  EXPECT_LT(left.x(), 0.4f);
  EXPECT_GT(left.y(), 0.8f);
  EXPECT_GT(left.z(), 0.8f);
  // The letter's stem (x 0.33..0.43) is navy, the disk right of the top bar's end is cream.
  const Eigen::Vector4f stem = at(image, 0.38, 0.45);
  EXPECT_LT(stem.x(), 0.2f);
  EXPECT_GT(stem.z(), 0.3f);
  const Eigen::Vector4f disk = at(image, 0.75, 0.3);
  EXPECT_GT(disk.x(), 0.9f);
  EXPECT_GT(disk.y(), 0.9f);
  // Anti-aliased: the ring's outer edge has partly covered pixels.
  int partial = 0;
  for (const Eigen::Vector4f& p : image.pixels) partial += p.w() > 0.0f && p.w() < 1.0f;
  EXPECT_GT(partial, 100);
}

TEST(Emblem, WhiteBackgroundOption) {
  EmblemOptions options;
  options.transparent_background = false;
  const Image image = make_emblem(32, options);
  EXPECT_EQ(image.at(0, 0), Eigen::Vector4f(1, 1, 1, 1));
  for (const Eigen::Vector4f& p : image.pixels) EXPECT_EQ(p.w(), 1.0f);
}

TEST(Emblem, RejectsBadSizes) {
  EXPECT_THROW(make_emblem(4), InvalidInputError);
  EmblemOptions options;
  options.supersampling = 0;
  EXPECT_THROW(make_emblem(16, options), InvalidInputError);
}

}  // namespace
}  // namespace elastic
