#pragma once
// The one verdict on a map run, shared by `elastic map`, `compare`, `paste` and `bench
// robustness`: a map holds when the solver converged AND the final map has no folds by the one
// definition of docs/metrics.md (MapMetrics::folds: a grid face with an inverted or degenerate
// triangle in either of its triangulations). Such a run exits 0; any other exits 70 with exactly
// one line on stderr naming what failed and what to try (docs/cli.md).
//
//   const MapVerdict verdict = judge_map(job, session);
//   ... write the reports and tables first (they are the diagnosis) ...
//   return finish(verdict);

#include <nlohmann/json.hpp>
#include <string>

#include "map_job.h"

namespace elastic::cli {

struct MapVerdict {
  bool converged = false;  ///< the solver's stop is a convergence (FoldConstrained is not)
  std::string reason;      ///< the solver's stop reason, as in the report
  int folds = 0;           ///< folded faces of the final map (MapMetrics::folds)
  double sigma_min = 0.0;  ///< worst signed sigma_min of the final map (reported, not judged)
  /// What failed ("not converged (...)", "3 folded faces", both joined by "and"); empty when ok.
  std::string failure;
  /// What to try, e.g. "--source-region ellipse, --rest-scale area or --boundary slide".
  std::string advice;

  bool ok() const { return converged && folds == 0; }
  int exit_code() const;
  /// The stderr line without its newline: "elastic: the map failed: <failure>; try <advice>".
  std::string line() const;
  /// {"ok", "exit", "converged", "reason", "folds", "sigma_min", "failure", "advice"}.
  nlohmann::json to_json() const;
};

/// Judges the session's final map (MapSession::metrics) and the solver's stop.
MapVerdict judge_map(const MapJob& job, const MapSession& session);

/// Prints the verdict's line to stderr when it failed (always, --quiet included: it is the error
/// message of exit 70) and returns its exit code.
int finish(const MapVerdict& verdict);

}  // namespace elastic::cli
