#pragma once
// Shared by the `elastic bench` subcommands: the machine line of a results page and reading a
// cases file ({"cases": [...]}).

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace elastic::cli {

/// The CPU's model name from /proc/cpuinfo ("unknown" elsewhere).
std::string cpu_model();
/// The current time as "YYYY-MM-DD HH:MM UTC".
std::string utc_now();
/// {"cpu", "threads" (hardware), "solver_threads", "date"}.
nlohmann::json machine_json(int solver_threads);
/// Reads a cases file: a JSON object with the given arrays ("cases" by default).
/// \throws IoError when it cannot be opened; InvalidInputError when it is not such an object.
nlohmann::json read_cases_file(const std::string& path,
                               const std::vector<std::string>& arrays = {"cases"});

}  // namespace elastic::cli
