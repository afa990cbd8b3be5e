#include "job_file.h"

#include <charconv>
#include <fstream>
#include <sstream>

#include "elastic/core/error.h"

namespace elastic::cli {
namespace {

/// The long name of an option ("source-region" for --source-region), empty for positionals.
std::string key_of(const CLI::Option& option) {
  const auto& names = option.get_lnames();
  return names.empty() ? std::string() : names.front();
}

bool skipped(const std::string& key) {
  return key.empty() || key == "job" || key == "help";
}

/// A JSON value as the strings CLI11 parses ("5775", "true", "disk:0,0,0,1").
std::vector<std::string> as_strings(const nlohmann::json& value, const std::string& where) {
  if (value.is_string()) return {value.get<std::string>()};
  if (value.is_boolean()) return {value.get<bool>() ? "true" : "false"};
  if (value.is_number_integer()) return {std::to_string(value.get<long long>())};
  if (value.is_number()) {
    std::ostringstream out;
    out.precision(17);
    out << value.get<double>();
    return {out.str()};
  }
  if (value.is_array()) {
    std::vector<std::string> all;
    for (const nlohmann::json& item : value) {
      if (item.is_array() || item.is_object()) {
        throw UsageError(where + ": nested arrays and objects are not flag values");
      }
      for (std::string& s : as_strings(item, where)) all.push_back(std::move(s));
    }
    return all;
  }
  throw UsageError(where + ": expected a string, number, boolean or array");
}

/// A flag value as JSON: numbers and booleans typed, the rest strings.
nlohmann::json as_json(const std::string& text) {
  if (text == "true") return true;
  if (text == "false") return false;
  long long integer = 0;
  const char* end = text.data() + text.size();
  if (!text.empty()) {
    auto [p, ec] = std::from_chars(text.data(), end, integer);
    if (ec == std::errc() && p == end) return integer;
    double real = 0.0;
    auto [q, ec2] = std::from_chars(text.data(), end, real);
    if (ec2 == std::errc() && q == end) return real;
  }
  return text;
}

}  // namespace

void add_job_option(CLI::App& sub) {
  sub.add_option("--job",
                 "Job file (JSON): flags as keys without dashes; the command line wins. A "
                 "report's \"job\" is accepted, to repeat a run exactly")
      ->type_name("FILE");
}

void apply_job_file(CLI::App& sub) {
  const CLI::Option* job = sub.get_option_no_throw("--job");
  if (job == nullptr || job->count() == 0) return;
  const std::string path = job->as<std::string>();
  std::ifstream in(path);
  if (!in) throw IoError(path, "cannot open the job file");
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InvalidInputError(path, std::string("not a JSON job file (") + e.what() + ")");
  }
  // A report carries its job under "job".
  if (document.is_object() && document.contains("job") && document["job"].is_object()) {
    document = document["job"];
  }
  if (!document.is_object()) throw InvalidInputError(path, "a job file holds one JSON object");
  for (const auto& [key, value] : document.items()) {
    if (key == "command") {
      if (!value.is_string() || value.get<std::string>() != sub.get_name()) {
        throw UsageError(path + ": the job is for 'elastic " +
                         (value.is_string() ? value.get<std::string>() : std::string("?")) +
                         "', not 'elastic " + sub.get_name() + "'");
      }
      continue;
    }
    if (key == "version") continue;
    CLI::Option* option = sub.get_option_no_throw("--" + key);
    if (option == nullptr || skipped(key)) {
      throw UsageError(path + ": unknown key '" + key + "' for 'elastic " + sub.get_name() + "'");
    }
    if (option->count() > 0) continue;  // the command line wins
    try {
      for (std::string& s : as_strings(value, path + ": " + key)) option->add_result(std::move(s));
      option->run_callback();
    } catch (const CLI::Error& e) {
      throw UsageError(path + ": " + key + ": " + e.what());
    }
  }
}

nlohmann::json job_of(const CLI::App& sub) {
  nlohmann::json job = nlohmann::json::object();
  job["command"] = sub.get_name();
  job["version"] = ELASTIC_VERSION;
  for (const CLI::Option* option : sub.get_options()) {
    const std::string key = key_of(*option);
    if (skipped(key)) continue;
    std::vector<std::string> values = option->results();
    if (values.empty()) {
      const std::string fallback = option->get_default_str();
      if (fallback.empty()) continue;
      values = {fallback};
    }
    if (option->get_type_size_max() <= 1 && option->get_expected_max() <= 1) {
      // A flag given without a value records "true".
      job[key] = values.front().empty() ? nlohmann::json(true) : as_json(values.back());
    } else {
      nlohmann::json list = nlohmann::json::array();
      for (const std::string& v : values) list.push_back(as_json(v));
      job[key] = list;
    }
  }
  return job;
}

void require_flag(const std::string& value, const std::string& flag) {
  if (value.empty()) throw UsageError(flag + " is required");
}

}  // namespace elastic::cli
