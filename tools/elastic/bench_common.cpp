#include "bench_common.h"

#include <ctime>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <thread>

#include "elastic/core/error.h"

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
