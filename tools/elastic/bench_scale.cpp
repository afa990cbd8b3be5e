#include "bench_scale.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
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

// The relaxed grid on the target as a Region (quads split along their 0-2 diagonal, as
// grid_triangles splits them), for CGAL.
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
  region.triangles = grid_triangles(grid);
  region.boundary = grid.boundary_loop;
  return region;
}

// What the operating system measured of one map's process.
struct ProcessFigures {
  double wall = 0.0;  ///< seconds from spawn to exit (loading of the shared libraries included)
};

// One `elastic map` of the job in a process of its own, as a user runs it: this binary again
// (/proc/self/exe), nothing shared with this process (its page cache aside). Returns the child's
// report and fills `figures`. \throws NumericalError when the map fails.
nlohmann::json map_in_own_process(const ScaleArgs& args, long particles,
                                  const std::filesystem::path& report, ProcessFigures& figures) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (error) {
    throw IoError("/proc/self/exe", "cannot find this program to run the map: " + error.message());
  }
  std::vector<std::string> words = {exe.string(),
                                    "map",
                                    "-q",
                                    "--source",
                                    args.source,
                                    "--source-region",
                                    args.source_region,
                                    "--target",
                                    args.target,
                                    "--target-region",
                                    args.target_region,
                                    "--particles",
                                    std::to_string(particles),
                                    "--threads",
                                    std::to_string(args.threads),
                                    "--report",
                                    report.string()};
  std::vector<char*> argv;
  argv.reserve(words.size() + 1);
  for (std::string& w : words) {
    argv.push_back(w.data());
  }
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const auto start = std::chrono::steady_clock::now();
  const int spawned = posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    throw IoError(exe.string(), std::string("cannot start the map: ") + std::strerror(spawned));
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  figures.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string how = WIFEXITED(status)
                                ? "exited with code " + std::to_string(WEXITSTATUS(status))
                                : "was killed by signal " + std::to_string(WTERMSIG(status));
    throw NumericalError("bench scale", "the map of " + std::to_string(particles) +
                                            " particles in its own process " + how +
                                            " (its message is above)");
  }
  std::ifstream in(report);
  nlohmann::json out = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (out.is_discarded() || !out.contains("seconds")) {
    throw IoError(report.string(), "the map's report is missing or not JSON");
  }
  return out;
}

// The map report's stages (seconds.*) the table shows, in the order they run; `total` first.
constexpr const char* kStages[] = {"total",     "loading",      "sampling", "coarse_start",
                                   "naive_map", "solver_setup", "solve",    "mapping"};

// Each timed run is a whole `elastic map` in its own process (map_in_own_process): a map repeated
// in one process runs warm (memory already faulted in, threads started) and read 2x faster than a
// user's `elastic map` at 5,775 particles. The grid CGAL flattens comes from one more map in this
// process, untimed and first, so that bad input fails here with its own message and exit code.
nlohmann::json run_size(long particles, const ScaleArgs& args) {
  MapJob job;
  job.source = args.source;
  job.source_region = args.source_region;
  job.target = args.target;
  job.target_region = args.target_region;
  job.particles = particles;
  job.threads = args.threads;
  job.quiet = true;
  nlohmann::json out = {{"requested_particles", particles}};
  std::vector<double> process, peak, lscm;
  std::map<std::string, std::vector<double>> stages;  // the report's seconds.*, by key
  {
    const std::unique_ptr<MapSession> s = run_map_job(job);
    const Region grid = target_grid_region(*s);
    for (int run = 0; run < args.runs; ++run) {
      lscm.push_back(flatten_region_cgal(grid, BaselineKind::Lscm, {.name = "target grid"})
                         .seconds_parameterize);
    }
    out["sampling_converged"] = s->result.sampling.sampling.converged;
    out["lscm_triangles"] = grid.triangles.size();
  }
  const std::filesystem::path report =
      std::filesystem::temp_directory_path() /
      ("elastic-bench-scale-" + std::to_string(::getpid()) + ".json");
  // The children's report file goes when this size is done, also when a run fails.
  const std::unique_ptr<const std::filesystem::path, void (*)(const std::filesystem::path*)>
      remove_report(&report, [](const std::filesystem::path* path) {
        std::error_code ignored;
        std::filesystem::remove(*path, ignored);
      });
  for (int run = 0; run < args.runs; ++run) {
    if (!args.quiet) {
      std::cerr << "elastic bench scale: " << particles << " particles, run " << run + 1 << '\n';
    }
    ProcessFigures figures;
    const nlohmann::json r = map_in_own_process(args, particles, report, figures);
    const nlohmann::json& t = r["seconds"];
    process.push_back(figures.wall);
    peak.push_back(r.value("peak_mib", 0.0));  // the child's own VmHWM (peak_resident_mib)
    for (const char* key : kStages) {
      stages[key].push_back(t.value(key, 0.0));
    }
    out["particles"] = r.value("particles", 0L);
    out["converged"] = r.value("converged", false);
    out["folds"] = r.value("folds", -1);
  }
  out["seconds"] = {{"process", median(process)}, {"lscm", median(lscm)}};
  for (const char* key : kStages) {
    out["seconds"][key] = median(stages[key]);
  }
  out["peak_mib"] = median(peak);
  out["ratio"] = median(process) / median(lscm);
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
  table << "| particles | process |";
  for (const char* key : kStages) {
    table << ' ' << key << " |";
  }
  table << " CGAL LSCM | ratio | peak MiB |\n|---:|---:|";
  for (std::size_t k = 0; k < std::size(kStages); ++k) {
    table << "---:|";
  }
  table << "---:|---:|---:|\n";
  for (const nlohmann::json& c : report["sizes"]) {
    const nlohmann::json& t = c["seconds"];
    const auto d = [](const nlohmann::json& v) { return v.get<double>(); };
    table << std::setprecision(3) << "| " << c["particles"] << " | " << d(t["process"]) << " |";
    for (const char* key : kStages) {
      table << ' ' << d(t[key]) << " |";
    }
    table << ' ' << d(t["lscm"]) << " | " << d(c["ratio"]) << " | " << d(c["peak_mib"]) << " |\n";
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
      "Each run is a whole `elastic map` in its own process. Times are medians of --runs:\n"
      "`process` from its start to its exit, the others its report's `seconds`; `ratio` is\n"
      "`process` over CGAL LSCM's parameterize call on the same grid; `peak MiB` the map\n"
      "process's largest resident set.");
  return [a, sub] { return run_scale(*a, *sub); };
}

}  // namespace elastic::cli
