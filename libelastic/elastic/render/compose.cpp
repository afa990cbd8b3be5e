// Side-by-side pictures, contact sheets and the 5 x 7 bitmap font; see compose.h.
#include "elastic/render/compose.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
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

namespace {
void fill_rect(Image& image, int x0, int y0, int w, int h, const Eigen::Vector4f& color) {
  for (int y = std::max(0, y0); y < std::min(image.height, y0 + h); ++y) {
    for (int x = std::max(0, x0); x < std::min(image.width, x0 + w); ++x) {
      image.at(x, y) = color;
    }
  }
}

std::string tick_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value == 0.0 ? 0.0 : value);  // no "-0"
  return text;
}
}  // namespace

Image draw_legend(const ColorLegend& legend, int width, const ComposeOptions& options) {
  const std::string name = "legend";
  if (legend.ramp.size() < 2) {
    throw InvalidInputError(name, "a colour ramp needs at least 2 colours");
  }
  if (legend.ticks < 2) {
    throw InvalidInputError(name, "at least 2 ticks");
  }
  if (!std::isfinite(legend.low) || !std::isfinite(legend.high) || !(legend.high > legend.low)) {
    throw InvalidInputError(name, "the range must be finite and increasing");
  }
  if (options.text_scale < 0) {
    throw InvalidInputError(name, "text scale must not be negative");
  }
  const int s = options.text_scale > 0 ? options.text_scale : std::max(1, width / 320);
  const int pad = 2 * s;
  std::vector<std::string> labels;
  int widest = 0;
  for (int k = 0; k < legend.ticks; ++k) {
    const double t = static_cast<double>(k) / (legend.ticks - 1);
    labels.push_back(tick_text(legend.low + t * (legend.high - legend.low)));
    widest = std::max(widest, text_size(labels.back(), s).x());
  }
  // The bar leaves room for half of the end labels on either side.
  const int margin = pad + widest / 2;
  const int bar_x = margin, bar_w = width - 2 * margin;
  if (bar_w < 2 * legend.ticks) {
    throw InvalidInputError(name, "width " + std::to_string(width) + " is too small");
  }
  const int title_y = pad, bar_y = title_y + 7 * s + pad, bar_h = 6 * s;
  const int tick_y = bar_y + bar_h, tick_h = 2 * s, text_y = tick_y + tick_h + s;
  Image image(width, text_y + 7 * s + pad, options.background);

  draw_text(image, bar_x, title_y, legend.title, s, options.text_color);
  // Swatches right-aligned on the title line: a square, a space, the name.
  int x = width - margin;
  for (auto it = legend.swatches.rbegin(); it != legend.swatches.rend(); ++it) {
    const int text_w = text_size(it->first, s).x();
    x -= text_w;
    draw_text(image, x, title_y, it->first, s, options.text_color);
    x -= 7 * s + s;
    fill_rect(image, x, title_y, 7 * s, 7 * s, options.text_color);
    fill_rect(image, x + std::max(1, s / 2), title_y + std::max(1, s / 2),
              7 * s - 2 * std::max(1, s / 2), 7 * s - 2 * std::max(1, s / 2),
              {it->second.x(), it->second.y(), it->second.z(), 1.0f});
    x -= 3 * s;
  }
  // The bar: pixel column i shows the ramp at its centre's value.
  const int segments = static_cast<int>(legend.ramp.size()) - 1;
  for (int i = 0; i < bar_w; ++i) {
    const double t = (i + 0.5) / bar_w * segments;
    const int k = std::min(segments - 1, static_cast<int>(t));
    const float f = static_cast<float>(t - k);
    const Eigen::Vector3f c = (1.0f - f) * legend.ramp[static_cast<size_t>(k)] +
                              f * legend.ramp[static_cast<size_t>(k) + 1];
    fill_rect(image, bar_x + i, bar_y, 1, bar_h, {c.x(), c.y(), c.z(), 1.0f});
  }
  // A thin frame around the bar, tick marks and their values centred under them.
  const int line = std::max(1, s / 3);
  fill_rect(image, bar_x, bar_y, bar_w, line, options.text_color);
  fill_rect(image, bar_x, bar_y + bar_h - line, bar_w, line, options.text_color);
  for (int k = 0; k < legend.ticks; ++k) {
    const int tx =
        bar_x +
        static_cast<int>(std::lround(static_cast<double>(k) * (bar_w - line) / (legend.ticks - 1)));
    fill_rect(image, tx, bar_y, line, bar_h + tick_h, options.text_color);
    const int text_w = text_size(labels[static_cast<size_t>(k)], s).x();
    draw_text(image, tx - text_w / 2, text_y, labels[static_cast<size_t>(k)], s,
              options.text_color);
  }
  return image;
}

Image stack(const std::vector<Image>& images, const ComposeOptions& options) {
  if (images.empty()) {
    throw InvalidInputError("stack", "no images to stack");
  }
  if (options.gap < 0) {
    throw InvalidInputError("stack", "gap must not be negative");
  }
  int width = 0, height = options.gap;
  for (size_t i = 0; i < images.size(); ++i) {
    if (images[i].empty()) {
      throw InvalidInputError("stack", "image " + std::to_string(i) + " is empty");
    }
    width = std::max(width, images[i].width);
    height += images[i].height + options.gap;
  }
  Image sheet(width + 2 * options.gap, height, options.background);
  int y0 = options.gap;
  for (const Image& image : images) {
    const int x0 = options.gap + (width - image.width) / 2;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        sheet.at(x0 + x, y0 + y) = image.at(x, y);
      }
    }
    y0 += image.height + options.gap;
  }
  return sheet;
}

}  // namespace elastic
