#include "compare_methods.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "elastic/baselines/decal_baseline.h"
#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"

namespace elastic::cli {
namespace {

// Measures one placement of the session's particles on the target.
MethodMeasurement measure(const MapSession& session, std::string name,
                          const Eigen::Matrix3Xd& positions,
                          const std::vector<SurfacePoint>& points, std::vector<char> outside) {
  MethodMeasurement m;
  m.name = std::move(name);
  m.metrics = measure_placement(session, positions, points, std::move(outside));
  m.positions = positions;
  m.ok = true;
  return m;
}

}  // namespace

std::vector<MethodMeasurement> compare_methods(const MapSession& session,
                                               const CompareOptions& options) {
  const MapResult& r = session.result;
  const ParticleGrid& grid = r.sampling.grid;
  std::vector<MethodMeasurement> out;

  // ElasticPaint and the naive map as the session measured them (the verdict's figures).
  MethodMeasurement elastic;
  elastic.name = "elastic";
  elastic.ok = true;
  elastic.metrics = session.metrics;
  elastic.positions = r.relaxation.positions;
  elastic.seconds = r.seconds_naive + r.relaxation.setup_seconds + r.relaxation.solve_seconds;
  elastic.extra = {{"iterations", r.relaxation.iterations},
                   {"converged", r.relaxation.converged},
                   {"reason", std::string(to_string(r.relaxation.reason))}};
  out.push_back(std::move(elastic));

  MethodMeasurement naive;
  naive.name = "naive";
  naive.ok = true;
  naive.metrics = session.naive_metrics;
  naive.positions = r.naive.positions;
  naive.seconds = r.seconds_naive;
  out.push_back(std::move(naive));

  if (session.decal) {
    // A placed decal has no drawn target curve for the flattening baselines: its baseline is the
    // decal of the same kind, the exponential map, on the same grid.
    const DecalBaselineResult b = exponential_map_decal(*session.target.surface, *session.decal);
    MethodMeasurement m = measure(session, "expmap", b.positions, b.points, {});
    m.seconds = b.seconds;
    m.extra = {{"stopped_at_boundary", b.stopped}};
    out.push_back(std::move(m));
  }
  for (const BaselineKind kind : session.decal ? std::vector<BaselineKind>{} : options.baselines) {
    const std::string name(to_string(kind));
    try {
      BaselineOptions baseline_options;
      baseline_options.target_offset = session.result.boundary_offset;
      baseline_options.kind = kind;
      const BaselineResult b =
          map_baseline(grid, *session.source.projector, session.source_region,
                       *session.target.projector, session.target_region, baseline_options);
      MethodMeasurement m = measure(session, name, b.positions, b.points, b.outside);
      m.seconds = b.seconds;
      m.extra = {{"alignment_scale", b.alignment_scale},
                 {"alignment_rotation", b.alignment_rotation},
                 {"alignment_rms", b.alignment_rms},
                 {"source_flipped_triangles", b.source_flipped_triangles},
                 {"target_flipped_triangles", b.target_flipped_triangles}};
      out.push_back(std::move(m));
    } catch (const Error& e) {
      // A baseline that fails or refuses the input (a flattening that fails, a region beyond its
      // size limit) is a result about that baseline, not a failure of the comparison.
      MethodMeasurement m;
      m.name = name;
      m.error = e.what();
      out.push_back(std::move(m));
    }
  }

  if (!options.heatmap_dir.empty()) {
    std::filesystem::create_directories(options.heatmap_dir);
    // One colour range for all methods (ElasticPaint's automatic range unless fixed), so the same
    // colour means the same distortion in every file.
    const HeatmapResult first =
        make_heatmap(out.front().positions, out.front().metrics, options.heatmap);
    HeatmapOptions shared = options.heatmap;
    shared.low = first.low;
    shared.high = first.high;
    for (const MethodMeasurement& m : out) {
      if (!m.ok) {
        continue;
      }
      write_mesh(options.heatmap_dir / (m.name + ".ply"),
                 make_heatmap(m.positions, m.metrics, shared).mesh);
    }
  }
  return out;
}

nlohmann::json measurement_json(const MethodMeasurement& m) {
  nlohmann::json j;
  j["seconds"] = m.seconds;
  if (!m.ok) {
    j["error"] = m.error;
    return j;
  }
  const MapMetrics& x = m.metrics;
  j["length_energy"] = x.length_energy;
  j["angle_error_mean_deg"] = x.angle_error_mean_deg;
  j["angle_error_max_deg"] = x.angle_error_max_deg;
  j["stretch_l2"] = x.stretch_l2;
  j["stretch_linf"] = x.stretch_linf;
  j["inverse_stretch_l2"] = x.inverse_stretch_l2;
  j["inverse_stretch_linf"] = x.inverse_stretch_linf;
  j["area_distortion"] = x.area_distortion;
  j["conformal_distortion"] = x.conformal_distortion;
  j["symmetric_dirichlet"] = x.symmetric_dirichlet;
  j["folds"] = x.folds;
  j["sigma_min"] = x.sigma_min;
  j["degenerate"] = x.degenerate;
  j["outside"] = x.outside;
  j["outside_triangles"] = x.outside_triangles;
  j["measured_triangles"] = x.measured_triangles;
  for (const auto& [key, value] : m.extra.items()) {
    j[key] = value;
  }
  return j;
}

std::string method_status(const MethodMeasurement& m) {
  if (!m.ok) {
    return "failed";
  }
  std::vector<std::string> problems;
  if (m.extra.contains("converged") && !m.extra["converged"].get<bool>()) {
    problems.push_back("not converged");
  }
  if (m.metrics.folds > 0) {
    problems.push_back(std::to_string(m.metrics.folds) +
                       (m.metrics.folds == 1 ? " fold" : " folds"));
  }
  if (m.metrics.outside > 0) {
    problems.push_back(std::to_string(m.metrics.outside) + " outside");
  }
  if (problems.empty()) {
    return "ok";
  }
  std::string out = "**";
  for (size_t k = 0; k < problems.size(); ++k) {
    out += (k > 0 ? ", " : "") + problems[k];
  }
  return out + "**";
}

std::string markdown_table(const std::vector<MethodMeasurement>& methods) {
  std::ostringstream s;
  s << "| method | status | length energy | angle err mean (deg) | angle err max (deg) | "
       "stretch L2 | stretch Linf | inv. stretch L2 | area dist. | conformal | sym. Dirichlet | "
       "worst sigma_min | folds | outside | seconds |\n"
    << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  const auto num = [](double v, int digits = 4) {
    std::ostringstream o;
    o << std::setprecision(digits) << v;
    return o.str();
  };
  for (const MethodMeasurement& m : methods) {
    s << "| " << m.name << " | " << method_status(m) << " | ";
    if (!m.ok) {
      s << m.error << " |||||||||||||\n";
      continue;
    }
    const MapMetrics& x = m.metrics;
    s << num(x.length_energy) << " | " << num(x.angle_error_mean_deg) << " | "
      << num(x.angle_error_max_deg) << " | " << num(x.stretch_l2) << " | " << num(x.stretch_linf)
      << " | " << num(x.inverse_stretch_l2) << " | " << num(x.area_distortion) << " | "
      << num(x.conformal_distortion) << " | " << num(x.symmetric_dirichlet) << " | "
      << num(x.sigma_min) << " | " << x.folds << " | " << x.outside << " | " << num(m.seconds, 3)
      << " |\n";
  }
  return s.str();
}

}  // namespace elastic::cli
