#include "bench_scale.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench_common.h"
#include "elastic/baselines/cgal_flattening.h"
#include "elastic/core/error.h"
#include "job_file.h"
#include "map_job.h"

namespace elastic::cli {
namespace {

struct ScaleArgs {
  std::string source = std::string(ELASTIC_SOURCE_DIR) + "/meshes/plane_quads.obj";
  std::string source_region = "disk:0,0,0,0.9";
  std::string target = std::string(ELASTIC_SOURCE_DIR) + "/meshes/cap_quads.obj";
  std::string target_region = "boundary";
  std::vector<long> sizes = {5775, 25000, 100000, 1000000};
  int runs = 3;
  int threads = 0;
  std::string report;
  bool quiet = false;
};

// The relaxed grid on the target as a Region (quads split along their 0-2 diagonal), for CGAL.
Region target_grid_region(const MapSession& session) {
  const MapResult& r = session.result;
  const ParticleGrid& grid = r.sampling.grid;
  Region region;
  region.surface = session.target_region.surface;
  const Eigen::Matrix3Xd& x = r.relaxation.positions;
  for (Eigen::Index p = 0; p < x.cols(); ++p) {
    region.positions.emplace_back(x.col(p));
  }
  region.points = r.relaxation.points;
  for (const auto f : grid.mesh.faces()) {
    std::vector<int> v;
    for (const auto vh : grid.mesh.fv_range(f)) {
      v.push_back(vh.idx());
    }
    for (size_t k = 1; k + 1 < v.size(); ++k) {
      region.triangles.emplace_back(v[0], v[k], v[k + 1]);
    }
  }
  region.boundary = grid.boundary_loop;
  return region;
}

nlohmann::json run_size(long particles, const ScaleArgs& args) {
  MapJob job;
  job.source = args.source;
  job.source_region = args.source_region;
  job.target = args.target;
  job.target_region = args.target_region;
  job.particles = particles;
  job.threads = args.threads;
  job.quiet = true;
  std::vector<double> total, loading, sampling, naive, solve, lscm;
  nlohmann::json out = {{"requested_particles", particles}};
  for (int run = 0; run < args.runs; ++run) {
    if (!args.quiet) {
      std::cerr << "elastic bench scale: " << particles << " particles, run " << run + 1 << '\n';
    }
    const std::unique_ptr<MapSession> s = run_map_job(job);
    const MapResult& r = s->result;
    total.push_back(s->seconds_total);
    loading.push_back(s->seconds_loading);
    sampling.push_back(r.seconds_sampling);
    naive.push_back(r.seconds_naive);
    solve.push_back(r.relaxation.solve_seconds);
    const Region grid = target_grid_region(*s);
    lscm.push_back(flatten_region_cgal(grid, BaselineKind::Lscm, {.name = "target grid"})
                       .seconds_parameterize);
    out["particles"] = r.sampling.statistics.particles;
    out["converged"] = r.relaxation.converged;
    out["sampling_converged"] = r.sampling.sampling.converged;
    out["folds"] = s->metrics.folds;
    out["lscm_triangles"] = grid.triangles.size();
  }
  out["seconds"] = {{"total", median(total)},       {"loading", median(loading)},
                    {"sampling", median(sampling)}, {"naive_map", median(naive)},
                    {"solve", median(solve)},       {"lscm", median(lscm)}};
  out["ratio"] = median(total) / median(lscm);
  return out;
}

int run_scale(const ScaleArgs& args, const CLI::App& sub) {
  nlohmann::json report;
  report["job"] = job_of(sub);
  report["runs"] = args.runs;
  report["machine"] = machine_json(args.threads);
  report["sizes"] = nlohmann::json::array();
  // The thread count holds for every stage (sampling, transfer kernels, CGAL), not only the
  // solver's own arena.
  tbb::task_arena arena(args.threads > 0 ? args.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    for (const long n : args.sizes) {
      report["sizes"].push_back(run_size(n, args));
    }
  });
  std::ostringstream table;
  table << "| particles | total | loading | sampling | naive map | solve | CGAL LSCM | ratio |\n"
        << "|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const nlohmann::json& c : report["sizes"]) {
    const nlohmann::json& t = c["seconds"];
    const auto d = [](const nlohmann::json& v) { return v.get<double>(); };
    table << std::setprecision(3) << "| " << c["particles"] << " | " << d(t["total"]) << " | "
          << d(t["loading"]) << " | " << d(t["sampling"]) << " | " << d(t["naive_map"]) << " | "
          << d(t["solve"]) << " | " << d(t["lscm"]) << " | " << d(c["ratio"]) << " |\n";
  }
  write_report(args.report, report);
  std::cout << table.str();
  return 0;
}

}  // namespace

std::function<int()> add_scale_subcommand(CLI::App& bench) {
  auto a = std::make_shared<ScaleArgs>();
  CLI::App* sub = bench.add_subcommand(
      "scale", "The whole `elastic map` at several sizes beside CGAL's LSCM on the same grid");
  sub->add_option("--source", a->source, "Source mesh (default: meshes/plane_quads.obj)");
  sub->add_option("--source-region", a->source_region, "Source region");
  sub->add_option("--target", a->target, "Target mesh (default: meshes/cap_quads.obj)");
  sub->add_option("--target-region", a->target_region, "Target region");
  sub->add_option("--sizes", a->sizes, "Particle counts (comma-separated)")
      ->delimiter(',')
      ->check(CLI::Range(16L, 5000000L));
  sub->add_option("--runs", a->runs, "Runs per size (median seconds)")->check(CLI::Range(1, 100));
  sub->add_option("--threads", a->threads, "Threads of every stage (0: all)")
      ->check(CLI::Range(0, 1024));
  sub->add_option("--report", a->report, "Write the JSON report here");
  sub->add_flag("--quiet,-q", a->quiet, "No progress lines on stderr");
  sub->footer(
      "Example:\n  elastic bench scale --sizes 5775,25000 --runs 3 --report scale.json\n"
      "Times are medians of --runs; `ratio` is the map's total over LSCM's parameterize call.");
  return [a, sub] { return run_scale(*a, *sub); };
}

}  // namespace elastic::cli
