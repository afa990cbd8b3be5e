#include "bench_robustness.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <vector>

#include "bench_common.h"
#include "command.h"
#include "compare_methods.h"
#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"
#include "job_file.h"
#include "map_job.h"
#include "verdict.h"

namespace elastic::cli {
namespace {

namespace fs = std::filesystem;

struct RobustnessArgs : BenchCaseArgs {
  std::string newton = "auto";  ///< --newton: ElasticPaint's only non-default choice allowed
};

const std::vector<std::string> kBaselines = {"lscm", "arap", "dcm"};

// The best baseline's figure of each metric (smallest SD, length energy and folds; largest
// sigma_min) and which baseline it is. Only baselines that produced a valid map (ran, no folds, no
// particle outside the target region) compete: a folded or partial map's figures leave out or
// mis-sign its worst triangles. When none is valid, the ones that ran do (`valid` false).
nlohmann::json best_baseline(const nlohmann::json& methods) {
  std::vector<std::string> ran, valid;
  for (const std::string& name : kBaselines) {
    if (!methods.contains(name) || methods[name].contains("error")) {
      continue;
    }
    ran.push_back(name);
    const nlohmann::json& m = methods[name];
    if (m.value("folds", 1) == 0 && m.value("outside", 1) == 0) {
      valid.push_back(name);
    }
  }
  if (ran.empty()) {
    return nullptr;
  }
  const std::vector<std::string>& pool = valid.empty() ? ran : valid;
  nlohmann::json best = {{"valid", !valid.empty()}};
  const auto pick = [&](const char* key, bool larger, const std::vector<std::string>& from) {
    double value = larger ? -INFINITY : INFINITY;
    std::string who;
    for (const std::string& name : from) {
      const double v = json_number(methods[name], key);
      if (std::isnan(v)) {
        continue;
      }
      if (larger ? v > value : v < value) {
        value = v;
        who = name;
      }
    }
    best[key] = who.empty() ? nlohmann::json() : nlohmann::json(value);
    best[std::string(key) + "_method"] = who;
  };
  pick("symmetric_dirichlet", false, pool);
  pick("length_energy", false, pool);
  pick("folds", false, ran);
  pick("sigma_min", true, ran);
  return best;
}

// Sum of target and source areas of the naive map's measured triangles: the target region's area
// on the grid (the naive map covers it) against the source region's.
void area_ratios(const MapSession& s, double& raw, double& scaled) {
  const TriangleValues& t = s.naive_metrics.per_triangle;
  double at = 0.0, as = 0.0;
  for (size_t k = 0; k < t.target_area.size(); ++k) {
    if (t.excluded[k] || !std::isfinite(t.target_area[k])) {
      continue;
    }
    at += t.target_area[k];
    as += t.source_area[k];
  }
  raw = as > 0.0 ? at / as : std::numeric_limits<double>::quiet_NaN();
  const double sigma = s.result.rest_scale;
  scaled = raw / (sigma * sigma);
}

nlohmann::json run_case(const nlohmann::json& c, const RobustnessArgs& args, SurfaceCache& cache) {
  nlohmann::json out = {{"name", c.at("name")},
                        {"reason", c.at("reason")},
                        {"source", c.value("source", "")},
                        {"source_image", c.value("source_image", "")},
                        {"source_region", c.value("source_region", "boundary")},
                        {"target", c.at("target")},
                        {"target_region", c.value("target_region", "boundary")},
                        {"requested_particles", c.at("particles")},
                        {"pass", false}};
  // The defaults a user gets: only what the case names is set.
  MapJob job;
  const auto path = [&](const std::string& p) { return (fs::path(args.root) / p).string(); };
  if (c.contains("source")) {
    job.source = path(c["source"].get<std::string>());
  }
  if (c.contains("source_image")) {
    job.source_image = path(c["source_image"].get<std::string>());
  }
  job.source_region = rooted_spec(out["source_region"].get<std::string>(), args.root);
  job.target = path(c["target"].get<std::string>());
  job.target_region = rooted_spec(out["target_region"].get<std::string>(), args.root);
  job.source_anchor = c.value("source_anchor", "");
  job.target_anchor = c.value("target_anchor", "");
  job.particles = c["particles"].get<long>();
  job.threads = args.threads;
  job.newton = args.newton;
  job.quiet = true;
  if (const std::string missing = missing_input(job); !missing.empty()) {
    out["error"] = missing + " is not present";
    return out;
  }
  try {
    const std::unique_ptr<MapSession> session = run_map_job(job, {}, {}, 1, &cache);
    const MapVerdict verdict = judge_map(job, *session);
    const auto start = std::chrono::steady_clock::now();
    const std::vector<MethodMeasurement> methods = compare_methods(*session);
    const double baseline_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    const MapResult& r = session->result;
    out["particles"] = r.sampling.statistics.particles;
    out["rest_scale"] = r.rest_scale;
    double raw = 0.0, scaled = 0.0;
    area_ratios(*session, raw, scaled);
    out["area_ratio"] = raw;
    out["area_ratio_over_sigma2"] = scaled;
    out["seconds"] = session->seconds_total - session->seconds_loading;
    out["seconds_baselines"] = baseline_seconds;
    out["iterations"] = r.relaxation.iterations;
    out["stop_reason"] = verdict.reason;
    out["verdict"] = verdict.to_json();
    nlohmann::json& m = out["methods"];
    m = nlohmann::json::object();
    for (const MethodMeasurement& x : methods) {
      m[x.name] = measurement_json(x);
    }
    const nlohmann::json& e = m["elastic"];
    out["elastic"] = {{"exit", verdict.exit_code()},
                      {"converged", verdict.converged},
                      {"folds", session->metrics.folds},
                      {"sigma_min", session->metrics.sigma_min},
                      {"symmetric_dirichlet", e["symmetric_dirichlet"]},
                      {"length_energy", e["length_energy"]}};
    out["best"] = best_baseline(m);
    out["checks"] = judge_robustness_case(out["elastic"], out["best"]);
    out["pass"] = out["checks"]["pass"];
  } catch (const Error& e) {
    // A case whose regions cannot be built or whose map throws is a failed case, reported.
    out["error"] = e.what();
  }
  return out;
}

std::string check_cell(const nlohmann::json& c, const char* check, const std::string& text) {
  const bool ok = c.contains("checks") && c["checks"].value(check, false);
  return ok ? text : "**" + text + "**";
}

std::string robustness_markdown(const nlohmann::json& report) {
  const nlohmann::json& cases = report["cases"];
  const RobustnessCriteria k;
  std::ostringstream s;
  int passed = 0, errors = 0;
  std::map<std::string, int> failed_checks;
  double worst_sd = 0.0, worst_len = 0.0, total_seconds = 0.0, max_seconds = 0.0;
  std::string worst_sd_case, worst_len_case;
  for (const auto& c : cases) {
    passed += c["pass"].get<bool>() ? 1 : 0;
    if (c.contains("error")) {
      ++errors;
      continue;
    }
    for (const auto& [name, value] : c["checks"].items()) {
      if (name != "pass" && !value.get<bool>()) {
        ++failed_checks[name];
      }
    }
    total_seconds += c["seconds"].get<double>();
    max_seconds = std::max(max_seconds, c["seconds"].get<double>());
    const nlohmann::json& b = c["best"];
    if (b.is_object()) {
      const double sd =
          json_number(c["elastic"], "symmetric_dirichlet") / json_number(b, "symmetric_dirichlet");
      const double len =
          json_number(c["elastic"], "length_energy") / json_number(b, "length_energy");
      if (sd > worst_sd) {
        worst_sd = sd;
        worst_sd_case = c["name"].get<std::string>();
      }
      if (len > worst_len) {
        worst_len = len;
        worst_len_case = c["name"].get<std::string>();
      }
    }
  }
  s << generated_by(report["machine"], "robustness", "robustness")
    << ". Cases and the reason for each: "
       "`tools/benchmarks/robustness_cases.json`; "
       "raw numbers: [results/robustness.json](results/robustness.json).\n\n"
    << "Every case runs `elastic compare` with the defaults a user gets (only the surfaces, "
       "regions "
       "and particle count are set) and the LSCM, ARAP and DCM baselines on the same grid. A case "
       "**passes** when: exit 0 (converged and no folds, the verdict of `map`, `paste` and "
       "`compare`), converged, zero folds (docs/metrics.md: a face with an inverted or degenerate "
       "triangle in either triangulation), worst-triangle sigma_min >= "
    << k.min_sigma << " (over the rest scale), symmetric Dirichlet <= " << k.sd_factor
    << " x the best baseline's, and length energy <= " << k.length_factor
    << " x the best baseline's (or at most " << k.length_slack << " above it where that is below "
    << k.length_floor
    << "). The best baseline is the best of LSCM, ARAP and DCM per metric among those whose map is "
       "valid (no folds, no particle outside; if none is, among those that ran). Failed checks are "
       "in bold; the baseline figures are in parentheses with the method's initial (l = LSCM, "
       "a = ARAP, d = DCM). Area: target / source area of the regions (on the grid), and the same "
       "over sigma^2 (the compression left after the rest scale: below 1 compresses, above 1 "
       "stretches).\n\n";
  s << "**Summary: " << passed << " of " << cases.size() << " cases pass.**";
  if (errors > 0) {
    s << " " << errors << " did not run (error in the table).";
  }
  s << " Failed checks:";
  bool any = false;
  for (const auto& [name, count] : failed_checks) {
    s << (any ? "," : "") << ' ' << name << ' ' << count;
    any = true;
  }
  if (!any) {
    s << " none";
  }
  s << ". Worst ratios to the best baseline: symmetric Dirichlet " << fmt_number(worst_sd) << " ("
    << worst_sd_case << "), length energy " << fmt_number(worst_len) << " (" << worst_len_case
    << "). ElasticPaint's seconds: " << fmt_number(total_seconds) << " in all, at most "
    << fmt_number(max_seconds) << " per case.\n\n";

  s << "| case | particles | area (÷σ²) | exit | converged | folds | worst σ_min | sym. Dirichlet "
       "| length energy | seconds (baselines) | pass |\n"
    << "|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---|\n";
  const auto initial = [](const nlohmann::json& b, const std::string& key) {
    const std::string who = b.value(key + "_method", "");
    return who.empty() ? std::string() : std::string(1, who[0]) + " ";
  };
  for (const auto& c : cases) {
    s << "| " << c["name"].get<std::string>() << " | ";
    if (c.contains("error")) {
      s << "error: " << c["error"].get<std::string>() << " |||||||||**fail** |\n";
      continue;
    }
    const nlohmann::json& e = c["elastic"];
    const nlohmann::json& b = c["best"];
    const auto beside = [&](const std::string& key, double v, int digits) {
      std::string text = fmt_number(v, digits);
      if (b.is_object() && b[key].is_number()) {
        text += " (" + initial(b, key) + fmt_number(b[key].get<double>(), digits) + ")";
      }
      return text;
    };
    s << c["particles"] << " | " << fmt_number(json_number(c, "area_ratio"), 2) << " ("
      << fmt_number(json_number(c, "area_ratio_over_sigma2"), 2) << ") | "
      << check_cell(c, "exit_0", std::to_string(e["exit"].get<int>())) << " | "
      << check_cell(c, "converged", e["converged"].get<bool>() ? "yes" : "no") << " | "
      << check_cell(c, "fold_free", beside("folds", json_number(e, "folds"), 4)) << " | "
      << check_cell(c, "sigma_min", beside("sigma_min", json_number(e, "sigma_min"), 3)) << " | "
      << check_cell(c, "symmetric_dirichlet",
                    beside("symmetric_dirichlet", json_number(e, "symmetric_dirichlet"), 4))
      << " | "
      << check_cell(c, "length_energy", beside("length_energy", json_number(e, "length_energy"), 3))
      << " | " << fmt_number(json_number(c, "seconds"), 2) << " ("
      << fmt_number(json_number(c, "seconds_baselines"), 2) << ") | "
      << (c["pass"].get<bool>() ? "pass" : "**fail**") << " |\n";
  }
  return s.str();
}

int run_robustness(const RobustnessArgs& args, const CLI::App& sub) {
  const nlohmann::json cases_file = read_cases_file(args.cases);
  nlohmann::json report;
  report["job"] = job_of(sub);
  report["machine"] = machine_json(args.threads);
  const RobustnessCriteria k;
  report["criteria"] = {{"exit", 0},
                        {"converged", true},
                        {"folds", 0},
                        {"min_sigma", k.min_sigma},
                        {"sd_factor", k.sd_factor},
                        {"length_factor", k.length_factor},
                        {"length_floor", k.length_floor},
                        {"length_slack", k.length_slack}};
  report["cases"] = nlohmann::json::array();
  int passed = 0;
  // Cases share their meshes: each is read and prepared once (limit surface, projector), so a
  // case's seconds are its map, not the loading.
  SurfaceCache cache;
  for (const auto& c : cases_file["cases"]) {
    if (!args.only.empty() && c.value("name", "") != args.only) {
      continue;
    }
    if (!args.quiet) {
      std::cerr << "elastic bench robustness: " << c.value("name", "?") << '\n';
    }
    try {
      report["cases"].push_back(run_case(c, args, cache));
    } catch (const nlohmann::json::exception& e) {
      throw InvalidInputError(args.cases, std::string("bad case: ") + e.what());
    }
    const nlohmann::json& last = report["cases"].back();
    passed += last["pass"].get<bool>() ? 1 : 0;
    if (!args.quiet) {
      std::cerr << "elastic bench robustness: " << last["name"].get<std::string>() << ' '
                << (last.contains("error")     ? "error: " + last["error"].get<std::string>()
                    : last["pass"].get<bool>() ? std::string("pass")
                                               : std::string("fail"))
                << '\n';
    }
  }
  report["summary"] = {{"cases", report["cases"].size()}, {"passed", passed}};
  write_bench_outputs(args, report, robustness_markdown(report));
  return kOk;
}

}  // namespace

nlohmann::json judge_robustness_case(const nlohmann::json& elastic, const nlohmann::json& best,
                                     const RobustnessCriteria& k) {
  nlohmann::json checks;
  checks["exit_0"] = elastic.value("exit", -1) == 0;
  checks["converged"] = elastic.value("converged", false);
  checks["fold_free"] = elastic.value("folds", -1) == 0;
  const double sigma = json_number(elastic, "sigma_min");
  checks["sigma_min"] = sigma >= k.min_sigma;  // false for NaN
  const double sd = json_number(elastic, "symmetric_dirichlet");
  const double len = json_number(elastic, "length_energy");
  const double none = std::numeric_limits<double>::quiet_NaN();
  const double best_sd = best.is_object() ? json_number(best, "symmetric_dirichlet") : none;
  const double best_len = best.is_object() ? json_number(best, "length_energy") : none;
  // No baseline figure to compare with: the comparison cannot fail.
  checks["symmetric_dirichlet"] = std::isnan(best_sd) || sd <= k.sd_factor * best_sd;
  checks["length_energy"] = std::isnan(best_len) || len <= k.length_factor * best_len ||
                            (best_len < k.length_floor && len <= best_len + k.length_slack);
  bool pass = true;
  for (const auto& [name, value] : checks.items()) {
    pass = pass && value.get<bool>();
  }
  checks["pass"] = pass;
  return checks;
}

std::function<int()> add_robustness_subcommand(CLI::App& bench) {
  auto a = std::make_shared<RobustnessArgs>();
  CLI::App* sub = bench.add_subcommand(
      "robustness",
      "Real meshes and ordinary choices: ElasticPaint (defaults) and the baselines, pass/fail");
  add_bench_case_options(*sub, *a, "robustness_cases.json");
  sub->add_option("--newton", a->newton,
                  "ElasticPaint's --newton (default auto, as a user gets it): off compares "
                  "the Laplacian H0 alone on the same cases")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  sub->footer(
      "Example:\n  elastic bench robustness --report robustness.json --markdown robustness.md\n"
      "Prints the table on stdout; exits 0 when every case ran (passing or not).");
  return [a, sub] { return run_robustness(*a, *sub); };
}

}  // namespace elastic::cli
