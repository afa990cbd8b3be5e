#pragma once
// `elastic bench robustness`: ElasticPaint with the defaults a user gets, against the LSCM, ARAP
// and DCM baselines on the same particle grid, over a matrix of public cases
// (tools/benchmarks/robustness_cases.json), each judged by the pass criteria below. JSON report
// (`cases`, each with a boolean `pass`) and a Markdown table (docs/results.md, "Robustness").

#include <CLI/CLI.hpp>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace elastic::cli {

/// The pass criteria of a robustness case, in one place (docs/results.md quotes them).
struct RobustnessCriteria {
  double min_sigma = 0.2;      ///< worst-triangle sigma_min (over the rest scale) at least this
  double sd_factor = 1.02;     ///< symmetric Dirichlet at most this times the best baseline's
  double length_factor = 0.9;  ///< length energy at most this times the best baseline's ...
  double length_floor = 1e-4;  ///< ... or, where the best baseline's is below this,
  double length_slack = 1e-5;  ///< ... at most this above it
};

/// The checks of one case: {"exit_0", "converged", "fold_free", "sigma_min", "symmetric_dirichlet",
/// "length_energy"} (booleans) and "pass" (all of them). `elastic` holds ElasticPaint's figures
/// ("exit", "converged", "folds", "sigma_min", "symmetric_dirichlet", "length_energy"), `best` the
/// best baseline's ("symmetric_dirichlet", "length_energy"; null when no baseline ran).
nlohmann::json judge_robustness_case(const nlohmann::json& elastic, const nlohmann::json& best,
                                     const RobustnessCriteria& criteria = {});

/// Adds `robustness` to the `bench` command and returns the function that runs it.
std::function<int()> add_robustness_subcommand(CLI::App& bench);

}  // namespace elastic::cli
