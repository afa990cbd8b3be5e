// The built-in emblem: layered shapes evaluated at sub-pixel points; see emblem.h for the design.
#include "elastic/image/emblem.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "elastic/core/error.h"

namespace elastic {
namespace {

constexpr double kDiskRadius = 0.40;
constexpr double kRingOuter = 0.48;

/// Hue in [0,1) at full value and the given saturation to RGB (the usual six-sector HSV formula).
Eigen::Vector3f hue_to_rgb(double hue, double saturation) {
  const double h = 6.0 * (hue - std::floor(hue));
  const int sector = std::min(5, static_cast<int>(h));
  const double f = h - sector;
  const double p = 1.0 - saturation, q = 1.0 - saturation * f, t = 1.0 - saturation * (1.0 - f);
  std::array<double, 3> rgb{};
  switch (sector) {
    case 0:
      rgb = {1.0, t, p};
      break;
    case 1:
      rgb = {q, 1.0, p};
      break;
    case 2:
      rgb = {p, 1.0, t};
      break;
    case 3:
      rgb = {p, q, 1.0};
      break;
    case 4:
      rgb = {t, p, 1.0};
      break;
    default:
      rgb = {1.0, p, q};
      break;
  }
  return Eigen::Vector3d(rgb[0], rgb[1], rgb[2]).cast<float>() * 0.92f;
}

/// Distance from p to the segment ab.
double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

bool in_rect(const Eigen::Vector2d& p, double x0, double y0, double x1, double y1) {
  return p.x() >= x0 && p.x() <= x1 && p.y() >= y0 && p.y() <= y1;
}

/// Straight-alpha RGBA of the emblem at point p of the unit square (y down).
Eigen::Vector4f emblem_at(const Eigen::Vector2d& p, const EmblemOptions& options) {
  const Eigen::Vector2d d = p - Eigen::Vector2d(0.5, 0.5);
  const double r = d.norm();
  const Eigen::Vector4f background = options.transparent_background
                                         ? Eigen::Vector4f(0.0f, 0.0f, 0.0f, 0.0f)
                                         : Eigen::Vector4f(1.0f, 1.0f, 1.0f, 1.0f);
  if (r > kRingOuter) {
    return background;
  }
  if (r > kDiskRadius) {
    // Screen y is down, so -d.y() is up: hue grows counter-clockwise as seen.
    const double angle = std::atan2(-d.y(), d.x());
    const Eigen::Vector3f c = hue_to_rgb(angle / (2.0 * std::numbers::pi), 0.8);
    return {c.x(), c.y(), c.z(), 1.0f};
  }
  // The letter: a vertical stem and top and bottom bars.
  if (in_rect(p, 0.33, 0.27, 0.43, 0.73) || in_rect(p, 0.33, 0.27, 0.67, 0.36) ||
      in_rect(p, 0.33, 0.64, 0.67, 0.73)) {
    const Eigen::Vector3f& c = options.letter_color;
    return {c.x(), c.y(), c.z(), 1.0f};
  }
  // The middle arm: a zigzag spring of 8 segments (two periods) from the stem to x = 0.64.
  constexpr int kSegments = 8;
  constexpr double kX0 = 0.42, kX1 = 0.64, kAmplitude = 0.055, kHalfWidth = 0.022;
  const auto zig = [&](int i) {
    const double y = i % 4 == 1 ? -kAmplitude : (i % 4 == 3 ? kAmplitude : 0.0);
    return Eigen::Vector2d(kX0 + (kX1 - kX0) * i / kSegments, 0.5 + y);
  };
  for (int i = 0; i < kSegments; ++i) {
    if (segment_distance(p, zig(i), zig(i + 1)) <= kHalfWidth) {
      const Eigen::Vector3f& c = options.spring_color;
      return {c.x(), c.y(), c.z(), 1.0f};
    }
  }
  return {0.98f, 0.96f, 0.89f, 1.0f};  // the cream disk
}

}  // namespace

Image make_emblem(int size, const EmblemOptions& options) {
  if (size < 8 || size > 8192) {
    throw InvalidInputError("emblem", "size " + std::to_string(size) + " is outside 8..8192");
  }
  const int s = options.supersampling;
  if (s < 1 || s > 16) {
    throw InvalidInputError("emblem", "supersampling " + std::to_string(s) + " is outside 1..16");
  }
  Image image(size, size);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      Eigen::Vector4f sum = Eigen::Vector4f::Zero();  // premultiplied
      for (int j = 0; j < s; ++j) {
        for (int i = 0; i < s; ++i) {
          // Sub-sample centres of an s x s grid inside the pixel.
          const Eigen::Vector2d p((x + (i + 0.5) / s) / size, (y + (j + 0.5) / s) / size);
          const Eigen::Vector4f c = emblem_at(p, options);
          sum += Eigen::Vector4f(c.x() * c.w(), c.y() * c.w(), c.z() * c.w(), c.w());
        }
      }
      Eigen::Vector4f pixel = sum / static_cast<float>(s * s);
      if (pixel.w() > 0.0f) {
        pixel.head<3>() /= pixel.w();
      }
      image.at(x, y) = pixel;
    }
  }
  return image;
}

}  // namespace elastic
