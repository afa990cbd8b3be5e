#include "bench_warm.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <deque>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench_common.h"
#include "elastic/core/error.h"
#include "elastic/regions/region_spec.h"
#include "job_file.h"
#include "map_job.h"

namespace elastic::cli {
namespace {

struct WarmArgs {
  std::string source = std::string(ELASTIC_SOURCE_DIR) + "/meshes/plane_quads.obj";
  std::string source_region = "disk:0,0,0,0.8";
  std::string target = std::string(ELASTIC_SOURCE_DIR) + "/meshes/sphere_quads.obj";
  std::string target_region = "disk:0,0,1,0.5";
  long particles = 2000;
  int steps = 10;
  double step = 0.05;  // fraction of the radius moved per step
  double grow = 1.0;   // factor on the radius per step
  int threads = 0;
  std::string report;
  bool quiet = false;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double spring_energy_of(const RelaxationResult& r) {
  return r.length_energy + r.angular_energy + r.barrier_energy + r.distortion_energy;
}

// The next step's disk: its centre moved by `step` radii along the surface, in the direction of
// the world axis least aligned with the normal at the centre (projected on the tangent plane),
// its radius times `grow`.
RegionSpec next_disk(const SurfaceProjector& projector, const RegionSpec& disk,
                     const WarmArgs& args) {
  const ClosestPoint at = projector.closest(disk.center);
  const Eigen::Vector3d n = at.normal;
  Eigen::Index axis = 0;
  n.cwiseAbs().minCoeff(&axis);
  Eigen::Vector3d t = Eigen::Vector3d::Unit(axis);
  t = (t - t.dot(n) * n).normalized();
  RegionSpec next = disk;
  next.center = projector.closest(at.position + args.step * disk.radius * t).position;
  next.radius = disk.radius * args.grow;
  next.text = "disk:" + std::to_string(next.center.x()) + "," + std::to_string(next.center.y()) +
              "," + std::to_string(next.center.z()) + "," + std::to_string(next.radius);
  return next;
}

nlohmann::json run_steps(const WarmArgs& args) {
  MapJob job;
  job.source = args.source;
  job.source_region = args.source_region;
  job.target = args.target;
  job.target_region = args.target_region;
  job.particles = args.particles;
  job.threads = args.threads;
  job.quiet = true;
  RegionSpec disk = parse_region_spec(args.target_region, "--target-region");
  if (disk.kind != RegionSpec::Kind::Disk) {
    throw InvalidInputError("--target-region", "must be a disk (disk:X,Y,Z,R) to be dragged");
  }
  const std::unique_ptr<MapSession> s = run_map_job(job);
  const MapOptions options = make_map_options(job);
  const SurfaceProjector& source = *s->source.projector;
  const SurfaceProjector& target = *s->target.projector;
  // Each warm map references its target region: the regions stay alive in `regions`.
  std::deque<Region> regions;
  std::unique_ptr<MapResult> previous;
  nlohmann::json steps = nlohmann::json::array();
  std::vector<double> region_s, cached_s, cold_s, warm_s, ratio;
  // The same disks cut again with a cache kept across the drag (RegionCache, as `elastic studio`
  // cuts its live updates); the maps use the fresh cuts.
  RegionCache cache;
  for (int k = 0; k <= args.steps; ++k) {
    if (k > 0) {
      disk = next_disk(target, disk, args);
    }
    auto start = std::chrono::steady_clock::now();
    regions.push_back(make_region(target, disk, {.name = "step " + std::to_string(k)}));
    const double region_seconds = seconds_since(start);
    start = std::chrono::steady_clock::now();
    const Region cached =
        make_region(target, disk, {.name = "step " + std::to_string(k), .cache = &cache});
    const double cached_seconds = seconds_since(start);
    start = std::chrono::steady_clock::now();
    const MapResult cold = map_regions(source, s->source_region, target, regions.back(), options);
    const double cold_seconds = seconds_since(start);
    nlohmann::json step = {{"step", k},
                           {"region", disk.text},
                           {"seconds_region", region_seconds},
                           {"seconds_region_cached", cached_seconds},
                           {"cached_area_ratio", cached.area() / regions.back().area()},
                           {"cold",
                            {{"seconds", cold_seconds},
                             {"iterations", cold.relaxation.iterations},
                             {"converged", cold.relaxation.converged},
                             {"folds", cold.relaxation.folded_faces},
                             {"energy", spring_energy_of(cold.relaxation)}}}};
    if (previous) {
      start = std::chrono::steady_clock::now();
      auto warm = std::make_unique<MapResult>(
          map_regions(source, s->source_region, target, regions.back(), *previous, options));
      const double warm_seconds = seconds_since(start);
      step["warm"] = {{"seconds", warm_seconds},
                      {"iterations", warm->relaxation.iterations},
                      {"converged", warm->relaxation.converged},
                      {"folds", warm->relaxation.folded_faces},
                      {"energy", spring_energy_of(warm->relaxation)}};
      step["ratio"] = warm_seconds / cold_seconds;
      region_s.push_back(region_seconds);
      cached_s.push_back(cached_seconds);
      cold_s.push_back(cold_seconds);
      warm_s.push_back(warm_seconds);
      ratio.push_back(warm_seconds / cold_seconds);
      previous = std::move(warm);
    } else {
      previous = std::make_unique<MapResult>(
          map_regions(source, s->source_region, target, regions.back(), options));
    }
    if (!args.quiet) {
      std::cerr << "elastic bench warm: step " << k << " of " << args.steps << '\n';
    }
    steps.push_back(step);
  }
  return {{"particles", previous->sampling.grid.num_particles()},
          {"steps", steps},
          {"median",
           {{"seconds_region", median(region_s)},
            {"seconds_region_cached", median(cached_s)},
            {"seconds_cold", median(cold_s)},
            {"seconds_warm", median(warm_s)},
            {"ratio", median(ratio)}}}};
}

int run_warm(const WarmArgs& args, const CLI::App& sub) {
  nlohmann::json report;
  report["job"] = job_of(sub);
  report["machine"] = machine_json(args.threads);
  tbb::task_arena arena(args.threads > 0 ? args.threads : tbb::task_arena::automatic);
  arena.execute([&] { report["result"] = run_steps(args); });
  const nlohmann::json& r = report["result"];
  std::ostringstream table;
  table << "| step | region s | cached region s | cached / fresh area | cold s | cold iterations | "
           "warm s | warm iterations | warm / cold | energy warm / cold |\n"
           "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  const auto d = [](const nlohmann::json& v) { return v.get<double>(); };
  for (const nlohmann::json& st : r["steps"]) {
    if (!st.contains("warm")) {
      continue;
    }
    table << std::setprecision(3) << "| " << st["step"] << " | " << d(st["seconds_region"]) << " | "
          << d(st["seconds_region_cached"]) << " | " << std::setprecision(6)
          << d(st["cached_area_ratio"]) << std::setprecision(3) << " | " << d(st["cold"]["seconds"])
          << " | " << st["cold"]["iterations"] << " | " << d(st["warm"]["seconds"]) << " | "
          << st["warm"]["iterations"] << " | " << d(st["ratio"]) << " | " << std::setprecision(6)
          << d(st["warm"]["energy"]) / d(st["cold"]["energy"]) << " |\n";
  }
  const nlohmann::json& m = r["median"];
  table << std::setprecision(3) << "\n"
        << r["particles"] << " particles; medians: region " << d(m["seconds_region"])
        << " s (cached " << d(m["seconds_region_cached"]) << " s), cold " << d(m["seconds_cold"])
        << " s, warm " << d(m["seconds_warm"]) << " s, warm / cold " << d(m["ratio"]) << "\n";
  write_report(args.report, report);
  std::cout << table.str();
  return 0;
}

}  // namespace

std::function<int()> add_warm_subcommand(CLI::App& bench) {
  auto a = std::make_shared<WarmArgs>();
  CLI::App* sub = bench.add_subcommand(
      "warm", "A target disk dragged in steps: warm-started maps beside cold ones");
  sub->add_option("--source", a->source, "Source mesh (default: meshes/plane_quads.obj)");
  sub->add_option("--source-region", a->source_region, "Source region");
  sub->add_option("--target", a->target, "Target mesh (default: meshes/sphere_quads.obj)");
  sub->add_option("--target-region", a->target_region, "Target disk at the first step");
  sub->add_option("--particles", a->particles, "Particles")->check(CLI::Range(16L, 5000000L));
  sub->add_option("--steps", a->steps, "Steps of the drag")->check(CLI::Range(1, 1000));
  sub->add_option("--step", a->step, "Move per step, a fraction of the radius")
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--grow", a->grow, "Factor on the radius per step")->check(CLI::Range(0.5, 2.0));
  sub->add_option("--threads", a->threads, "Threads of every stage (0: all)")
      ->check(CLI::Range(0, 1024));
  sub->add_option("--report", a->report, "Write the JSON report here");
  sub->add_flag("--quiet,-q", a->quiet, "No progress lines on stderr");
  sub->footer(
      "Example:\n  elastic bench warm --target ../shared/meshes/spot.obj --target-region "
      "disk:0.358,-0.032,0.073,0.25 --particles 2000 --steps 10\n"
      "Cold: map_regions from scratch; warm: map_regions from the previous step's warm map "
      "(docs/api.md). Times exclude loading; `region s` is the new disk's cut, needed by both; "
      "`cached region s` the same cut with a RegionCache kept across the drag (the first step "
      "builds it), and its area over the fresh cut's.");
  return [a, sub] { return run_warm(*a, *sub); };
}

}  // namespace elastic::cli
