// Side-by-side pictures, contact sheets, stacks, colour legends and the bitmap font: sizes from the
// documented layout, pixels copied exactly to where the layout puts them.
#include "elastic/render/compose.h"

#include <gtest/gtest.h>

#include "elastic/core/error.h"

namespace elastic {
namespace {

Image filled(int w, int h, const Eigen::Vector4f& c) {
  return Image(w, h, c);
}

const Eigen::Vector4f kRed(1, 0, 0, 1), kBlue(0, 0, 1, 1), kWhite(1, 1, 1, 1);

TEST(Compose, SideBySideLaysImagesOutInARowWithGaps) {
  ComposeOptions options;
  options.gap = 2;
  const Image sheet = side_by_side({filled(10, 8, kRed), filled(6, 12, kBlue)}, {}, options);
  // gap + 2 cells of the largest size (10 x 12), each followed by a gap.
  ASSERT_EQ(sheet.width, 2 + 2 * (10 + 2));
  ASSERT_EQ(sheet.height, 2 + 12 + 2);
  EXPECT_EQ(sheet.at(0, 0), kWhite);
  EXPECT_EQ(sheet.at(2, 2), kRed);
  EXPECT_EQ(sheet.at(11, 9), kRed);     // last pixel of the 10 x 8 image
  EXPECT_EQ(sheet.at(11, 10), kWhite);  // below it: cell background
  // The 6-wide image is centred in its 10-wide cell starting at x = 14: columns 16..21.
  EXPECT_EQ(sheet.at(15, 2), kWhite);
  EXPECT_EQ(sheet.at(16, 2), kBlue);
  EXPECT_EQ(sheet.at(21, 13), kBlue);
  EXPECT_EQ(sheet.at(22, 13), kWhite);
}

TEST(Compose, ContactSheetFillsRowsAndLeavesTheRestEmpty) {
  ComposeOptions options;
  options.gap = 1;
  std::vector<Image> frames;
  for (int i = 0; i < 5; ++i) frames.push_back(filled(4, 3, Eigen::Vector4f(0.1f * i, 0, 0, 1)));
  const Image sheet = contact_sheet(frames, 2, {}, options);
  ASSERT_EQ(sheet.width, 1 + 2 * (4 + 1));
  ASSERT_EQ(sheet.height, 1 + 3 * (3 + 1));
  for (int i = 0; i < 5; ++i) {
    const int x0 = 1 + (i % 2) * 5, y0 = 1 + (i / 2) * 4;
    EXPECT_EQ(sheet.at(x0, y0), frames[i].at(0, 0)) << "frame " << i;
    EXPECT_EQ(sheet.at(x0 + 3, y0 + 2), frames[i].at(3, 2)) << "frame " << i;
  }
  EXPECT_EQ(sheet.at(6, 9), kWhite);  // the sixth cell is empty
}

TEST(Compose, LabelsGoInABandAboveEachImage) {
  ComposeOptions options;
  options.gap = 0;
  options.text_scale = 1;
  const Image sheet =
      side_by_side({filled(20, 10, kRed), filled(20, 10, kBlue)}, {"1", "88"}, options);
  // A band of 11 font pixels (7 for the glyphs, 2 above and below) sits above the images.
  ASSERT_EQ(sheet.height, 11 + 10);
  EXPECT_EQ(sheet.at(5, 11), kRed);
  int ink_left = 0, ink_right = 0;
  for (int y = 0; y < 11; ++y) {
    for (int x = 0; x < 40; ++x) {
      if (sheet.at(x, y) == options.text_color) (x < 20 ? ink_left : ink_right) += 1;
    }
  }
  // Each label is drawn once, inside its own cell: "1" has 10 ink pixels, "8" has 17.
  EXPECT_EQ(ink_left, 10);
  EXPECT_EQ(ink_right, 34);
  // Rows 0-1 and 9-10 are the padding.
  for (int x = 0; x < 40; ++x) {
    EXPECT_EQ(sheet.at(x, 0), kWhite);
    EXPECT_EQ(sheet.at(x, 10), kWhite);
  }
}

TEST(Compose, TextHasTheDocumentedSizeAndShape) {
  EXPECT_EQ(text_size("", 1), Eigen::Vector2i(0, 7));
  EXPECT_EQ(text_size("12", 1), Eigen::Vector2i(11, 7));
  EXPECT_EQ(text_size("abc", 3), Eigen::Vector2i(51, 21));
  // "-" is one full row of five pixels, the 4th row of the glyph.
  Image image(5, 7, kWhite);
  draw_text(image, 0, 0, "-", 1, Eigen::Vector4f(0, 0, 0, 1));
  for (int y = 0; y < 7; ++y) {
    for (int x = 0; x < 5; ++x) {
      EXPECT_EQ(image.at(x, y).x(), y == 3 ? 0.0f : 1.0f) << x << "," << y;
    }
  }
  // Clipped at the image border without error; lower case drawn as upper case.
  Image small(4, 4, kWhite), upper(20, 9, kWhite), lower(20, 9, kWhite);
  EXPECT_NO_THROW(draw_text(small, -3, -2, "W", 2, Eigen::Vector4f(0, 0, 0, 1)));
  draw_text(upper, 1, 1, "AB", 1, Eigen::Vector4f(0, 0, 0, 1));
  draw_text(lower, 1, 1, "ab", 1, Eigen::Vector4f(0, 0, 0, 1));
  EXPECT_TRUE(upper.pixels == lower.pixels);
  EXPECT_FALSE(upper.pixels == Image(20, 9, kWhite).pixels);
}

TEST(Compose, StackCentresImagesOneAboveTheOther) {
  ComposeOptions options;
  options.gap = 1;
  const Image s = stack({filled(4, 2, kRed), filled(2, 3, kBlue)}, options);
  EXPECT_EQ(s.width, 1 + 4 + 1);
  EXPECT_EQ(s.height, 1 + 2 + 1 + 3 + 1);
  EXPECT_EQ(s.at(1, 1), kRed);
  EXPECT_EQ(s.at(4, 2), kRed);
  EXPECT_EQ(s.at(1, 4), kWhite);  // the narrower image is centred: columns 2..3
  EXPECT_EQ(s.at(2, 4), kBlue);
  EXPECT_EQ(s.at(3, 6), kBlue);
  EXPECT_THROW(stack({}), InvalidInputError);
}

TEST(Compose, LegendBarShowsTheRampBetweenItsTicks) {
  // Scale 1: title at y 2..8, bar at y 11..16, ticks to y 18, numbers at y 20..26, 2 pixels under.
  // The widest number ("4" ... "8") is 5 pixels: the bar runs from x = 2 + 2 = 4 over 392 pixels.
  ColorLegend legend;
  legend.title = "metric";
  legend.low = 4.0;
  legend.high = 8.0;
  legend.ramp = {{0, 1, 0}, {1, 1, 0}, {1, 0, 0}};
  legend.swatches = {{"fold", {1, 0, 1}}};
  ComposeOptions options;
  options.text_scale = 1;
  const Image key = draw_legend(legend, 400, options);
  EXPECT_EQ(key.width, 400);
  EXPECT_EQ(key.height, 29);
  // Column 150 of the bar: its centre is at 146.5 / 392 of the bar, 0.747 of the way from green
  // to yellow (the ramp has two segments over the bar).
  const double t = 146.5 / 392.0 * 2.0;
  EXPECT_NEAR(key.at(150, 14).x(), t, 1e-6);
  EXPECT_FLOAT_EQ(key.at(150, 14).y(), 1.0f);
  EXPECT_FLOAT_EQ(key.at(150, 14).z(), 0.0f);
  // The right end is red but for the half pixel; the left end green.
  EXPECT_NEAR(key.at(394, 14).y(), 2.0 * (1.0 - 390.5 / 392.0), 1e-6);
  EXPECT_NEAR(key.at(5, 14).x(), 1.5 / 392.0 * 2.0, 1e-6);
  // The fold swatch is on the title line, and the numbers are drawn under the bar.
  bool swatch = false, numbers = false;
  for (int y = 0; y < key.height; ++y) {
    for (int x = 0; x < key.width; ++x) {
      swatch |= y < 10 && key.at(x, y) == Eigen::Vector4f(1, 0, 1, 1);
      numbers |= y >= 20 && key.at(x, y).x() < 0.5f;
    }
  }
  EXPECT_TRUE(swatch);
  EXPECT_TRUE(numbers);
  legend.ramp.pop_back();
  legend.ramp.pop_back();
  EXPECT_THROW(draw_legend(legend, 400, options), InvalidInputError);
  legend.ramp = {{0, 1, 0}, {1, 0, 0}};
  legend.high = legend.low;
  EXPECT_THROW(draw_legend(legend, 400, options), InvalidInputError);
}

TEST(Compose, RejectsBadInput) {
  EXPECT_THROW(side_by_side({}), InvalidInputError);
  EXPECT_THROW(side_by_side({filled(2, 2, kRed), Image()}), InvalidInputError);
  EXPECT_THROW(side_by_side({filled(2, 2, kRed)}, {"a", "b"}), InvalidInputError);
  EXPECT_THROW(contact_sheet({filled(2, 2, kRed)}, 0), InvalidInputError);
}

}  // namespace
}  // namespace elastic
