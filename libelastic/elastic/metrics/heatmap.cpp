#include "elastic/metrics/heatmap.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "elastic/core/error.h"

namespace elastic {

Eigen::Vector3f heatmap_color(double value, double low, double high) {
  double t = 0.0;
  if (std::isfinite(value)) {
    t = high > low ? (value - low) / (high - low) : (value > low ? 1.0 : 0.0);
  } else if (value > 0.0) {
    t = 1.0;  // +inf: as bad as it gets
  }
  t = std::clamp(t, 0.0, 1.0);
  // green -> yellow over the first half (red rises), yellow -> red over the second (green falls).
  const float red = static_cast<float>(std::min(1.0, 2.0 * t));
  const float green = static_cast<float>(std::min(1.0, 2.0 * (1.0 - t)));
  return {red, green, 0.0f};
}

namespace {
double widened_high(double low, double high) {
  return high > low ? high : low + std::max(0.01, 0.01 * std::abs(low));
}
}  // namespace

std::vector<Eigen::Vector3f> heatmap_ramp_stops() {
  return {heatmap_color(0.0, 0.0, 1.0), heatmap_color(0.5, 0.0, 1.0), heatmap_color(1.0, 0.0, 1.0)};
}

double heatmap_automatic_high(const MapMetrics& metrics, const HeatmapOptions& options) {
  if (!(options.percentile >= 0.0 && options.percentile <= 1.0)) {
    throw InvalidInputError("heatmap", "percentile must lie in [0, 1]");
  }
  const double low = options.low.value_or(perfect_value(options.metric));
  const std::vector<double>& values = metrics.per_triangle.values(options.metric);
  // A quantile of the values of the measured, unfolded triangles (nearest rank on the sorted
  // values), so that the colours spread over the bulk of the map.
  std::vector<double> finite;
  finite.reserve(values.size());
  for (size_t t = 0; t < values.size(); ++t) {
    const bool excluded =
        t < metrics.per_triangle.excluded.size() && metrics.per_triangle.excluded[t];
    const bool folded = t < metrics.per_triangle.folded.size() && metrics.per_triangle.folded[t];
    if (!excluded && !folded && std::isfinite(values[t])) {
      finite.push_back(values[t]);
    }
  }
  if (finite.empty()) {
    return low;
  }
  std::sort(finite.begin(), finite.end());
  const auto rank =
      static_cast<size_t>(std::lround(options.percentile * static_cast<double>(finite.size() - 1)));
  return finite[rank];
}

HeatmapOptions shared_heatmap_scale(const std::vector<const MapMetrics*>& metrics,
                                    const HeatmapOptions& options) {
  if (metrics.empty()) {
    throw InvalidInputError("heatmap", "no maps to share a colour scale");
  }
  if ((options.low && !std::isfinite(*options.low)) ||
      (options.high && !std::isfinite(*options.high))) {
    throw InvalidInputError("heatmap", "a fixed range bound is not finite");
  }
  HeatmapOptions shared = options;
  shared.low = options.low.value_or(perfect_value(options.metric));
  if (!options.high) {
    double high = *shared.low;
    for (const MapMetrics* m : metrics) {
      high = std::max(high, heatmap_automatic_high(*m, options));
    }
    shared.high = high;
  }
  shared.high = widened_high(*shared.low, *shared.high);
  return shared;
}

HeatmapResult make_heatmap(const Eigen::Matrix3Xd& target_positions, const MapMetrics& metrics,
                           const HeatmapOptions& options) {
  const std::string name = "heatmap";
  const std::vector<double>& values = metrics.per_triangle.values(options.metric);
  const int nt = static_cast<int>(metrics.triangles.size());
  if (static_cast<int>(values.size()) != nt ||
      static_cast<int>(metrics.per_triangle.folded.size()) != nt ||
      static_cast<int>(metrics.per_triangle.excluded.size()) != nt) {
    throw InvalidInputError(name, "per-triangle values do not match the triangles");
  }
  if (!(options.percentile >= 0.0 && options.percentile <= 1.0)) {
    throw InvalidInputError(name, "percentile must lie in [0, 1]");
  }
  if ((options.low && !std::isfinite(*options.low)) ||
      (options.high && !std::isfinite(*options.high))) {
    throw InvalidInputError(name, "a fixed range bound is not finite");
  }
  for (const auto& tri : metrics.triangles) {
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || tri[k] >= target_positions.cols()) {
        throw InvalidInputError(name, "a triangle index is out of range of the target positions");
      }
    }
  }

  HeatmapResult out;
  out.low = options.low.value_or(perfect_value(options.metric));
  out.high = options.high ? *options.high : heatmap_automatic_high(metrics, options);
  // A map that is perfect everywhere has high == low: widen the range so that it shows all green
  // and any later deviation is visible on the same scale (1% of the perfect value, or 0.01).
  out.high = widened_high(out.low, out.high);

  PolygonMesh& mesh = out.mesh;
  const int np = static_cast<int>(target_positions.cols());
  mesh.positions.resize(np);
  for (int p = 0; p < np; ++p) {
    mesh.positions[p] = target_positions.col(p);
  }
  mesh.face_colors.reserve(nt);
  // Per vertex: the sum and count of the measured values around it, and whether a fold touches it.
  std::vector<double> value_sum(np, 0.0);
  std::vector<int> value_count(np, 0);
  std::vector<char> at_fold(np, 0);
  for (int t = 0; t < nt; ++t) {
    const Eigen::Vector3i& tri = metrics.triangles[t];
    mesh.add_face({tri[0], tri[1], tri[2]});
    Eigen::Vector3f color;
    if (metrics.per_triangle.excluded[t]) {
      color = options.excluded_color;
    } else if (metrics.per_triangle.folded[t]) {
      color = options.fold_color;
    } else {
      color = heatmap_color(values[t], out.low, out.high);
    }
    mesh.face_colors.push_back(color);
    for (int k = 0; k < 3; ++k) {
      if (metrics.per_triangle.excluded[t]) {
        continue;
      }
      if (metrics.per_triangle.folded[t]) {
        at_fold[tri[k]] = 1;
      } else {
        // +inf counts as the top of the scale; NaN as the bottom (heatmap_color's rules).
        const double v = std::isnan(values[t])      ? out.low
                         : std::isfinite(values[t]) ? values[t]
                                                    : out.high;
        value_sum[tri[k]] += v;
        ++value_count[tri[k]];
      }
    }
  }
  mesh.vertex_colors.resize(np);
  for (int p = 0; p < np; ++p) {
    if (at_fold[p]) {
      mesh.vertex_colors[p] = options.fold_color;
    } else if (value_count[p] > 0) {
      mesh.vertex_colors[p] = heatmap_color(value_sum[p] / value_count[p], out.low, out.high);
    } else {
      mesh.vertex_colors[p] = options.excluded_color;
    }
  }
  return out;
}

}  // namespace elastic
