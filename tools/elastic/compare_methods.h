#pragma once
// Shared by `elastic compare` and `elastic bench table1`: measure ElasticPaint's map and the
// baselines (LSCM, ARAP, DCM through CGAL; the naive map) on the same particle grid with the same
// boundary correspondence and the same metrics (libelastic metrics/map_metrics.h).

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "elastic/baselines/baseline_map.h"
#include "elastic/metrics/heatmap.h"
#include "elastic/metrics/map_metrics.h"
#include "map_job.h"

namespace elastic::cli {

struct CompareOptions {
  /// Baselines run besides "elastic" and "naive", in this order.
  std::vector<BaselineKind> baselines = {BaselineKind::Lscm, BaselineKind::Arap, BaselineKind::Dcm};
  /// When not empty, one PLY heatmap per method is written here (<method>.ply).
  std::filesystem::path heatmap_dir;
  /// The per-triangle metric the heatmaps show; their range is shared by all methods (automatic:
  /// the percentile of ElasticPaint's values, so the colours compare across methods).
  HeatmapOptions heatmap;
};

/// One method's measurement.
struct MethodMeasurement {
  std::string name;            ///< "elastic", "naive", "lscm", "arap", "dcm"
  bool ok = false;             ///< false: the method failed (error says why)
  std::string error;           ///< the failure's message
  double seconds = 0.0;        ///< time of the method on the shared grid (see metrics_report_json)
  MapMetrics metrics;          ///< when ok
  nlohmann::json extra;        ///< method-specific figures (alignment residual, iterations, ...)
  Eigen::Matrix3Xd positions;  ///< 3 x #P target positions measured
};

/// Runs the baselines on the session's grid and measures every method, "elastic" first, then
/// "naive", then the baselines. Seconds: elastic = naive map + relaxation (setup and solve) of the
/// session's run; naive = the naive map; a baseline = map_baseline's own timing (both
/// flattenings, alignment, composition). Sampling the grid is common to all and not counted.
std::vector<MethodMeasurement> compare_methods(const MapSession& session,
                                               const CompareOptions& options = {});

/// {"seconds", every aggregate metric key, "error" when failed, plus `extra`}.
nlohmann::json measurement_json(const MethodMeasurement& m);

/// "ok", or what is wrong with the method's map in bold ("**not converged, 3 folds, 2
/// outside**"), or "failed" (the error is in the next column).
std::string method_status(const MethodMeasurement& m);

/// A Markdown table, one row per method: its status (folds and failures marked), the headline
/// metrics as columns.
std::string markdown_table(const std::vector<MethodMeasurement>& methods);

}  // namespace elastic::cli
