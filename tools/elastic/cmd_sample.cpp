// `elastic sample`: the particle grid on a source region (§4.1, §4.3): layout, curvature-adaptive
// sampling, springs. Writes the grid as a mesh and reports counts and density statistics.
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "command.h"
#include "elastic/core/atomic_file.h"
#include "elastic/core/staged_folder.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/regions/region_spec.h"
#include "elastic/sampling/sample_region.h"
#include "job_file.h"
#include "map_job.h"

namespace elastic::cli {
namespace {

struct SampleArgs {
  std::string mesh;
  std::string region;
  std::string scheme = "auto";
  long particles = 1000;
  std::uint64_t seed = 0;
  double jitter = 0.0;
  int iterations = AdaptiveSamplingOptions{}.max_iterations;
  double floor = AdaptiveSamplingOptions{}.floor;
  double max_weight = AdaptiveSamplingOptions{}.max_weight;
  double curvature_radius = AdaptiveSamplingOptions{}.curvature_radius;
  bool adaptive = true;
  bool fixed_boundary = false;
  std::string flattening = "conformal";
  std::string out;
  std::string report;
  bool quiet = false;
  long long max_memory_mb = 0;  // --max-memory MB (0: default_max_memory_mb())
};

int run_sample(const SampleArgs& args, const CLI::App& sub) {
  require_flag(args.mesh, "--source");
  require_flag(args.region, "--source-region");
  check_memory(kBaseBytes + kSampleBytesPerParticle * static_cast<double>(args.particles),
               "--particles " + std::to_string(args.particles), args.max_memory_mb);
  // Output paths are checked before any work.
  if (!args.out.empty()) check_output_file(args.out, "--out");
  if (!args.report.empty()) check_output_file(args.report, "--report");
  LoadedSurface loaded = load_surface(args.mesh, args.scheme);
  print_warnings(loaded.warnings, args.quiet);
  RegionOptions region_options;
  region_options.name = "--source-region";
  const Region region = make_region(
      *loaded.projector, parse_region_flag(args.region, "--source-region"), region_options);

  SampleRegionOptions options;
  options.layout.particles = args.particles;
  options.layout.name = "--source-region";
  options.layout.flattening = args.flattening == "disk" ? FlatteningMethod::Disk
                              : args.flattening == "boundary-first"
                                  ? FlatteningMethod::BoundaryFirst
                                  : FlatteningMethod::Conformal;
  options.adaptive = args.adaptive;
  options.sampling.seed = args.seed;
  options.sampling.jitter = args.jitter;
  options.sampling.max_iterations = args.iterations;
  options.sampling.floor = args.floor;
  options.sampling.max_weight = args.max_weight;
  options.sampling.curvature_radius = args.curvature_radius;
  options.sampling.move_boundary = !args.fixed_boundary;
  options.sampling.progress = terminal_progress(args.quiet);
  const SampleRegionResult sampled = sample_region(region, *loaded.projector, options);
  end_progress_line();

  if (!args.out.empty())
    write_mesh(args.out, to_polygon_mesh(sampled.grid, sampled.grid.source_positions()));

  const SamplingStatistics& st = sampled.statistics;
  const nlohmann::json report = {
      {"job", job_of(sub)},
      {"source", args.mesh},
      {"source_region", args.region},
      {"requested_particles", args.particles},
      {"particles", st.particles},
      {"interior_particles", st.interior_particles},
      {"boundary_particles", st.boundary_particles},
      // The spring and sampling keys are named as in the map report (docs/file-formats.md).
      {"springs", st.normal_springs + st.angular_springs},
      {"springs_normal", st.normal_springs},
      {"springs_angular", st.angular_springs},
      {"quads", st.quads},
      {"triangles", st.triangles},
      {"count_error", sampled.layout.count_error},
      {"lattice_spacing", sampled.layout.spacing},
      {"flattening", sampled.layout.flattening == FlatteningMethod::Disk ? "disk"
                     : sampled.layout.flattening == FlatteningMethod::BoundaryFirst
                         ? "boundary-first"
                         : "conformal"},
      {"region_area", region.area()},
      {"sampling",
       {{"spacing_min", st.spacing_min},
        {"spacing_median", st.spacing_median},
        {"spacing_max", st.spacing_max},
        {"density_ratio", st.density_ratio}}},
      {"min_corner_sine", st.min_corner_sine},
      {"inverted_faces", st.inverted_faces},
      {"adaptive",
       {{"enabled", args.adaptive},
        {"iterations", sampled.sampling.iterations},
        {"newton_steps", sampled.sampling.newton_steps},
        {"cg_iterations", sampled.sampling.cg_iterations},
        {"converged", sampled.sampling.converged},
        {"stalled", sampled.sampling.stalled},
        {"last_max_move", sampled.sampling.max_move},
        {"rejected_moves", sampled.sampling.rejected_moves},
        {"mean_curvature_weight", sampled.sampling.mean_curvature_weight},
        {"seed", args.seed}}}};
  if (!args.report.empty()) {
    write_file_atomically(args.report, [&](std::ofstream& out) { out << report.dump(2) << '\n'; });
  }

  std::cout << std::setprecision(4) << st.particles << " particles (requested " << args.particles
            << ", " << std::showpos << 100.0 * sampled.layout.count_error << std::noshowpos
            << "%): " << st.interior_particles << " interior, " << st.boundary_particles
            << " on the boundary\n"
            << st.normal_springs << " normal springs, " << st.angular_springs
            << " angular springs (" << st.quads << " quads, " << st.triangles
            << " band triangles)\n"
            << "spacing min " << st.spacing_min << ", median " << st.spacing_median << ", max "
            << st.spacing_max << "; density ratio high/low curvature " << st.density_ratio << '\n';
  if (args.adaptive) {
    std::cout << "adaptive sampling: " << sampled.sampling.iterations << " iterations, "
              << (sampled.sampling.converged ? "converged"
                  : sampled.sampling.stalled ? "not converged, stalled"
                                             : "not converged")
              << " (last move " << sampled.sampling.max_move << " of the mean spacing)\n";
  }
  if (!args.out.empty()) std::cout << "wrote " << args.out << '\n';
  return kOk;
}

}  // namespace
}  // namespace elastic::cli

ELASTIC_COMMAND("sample", "Sample a source region with the particle grid", [](CLI::App& sub) {
  auto args = std::make_shared<elastic::cli::SampleArgs>();
  // --mesh and --region: the names before 0.2, kept as aliases for one release (docs/cli.md).
  sub.add_option("--source,--mesh", args->mesh,
                 "Source mesh file (OBJ, OFF, PLY, STL) (required; old name --mesh)");
  sub.add_option("--source-region,--region", args->region,
                 "Source region (required; old name --region): disk:X,Y,Z,R | points:FILE | "
                 "boundary | uv:FILE");
  sub.add_option("--particles", args->particles, "Number of particles (within 5%), 16..5000000")
      ->check(CLI::Range(elastic::cli::kMinParticles, elastic::cli::kMaxParticles));
  sub.add_option("--seed", args->seed, "Seed of the initial jitter (with --jitter)");
  sub.add_option("--jitter", args->jitter, "Random initial displacement, fraction of the spacing")
      ->check(CLI::Range(0.0, 0.5));
  sub.add_option("--iterations", args->iterations, "Adaptive sampling iterations")
      ->check(CLI::Range(0, 100000));
  sub.add_option("--floor", args->floor, "Curvature weight floor, fraction of the mean weight")
      ->check(CLI::Range(0.0, 100.0));
  sub.add_option("--max-weight", args->max_weight,
                 "Clamp curvature weights at this multiple of their mean (0: no clamp)")
      ->check(CLI::Range(0.0, 1e6));
  sub.add_option("--curvature-radius", args->curvature_radius,
                 "Average the curvature over about this many grid spacings (a kernel as wide as a "
                 "Gaussian of this standard deviation; 0: pointwise, the paper's)")
      ->check(CLI::Range(0.0, 100.0));
  sub.add_flag("!--no-adaptive", args->adaptive,
               "Keep the regular layout (no curvature adaptation)");
  sub.add_flag("--fixed-boundary", args->fixed_boundary,
               "Keep boundary particles at equal arc length");
  sub.add_option("--flattening", args->flattening,
                 "Flattening used for the layout: least-squares conformal, boundary first "
                 "(conformal, keeps the boundary's lengths; faster, spreads the spacings more on "
                 "large curved regions), or the mean-value disk map")
      ->check(CLI::IsMember({"conformal", "boundary-first", "disk"}));
  sub.add_option("--scheme", args->scheme, "Subdivision scheme")
      ->check(CLI::IsMember({"auto", "loop", "catmull-clark"}));
  sub.add_option("--out", args->out, "Write the grid (particles and springs' faces): .obj or .ply");
  sub.add_option("--report", args->report, "Write the statistics as JSON");
  sub.add_option("--max-memory", args->max_memory_mb,
                 "Refuse runs estimated to need more memory, in MB (0: half the physical memory, "
                 "at most 4096), checked before any work")
      ->check(CLI::NonNegativeNumber);
  sub.add_flag("-q,--quiet", args->quiet, "No progress line or warnings");
  sub.footer(
      "Example:\n  elastic sample --source cap.obj --source-region disk:0,0,1,0.5 --particles 5000 "
      "--out grid.obj --report grid.json");
  return [args, &sub] { return elastic::cli::run_sample(*args, sub); };
});
