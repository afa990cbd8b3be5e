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
  if (options.high) {
    out.high = *options.high;
  } else {
    // Automatic: a quantile of the values of the measured, unfolded triangles (nearest rank on the
    // sorted values), so that the colours spread over the bulk of the map.
    std::vector<double> finite;
    finite.reserve(values.size());
    for (int t = 0; t < nt; ++t) {
      if (!metrics.per_triangle.excluded[t] && !metrics.per_triangle.folded[t] &&
          std::isfinite(values[t])) {
        finite.push_back(values[t]);
      }
    }
    if (finite.empty()) {
      out.high = out.low;
    } else {
      std::sort(finite.begin(), finite.end());
      const auto rank = static_cast<size_t>(
          std::lround(options.percentile * static_cast<double>(finite.size() - 1)));
      out.high = finite[rank];
    }
  }
  // A map that is perfect everywhere has high == low: widen the range so that it shows all green
  // and any later deviation is visible on the same scale (1% of the perfect value, or 0.01).
  if (!(out.high > out.low)) {
    out.high = out.low + std::max(0.01, 0.01 * std::abs(out.low));
  }

  PolygonMesh& mesh = out.mesh;
  const int np = static_cast<int>(target_positions.cols());
  mesh.positions.resize(np);
  for (int p = 0; p < np; ++p) {
    mesh.positions[p] = target_positions.col(p);
  }
  mesh.face_colors.reserve(nt);
  std::vector<Eigen::Vector3f> color_sum(np, Eigen::Vector3f::Zero());
  std::vector<int> color_count(np, 0);
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
      color_sum[tri[k]] += color;
      ++color_count[tri[k]];
    }
  }
  mesh.vertex_colors.resize(np);
  for (int p = 0; p < np; ++p) {
    mesh.vertex_colors[p] = color_count[p] > 0
                                ? Eigen::Vector3f(color_sum[p] / static_cast<float>(color_count[p]))
                                : options.excluded_color;
  }
  return out;
}

}  // namespace elastic
