// libFuzzer target for job files (tools/elastic/job_file.h): the input is given as `--job FILE`
// to a subcommand with one option of every kind the tool uses (text, integers and reals with
// range checks, a choice, a flag, a list), then apply_job_file sets the options from it and
// job_of records the job. Each input must either apply or throw elastic::cli::UsageError or
// elastic::Error (exit 64, 65 or 66 in the tool); anything else is a finding.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "elastic/core/error.h"
#include "fuzz_scratch.h"
#include "job_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string file = elastic::fuzz::write_scratch_file(data, size, ".json").string();
  CLI::App app{"fuzz"};
  CLI::App* sub = app.add_subcommand("map", "a subcommand like the tool's");
  sub->option_defaults()->always_capture_default();
  std::string text = "boundary";
  long count = 1000;
  int level = 0;
  double width = 2.0;
  std::string choice = "lbfgs";
  bool quiet = false;
  std::vector<double> values;
  unsigned long seed = 0;
  sub->add_option("--source-region", text, "text");
  sub->add_option("--particles", count, "integer");
  sub->add_option("--subdivide", level, "integer in a range")->check(CLI::Range(0, 4));
  sub->add_option("--image-width", width, "positive real")->check(CLI::PositiveNumber);
  sub->add_option("--solver", choice, "choice")->check(CLI::IsMember({"lbfgs", "explicit"}));
  sub->add_flag("--quiet,-q", quiet, "flag");
  sub->add_option("--values", values, "list");
  sub->add_option("--seed", seed, "unsigned");
  elastic::cli::add_job_option(*sub);
  try {
    std::vector<std::string> args = {"fuzz", "map", "--job", file};
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    app.parse(static_cast<int>(argv.size()), argv.data());
    elastic::cli::apply_job_file(*sub);
    const nlohmann::json job = elastic::cli::job_of(*sub);
    if (job.at("command") != "map") std::abort();
  } catch (const elastic::cli::UsageError&) {
  } catch (const elastic::Error&) {
  }
  return 0;
}
