#pragma once
/// \file
/// Putting pictures together: side-by-side comparisons (naive vs relaxed, Figs. 6 and 9 of the
/// paper), contact sheets of relaxation frames, and short labels in a built-in 5 x 7 pixel bitmap
/// font (digits, letters A-Z, lower case drawn as upper case, space and `- . , : / % = ( ) _ + ?`;
/// any other character is drawn as `?`).
///
/// All positions are in pixels of image/image.h's convention (x right, y down from the top row).
/// Compositing copies pixels exactly (no resampling); an image smaller than its cell is centred in
/// it horizontally and aligned to its top.

#include <Eigen/Core>
#include <string>
#include <string_view>
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

/// Width and height in pixels of `text` in the bitmap font at `scale`: 6 * scale per character
/// (5 columns and 1 of spacing) minus the trailing spacing, and 7 * scale high.
Eigen::Vector2i text_size(std::string_view text, int scale);

/// Draws `text` with its top-left corner at (x, y); pixels outside the image are skipped. Each
/// covered pixel is set to `color` blended over it by its alpha.
void draw_text(Image& image, int x, int y, std::string_view text, int scale,
               const Eigen::Vector4f& color);

}  // namespace elastic
