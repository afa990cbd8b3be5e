#pragma once
// Job files: a JSON object that stands in for a subcommand's flags, so that a run can be repeated
// exactly. Every subcommand gets `--job FILE`; each key is a long flag name without its dashes
// ("source-region": "disk:0,0,0,0.5", "particles": 5775, "quiet": true), and flags given on the
// command line win over the file. A report written by a command records the job that produced it
// under "job", and `--job report.json` accepts such a report too (it reads its "job" object).

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace elastic::cli {

/// A usage error found after CLI11's parse (a missing required flag, a bad job file key); main()
/// turns it into exit code 64 with the message on one line.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Adds `--job FILE` to a subcommand (main() does this for every subcommand).
void add_job_option(CLI::App& sub);

/// When `--job FILE` was given, sets every option of `sub` that the command line did not give from
/// the file. \throws UsageError naming the file and the key for unknown keys or bad values;
/// elastic::IoError when the file cannot be read; elastic::InvalidInputError when it is not JSON.
void apply_job_file(CLI::App& sub);

/// The effective job of a parsed subcommand: {"command": name, "version": ..., key: value, ...}
/// with every option's value (given, from the job file, or its default), except --job and --help.
/// Numbers and booleans are written as JSON numbers and booleans.
nlohmann::json job_of(const CLI::App& sub);

/// Throws UsageError("--flag is required") when `value` is empty.
void require_flag(const std::string& value, const std::string& flag);

}  // namespace elastic::cli
