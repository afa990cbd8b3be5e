#pragma once
/// \file
/// The project's own emblem: a procedural picture the default demo pastes from a plane onto a
/// curved surface, so the demo needs no image file.
///
/// The design, in a square of side 1 with y down: a cream disk of radius 0.40 inside a ring
/// (0.40 .. 0.48) whose hue runs once around the colour wheel (hue = angle / 360, the angle
/// measured counter-clockwise on screen from the right: red at the right, cyan at the left, at
/// saturation 0.8 and value 0.92), and a bold navy
/// letter "E" whose middle arm is a red zigzag spring ("elastic"). The ring's hue and the
/// asymmetric letter make rotations, reflections and shears visible in a paste. Outside the ring
/// the background is transparent (or white).
///
/// Anti-aliasing: each pixel averages s x s point samples on a regular sub-grid (premultiplied
/// alpha), so edges get intermediate coverage. No randomness: the same size and options give the
/// same pixels on every run and platform with IEEE doubles.

#include <Eigen/Core>

#include "elastic/image/image.h"

namespace elastic {

struct EmblemOptions {
  /// Transparent outside the ring (alpha 0); false paints it white (alpha 1).
  bool transparent_background = true;
  /// Point samples per pixel along each axis (s x s in all), 1..16.
  int supersampling = 4;
  /// Colour of the letter's bars (RGB in [0,1]).
  Eigen::Vector3f letter_color{0.11f, 0.17f, 0.38f};
  /// Colour of the spring (the letter's middle arm).
  Eigen::Vector3f spring_color{0.86f, 0.20f, 0.14f};
};

/// The emblem as a size x size RGBA image (image/image.h conventions).
/// \throws InvalidInputError ("emblem") for a size outside 8..8192 or supersampling outside 1..16.
Image make_emblem(int size, const EmblemOptions& options = {});

}  // namespace elastic
