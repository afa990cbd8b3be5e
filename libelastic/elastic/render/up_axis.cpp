// Up-axis guess from the footprint a model stands on; see up_axis.h.
#include "elastic/render/up_axis.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "elastic/core/error.h"

namespace elastic {
namespace {

/// Area of the convex hull of 2D points (Andrew's monotone chain; collinear points dropped).
double hull_area(std::vector<Eigen::Vector2d> p) {
  if (p.size() < 3) return 0.0;
  std::sort(p.begin(), p.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> hull(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {  // lower chain
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[i]) <= 0.0) --k;
    hull[k++] = p[i];
  }
  for (size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && cross(hull[k - 2], hull[k - 1], p[i]) <= 0.0) --k;
    hull[k++] = p[i];
  }
  hull.resize(k - 1);  // the last point repeats the first
  double twice = 0.0;  // shoelace formula
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull[i];
    const Eigen::Vector2d& b = hull[(i + 1) % hull.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return 0.5 * std::abs(twice);
}

UpAxisGuess make_guess(int axis, int sign, std::vector<double> footprints, std::string reason) {
  UpAxisGuess guess;
  guess.axis = axis;
  guess.sign = sign;
  guess.direction = sign * Eigen::Vector3d::Unit(axis);
  guess.footprints = std::move(footprints);
  guess.reason = std::move(reason);
  return guess;
}

}  // namespace

std::string UpAxisGuess::name() const {
  return std::string(sign > 0 ? "+" : "-") + "xyz"[axis];
}

UpAxisGuess guess_up_axis(const std::vector<Eigen::Vector3d>& points,
                          const UpAxisOptions& options) {
  if (points.empty()) throw InvalidInputError("up axis", "no points");
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) throw InvalidInputError("up axis", "a point is not finite");
    box.extend(p);
  }
  const Eigen::Vector3d extent = box.sizes();
  int thin = 0;
  extent.minCoeff(&thin);
  if (!(extent[thin] > options.flat_ratio * extent.maxCoeff())) {
    return make_guess(thin, 1, std::vector<double>(6, 0.0),
                      std::string("the model is flat along ") + "xyz"[thin]);
  }

  // footprints[2 a + (sign < 0)]: the hull of the points near the end the model would stand on
  // if +/- e_a were up (the lowest points for +, the highest for -), over the cross-section.
  std::vector<double> footprints(6, 0.0);
  for (int a = 0; a < 3; ++a) {
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    const double cross_section = extent[u] * extent[v];
    const double slab = options.base_slab * extent[a];
    for (int side = 0; side < 2; ++side) {
      std::vector<Eigen::Vector2d> base;
      for (const Eigen::Vector3d& p : points) {
        const double height = side == 0 ? p[a] - box.min()[a] : box.max()[a] - p[a];
        if (height <= slab) base.emplace_back(p[u], p[v]);
      }
      footprints[static_cast<size_t>(2 * a + side)] =
          cross_section > 0.0 ? hull_area(std::move(base)) / cross_section : 0.0;
    }
  }
  const auto best = std::max_element(footprints.begin(), footprints.end());
  const int index = static_cast<int>(best - footprints.begin());
  const int axis = index / 2;
  const double opposite = footprints[static_cast<size_t>(index ^ 1)];
  std::ostringstream reason;
  reason.precision(2);
  if (!(*best >= options.min_footprint)) {
    reason << "no side to stand on (largest footprint " << 100.0 * *best
           << "% of the box); default +z";
    return make_guess(2, 1, std::move(footprints), reason.str());
  }
  if (opposite >= options.symmetric_ratio * *best) {
    reason << "both ends of "
           << "xyz"[axis] << " are bases (" << 100.0 * footprints[2 * axis] << "% and "
           << 100.0 * footprints[2 * axis + 1] << "% of the box); + taken";
    return make_guess(axis, 1, std::move(footprints), reason.str());
  }
  const int sign = index % 2 == 0 ? 1 : -1;
  reason << "the model stands on its " << (sign > 0 ? "lowest " : "highest ") << "xyz"[axis]
         << " (a base of " << 100.0 * *best << "% of the box's cross-section)";
  return make_guess(axis, sign, std::move(footprints), reason.str());
}

Eigen::Vector3d parse_up_direction(const std::string& text, const std::string& name) {
  std::string axis = text;
  int sign = 1;
  if (!axis.empty() && (axis[0] == '+' || axis[0] == '-')) {
    sign = axis[0] == '-' ? -1 : 1;
    axis.erase(0, 1);
  }
  if (axis == "x" || axis == "y" || axis == "z") {
    return sign * Eigen::Vector3d::Unit(axis[0] - 'x');
  }
  Eigen::Vector3d d;
  char c1 = 0, c2 = 0;
  std::istringstream in(text);
  std::string rest;
  if (in >> d.x() >> c1 >> d.y() >> c2 >> d.z() && c1 == ',' && c2 == ',' && !(in >> rest) &&
      d.allFinite() && d.norm() > 0.0) {
    return d.normalized();
  }
  throw InvalidInputError(name,
                          "expected x, y, z, -x, -y, -z or X,Y,Z (non-zero), got '" + text + "'");
}

}  // namespace elastic
