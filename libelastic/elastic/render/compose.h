#pragma once
/// \file
/// Putting pictures together: side-by-side comparisons (naive vs relaxed, Figs. 6 and 9 of the
/// paper), contact sheets of relaxation frames, colour legends for heatmaps, and short labels in a
/// built-in 5 x 7 pixel bitmap font (digits, letters A-Z, lower case drawn as upper case, space and
/// `- . , : / % = ( ) _ + ?`; any other character is drawn as `?`).
///
/// All positions are in pixels of image/image.h's convention (x right, y down from the top row).
/// Compositing copies pixels exactly (no resampling); an image smaller than its cell is centred in
/// it horizontally and aligned to its top.

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "elastic/image/image.h"

namespace elastic {

struct ComposeOptions {
  /// Pixels between cells and around the whole sheet, >= 0.
  int gap = 4;
  /// Colour of the gaps, the label bands and cells without an image (RGBA).
  Eigen::Vector4f background{1.0f, 1.0f, 1.0f, 1.0f};
  /// Colour of the labels.
  Eigen::Vector4f text_color{0.1f, 0.1f, 0.1f, 1.0f};
  /// Font scale (each font pixel becomes scale x scale image pixels), >= 0; 0 picks
  /// max(1, cell width / 160), i.e. 7-pixel-high text per 160 pixels of cell width.
  int text_scale = 0;
};

/// Images in one row, each under its label (labels empty: no label band; otherwise one label per
/// image). Images may differ in size: each cell is as tall as the tallest image.
/// \throws InvalidInputError ("side_by_side") for no images, an empty image, or a label count
///         that is neither 0 nor the number of images.
Image side_by_side(const std::vector<Image>& images, const std::vector<std::string>& labels = {},
                   const ComposeOptions& options = {});

/// Frames in rows of `columns` cells (the last row may be partly empty), each cell the size of the
/// largest frame, each under its label (labels as for side_by_side).
/// \throws InvalidInputError ("contact_sheet") for no frames, an empty frame, columns < 1, or a
///         label count that is neither 0 nor the number of frames.
Image contact_sheet(const std::vector<Image>& frames, int columns,
                    const std::vector<std::string>& labels = {},
                    const ComposeOptions& options = {});

/// A colour legend (the key of a heatmap): a title, a horizontal bar of a colour ramp from `low` at
/// its left end to `high` at its right end, tick marks with their values under it, and swatches
/// for colours outside the ramp (e.g. "fold").
struct ColorLegend {
  std::string title;  ///< e.g. "symmetric Dirichlet"
  double low = 0.0;   ///< value at the bar's left end
  double high = 1.0;  ///< value at the bar's right end, > low
  /// Colours at evenly spaced values from low to high (at least 2), interpolated linearly between.
  std::vector<Eigen::Vector3f> ramp;
  /// Named colours drawn as squares on the title line, right-aligned.
  std::vector<std::pair<std::string, Eigen::Vector3f>> swatches;
  /// Number of labelled ticks, evenly spaced from low to high, >= 2.
  int ticks = 5;
};

/// The legend as an image `width` pixels wide on options.background; text at options.text_scale
/// (0: max(1, width / 320)). Tick values are printed with up to 4 significant digits (%.4g).
/// \throws InvalidInputError ("legend") for fewer than 2 ramp colours or ticks, a range that is
///         not finite or not increasing, or a width too small for the text.
Image draw_legend(const ColorLegend& legend, int width, const ComposeOptions& options = {});

/// Images one above the other, each centred horizontally, options.gap pixels between and around
/// them, on options.background (e.g. a side-by-side picture above its legend).
/// \throws InvalidInputError ("stack") for no images or an empty image.
Image stack(const std::vector<Image>& images, const ComposeOptions& options = {});

/// Width and height in pixels of `text` in the bitmap font at `scale`: 6 * scale per character
/// (5 columns and 1 of spacing) minus the trailing spacing, and 7 * scale high.
Eigen::Vector2i text_size(std::string_view text, int scale);

/// Draws `text` with its top-left corner at (x, y); pixels outside the image are skipped. Each
/// covered pixel is set to `color` blended over it by its alpha.
void draw_text(Image& image, int x, int y, std::string_view text, int scale,
               const Eigen::Vector4f& color);

}  // namespace elastic
