// `elastic bench table1`: the paper's Table 1 reproduced. The nine cases (surfaces, regions,
// particle counts, the paper's seconds) come from a cases file
// (tools/benchmarks/table1_cases.json); each is mapped --runs times (median seconds), then
// ElasticPaint, the naive map and the baselines are measured on its grid (compare_methods.h). JSON
// report and a Markdown results page.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "bench_common.h"
#include "bench_decals.h"
#include "bench_robustness.h"
#include "bench_scale.h"
#include "bench_warm.h"
#include "cli_common.h"
#include "command.h"
#include "compare_methods.h"
#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"
#include "elastic/metrics/map_metrics.h"
#include "job_file.h"
#include "map_job.h"

namespace elastic::cli {
namespace {

namespace fs = std::filesystem;

struct BenchArgs {
  std::string cases = std::string(ELASTIC_SOURCE_DIR) + "/tools/benchmarks/table1_cases.json";
  std::string root = ELASTIC_SOURCE_DIR;
  std::string report;
  std::string markdown;
  std::string only;
  int runs = 3;
  int threads = 0;
  bool extra = false;
  bool quiet = false;
};

std::string fmt(double v, int digits = 4) {
  std::ostringstream o;
  o << std::setprecision(digits) << v;
  return o.str();
}

// One case of the cases file: {"name", "source", "source_region", "target", "target_region",
// "particles", "paper_seconds", "paper_springs", "why", "extra"}; paths relative to --root.
nlohmann::json run_case(const nlohmann::json& c, const BenchArgs& args) {
  const std::string name = c.at("name").get<std::string>();
  nlohmann::json out = {
      {"name", name},
      {"source", c.at("source")},
      {"target", c.at("target")},
      {"source_region", c.value("source_region", "boundary")},
      {"target_region", c.value("target_region", "boundary")},
      {"requested_particles", c.value("particles", 0)},
      // An extra case has no counterpart in the paper.
      {"paper_particles",
       c.value("extra", false) ? nlohmann::json() : nlohmann::json(c.value("particles", 0))},
      {"paper_seconds", c.value("paper_seconds", nlohmann::json())},
      {"paper_springs", c.value("paper_springs", nlohmann::json())}};
  const fs::path source = fs::path(args.root) / c.at("source").get<std::string>();
  const fs::path target = fs::path(args.root) / c.at("target").get<std::string>();
  for (const fs::path& p : {source, target}) {
    if (!fs::exists(p)) {
      out["skipped"] = p.string() + " is not present";
      return out;
    }
  }
  MapJob job;
  job.source = source.string();
  job.target = target.string();
  job.source_region = out["source_region"].get<std::string>();
  job.target_region = out["target_region"].get<std::string>();
  job.source_anchor = c.value("source_anchor", "");
  job.target_anchor = c.value("target_anchor", "");
  job.particles = c.at("particles").get<long>();
  job.threads = args.threads;
  job.quiet = true;
  // Table 1 reproduces the paper's method: its energy, its boundary rest scale, the regions' own
  // anchors and its pointwise curvature (the robust defaults of `elastic map` are measured by
  // `bench robustness`).
  job.energy = "paper";
  job.rest_scale = "boundary";
  job.boundary_offset = "anchor";
  job.boundary = "fixed";
  job.curvature_radius = 0.0;  // the paper's pointwise curvature in the sampling (eqs. 6-8)

  if (!args.quiet) std::cerr << "elastic bench: " << name << " run 1\n";
  const std::unique_ptr<MapSession> session = run_map_job(job);
  // The map itself (sampling, naive map, relaxation, queryable mapping), not reading the files.
  std::vector<double> seconds = {session->seconds_total - session->seconds_loading};
  // Further runs map again on the loaded surfaces and regions with the options run_map_job used
  // (L-BFGS, the paper's energy, boundary rest scale, seed 0), so loading is not repeated.
  const MapOptions options = make_map_options(job);
  for (int run = 1; run < args.runs; ++run) {
    if (!args.quiet) std::cerr << "elastic bench: " << name << " run " << run + 1 << "\n";
    const auto start = std::chrono::steady_clock::now();
    const MapResult again =
        map_regions(*session->source.projector, session->source_region, *session->target.projector,
                    session->target_region, options);
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (again.sampling.statistics.particles != session->result.sampling.statistics.particles) {
      throw NumericalError(name, "a repeated run sampled a different grid");
    }
  }
  if (!args.quiet) std::cerr << "elastic bench: " << name << " baselines\n";
  const std::vector<MethodMeasurement> methods = compare_methods(*session);

  const MapResult& r = session->result;
  const SamplingStatistics& st = r.sampling.statistics;
  out["particles"] = st.particles;
  out["springs"] = st.normal_springs + st.angular_springs;
  out["springs_normal"] = st.normal_springs;
  out["springs_angular"] = st.angular_springs;
  out["seconds"] = median(seconds);
  out["seconds_runs"] = seconds;
  out["iterations"] = r.relaxation.iterations;
  out["converged"] = r.relaxation.converged;
  out["reason"] = std::string(to_string(r.relaxation.reason));
  out["rest_scale"] = r.rest_scale;
  nlohmann::json& m = out["methods"];
  m = nlohmann::json::object();
  for (const MethodMeasurement& x : methods) m[x.name] = measurement_json(x);
  // ElasticPaint's metrics at the case's top level too, as Table 1 lists them.
  for (const auto& [key, value] : m["elastic"].items()) {
    if (key != "seconds" && !out.contains(key)) out[key] = value;
  }
  return out;
}

// ---- the results page ----------------------------------------------------------------------

const std::vector<std::string> kMethods = {"elastic", "naive", "lscm", "arap", "dcm"};
const std::vector<std::string> kBaselines = {"naive", "lscm", "arap", "dcm"};

// One table of the page per report key. The perfect value of a per-triangle metric is the
// library's (perfect_value); the counts, the length energy and seconds are perfect at 0.
struct MetricColumn {
  std::string key;
  std::string qualifier;                  // after the key in the title ("forward", "particles")
  std::optional<TriangleMetric> measure;  // the triangle metric the aggregate is of
  bool timing = false;                    // seconds: no perfect value, no best value
  std::string note;                       // before the perfect value in the title

  double perfect() const { return measure ? perfect_value(*measure) : 0.0; }
  // Closeness to perfect: |value - perfect| where perfect is not 0 (a stretch of 0.9 is as far
  // from perfect as one of 1.1), else the value itself.
  double score(double value) const {
    return perfect() != 0.0 ? std::abs(value - perfect()) : value;
  }
  std::string title() const {
    if (timing) return key + " " + qualifier;
    return key + qualifier + " (" + note + fmt(perfect()) + " is perfect)";
  }
};
const std::vector<MetricColumn> kMetricTables = {
    {"length_energy", "", std::nullopt, false, "eq. 13 normalised; "},
    {"symmetric_dirichlet", "", TriangleMetric::SymmetricDirichlet, false, ""},
    {"angle_error_mean_deg", "", TriangleMetric::AngleError, false, ""},
    {"angle_error_max_deg", "", TriangleMetric::AngleError, false, ""},
    {"stretch_l2", ", forward", TriangleMetric::StretchL2, false, ""},
    {"stretch_linf", ", forward", TriangleMetric::StretchLinf, false, ""},
    {"inverse_stretch_l2", "", TriangleMetric::InverseStretchL2, false, ""},
    // The largest inverse stretch 1/s2: perfect where the inverse L2 stretch is.
    {"inverse_stretch_linf", "", TriangleMetric::InverseStretchL2, false, ""},
    {"area_distortion", "", TriangleMetric::AreaDistortion, false, ""},
    {"conformal_distortion", "", TriangleMetric::ConformalDistortion, false, ""},
    {"folds", "", std::nullopt, false, ""},
    {"outside", " particles", std::nullopt, false, ""},
    {"seconds", "on the shared grid", std::nullopt, true, ""},
};

bool has_metric(const nlohmann::json& method, const std::string& key) {
  return method.contains(key) && method[key].is_number();
}

// The page's prose (what the methods are, what the bar is) lives in the cases file beside the cases
// it describes ("page": {"methods": ..., "bar": ...}); a cases file without it gets the tables
// alone.
std::string page_text(const nlohmann::json& cases_file, const char* key) {
  if (!cases_file.contains("page") || !cases_file["page"].is_object()) return "";
  const nlohmann::json& page = cases_file["page"];
  return page.contains(key) && page[key].is_string() ? page[key].get<std::string>() : "";
}

// The page's Table 1: one row per case, with the paper's numbers beside ours.
void table1_section(std::ostringstream& s, const nlohmann::json& cases) {
  s << "## Table 1\n\n"
    << "| source → target | particles (paper) | springs (paper) | seconds | paper seconds | "
       "iterations | folds | length_energy | symmetric_dirichlet |\n"
    << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& c : cases) {
    s << "| " << c["name"].get<std::string>() << " | ";
    if (c.contains("skipped")) {
      s << "skipped: " << c["skipped"].get<std::string>() << " ||||||||\n";
      continue;
    }
    const auto paper = [&](const char* key) {
      return c[key].is_number() ? c[key].dump() : std::string("–");
    };
    s << c["particles"] << " (" << paper("paper_particles") << ") | " << c["springs"] << " ("
      << paper("paper_springs") << ") | " << fmt(c["seconds"].get<double>(), 3) << " | "
      << paper("paper_seconds") << " | " << c["iterations"] << " | " << c["folds"] << " | "
      << fmt(c["length_energy"].get<double>()) << " | "
      << fmt(c["symmetric_dirichlet"].get<double>()) << " |\n";
  }
}

// One table per metric (kMetricTables), every method a column, the best value of a row in bold.
void metric_sections(std::ostringstream& s, const nlohmann::json& cases) {
  s << "\n## Every metric, every method\n\nBold: the best value of the row (closest to perfect).\n";
  for (const MetricColumn& col : kMetricTables) {
    s << "\n### " << col.title() << "\n\n| case |";
    for (const auto& m : kMethods) s << ' ' << m << " |";
    s << "\n|---|";
    for (size_t k = 0; k < kMethods.size(); ++k) s << "---:|";
    s << '\n';
    for (const auto& c : cases) {
      if (c.contains("skipped")) continue;
      const nlohmann::json& methods = c["methods"];
      double best = INFINITY;
      for (const auto& m : kMethods) {
        if (methods.contains(m) && has_metric(methods[m], col.key)) {
          const double v = methods[m][col.key].get<double>();
          best = std::min(best, col.score(v));
        }
      }
      s << "| " << c["name"].get<std::string>() << " |";
      for (const auto& m : kMethods) {
        if (!methods.contains(m) || !has_metric(methods[m], col.key)) {
          s << (methods.contains(m) && methods[m].contains("error") ? " failed |" : " – |");
          continue;
        }
        const double v = methods[m][col.key].get<double>();
        const std::string text = fmt(v);
        s << ' ' << (col.score(v) == best && !col.timing ? "**" + text + "**" : text) << " |";
      }
      s << '\n';
    }
  }
}

// ElasticPaint against LSCM: ratios, folds and outside particles.
void lscm_section(std::ostringstream& s, const nlohmann::json& cases) {
  const double sd_perfect = perfect_value(TriangleMetric::SymmetricDirichlet);
  s << "\n## Against LSCM\n\nRatios elastic / lscm (below 1: ElasticPaint is better) and the "
       "folds and outside particles of both.\n\n"
    << "| case | length_energy ratio | symmetric_dirichlet − 4 ratio | angle_error_mean ratio | "
       "folds elastic / lscm | outside lscm |\n|---|---:|---:|---:|---:|---:|\n";
  for (const auto& c : cases) {
    if (c.contains("skipped")) continue;
    const nlohmann::json& e = c["methods"]["elastic"];
    const nlohmann::json& l = c["methods"]["lscm"];
    s << "| " << c["name"].get<std::string>() << " | ";
    if (!has_metric(l, "length_energy")) {
      s << "lscm failed ||||\n";
      continue;
    }
    const auto ratio = [](double a, double b) { return b > 0.0 ? fmt(a / b, 3) : "–"; };
    s << ratio(e["length_energy"].get<double>(), l["length_energy"].get<double>()) << " | "
      << ratio(e["symmetric_dirichlet"].get<double>() - sd_perfect,
               l["symmetric_dirichlet"].get<double>() - sd_perfect)
      << " | "
      << ratio(e["angle_error_mean_deg"].get<double>(), l["angle_error_mean_deg"].get<double>())
      << " | " << e["folds"] << " / " << l["folds"] << " | " << l["outside"] << " |\n";
  }
}

// The bar of issue 5: no folds, and length energy and symmetric Dirichlet at most the best other
// method's.
void bar_section(std::ostringstream& s, const nlohmann::json& cases,
                 const nlohmann::json& cases_file) {
  const std::string bar_text = page_text(cases_file, "bar");
  s << "\n## The bar (issue 5)\n\n"
    << (bar_text.empty() ? "" : bar_text + "\n\n")
    << "| case | folds | length_energy: elastic / best other | symmetric_dirichlet: elastic / "
       "best other | verdict |\n|---|---:|---|---|---|\n";
  for (const auto& c : cases) {
    if (c.contains("skipped")) continue;
    const nlohmann::json& methods = c["methods"];
    const nlohmann::json& e = methods["elastic"];
    const auto best_other = [&](const std::string& key, std::string& who) {
      double best = INFINITY;
      for (const auto& m : kBaselines) {
        if (methods.contains(m) && has_metric(methods[m], key) &&
            methods[m][key].get<double>() < best) {
          best = methods[m][key].get<double>();
          who = m;
        }
      }
      return best;
    };
    std::string who_len, who_sd;
    const double best_len = best_other("length_energy", who_len);
    const double best_sd = best_other("symmetric_dirichlet", who_sd);
    const double len = e["length_energy"].get<double>();
    const double sd = e["symmetric_dirichlet"].get<double>();
    const bool pass = e["folds"].get<int>() == 0 && len <= best_len && sd <= best_sd;
    s << "| " << c["name"].get<std::string>() << " | " << e["folds"] << " | " << fmt(len) << " / "
      << fmt(best_len) << " (" << who_len << ") | " << fmt(sd) << " / " << fmt(best_sd) << " ("
      << who_sd << ") | " << (pass ? "pass" : "**fail**") << " |\n";
  }
}

std::string results_markdown(const nlohmann::json& report, const nlohmann::json& cases_file) {
  std::ostringstream s;
  const nlohmann::json& cases = report["cases"];
  const nlohmann::json& machine = report["machine"];
  s << "# Results: the paper's Table 1 reproduced\n\n"
    << generated_by(machine, "results", "table1") << ", solver threads "
    << machine["solver_threads"] << ", median of " << report["runs"]
    << " runs. Raw numbers: [results/table1.json](results/table1.json). Cases, regions and why: "
       "`tools/benchmarks/table1_cases.json`. Metric definitions: [metrics.md](metrics.md).\n\n";
  const std::string methods_text = page_text(cases_file, "methods");
  if (!methods_text.empty()) s << methods_text << "\n\n";

  table1_section(s, cases);
  metric_sections(s, cases);
  lscm_section(s, cases);
  bar_section(s, cases, cases_file);
  return s.str();
}

int run_bench(const BenchArgs& args, const CLI::App& sub) {
  if (args.runs < 1) throw UsageError("--runs: must be at least 1");
  const nlohmann::json cases_file = read_cases_file(args.cases);
  nlohmann::json report;
  report["job"] = job_of(sub);
  report["runs"] = args.runs;
  report["machine"] = machine_json(args.threads);
  report["cases"] = nlohmann::json::array();
  for (const auto& c : cases_file["cases"]) {
    if (c.value("extra", false) && !args.extra) continue;
    if (!args.only.empty() && c.value("name", "") != args.only) continue;
    try {
      report["cases"].push_back(run_case(c, args));
    } catch (const nlohmann::json::exception& e) {
      throw InvalidInputError(args.cases, std::string("bad case: ") + e.what());
    } catch (const Error& e) {
      // A case that fails (a region that cannot be built, a stage that fails numerically) is a
      // result to report, not a reason to lose the other cases.
      report["cases"].push_back({{"name", c.value("name", "")},
                                 {"source", c.value("source", "")},
                                 {"target", c.value("target", "")},
                                 {"skipped", std::string("failed: ") + e.what()}});
    }
    const nlohmann::json& last = report["cases"].back();
    if (!args.quiet) {
      std::cerr << "elastic bench: " << last["name"].get<std::string>()
                << (last.contains("skipped") ? " skipped: " + last["skipped"].get<std::string>()
                                             : " done")
                << '\n';
    }
  }
  write_report(args.report, report);
  const std::string page = results_markdown(report, cases_file);
  if (!args.markdown.empty()) {
    write_file_atomically(args.markdown, [&](std::ofstream& out) { out << page; });
  } else {
    std::cout << page;
  }
  return kOk;
}

}  // namespace
}  // namespace elastic::cli

ELASTIC_COMMAND(
    "bench",
    "Benchmarks: `bench table1` (the paper's Table 1), `bench robustness` (real "
    "inputs), `bench scale` (speed against CGAL's LSCM), `bench decals` (placed "
    "decals against the exponential map), `bench warm` (warm-started maps of a "
    "dragged region against cold ones)",
    [](CLI::App& sub) {
      auto a = std::make_shared<elastic::cli::BenchArgs>();
      sub.require_subcommand(1);
      CLI::App* table1 =
          sub.add_subcommand("table1", "The paper's nine cases: ElasticPaint and the baselines");
      table1->add_option("--cases", a->cases, "Cases file (JSON)");
      table1->add_option("--root", a->root, "Folder the cases' mesh paths are relative to");
      table1->add_option("--report", a->report, "Write the JSON report here");
      table1->add_option("--markdown", a->markdown,
                         "Write the Markdown results page here (default: stdout)");
      table1->add_option("--runs", a->runs, "Runs per case (median seconds)")
          ->check(CLI::Range(1, 100));
      table1->add_option("--threads", a->threads, "Threads of every stage (0: all)")
          ->check(CLI::Range(0, 1024));
      table1->add_option("--only", a->only, "Run only the case with this name");
      table1->add_flag("--extra", a->extra,
                       "Also run the extra cases (real meshes of ../shared/meshes)");
      table1->add_flag("--quiet,-q", a->quiet, "No progress lines on stderr");
      const std::function<int()> robustness = elastic::cli::add_robustness_subcommand(sub);
      CLI::App* scale_sub = nullptr;
      const std::function<int()> scale = elastic::cli::add_scale_subcommand(sub);
      scale_sub = sub.get_subcommand("scale");
      const std::function<int()> decals = elastic::cli::add_decals_subcommand(sub);
      CLI::App* decals_sub = sub.get_subcommand("decals");
      const std::function<int()> warm = elastic::cli::add_warm_subcommand(sub);
      CLI::App* warm_sub = sub.get_subcommand("warm");
      return [a, table1, robustness, scale, scale_sub, decals, decals_sub, warm, warm_sub] {
        if (table1->parsed()) return elastic::cli::run_bench(*a, *table1);
        if (scale_sub->parsed()) return scale();
        if (decals_sub->parsed()) return decals();
        if (warm_sub->parsed()) return warm();
        return robustness();
      };
    });
