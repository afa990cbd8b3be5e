// `elastic compare`: ElasticPaint against the baselines (LSCM, ARAP, DCM via CGAL; the naive map)
// on one case, on the same particle grid with the same boundary correspondence, measured by the
// same metrics (docs/metrics.md). JSON report and a Markdown table on stdout.
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "cli_common.h"
#include "command.h"
#include "compare_methods.h"
#include "elastic/core/error.h"
#include "elastic/core/staged_folder.h"
#include "job_file.h"
#include "map_job.h"
#include "verdict.h"

namespace elastic::cli {
namespace {

struct CompareArgs {
  MapJob job;
  std::string baselines = "lscm,arap,dcm";
  std::string heatmap_dir;
  std::string heatmap_metric = "symmetric_dirichlet";
  double heatmap_percentile = 0.95;
};

std::vector<BaselineKind> parse_baselines(const std::string& text) {
  std::vector<BaselineKind> out;
  std::istringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item.empty()) continue;
    try {
      out.push_back(parse_baseline_kind(item, "--baselines"));
    } catch (const InvalidInputError& e) {
      throw UsageError(e.what());  // a malformed flag value: exit 64 (docs/cli.md)
    }
  }
  return out;
}

int run_compare(const CompareArgs& args, const CLI::App& sub) {
  CompareOptions options;
  options.baselines = parse_baselines(args.baselines);
  try {
    options.heatmap.metric = parse_triangle_metric(args.heatmap_metric, "--heatmap-metric");
  } catch (const InvalidInputError& e) {
    throw UsageError(e.what());
  }
  options.heatmap.percentile = args.heatmap_percentile;
  // Output paths are checked before any work; the heatmaps appear together (staged_folder.h).
  if (!args.job.report.empty()) check_output_file(args.job.report, "--report");
  std::optional<StagedFolder> heatmaps;
  if (!args.heatmap_dir.empty()) {
    heatmaps.emplace(args.heatmap_dir, "--heatmap");
    options.heatmap_dir = heatmaps->staging();
  }

  const std::unique_ptr<MapSession> session =
      run_map_job(args.job, terminal_progress(args.job.quiet));
  end_progress_line();
  const std::vector<MethodMeasurement> methods = compare_methods(*session, options);
  if (heatmaps) heatmaps->commit();

  const nlohmann::json job = recorded_job(args.job, job_of(sub));
  const MapVerdict verdict = judge_map(args.job, *session);
  nlohmann::json report = {{"job", job},
                           {"map", map_report(args.job, *session, job)},
                           {"rest_scale", session->result.rest_scale},
                           {"verdict", verdict.to_json()}};
  nlohmann::json& out = report["methods"];
  out = nlohmann::json::object();
  for (const MethodMeasurement& m : methods) out[m.name] = measurement_json(m);
  // The report and the table are written whatever the verdict: they are the diagnosis.
  write_report(args.job.report, report);
  std::cout << markdown_table(methods);
  return finish(verdict);
}

}  // namespace
}  // namespace elastic::cli

ELASTIC_COMMAND(
    "compare", "Compare ElasticPaint with LSCM, ARAP, DCM and the naive map on one case",
    [](CLI::App& sub) {
      auto a = std::make_shared<elastic::cli::CompareArgs>();
      elastic::cli::add_map_flags(sub, a->job);
      sub.add_option("--baselines", a->baselines, "Comma-separated baselines: lscm, arap, dcm");
      sub.add_option("--heatmap", a->heatmap_dir,
                     "Write one PLY distortion heatmap per method into this folder");
      sub.add_option("--heatmap-metric", a->heatmap_metric,
                     "Per-triangle metric of the heatmaps (docs/metrics.md)");
      sub.add_option("--heatmap-percentile", a->heatmap_percentile,
                     "Red from this quantile of ElasticPaint's values up (shared by all methods)")
          ->check(CLI::Range(0.0, 1.0));
      sub.footer(
          "Example:\n  elastic compare --source meshes/plane_quads.obj --source-region "
          "disk:0,0,0,0.8 \\\n"
          "      --target meshes/torus_quads.obj --target-region disk:1.35,0,0,0.5 --particles 345 "
          "\\\n      --report compare.json --heatmap heatmaps/\n"
          "Every method is measured on the same particle grid with the same boundary "
          "correspondence;\nthe report has every metric of docs/metrics.md and the seconds of each "
          "method.\nExit 0 when ElasticPaint converged with no folds, 70 otherwise (one line on "
          "stderr); the "
          "report\nand the table are written either way.");
      return [a, &sub] { return elastic::cli::run_compare(*a, sub); };
    });
