#pragma once
/// \file
/// Distortion heatmaps (the paper's Fig. 9: green = little distortion, red = much): one
/// per-triangle metric of `measure_map` coloured on the target grid, as a PolygonMesh to write as
/// PLY with face colours and vertex colours (for viewers that read only one of them).
///
/// Vertex colours: the ramp colour of the mean value of the measured triangles around the vertex
/// (excluded ones left out), so every vertex colour is a colour of the legend and a viewer that
/// interpolates vertex colours shows the same scale as the faces; a vertex of a folded or
/// degenerate triangle takes the fold colour (folds must stay visible), a vertex whose triangles
/// are all excluded the excluded colour.
///
/// Colour ramp: a value v is normalised to t = (v - low) / (high - low), clamped to [0, 1], and
/// coloured green (0, 1, 0) at t = 0, yellow (1, 1, 0) at t = 1/2, red (1, 0, 0) at t = 1, linearly
/// in between (red rises over the first half, green falls over the second).
///
/// Range: `low` is the metric's perfect value (0 for angle and area, 1 for stretches and conformal
/// distortion, 4 for the symmetric Dirichlet energy) unless fixed. `high` is fixed, or automatic:
/// the `percentile` of the measured triangles' finite values, so that a few extreme triangles do
/// not wash the rest out in green. Folded and degenerate triangles are painted the `fold_color`
/// (default magenta: a fold is worse than any finite distortion and must stand out), triangles
/// excluded because a corner is outside the `excluded_color` (grey).

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"
#include "elastic/metrics/map_metrics.h"

namespace elastic {

struct HeatmapOptions {
  TriangleMetric metric = TriangleMetric::SymmetricDirichlet;  ///< which per-triangle value
  std::optional<double> low;   ///< value coloured green; default: perfect_value(metric)
  std::optional<double> high;  ///< value coloured red; default: automatic (percentile)
  double percentile = 0.95;    ///< automatic high: this quantile (0..1) of the finite values
  Eigen::Vector3f fold_color{1.0f, 0.0f, 1.0f};      ///< folded or degenerate triangles
  Eigen::Vector3f excluded_color{0.5f, 0.5f, 0.5f};  ///< triangles with an outside corner
};

struct HeatmapResult {
  /// The grid's triangles at the target positions with face_colors and vertex_colors.
  PolygonMesh mesh;
  double low = 0.0;   ///< the range actually used
  double high = 1.0;  ///< (high > low always: a degenerate range is widened, see heatmap_color)
};

/// The ramp colour of `value` in [low, high] (see the file comment). NaN gives the low colour.
Eigen::Vector3f heatmap_color(double value, double low, double high);

/// The colours of the ramp at its stops t = 0, 1/2, 1: green (0, 1, 0), yellow (1, 1, 0), red
/// (1, 0, 0); heatmap_color interpolates them linearly.
std::vector<Eigen::Vector3f> heatmap_ramp_stops();

/// The automatic `high` of make_heatmap for one map: the options' percentile of its measured,
/// unfolded, finite values (nearest rank), or `low` when there are none.
/// \throws InvalidInputError as make_heatmap for a percentile outside [0, 1].
double heatmap_automatic_high(const MapMetrics& metrics, const HeatmapOptions& options = {});

/// One colour scale for several maps of the same grid (ElasticPaint beside baselines), so their
/// heatmaps compare: `options` with `low` fixed to options.low or the metric's perfect value and
/// `high` to options.high or the largest of the maps' automatic highs (widened like make_heatmap
/// when not above low). Pass the result to make_heatmap for every map.
/// \throws InvalidInputError for no maps, or as make_heatmap.
HeatmapOptions shared_heatmap_scale(const std::vector<const MapMetrics*>& metrics,
                                    const HeatmapOptions& options = {});

/// Colours `metrics.per_triangle.values(options.metric)` on the triangles `metrics.triangles`
/// placed at `target_positions` (3 x #P, the positions the metrics were measured on). \throws
/// InvalidInputError when sizes disagree, the percentile is outside [0, 1], or a fixed
///         range is not finite.
HeatmapResult make_heatmap(const Eigen::Matrix3Xd& target_positions, const MapMetrics& metrics,
                           const HeatmapOptions& options = {});

}  // namespace elastic
