#include "bench_common.h"

#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <thread>

#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"
#include "map_job.h"

namespace elastic::cli {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) {
        return line.substr(colon + 2);
      }
    }
  }
  return "unknown";
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  std::ostringstream s;
  s << std::put_time(&tm, "%Y-%m-%d %H:%M UTC");
  return s.str();
}

nlohmann::json machine_json(int solver_threads) {
  return {{"cpu", cpu_model()},
          {"threads", std::thread::hardware_concurrency()},
          {"solver_threads", solver_threads},
          {"date", utc_now()}};
}

void add_bench_case_options(CLI::App& sub, BenchCaseArgs& a, const std::string& cases_file) {
  a.cases = std::string(ELASTIC_SOURCE_DIR) + "/tools/benchmarks/" + cases_file;
  a.root = ELASTIC_SOURCE_DIR;
  sub.add_option("--cases", a.cases,
                 "Cases file (JSON; default tools/benchmarks/" + cases_file + ")");
  sub.add_option("--root", a.root, "Folder the cases' paths are relative to");
  sub.add_option("--report", a.report, "Write the JSON report here (cases with `pass`)");
  sub.add_option("--markdown", a.markdown, "Also write the Markdown table here");
  sub.add_option("--threads", a.threads, "Threads of every stage (0: all)")
      ->check(CLI::Range(0, 1024));
  sub.add_option("--only", a.only, "Run only the case with this name");
  sub.add_flag("--quiet,-q", a.quiet, "No progress lines on stderr");
}

void write_bench_outputs(const BenchCaseArgs& args, const nlohmann::json& report,
                         const std::string& page) {
  write_report(args.report, report);
  if (!args.markdown.empty()) {
    write_file_atomically(args.markdown, [&](std::ofstream& out) { out << page; });
  }
  std::cout << page;
}

std::string rooted_spec(const std::string& spec, const std::string& root) {
  for (const std::string kind : {"points:", "uv:"}) {
    if (spec.rfind(kind, 0) != 0) {
      continue;
    }
    const size_t end = spec.find(';');
    const std::string file = spec.substr(kind.size(), end - kind.size());
    if (std::filesystem::path(file).is_absolute()) {
      return spec;
    }
    return kind + (std::filesystem::path(root) / file).string() +
           (end == std::string::npos ? std::string() : spec.substr(end));
  }
  return spec;
}

std::string missing_input(const MapJob& job) {
  for (const std::string& p : {job.source, job.source_image, job.target}) {
    if (!p.empty() && !std::filesystem::exists(p)) {
      return p;
    }
  }
  return {};
}

std::string fmt_number(double v, int digits) {
  if (!std::isfinite(v)) {
    return std::isnan(v) ? "–" : (v > 0 ? "inf" : "-inf");
  }
  std::ostringstream o;
  o << std::setprecision(digits) << v;
  return o.str();
}

double json_number(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>()
                                               : std::numeric_limits<double>::quiet_NaN();
}

nlohmann::json read_cases_file(const std::string& path, const std::vector<std::string>& arrays) {
  nlohmann::json cases_file;
  std::ifstream in(path);
  if (!in) {
    throw IoError(path, "cannot open the cases file");
  }
  try {
    in >> cases_file;
  } catch (const nlohmann::json::exception& e) {
    throw InvalidInputError(path, std::string("not valid JSON: ") + e.what());
  }
  for (const std::string& key : arrays) {
    if (!cases_file.is_object() || !cases_file.contains(key) || !cases_file[key].is_array()) {
      throw InvalidInputError(path, "expected an object with a \"" + key + "\" array");
    }
  }
  return cases_file;
}

}  // namespace elastic::cli
