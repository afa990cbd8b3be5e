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
#include "elastic/mapping/map_regions.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/regions/image_source.h"
#include "elastic/regions/region_spec.h"

namespace elastic::cli {
namespace {

struct MapArgs {
  std::string source, source_region = "boundary", source_anchor;
  std::string source_image;
  double image_width = 2.0;
  std::string target, target_region = "boundary", target_anchor;
  long particles = 1000;
  std::string solver = "lbfgs";
  std::string rest_scale = "boundary";
  std::string scheme = "auto";
  int threads = 0;
  unsigned long seed = 0;
  long max_iterations = 0;
  std::string report, out;
  bool quiet = false;
};

Eigen::Vector3d parse_point(const std::string& text, const std::string& flag) {
  Eigen::Vector3d p;
  char c1 = 0, c2 = 0;
  std::istringstream in(text);
  if (!(in >> p.x() >> c1 >> p.y() >> c2 >> p.z()) || c1 != ',' || c2 != ',' || !p.allFinite()) {
    throw InvalidInputError(flag, "expected X,Y,Z, got '" + text + "'");
  }
  return p;
}

nlohmann::json map_report(const MapArgs& args, const MapResult& r, double total_seconds) {
  const RelaxationResult& x = r.relaxation;
  const SamplingStatistics& s = r.sampling.statistics;
  return {{"job",
           {{"command", "map"},
            {"source", args.source.empty() ? args.source_image : args.source},
            {"source_region", args.source_region},
            {"target", args.target},
            {"target_region", args.target_region},
            {"particles", args.particles},
            {"solver", args.solver},
            {"rest_scale", args.rest_scale},
            {"seed", args.seed},
            {"threads", args.threads}}},
          {"particles", s.particles},
          {"springs", s.normal_springs + s.angular_springs},
          {"springs_normal", s.normal_springs},
          {"springs_angular", s.angular_springs},
          {"boundary_particles", s.boundary_particles},
          {"solver", args.solver},
          {"iterations", x.iterations},
          {"converged", x.converged},
          {"reason", std::string(to_string(x.reason))},
          {"seconds",
           {{"total", total_seconds},
            {"setup", r.seconds_sampling + r.seconds_naive + x.setup_seconds},
            {"solve", x.solve_seconds},
            {"sampling", r.seconds_sampling},
            {"naive_map", r.seconds_naive},
            {"solver_setup", x.setup_seconds}}},
          {"energy",
           {{"length", x.length_energy},
            {"angle", x.angular_energy},
            {"magnet", x.magnet_energy},
            {"initial", x.initial_energy}}},
          {"gradient", {{"relative", x.relative_gradient}, {"norm", x.gradient_norm}}},
          {"folds", x.folded_faces},
          {"initial_folds", x.initial_folded_faces},
          {"boundary_residual", x.boundary_residual},
          {"rest_scale", {{"mode", args.rest_scale}, {"factor", r.rest_scale}}},
          {"sampling",
           {{"spacing_min", s.spacing_min},
            {"spacing_median", s.spacing_median},
            {"spacing_max", s.spacing_max},
            {"density_ratio", s.density_ratio}}}};
}

int run_map(const MapArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  if (args.particles < 16 || args.particles > 5'000'000) {
    throw InvalidInputError(
        "--particles", "must be between 16 and 5000000, got " + std::to_string(args.particles));
  }
  if (args.source.empty() == args.source_image.empty()) {
    throw InvalidInputError("--source",
                            "give exactly one of --source MESH and --source-image IMAGE");
  }
  // An image source is a plane carrying the image; its region is the rectangle or the inscribed
  // ellipse.
  std::optional<ImagePlane> image;
  if (!args.source_image.empty()) {
    if (args.source_region != "boundary" && args.source_region != "rectangle" &&
        args.source_region != "ellipse") {
      throw InvalidInputError(
          "--source-region", "with --source-image it is 'rectangle' (default) or 'ellipse', got '" +
                                 args.source_region + "'");
    }
    image = make_image_plane(args.source_image, {.width = args.image_width,
                                                 .shape = args.source_region == "ellipse"
                                                              ? ImageRegionShape::Ellipse
                                                              : ImageRegionShape::Rectangle});
  }
  const LoadedSurface source = image
                                   ? surface_from_mesh(image->mesh, args.source_image, args.scheme)
                                   : load_surface(args.source, args.scheme);
  print_warnings(source.warnings, args.quiet);
  const LoadedSurface target = load_surface(args.target, args.scheme);
  print_warnings(target.warnings, args.quiet);

  RegionSpec source_spec =
      image ? image->region : parse_region_spec(args.source_region, "--source-region");
  if (!args.source_anchor.empty())
    source_spec.anchor = parse_point(args.source_anchor, "--source-anchor");
  RegionSpec target_spec = parse_region_spec(args.target_region, "--target-region");
  if (!args.target_anchor.empty())
    target_spec.anchor = parse_point(args.target_anchor, "--target-anchor");
  const Region source_region =
      make_region(*source.projector, source_spec, {.name = "--source-region"});
  const Region target_region =
      make_region(*target.projector, target_spec, {.name = "--target-region"});

  MapOptions options;
  options.sampling.layout.particles = args.particles;
  options.sampling.layout.name = "--source-region";
  options.sampling.sampling.seed = args.seed;
  options.rest_scale = parse_rest_scale(args.rest_scale, "--rest-scale");
  options.relaxation.solver = args.solver == "explicit" ? SolverKind::Faithful : SolverKind::Fast;
  options.relaxation.threads = args.threads;
  options.relaxation.max_iterations = args.max_iterations;
  options.progress = terminal_progress(args.quiet);
  options.relaxation.progress = options.progress;
  const MapResult result =
      map_regions(*source.projector, source_region, *target.projector, target_region, options);
  end_progress_line();

  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const nlohmann::json report = map_report(args, result, total);
  if (!args.out.empty()) {
    const std::filesystem::path dir(args.out);
    std::filesystem::create_directories(dir);
    const ParticleGrid& grid = result.sampling.grid;
    write_mesh(dir / "source_grid.obj", to_polygon_mesh(grid, grid.source_positions()));
    write_mesh(dir / "naive_grid.obj", to_polygon_mesh(grid, result.naive.positions));
    write_mesh(dir / "target_grid.obj", to_polygon_mesh(grid, result.relaxation.positions));
  }
  if (!args.report.empty()) {
    write_file_atomically(args.report, [&](std::ofstream& out) { out << report.dump(2) << '\n'; });
  }
  std::cout << "particles " << report["particles"] << ", springs " << report["springs"]
            << ", solver " << args.solver << ", " << result.relaxation.iterations << " iterations, "
            << (result.relaxation.converged ? "converged" : "NOT converged") << " ("
            << to_string(result.relaxation.reason) << ")\n"
            << "length energy " << result.relaxation.length_energy << ", angle energy "
            << result.relaxation.angular_energy << ", relative gradient "
            << result.relaxation.relative_gradient << ", folds " << result.relaxation.folded_faces
            << ", boundary residual " << result.relaxation.boundary_residual << '\n'
            << "seconds: total " << total << ", solve " << result.relaxation.solve_seconds << '\n';
  return result.relaxation.converged ? kOk : kNumerical;
}

}  // namespace
}  // namespace elastic::cli

ELASTIC_COMMAND(
    "map", "Map a source region onto a target region with least distortion", [](CLI::App& sub) {
      auto a = std::make_shared<elastic::cli::MapArgs>();
      sub.add_option("--source", a->source, "Source mesh file");
      sub.add_option("--source-image", a->source_image,
                     "Source image (PNG, JPEG, ...) on a plane; region: rectangle or ellipse");
      sub.add_option("--image-width", a->image_width, "Physical width of the source image's plane")
          ->check(CLI::PositiveNumber);
      sub.add_option("--source-region", a->source_region,
                     "Source region: disk:X,Y,Z,R | points:FILE | boundary | uv:FILE");
      sub.add_option("--source-anchor", a->source_anchor,
                     "X,Y,Z: start of the boundary correspondence");
      sub.add_option("--target", a->target, "Target mesh file")->required();
      sub.add_option("--target-region", a->target_region, "Target region (same forms)");
      sub.add_option("--target-anchor", a->target_anchor,
                     "X,Y,Z: start of the boundary correspondence");
      sub.add_option("--particles", a->particles, "Number of particles (within 5%)");
      sub.add_option("--solver", a->solver, "lbfgs (fast) or explicit (the paper's integrator)")
          ->check(CLI::IsMember({"lbfgs", "explicit"}));
      sub.add_option("--rest-scale", a->rest_scale, "boundary | area | none")
          ->check(CLI::IsMember({"boundary", "area", "none"}));
      sub.add_option("--scheme", a->scheme, "Subdivision scheme for both meshes")
          ->check(CLI::IsMember({"auto", "loop", "catmull-clark"}));
      sub.add_option("--threads", a->threads, "Threads (0: all)")->check(CLI::Range(0, 1024));
      sub.add_option("--seed", a->seed, "Seed of the sampling's random jitter");
      sub.add_option("--max-iterations", a->max_iterations, "Solver iteration budget (0: default)");
      sub.add_option("--report", a->report, "Write the JSON report to this file");
      sub.add_option("--out", a->out, "Write source/naive/target grids (OBJ) into this folder");
      sub.add_flag("--quiet,-q", a->quiet, "No progress line, no warnings");
      sub.footer(
          "Example:\n  elastic map --source meshes/plane_quads.obj --target meshes/cap_quads.obj "
          "\\\n"
          "      --particles 5775 --report report.json --out out/\n"
          "maps the whole plane onto the whole cap (both regions: the surface boundary).");
      return [a] { return elastic::cli::run_map(*a); };
    });
