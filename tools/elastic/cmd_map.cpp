// `elastic map`: sample the source region, map it onto the target region with least distortion,
// report.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "cli_common.h"
#include "command.h"
#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"
#include "elastic/core/staged_folder.h"
#include "elastic/mapping/map_regions.h"
#include "elastic/mesh/mesh_io.h"
#include "job_file.h"
#include "map_job.h"
#include "verdict.h"

namespace elastic::cli {
namespace {

struct MapArgs {
  MapJob job;
  std::string out;
};

int run_map(const MapArgs& args, const CLI::App& sub) {
  // Output paths are checked before any work; the grids appear together (staged_folder.h).
  if (!args.job.report.empty()) check_output_file(args.job.report, "--report");
  std::optional<StagedFolder> out;
  if (!args.out.empty()) out.emplace(args.out, "--out");
  const std::unique_ptr<MapSession> session =
      run_map_job(args.job, terminal_progress(args.job.quiet));
  end_progress_line();
  const MapResult& result = session->result;
  const nlohmann::json report = map_report(args.job, *session, job_of(sub));
  if (out) {
    const std::filesystem::path& dir = out->staging();
    const ParticleGrid& grid = result.sampling.grid;
    write_mesh(dir / "source_grid.obj", to_polygon_mesh(grid, grid.source_positions()));
    write_mesh(dir / "naive_grid.obj", to_polygon_mesh(grid, result.naive.positions));
    write_mesh(dir / "target_grid.obj", to_polygon_mesh(grid, result.relaxation.positions));
    out->commit();
  }
  write_report(args.job.report, report);
  print_map_summary(args.job, *session);
  return finish(judge_map(args.job, *session));
}

}  // namespace
}  // namespace elastic::cli

ELASTIC_COMMAND(
    "map", "Map a source region onto a target region with least distortion", [](CLI::App& sub) {
      auto a = std::make_shared<elastic::cli::MapArgs>();
      elastic::cli::add_map_flags(sub, a->job);
      sub.add_option("--out", a->out, "Write source/naive/target grids (OBJ) into this folder");
      sub.footer(
          "Example:\n  elastic map --source meshes/plane_quads.obj --source-region "
          "disk:0,0,0,0.9 \\\n"
          "      --target meshes/cap_quads.obj --particles 5775 --report report.json --out out/\n"
          "maps a disk of the plane onto the whole cap (its boundary). `--job report.json` repeats "
          "the run.");
      return [a, &sub] { return elastic::cli::run_map(*a, sub); };
    });
