// Side-by-side pictures, contact sheets and the 5 x 7 bitmap font; see compose.h.
#include "elastic/render/compose.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <string>

#include "elastic/core/error.h"

namespace elastic {
namespace {

// The font: each glyph is 7 rows of 5 columns, '#' for ink, drawn for this project.
struct Glyph {
  char c;
  std::array<const char*, 7> rows;
};

// clang-format off
constexpr Glyph kGlyphs[] = {
    {'0', {".###.", "#...#", "#..##", "#.#.#", "##..#", "#...#", ".###."}},
    {'1', {"..#..", ".##..", "..#..", "..#..", "..#..", "..#..", ".###."}},
    {'2', {".###.", "#...#", "....#", "...#.", "..#..", ".#...", "#####"}},
    {'3', {"#####", "...#.", "..#..", "...#.", "....#", "#...#", ".###."}},
    {'4', {"...#.", "..##.", ".#.#.", "#..#.", "#####", "...#.", "...#."}},
    {'5', {"#####", "#....", "####.", "....#", "....#", "#...#", ".###."}},
    {'6', {"..##.", ".#...", "#....", "####.", "#...#", "#...#", ".###."}},
    {'7', {"#####", "....#", "...#.", "..#..", ".#...", ".#...", ".#..."}},
    {'8', {".###.", "#...#", "#...#", ".###.", "#...#", "#...#", ".###."}},
    {'9', {".###.", "#...#", "#...#", ".####", "....#", "...#.", ".##.."}},
    {'A', {".###.", "#...#", "#...#", "#####", "#...#", "#...#", "#...#"}},
    {'B', {"####.", "#...#", "#...#", "####.", "#...#", "#...#", "####."}},
    {'C', {".###.", "#...#", "#....", "#....", "#....", "#...#", ".###."}},
    {'D', {"###..", "#..#.", "#...#", "#...#", "#...#", "#..#.", "###.."}},
    {'E', {"#####", "#....", "#....", "####.", "#....", "#....", "#####"}},
    {'F', {"#####", "#....", "#....", "####.", "#....", "#....", "#...."}},
    {'G', {".###.", "#...#", "#....", "#.###", "#...#", "#...#", ".####"}},
    {'H', {"#...#", "#...#", "#...#", "#####", "#...#", "#...#", "#...#"}},
    {'I', {".###.", "..#..", "..#..", "..#..", "..#..", "..#..", ".###."}},
    {'J', {"..###", "...#.", "...#.", "...#.", "...#.", "#..#.", ".##.."}},
    {'K', {"#...#", "#..#.", "#.#..", "##...", "#.#..", "#..#.", "#...#"}},
    {'L', {"#....", "#....", "#....", "#....", "#....", "#....", "#####"}},
    {'M', {"#...#", "##.##", "#.#.#", "#.#.#", "#...#", "#...#", "#...#"}},
    {'N', {"#...#", "#...#", "##..#", "#.#.#", "#..##", "#...#", "#...#"}},
    {'O', {".###.", "#...#", "#...#", "#...#", "#...#", "#...#", ".###."}},
    {'P', {"####.", "#...#", "#...#", "####.", "#....", "#....", "#...."}},
    {'Q', {".###.", "#...#", "#...#", "#...#", "#.#.#", "#..#.", ".##.#"}},
    {'R', {"####.", "#...#", "#...#", "####.", "#.#..", "#..#.", "#...#"}},
    {'S', {".####", "#....", "#....", ".###.", "....#", "....#", "####."}},
    {'T', {"#####", "..#..", "..#..", "..#..", "..#..", "..#..", "..#.."}},
    {'U', {"#...#", "#...#", "#...#", "#...#", "#...#", "#...#", ".###."}},
    {'V', {"#...#", "#...#", "#...#", "#...#", "#...#", ".#.#.", "..#.."}},
    {'W', {"#...#", "#...#", "#...#", "#.#.#", "#.#.#", "#.#.#", ".#.#."}},
    {'X', {"#...#", "#...#", ".#.#.", "..#..", ".#.#.", "#...#", "#...#"}},
    {'Y', {"#...#", "#...#", ".#.#.", "..#..", "..#..", "..#..", "..#.."}},
    {'Z', {"#####", "....#", "...#.", "..#..", ".#...", "#....", "#####"}},
    {' ', {".....", ".....", ".....", ".....", ".....", ".....", "....."}},
    {'-', {".....", ".....", ".....", "#####", ".....", ".....", "....."}},
    {'.', {".....", ".....", ".....", ".....", ".....", ".##..", ".##.."}},
    {',', {".....", ".....", ".....", ".....", ".##..", "..#..", ".#..."}},
    {':', {".....", ".##..", ".##..", ".....", ".##..", ".##..", "....."}},
    {'/', {".....", "....#", "...#.", "..#..", ".#...", "#....", "....."}},
    {'%', {"##...", "##..#", "...#.", "..#..", ".#...", "#..##", "...##"}},
    {'=', {".....", ".....", "#####", ".....", "#####", ".....", "....."}},
    {'(', {"...#.", "..#..", ".#...", ".#...", ".#...", "..#..", "...#."}},
    {')', {".#...", "..#..", "...#.", "...#.", "...#.", "..#..", ".#..."}},
    {'_', {".....", ".....", ".....", ".....", ".....", ".....", "#####"}},
    {'+', {".....", "..#..", "..#..", "#####", "..#..", "..#..", "....."}},
    {'?', {".###.", "#...#", "....#", "...#.", "..#..", ".....", "..#.."}},
};
// clang-format on

const Glyph& glyph(char c) {
  const char upper = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  for (const Glyph& g : kGlyphs) {
    if (g.c == upper) {
      return g;
    }
  }
  return kGlyphs[std::size(kGlyphs) - 1];  // '?'
}

void blend(Eigen::Vector4f& pixel, const Eigen::Vector4f& color) {
  const float a = color.w();
  pixel.head<3>() = a * color.head<3>() + (1.0f - a) * pixel.head<3>();
  pixel.w() = a + (1.0f - a) * pixel.w();
}

Image compose(const std::vector<Image>& frames, int columns, const std::vector<std::string>& labels,
              const ComposeOptions& options, const std::string& name) {
  if (frames.empty()) {
    throw InvalidInputError(name, "no images to compose");
  }
  if (columns < 1) {
    throw InvalidInputError(name, "columns must be at least 1");
  }
  if (options.gap < 0 || options.text_scale < 0) {
    throw InvalidInputError(name, "gap and text scale must not be negative");
  }
  if (!labels.empty() && labels.size() != frames.size()) {
    throw InvalidInputError(name, std::to_string(labels.size()) + " labels for " +
                                      std::to_string(frames.size()) + " images");
  }
  int cell_w = 0, cell_h = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].empty()) {
      throw InvalidInputError(name, "image " + std::to_string(i) + " is empty");
    }
    cell_w = std::max(cell_w, frames[i].width);
    cell_h = std::max(cell_h, frames[i].height);
  }
  const int scale = options.text_scale > 0 ? options.text_scale : std::max(1, cell_w / 160);
  // A label band holds one line of text with 2 font pixels of padding above and below.
  const int band = labels.empty() ? 0 : 11 * scale;
  const int count = static_cast<int>(frames.size());
  const int used_columns = std::min(columns, count);
  const int rows = (count + columns - 1) / columns;
  const int gap = options.gap;
  Image sheet(gap + used_columns * (cell_w + gap), gap + rows * (band + cell_h + gap),
              options.background);
  for (int i = 0; i < count; ++i) {
    const int x0 = gap + (i % columns) * (cell_w + gap);
    const int y0 = gap + (i / columns) * (band + cell_h + gap);
    if (!labels.empty()) {
      const Eigen::Vector2i size = text_size(labels[static_cast<size_t>(i)], scale);
      draw_text(sheet, x0 + (cell_w - size.x()) / 2, y0 + 2 * scale, labels[static_cast<size_t>(i)],
                scale, options.text_color);
    }
    const Image& frame = frames[static_cast<size_t>(i)];
    const int fx = x0 + (cell_w - frame.width) / 2, fy = y0 + band;
    for (int y = 0; y < frame.height; ++y) {
      for (int x = 0; x < frame.width; ++x) {
        sheet.at(fx + x, fy + y) = frame.at(x, y);
      }
    }
  }
  return sheet;
}

}  // namespace

Eigen::Vector2i text_size(std::string_view text, int scale) {
  const int n = static_cast<int>(text.size());
  return {n == 0 ? 0 : (6 * n - 1) * scale, 7 * scale};
}

void draw_text(Image& image, int x, int y, std::string_view text, int scale,
               const Eigen::Vector4f& color) {
  if (scale < 1) {
    throw InvalidInputError("draw_text", "scale must be at least 1");
  }
  for (size_t i = 0; i < text.size(); ++i) {
    const Glyph& g = glyph(text[i]);
    const int gx = x + static_cast<int>(i) * 6 * scale;
    for (int row = 0; row < 7; ++row) {
      for (int col = 0; col < 5; ++col) {
        if (g.rows[static_cast<size_t>(row)][col] != '#') {
          continue;
        }
        for (int dy = 0; dy < scale; ++dy) {
          for (int dx = 0; dx < scale; ++dx) {
            const int px = gx + col * scale + dx, py = y + row * scale + dy;
            if (px >= 0 && py >= 0 && px < image.width && py < image.height) {
              blend(image.at(px, py), color);
            }
          }
        }
      }
    }
  }
}

Image side_by_side(const std::vector<Image>& images, const std::vector<std::string>& labels,
                   const ComposeOptions& options) {
  return compose(images, std::max<int>(1, static_cast<int>(images.size())), labels, options,
                 "side_by_side");
}

Image contact_sheet(const std::vector<Image>& frames, int columns,
                    const std::vector<std::string>& labels, const ComposeOptions& options) {
  return compose(frames, columns, labels, options, "contact_sheet");
}

}  // namespace elastic
