#include "bench_decals.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <sstream>

#include "bench_common.h"
#include "command.h"
#include "compare_methods.h"
#include "elastic/baselines/decal_baseline.h"
#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"
#include "job_file.h"
#include "map_job.h"
#include "verdict.h"

namespace elastic::cli {
namespace {

namespace fs = std::filesystem;

struct DecalArgs : BenchCaseArgs {
  long particles = 0;  ///< --particles: every case's count (0: the cases file's)
};

// Signed angle (degrees, counter-clockwise about n) from a to b, both projected on the plane
// normal to n.
double turn_deg(Eigen::Vector3d a, Eigen::Vector3d b, const Eigen::Vector3d& n) {
  a -= n * n.dot(a);
  b -= n * n.dot(b);
  return std::atan2(n.dot(a.cross(b)), a.dot(b)) * 180.0 / std::numbers::pi;
}

// The boundary particles nearest the rectangle's corners: the extremes of the source coordinates
// along the four diagonals, in boundary-loop order.
std::vector<int> rectangle_corners(const ParticleGrid& grid, const DecalGeometry& g) {
  std::vector<int> corners;
  for (const Eigen::Vector2d& dir : {Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1),
                                     Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1)}) {
    int best = -1;
    double most = -std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < grid.boundary_loop.size(); ++k) {
      const double along =
          g.source_coordinates[static_cast<size_t>(grid.boundary_loop[k])].dot(dir);
      if (along > most) {
        most = along;
        best = static_cast<int>(k);
      }
    }
    corners.push_back(best);
  }
  std::sort(corners.begin(), corners.end());
  return corners;
}

nlohmann::json shape_json(const BoundaryShape& s) {
  return {{"edge_turning_deg", s.edge_turning_deg}, {"corner_error_deg", s.corner_error_deg}};
}

nlohmann::json figures(const nlohmann::json& m) {
  nlohmann::json out;
  for (const char* key : {"length_energy", "symmetric_dirichlet", "angle_error_mean_deg", "folds",
                          "sigma_min", "seconds"}) {
    out[key] = m.contains(key) ? m[key] : nlohmann::json();
  }
  if (m.contains("error")) {
    out["error"] = m["error"];
  }
  return out;
}

nlohmann::json run_case(const nlohmann::json& source, const nlohmann::json& size,
                        const nlohmann::json& target, long particles, const DecalArgs& args,
                        SurfaceCache& cache) {
  const auto path = [&](const std::string& p) { return (fs::path(args.root) / p).string(); };
  const double radius = size.at("fraction").get<double>() * target.at("feature_size").get<double>();
  const double scale = radius / source.at("radius").get<double>();
  const auto& point = target.at("point");
  std::ostringstream place;
  place << std::setprecision(9) << point[0].get<double>() << ',' << point[1].get<double>() << ','
        << point[2].get<double>() << ',' << target.value("angle", 0.0) << ',' << scale;
  nlohmann::json out = {
      {"name", source.at("name").get<std::string>() + " → " + target.at("name").get<std::string>() +
                   " " + size.at("name").get<std::string>()},
      {"source", source.at("name")},
      {"target", target.at("name")},
      {"size", size.at("name")},
      {"decal_radius", radius},
      {"target_place", place.str()},
      {"pass", false}};
  MapJob job;
  if (source.contains("source")) {
    job.source = path(source["source"].get<std::string>());
  }
  if (source.contains("source_image")) {
    job.source_image = path(source["source_image"].get<std::string>());
    job.image_width = source.value("image_width", job.image_width);
  }
  job.source_region = rooted_spec(source.value("source_region", "boundary"), args.root);
  job.target = path(target.at("target").get<std::string>());
  job.target_place = place.str();
  job.particles = particles;
  job.threads = args.threads;
  job.quiet = true;
  if (const std::string missing = missing_input(job); !missing.empty()) {
    out["error"] = missing + " is not present";
    return out;
  }
  try {
    const std::unique_ptr<MapSession> session = run_map_job(job, {}, {}, 1, &cache);
    const MapVerdict verdict = judge_map(job, *session);
    const std::vector<MethodMeasurement> methods = compare_methods(*session);
    nlohmann::json m = nlohmann::json::object();
    for (const MethodMeasurement& x : methods) {
      m[x.name] = measurement_json(x);
    }
    out["particles"] = session->result.sampling.statistics.particles;
    out["exit"] = verdict.exit_code();
    out["converged"] = verdict.converged;
    out["turned_deg"] = session->decal->turned_degrees;
    out["elastic"] = figures(m["elastic"]);
    out["elastic"]["seconds"] = session->seconds_total - session->seconds_loading;
    out["expmap"] = figures(m["expmap"]);
    if (source.value("corners", 0) == 4) {
      const ParticleGrid& grid = session->result.sampling.grid;
      const std::vector<int> corners = rectangle_corners(grid, *session->decal);
      const LimitSurface& surface = *session->target.surface;
      const std::vector<double> source_turns = boundary_turns(
          grid, *session->source.surface, grid.source_positions(), grid.source_points);
      const auto shape = [&](const Eigen::Matrix3Xd& x, const std::vector<SurfacePoint>& p) {
        return shape_json(
            boundary_shape(boundary_turns(grid, surface, x, p), source_turns, corners));
      };
      out["elastic"]["shape"] =
          shape(session->result.relaxation.positions, session->result.relaxation.points);
      const DecalBaselineResult expmap = exponential_map_decal(surface, *session->decal);
      out["expmap"]["shape"] = shape(expmap.positions, expmap.points);
    }
    const nlohmann::json& e = out["elastic"];
    const nlohmann::json& x = out["expmap"];
    nlohmann::json checks;
    checks["exit_0"] = verdict.exit_code() == 0;
    checks["fold_free"] = json_number(e, "folds") == 0.0;
    checks["length_energy"] = json_number(e, "length_energy") < json_number(x, "length_energy");
    checks["symmetric_dirichlet"] =
        json_number(e, "symmetric_dirichlet") < json_number(x, "symmetric_dirichlet");
    bool pass = true;
    for (const auto& [name, value] : checks.items()) {
      pass = pass && value.get<bool>();
    }
    checks["pass"] = pass;
    out["checks"] = checks;
    out["pass"] = pass;
  } catch (const Error& e) {
    out["error"] = e.what();
  }
  return out;
}

std::string bold_unless(bool ok, const std::string& text) {
  return ok ? text : "**" + text + "**";
}

// Symmetric Dirichlet minus its isometric value 4: the part that is distortion.
double sd_excess(const nlohmann::json& j) {
  return json_number(j, "symmetric_dirichlet") - 4.0;
}

// What the table is and how a case passes (the top of docs/results.md's "Decals").
std::string decals_preamble(const nlohmann::json& report) {
  std::ostringstream s;
  s << generated_by(report["machine"], "decals", "decals")
    << ". Cases: `tools/benchmarks/decal_cases.json`; raw numbers: "
       "[results/decals.json](results/decals.json).\n\n"
       "Every case places the source with `--target-place X,Y,Z,ANGLE,SCALE` (a free boundary, "
       "docs/transfer.md) and the defaults a user gets, and measures the exponential-map decal "
       "on the same grid (`compare`'s `expmap`). The decal's radius on the target is 0.1 "
       "(small), 0.25 (quarter) or 0.5 (half) times the local feature size at the point. A case "
       "**passes** when ElasticPaint exits 0 (converged, no folds) and both its length energy and "
       "its symmetric Dirichlet energy are below the exponential map's. SD − 4 is the symmetric "
       "Dirichlet energy's excess over an isometry's. For the rectangle: edge turning is the mean "
       "over its four sides of the total turn of the side in the tangent planes (0: geodesic, as "
       "straight as the surface allows), corner error the largest departure of a corner from 90 "
       "degrees. The exponential map's figures are in parentheses.\n\n";
  return s.str();
}

std::string decals_markdown(const nlohmann::json& report) {
  const nlohmann::json& cases = report["cases"];
  std::ostringstream s;
  int passed = 0;
  // Per size: the exponential map's length and SD excess over ElasticPaint's, as medians.
  std::map<std::string, std::vector<double>> length_margin, sd_margin;
  std::vector<std::string> size_order;
  for (const auto& c : cases) {
    passed += c["pass"].get<bool>() ? 1 : 0;
    const std::string size = c["size"].get<std::string>();
    if (std::find(size_order.begin(), size_order.end(), size) == size_order.end()) {
      size_order.push_back(size);
    }
    if (c.contains("error")) {
      continue;
    }
    length_margin[size].push_back(json_number(c["expmap"], "length_energy") /
                                  json_number(c["elastic"], "length_energy"));
    sd_margin[size].push_back(sd_excess(c["expmap"]) / sd_excess(c["elastic"]));
  }
  s << decals_preamble(report);
  s << "**Summary: " << passed << " of " << cases.size() << " cases pass.** Margins (median "
    << "over the cases of each size, exponential map ÷ ElasticPaint): ";
  for (size_t k = 0; k < size_order.size(); ++k) {
    const std::string& size = size_order[k];
    s << (k > 0 ? "; " : "") << size << ": length energy "
      << fmt_number(median(length_margin[size])) << "×, SD − 4 "
      << fmt_number(median(sd_margin[size])) << "×";
  }
  s << ".\n\n";
  s << "| case | particles | exit | folds | length energy | SD − 4 | angle err mean (deg) | "
       "edge turning (deg) | corner error (deg) | seconds | pass |\n"
    << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
  for (const auto& c : cases) {
    s << "| " << c["name"].get<std::string>() << " | ";
    if (c.contains("error")) {
      s << "error: " << c["error"].get<std::string>() << " |||||||||**fail** |\n";
      continue;
    }
    const nlohmann::json& e = c["elastic"];
    const nlohmann::json& x = c["expmap"];
    const nlohmann::json& k = c["checks"];
    const auto pair = [](double a, double b, int digits) {
      return fmt_number(a, digits) + " (" + fmt_number(b, digits) + ")";
    };
    const auto shape = [&](const char* key) {
      if (!e.contains("shape")) {
        return std::string("–");
      }
      return pair(json_number(e["shape"], key), json_number(x["shape"], key), 3);
    };
    s << c["particles"] << " | "
      << bold_unless(k["exit_0"].get<bool>(), std::to_string(c["exit"].get<int>())) << " | "
      << bold_unless(k["fold_free"].get<bool>(),
                     pair(json_number(e, "folds"), json_number(x, "folds"), 4))
      << " | "
      << bold_unless(k["length_energy"].get<bool>(),
                     pair(json_number(e, "length_energy"), json_number(x, "length_energy"), 3))
      << " | "
      << bold_unless(k["symmetric_dirichlet"].get<bool>(), pair(sd_excess(e), sd_excess(x), 3))
      << " | "
      << pair(json_number(e, "angle_error_mean_deg"), json_number(x, "angle_error_mean_deg"), 3)
      << " | " << shape("edge_turning_deg") << " | " << shape("corner_error_deg") << " | "
      << pair(json_number(e, "seconds"), json_number(x, "seconds"), 2) << " | "
      << (c["pass"].get<bool>() ? "pass" : "**fail**") << " |\n";
  }
  return s.str();
}

int run_decals(const DecalArgs& args, const CLI::App& sub) {
  const nlohmann::json file = read_cases_file(args.cases, {"sources", "sizes", "targets"});
  nlohmann::json report;
  report["job"] = job_of(sub);
  report["machine"] = machine_json(args.threads);
  report["cases"] = nlohmann::json::array();
  int passed = 0;
  SurfaceCache cache;
  try {
    const long particles = args.particles > 0 ? args.particles : file.at("particles").get<long>();
    for (const auto& target : file.at("targets")) {
      for (const auto& source : file.at("sources")) {
        for (const auto& size : file.at("sizes")) {
          const std::string name = source.at("name").get<std::string>() + " → " +
                                   target.at("name").get<std::string>() + " " +
                                   size.at("name").get<std::string>();
          if (!args.only.empty() && name != args.only) {
            continue;
          }
          if (!args.quiet) {
            std::cerr << "elastic bench decals: " << name << '\n';
          }
          report["cases"].push_back(run_case(source, size, target, particles, args, cache));
          const nlohmann::json& last = report["cases"].back();
          passed += last["pass"].get<bool>() ? 1 : 0;
          if (!args.quiet) {
            std::cerr << "elastic bench decals: " << name << ' '
                      << (last.contains("error")     ? "error: " + last["error"].get<std::string>()
                          : last["pass"].get<bool>() ? std::string("pass")
                                                     : std::string("fail"))
                      << '\n';
          }
        }
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw InvalidInputError(args.cases, std::string("bad cases file: ") + e.what());
  }
  report["summary"] = {{"cases", report["cases"].size()}, {"passed", passed}};
  write_bench_outputs(args, report, decals_markdown(report));
  return kOk;
}

}  // namespace

std::vector<double> boundary_turns(const ParticleGrid& grid, const LimitSurface& surface,
                                   const Eigen::Matrix3Xd& positions,
                                   const std::vector<SurfacePoint>& points) {
  const std::vector<int>& loop = grid.boundary_loop;
  const auto n = static_cast<int>(loop.size());
  std::vector<double> turns(loop.size(), 0.0);
  for (int k = 0; k < n; ++k) {
    const int prev = loop[static_cast<size_t>((k + n - 1) % n)];
    const int p = loop[static_cast<size_t>(k)];
    const int next = loop[static_cast<size_t>((k + 1) % n)];
    turns[static_cast<size_t>(k)] =
        turn_deg(positions.col(p) - positions.col(prev), positions.col(next) - positions.col(p),
                 surface.curvature(points[static_cast<size_t>(p)]).normal);
  }
  return turns;
}

BoundaryShape boundary_shape(const std::vector<double>& turns,
                             const std::vector<double>& source_turns,
                             const std::vector<int>& corners) {
  BoundaryShape shape;
  const auto n = static_cast<int>(turns.size());
  if (corners.empty() || n < 3 || source_turns.size() != turns.size()) {
    return shape;
  }
  const auto change = [&](int k) {
    const auto i = static_cast<size_t>(((k % n) + n) % n);
    return std::abs(turns[i] - source_turns[i]);
  };
  double sides = 0.0;
  for (size_t c = 0; c < corners.size(); ++c) {
    const int first = corners[c];
    const int last = corners[(c + 1) % corners.size()] + (c + 1 == corners.size() ? n : 0);
    for (int k = first + 1; k < last; ++k) {
      sides += change(k);
    }
    shape.corner_error_deg = std::max(shape.corner_error_deg, change(first));
  }
  shape.edge_turning_deg = sides / static_cast<double>(corners.size());
  return shape;
}

std::function<int()> add_decals_subcommand(CLI::App& bench) {
  auto a = std::make_shared<DecalArgs>();
  CLI::App* sub = bench.add_subcommand(
      "decals", "Placed decals (--target-place) against the exponential-map decal, pass/fail");
  add_bench_case_options(*sub, *a, "decal_cases.json");
  sub->add_option("--particles", a->particles, "Particles of every case (0: the cases file's)")
      ->check(CLI::Range(0L, kMaxParticles));
  sub->footer(
      "Example:\n  elastic bench decals --report decals.json --markdown decals.md\n"
      "Prints the table on stdout; exits 0 when every case ran (passing or not).");
  return [a, sub] { return run_decals(*a, *sub); };
}

}  // namespace elastic::cli
