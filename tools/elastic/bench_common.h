#pragma once
// Shared by the `elastic bench` subcommands: the machine line of a results page and reading a
// cases file ({"cases": [...]}).

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "map_job.h"

namespace elastic::cli {

/// The CPU's model name from /proc/cpuinfo ("unknown" elsewhere).
std::string cpu_model();
/// The current time as "YYYY-MM-DD HH:MM UTC".
std::string utc_now();
/// {"cpu", "threads" (hardware), "solver_threads", "date"}.
nlohmann::json machine_json(int solver_threads);
/// The options every cases-file benchmark (`bench robustness`, `bench decals`) shares.
struct BenchCaseArgs {
  std::string cases;     ///< --cases FILE (the command's default under tools/benchmarks/)
  std::string root;      ///< --root: folder the cases' paths are relative to
  std::string report;    ///< --report FILE: the JSON report
  std::string markdown;  ///< --markdown FILE: the table, also printed on stdout
  std::string only;      ///< --only NAME: one case
  int threads = 0;       ///< --threads N (0: all)
  bool quiet = false;    ///< --quiet: no progress lines
};
/// Adds those options to `sub`, with `cases_file` (under tools/benchmarks/) as --cases' default.
void add_bench_case_options(CLI::App& sub, BenchCaseArgs& args, const std::string& cases_file);
/// Writes the report (--report) and the page (--markdown), and prints the page.
void write_bench_outputs(const BenchCaseArgs& args, const nlohmann::json& report,
                         const std::string& page);

/// A region spec whose file (points:FILE, uv:FILE) is relative, made relative to `root` like the
/// cases' mesh paths; other specs as they are.
std::string rooted_spec(const std::string& spec, const std::string& root);
/// The first of a job's input files (source, source image, target) that is not there, or "".
std::string missing_input(const MapJob& job);

/// A figure for a results table: `digits` significant digits; "–" for NaN, "inf" / "-inf".
std::string fmt_number(double v, int digits = 3);
/// j[key] as a double, NaN when absent or not a number.
double json_number(const nlohmann::json& j, const char* key);

/// Reads a cases file: a JSON object with the given arrays ("cases" by default).
/// \throws IoError when it cannot be opened; InvalidInputError when it is not such an object.
nlohmann::json read_cases_file(const std::string& path,
                               const std::vector<std::string>& arrays = {"cases"});

}  // namespace elastic::cli
