// Parsing region specifications (parse_region_spec, region_spec.h) and reading their point files:
// text and files only, no surface, so that the parsing can be fuzzed on its own
// (tests/fuzz/region_file_fuzzer.cpp).
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/regions/region_spec.h"

namespace elastic {
namespace {
std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) {
    return {};
  }
  const auto e = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(b, e - b + 1));
}

std::vector<double> parse_numbers(const std::string& text, const std::string& flag,
                                  const std::string& what) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const std::string t = trim(item);
    size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(t, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (t.empty() || used != t.size() || !std::isfinite(value)) {
      throw InvalidInputError(flag, what + ": '" + t + "' is not a finite number");
    }
    out.push_back(value);
  }
  return out;
}

/// Reads rows of `columns` numbers (blank lines and '#' comments skipped).
std::vector<Eigen::VectorXd> read_rows(const std::string& path, int columns) {
  std::ifstream in(path);
  if (!in) {
    throw IoError(path, "cannot open the file");
  }
  std::vector<Eigen::VectorXd> rows;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto hash = line.find('#');
    if (hash != std::string::npos) {
      line.erase(hash);
    }
    if (trim(line).empty()) {
      continue;
    }
    std::istringstream ls(line);
    Eigen::VectorXd row(columns);
    for (int c = 0; c < columns; ++c) {
      std::string token;
      if (!(ls >> token)) {
        throw InvalidInputError(path, "line " + std::to_string(number) + ": expected " +
                                          std::to_string(columns) + " numbers");
      }
      size_t used = 0;
      double value = 0.0;
      try {
        value = std::stod(token, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != token.size() || !std::isfinite(value)) {
        throw InvalidInputError(
            path, "line " + std::to_string(number) + ": '" + token + "' is not a finite number");
      }
      row[c] = value;
    }
    std::string extra;
    if (ls >> extra) {
      throw InvalidInputError(path, "line " + std::to_string(number) + ": expected " +
                                        std::to_string(columns) + " numbers, found more");
    }
    rows.push_back(row);
  }
  if (in.bad()) {
    throw IoError(path, "read error");
  }
  return rows;
}

}  // namespace

RegionSpec parse_region_spec(std::string_view text_in, std::string_view flag_in) {
  const std::string flag(flag_in);
  RegionSpec spec;
  spec.text = std::string(text_in);
  std::string text = trim(text_in);
  // Optional anchor suffix: "<spec>;anchor=X,Y,Z".
  const auto semi = text.find(";anchor=");
  if (semi != std::string::npos) {
    const auto values = parse_numbers(text.substr(semi + 8), flag, "anchor");
    if (values.size() != 3) {
      throw InvalidInputError(flag, "anchor needs X,Y,Z");
    }
    spec.anchor = Eigen::Vector3d(values[0], values[1], values[2]);
    text = trim(text.substr(0, semi));
  }
  const auto colon = text.find(':');
  const std::string kind = colon == std::string::npos ? text : text.substr(0, colon);
  const std::string arg = colon == std::string::npos ? std::string() : text.substr(colon + 1);
  if (kind == "boundary" && colon == std::string::npos) {
    spec.kind = RegionSpec::Kind::Boundary;
  } else if (kind == "disk") {
    const auto values = parse_numbers(arg, flag, "disk");
    if (values.size() != 4) {
      throw InvalidInputError(flag, "disk needs X,Y,Z,R, got '" + arg + "'");
    }
    spec.kind = RegionSpec::Kind::Disk;
    spec.center = Eigen::Vector3d(values[0], values[1], values[2]);
    spec.radius = values[3];
    if (!(spec.radius > 0.0)) {
      throw InvalidInputError(flag, "disk radius must be positive");
    }
  } else if (kind == "points") {
    if (arg.empty()) {
      throw InvalidInputError(flag, "points: needs a file name");
    }
    spec.kind = RegionSpec::Kind::Points;
    for (const auto& row : read_rows(arg, 3)) {
      spec.points.emplace_back(row[0], row[1], row[2]);
    }
    if (spec.points.size() < 3) {
      throw InvalidInputError(arg, "a points curve needs at least 3 points, the file has " +
                                       std::to_string(spec.points.size()));
    }
  } else if (kind == "uv") {
    if (arg.empty()) {
      throw InvalidInputError(flag, "uv: needs a file name");
    }
    spec.kind = RegionSpec::Kind::UvPolygon;
    for (const auto& row : read_rows(arg, 2)) {
      spec.uv_polygon.emplace_back(row[0], row[1]);
    }
    if (spec.uv_polygon.size() < 3) {
      throw InvalidInputError(arg, "a uv polygon needs at least 3 points, the file has " +
                                       std::to_string(spec.uv_polygon.size()));
    }
  } else {
    throw InvalidInputError(flag,
                            "unknown region '" + spec.text +
                                "' (expected disk:X,Y,Z,R, points:FILE, boundary or uv:FILE)");
  }
  return spec;
}

}  // namespace elastic
