#include "elastic/regions/surface_curve.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace elastic {

double SurfaceCurve::length() const {
  const int n = size();
  double total = 0.0;
  for (int i = 0; i < n; ++i) {
    total +=
        (positions[static_cast<size_t>((i + 1) % n)] - positions[static_cast<size_t>(i)]).norm();
  }
  return total;
}

std::vector<double> SurfaceCurve::arc_lengths() const {
  std::vector<double> out(positions.size(), 0.0);
  for (size_t i = 1; i < positions.size(); ++i) {
    out[i] = out[i - 1] + (positions[i] - positions[i - 1]).norm();
  }
  return out;
}

SurfaceCurve::Location SurfaceCurve::locate(double s) const {
  return locate(s, arc_lengths(), length());
}

SurfaceCurve::Location SurfaceCurve::locate(double s, const std::vector<double>& cum,
                                            double total) const {
  Location loc;
  const int n = size();
  if (n == 0) {
    return loc;
  }
  loc.position = positions.front();
  if (n == 1 || total == 0.0) {
    return loc;
  }
  // Normalised arc length from vertex 0, wrapped into [0, 1).
  double w = anchor + s;
  w -= std::floor(w);
  const double target = w * total;
  // Last vertex whose cumulative length is <= target; the closing chord is segment n-1.
  const auto it = std::upper_bound(cum.begin(), cum.end(), target);
  const int seg = std::max(0, static_cast<int>(it - cum.begin()) - 1);
  const Eigen::Vector3d& a = positions[static_cast<size_t>(seg)];
  const Eigen::Vector3d& b = positions[static_cast<size_t>((seg + 1) % n)];
  const double len = (b - a).norm();
  loc.segment = seg;
  loc.t = len > 0.0 ? std::clamp((target - cum[static_cast<size_t>(seg)]) / len, 0.0, 1.0) : 0.0;
  loc.position = (1.0 - loc.t) * a + loc.t * b;
  return loc;
}

double SurfaceCurve::nearest_arc_parameter(const Eigen::Vector3d& x) const {
  const int n = size();
  const double total = length();
  if (n < 2 || total == 0.0) {
    return 0.0;
  }
  const std::vector<double> cum = arc_lengths();
  double best = std::numeric_limits<double>::infinity(), best_arc = 0.0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = positions[static_cast<size_t>(i)];
    const Eigen::Vector3d& b = positions[static_cast<size_t>((i + 1) % n)];
    const Eigen::Vector3d e = b - a;
    const double len2 = e.squaredNorm();
    const double t = len2 > 0.0 ? std::clamp((x - a).dot(e) / len2, 0.0, 1.0) : 0.0;
    const double d = (a + t * e - x).squaredNorm();
    if (d < best) {
      best = d;
      best_arc = cum[static_cast<size_t>(i)] + t * std::sqrt(len2);
    }
  }
  const double w = best_arc / total;
  return w >= 1.0 ? 0.0 : w;
}

}  // namespace elastic
