#include "map_job.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>

#include "allocator.h"
#include "command.h"
#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/regions/region_spec.h"
#include "job_file.h"
#include "verdict.h"

namespace elastic::cli {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// A placed decal's placement (null for a drawn target region).
nlohmann::json decal_report(const MapSession& session) {
  if (!session.decal) {
    return nullptr;
  }
  const DecalGeometry& g = *session.decal;
  const auto vec = [](const Eigen::Vector3d& v) { return nlohmann::json{v.x(), v.y(), v.z()}; };
  return {{"point", vec(g.placement.point)},
          {"angle_deg", g.placement.angle_degrees},
          {"scale", g.placement.scale},
          {"centre", vec(g.target_centre_position)},
          {"up", vec(g.target_frame.up)},
          {"normal", vec(g.target_frame.normal)},
          {"source_centre", vec(g.source_centre)},
          {"source_radius", g.source_radius},
          {"turned_deg", g.turned_degrees},
          {"snapped_particles", g.snapped_particles},
          {"snap_distance", g.snap_distance},
          {"target_area", session.target_region.area()},
          {"seconds_shooting", g.seconds_shooting},
          {"seconds_cut", g.seconds_cut}};
}

/// The subdivision step after the map (end of §4.3): one entry per level.
nlohmann::json subdivision_report(const MapResult& r) {
  nlohmann::json levels = nlohmann::json::array();
  for (const RefinementLevel& level : r.subdivision_levels) {
    levels.push_back({{"particles_before", level.particles_before},
                      {"particles_after", level.particles_after},
                      {"iterations", level.iterations},
                      {"converged", level.converged},
                      {"reason", std::string(to_string(level.reason))},
                      // The solver's own fold-guard count on that level's grid (faces with
                      // a folded corner); the report's `folds` judges the final map.
                      {"solver_initial_folded_faces", level.initial_folded_faces},
                      {"solver_folded_faces", level.folded_faces},
                      {"energy_before", level.initial_energy},
                      {"energy", level.energy},
                      {"seconds", level.seconds_subdivide + level.seconds_relax}});
  }
  return {{"levels", r.subdivisions},
          {"sampled_particles", r.sampled_particles},
          {"iterations", r.subdivision_iterations},
          {"seconds", r.seconds_subdivision},
          {"per_level", levels}};
}

// The flags of a drawn target region's map that a placed decal has no use for: refused rather
// than ignored.
void check_decal_flags(const MapJob& job) {
  const auto refuse = [](bool given, const std::string& flag, const std::string& why) {
    if (given) {
      throw UsageError(flag + " does not apply to --target-place: " + why);
    }
  };
  refuse(job.rest_scale != "auto", "--rest-scale", "the decal's size is its SCALE");
  refuse(job.boundary != "auto", "--boundary", "a placed decal's boundary is free");
  refuse(job.boundary_offset != "auto", "--boundary-offset", "a placed decal has no target curve");
  refuse(job.subdivide != 0, "--subdivide", "not available for placed decals yet");
}

// A placed decal (--target-place): map_decal, its cut region kept in the session.
void run_decal(const MapJob& job, const MapOptions& options, MapSession& s) {
  check_decal_flags(job);
  DecalPlacement placement;
  try {
    placement = parse_decal_placement(job.target_place, "--target-place");
  } catch (const InvalidInputError& e) {
    throw UsageError(e.what());
  }
  MapDecalOptions decal;
  decal.sampling = options.sampling;
  decal.relaxation = options.relaxation;
  decal.progress = options.progress;
  MapDecalResult placed =
      map_decal(*s.source.projector, s.source_region, *s.target.projector, placement, decal);
  s.result = std::move(placed.map);
  s.decal = std::move(placed.geometry);
  s.placed_region = std::move(placed.target_region);
  s.target_region = *s.placed_region;
}

}  // namespace

Eigen::Vector3d parse_point(const std::string& text, const std::string& flag) {
  Eigen::Vector3d p;
  char c1 = 0, c2 = 0;
  std::istringstream in(text);
  if (!(in >> p.x() >> c1 >> p.y() >> c2 >> p.z()) || c1 != ',' || c2 != ',' || !p.allFinite()) {
    throw UsageError(flag + ": expected X,Y,Z (finite numbers), got '" + text + "'");
  }
  std::string rest;
  if (in >> rest) {
    throw UsageError(flag + ": expected X,Y,Z (finite numbers), got '" + text + "'");
  }
  return p;
}

void add_map_flags(CLI::App& sub, MapJob& a) {
  sub.add_option("--source", a.source, "Source mesh file (OBJ, OFF, PLY, STL)");
  sub.add_option("--source-image", a.source_image,
                 "Source image (PNG, JPEG, ...) on a plane; region: rectangle or ellipse");
  sub.add_option("--image-width", a.image_width, "Physical width of the source image's plane")
      ->check(CLI::PositiveNumber);
  sub.add_option("--max-image-pixels", a.max_image_pixels,
                 "Refuse images with more pixels (width x height), checked before decoding")
      ->check(CLI::PositiveNumber);
  sub.add_option("--source-region", a.source_region,
                 "Source region: disk:X,Y,Z,R | points:FILE | boundary | uv:FILE");
  sub.add_option("--source-anchor", a.source_anchor, "X,Y,Z: start of the boundary correspondence");
  sub.add_option("--target", a.target, "Target mesh file (required)");
  CLI::Option* target_region =
      sub.add_option("--target-region", a.target_region, "Target region (same forms)");
  CLI::Option* target_anchor = sub.add_option("--target-anchor", a.target_anchor,
                                              "X,Y,Z: start of the boundary correspondence");
  sub.add_option("--target-place", a.target_place,
                 "X,Y,Z[,ANGLE_DEG[,SCALE]]: instead of --target-region, place the source as a "
                 "decal with a free boundary: its centre on the target point closest to X,Y,Z, "
                 "its up ANGLE_DEG counter-clockwise from the world +Y projected on the surface "
                 "(default 0), SCALE times its own size (default 1)")
      ->excludes(target_region)
      ->excludes(target_anchor);
  sub.add_option("--particles", a.particles, "Number of particles (within 5%), 16..5000000")
      ->check(CLI::Range(kMinParticles, kMaxParticles));
  sub.add_option("--solver", a.solver, "lbfgs (fast) or explicit (the paper's integrator)")
      ->check(CLI::IsMember({"lbfgs", "explicit"}));
  sub.add_option("--preconditioner", a.preconditioner,
                 "H0 of lbfgs: multigrid (V-cycle, default) or direct (exact factorisation)")
      ->check(CLI::IsMember({"multigrid", "direct"}));
  sub.add_option("--newton", a.newton,
                 "auto (default: H0 of lbfgs becomes the energy's Hessian after 50 iterations "
                 "without convergence, on grids of up to 10,000 particles), on (from the first "
                 "iteration, any size) or off (the Laplacian H0 throughout); with a sliding "
                 "boundary, in its held phase only")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  sub.add_option("--coarse-start", a.coarse_start,
                 "N: a grid of more than N particles (default 50000) relaxes from the relaxed "
                 "map of a grid of 1/8 as many, carried onto it, instead of from the naive map "
                 "(the coarse map chooses the boundary offset and where a sliding boundary goes); "
                 "0: never")
      ->check(CLI::Range(0L, static_cast<long>(kMaxParticles)));
  sub.add_option("--coarse-hold", a.coarse_hold,
                 "N: with --coarse-start, a sliding boundary on a grid of more than N particles "
                 "(default 500000) is held where the coarse map slid it (faster; the coarse "
                 "boundary can cost energy on compressed regions); on smaller grids it slides on")
      ->check(CLI::Range(0L, static_cast<long>(kMaxParticles)));
  sub.add_option("--rest-scale", a.rest_scale,
                 "auto (default: the smaller of boundary and area) | boundary | area | none")
      ->check(CLI::IsMember({"auto", "boundary", "area", "none"}));
  sub.add_option("--boundary", a.boundary,
                 "auto (default: slide, or fixed with --subdivide), fixed (the paper's arc-length "
                 "boundary) or slide (boundary particles move along the target curve, in order, "
                 "to lower the energy)")
      ->check(CLI::IsMember({"auto", "fixed", "slide"}));
  sub.add_option("--boundary-offset", a.boundary_offset,
                 "auto (default: turn the correspondence to the least naive-map energy when no "
                 "anchor is given) or anchor (start at the regions' anchors)")
      ->check(CLI::IsMember({"auto", "anchor"}));
  sub.add_option("--energy", a.energy,
                 "robust (default: the paper's springs plus an injectivity barrier) or paper "
                 "(the paper's springs alone, as in Table 1)")
      ->check(CLI::IsMember({"robust", "paper"}));
  sub.add_option("--angular-stiffness", a.angular_stiffness,
                 "auto (default: 0.25 with --energy robust, 1 with --energy paper or --solver "
                 "explicit) or the stiffness of the angular springs relative to the normal "
                 "springs, 0..100")
      ->check(CLI::IsMember({"auto"}) | CLI::Range(0.0, 100.0));
  sub.add_option("--distortion-weight", a.distortion_weight,
                 "Weight of a symmetric Dirichlet term over the grid's triangles, relative to the "
                 "normal springs, 0..100 (default 0: off; --energy robust only). It trades length "
                 "for angle fidelity: 0.2 brings a flat disk on a hump within 2% of DCM's "
                 "distortion at about 7% more length energy (docs/solvers.md)")
      ->check(CLI::Range(0.0, 100.0));
  sub.add_option("--distortion-guard", a.distortion_guard,
                 "on (default): when the relaxed map's symmetric Dirichlet distortion is above its "
                 "naive start's, relax on with --distortion-weight 0.2 (--energy robust with no "
                 "--distortion-weight only; the report's distortion_guard says what it did); off")
      ->check(CLI::IsMember({"on", "off"}));
  sub.add_option("--scheme", a.scheme, "Subdivision scheme for both meshes")
      ->check(CLI::IsMember({"auto", "loop", "catmull-clark"}));
  sub.add_option("--subdivide", a.subdivide,
                 "Refine the particle grid K times after the map and relax briefly (end of §4.3)")
      ->check(CLI::Range(0, 4));
  sub.add_option("--threads", a.threads, "Threads (0: all)")->check(CLI::Range(0, 1024));
  sub.add_option("--jitter", a.jitter,
                 "Random initial displacement of the sampling's particles, fraction of the "
                 "spacing (0: none, the sampling is deterministic)")
      ->check(CLI::Range(0.0, 0.5));
  sub.add_option("--seed", a.seed, "Seed of the --jitter (the same seed repeats a run exactly)");
  sub.add_option("--curvature-radius", a.curvature_radius,
                 "The adaptive sampling's curvature averaged over about this many grid spacings "
                 "(a kernel as wide as a Gaussian of this standard deviation; 0: pointwise, the "
                 "paper's and Table 1's)")
      ->check(CLI::Range(0.0, 100.0));
  sub.add_option("--max-iterations", a.max_iterations, "Solver iteration budget (0: default)")
      ->check(CLI::NonNegativeNumber);
  sub.add_option("--max-memory", a.max_memory_mb,
                 "Refuse runs estimated to need more memory, in MB (0: half the physical memory, "
                 "at most 4096), checked before any work")
      ->check(CLI::NonNegativeNumber);
  sub.add_option("--report", a.report, "Write the JSON report to this file");
  sub.add_flag("--quiet,-q", a.quiet, "No progress, no warnings: only results");
}

MapOptions make_map_options(const MapJob& job, const ProgressCallback& progress) {
  MapOptions options;
  options.sampling.layout.particles = job.particles;
  options.sampling.layout.name = "--source-region";
  options.sampling.sampling.seed = job.seed;
  options.sampling.sampling.jitter = job.jitter;
  options.sampling.sampling.curvature_radius = job.curvature_radius;
  options.rest_scale = parse_rest_scale(job.rest_scale, "--rest-scale");
  options.relaxation.solver = job.solver == "explicit" ? SolverKind::Faithful : SolverKind::Fast;
  options.relaxation.energy = parse_energy_kind(job.energy, "--energy");
  options.choose_offset = job.boundary_offset == "auto";
  options.relaxation.boundary = job.boundary == "auto"
                                    ? auto_boundary_mode(job.subdivide)
                                    : parse_boundary_mode(job.boundary, "--boundary");
  options.relaxation.lbfgs.preconditioner =
      parse_preconditioner(job.preconditioner, "--preconditioner");
  options.relaxation.lbfgs.newton.mode = parse_newton_mode(job.newton, "--newton");
  options.relaxation.threads = job.threads;
  options.relaxation.max_iterations = job.max_iterations;
  if (job.angular_stiffness != "auto") {
    options.relaxation.angular_stiffness = std::stod(job.angular_stiffness);  // checked: 0..100
  }
  options.relaxation.distortion_stiffness = job.distortion_weight;
  options.distortion_guard = job.distortion_guard == "on";
  options.subdivisions = job.subdivide;
  options.coarse_start_above = static_cast<int>(job.coarse_start);
  options.coarse_hold_above = static_cast<int>(job.coarse_hold);
  options.progress = progress;
  options.relaxation.progress = progress;
  return options;
}

std::string mesh_surface_key(const std::string& path, const std::string& scheme) {
  return "mesh|" + path + "|" + scheme;
}

std::string image_surface_key(const std::string& path, double width, const std::string& scheme) {
  return "image|" + path + "|" + std::to_string(width) + "|" + scheme;
}

namespace {

// One side's region from its spec and its --<side>-anchor flag (side: "source" or "target").
Region side_region(const SurfaceProjector& projector, RegionSpec spec, const std::string& anchor,
                   const std::string& side) {
  if (!anchor.empty()) {
    spec.anchor = parse_point(anchor, "--" + side + "-anchor");
  }
  return make_region(projector, spec, {.name = "--" + side + "-region"});
}

// Loads both sides of the job into `s`: each surface (read, repaired, limit surface, projector)
// and its region (the target's only for a drawn region, not for --target-place). Without a cache
// the two sides load at once, as nothing of one depends on the other (spot.obj -> bob_tri.obj,
// 2,000 particles, 2 threads: the whole `elastic map` 0.63 -> 0.53 s, farm-bench medians), and
// both meshes are read and checked before either limit surface is built, so that a mesh the map
// refuses is refused at once (a non-manifold target beside armadillo.obj was refused after the
// 7.7 s armadillo's side took). With a cache (shared by the two sides) they load one after the
// other. Within each half, the source's errors and warnings come out first.
void load_sides(const MapJob& job, MapSession& s, std::optional<MeshReadResult> target_read,
                SurfaceCache* cache) {
  // Both sides' meshes, read and sanitised, or surfaces found in the cache (then `built`).
  LoadedSurface source, target;
  bool source_built = false, target_built = false;
  const std::string source_key =
      s.image ? image_surface_key(job.source_image, job.image_width, job.scheme)
              : mesh_surface_key(job.source, job.scheme);
  const std::string target_key = mesh_surface_key(job.target, job.scheme);
  const auto cached = [&](const std::string& key, LoadedSurface& into) {
    if (cache == nullptr) {
      return false;
    }
    const auto found = cache->find(key);
    if (found != cache->end()) {
      into = found->second;
    }
    return found != cache->end();
  };
  std::exception_ptr source_error, target_error;
  // Runs `work`, keeping what it throws in `error` (the other side goes on).
  const auto guarded = [](std::exception_ptr& error, const auto& work) {
    return [&error, &work] {
      try {
        work();
      } catch (...) {
        error = std::current_exception();
      }
    };
  };
  const auto read_source_mesh = [&] {
    if (!source_built) {
      source =
          s.image ? sanitised_mesh(s.image->mesh, job.source_image) : read_surface_mesh(job.source);
    }
  };
  const auto read_target_mesh = [&] {
    if (!target_built) {
      target = target_read ? sanitised_mesh(std::move(target_read->mesh), job.target,
                                            std::move(target_read->warnings))
                           : read_surface_mesh(job.target);
    }
  };
  // The limit surface (cached when there is a cache) unless found there, then the region.
  const auto build = [&](LoadedSurface& loaded, bool built, const std::string& key) {
    if (!built) {
      build_limit_surface(loaded, job.scheme);
      if (cache != nullptr) {
        cache->emplace(key, loaded);
      }
    }
  };
  const auto build_source_side = [&] {
    build(source, source_built, source_key);
    s.source = source;
    s.source_region = side_region(
        *s.source.projector,
        s.image ? s.image->region : parse_region_flag(job.source_region, "--source-region"),
        job.source_anchor, "source");
  };
  const auto build_target_side = [&] {
    build(target, target_built, target_key);
    s.target = target;
    if (job.target_place.empty()) {
      s.target_region =
          side_region(*s.target.projector, parse_region_flag(job.target_region, "--target-region"),
                      job.target_anchor, "target");
    }
  };
  const auto read_source = guarded(source_error, read_source_mesh);
  const auto read_target = guarded(target_error, read_target_mesh);
  const auto build_source = guarded(source_error, build_source_side);
  const auto build_target = guarded(target_error, build_target_side);
  const auto rethrow = [&] {
    if (source_error) {
      std::rethrow_exception(source_error);
    }
    if (target_error) {
      print_warnings(source.warnings, job.quiet);
      std::rethrow_exception(target_error);
    }
  };
  if (cache == nullptr) {
    tbb::parallel_invoke(read_source, read_target);
    rethrow();
    tbb::parallel_invoke(build_source, build_target);
  } else {  // one side after the other: the target may be the source's surface, cached
    source_built = cached(source_key, source);
    read_source();
    rethrow();
    build_source();
    rethrow();
    target_built = cached(target_key, target);
    read_target();
    rethrow();
    build_target();
  }
  rethrow();
  print_warnings(s.source.warnings, job.quiet);
  print_warnings(s.target.warnings, job.quiet);
}

}  // namespace

std::unique_ptr<MapSession> run_map_job(const MapJob& job, const ProgressCallback& progress,
                                        const FrameCallback& frame, long frame_interval,
                                        SurfaceCache* cache) {
  const auto start = std::chrono::steady_clock::now();
  require_flag(job.target, "--target");
  check_particles(job.particles);
  if (job.seed != 0 && job.jitter == 0.0) {
    throw UsageError("--seed chooses the random start of --jitter, which is 0: give --jitter F");
  }
  if (job.source.empty() == job.source_image.empty()) {
    throw UsageError("give exactly one of --source MESH and --source-image IMAGE");
  }
  // The map's memory, from the final particle count (each --subdivide level quadruples it).
  const double final_particles = static_cast<double>(job.particles) * std::pow(4.0, job.subdivide);
  const double map_bytes = kBaseBytes + kMapBytesPerParticle * final_particles;
  const std::string map_what =
      "--particles " + std::to_string(job.particles) +
      (job.subdivide > 0 ? " --subdivide " + std::to_string(job.subdivide) : std::string());
  check_memory(map_bytes + job.extra_bytes,
               map_what + (job.extra_bytes > 0.0 ? " " + job.extra_what : ""), job.max_memory_mb);
  // A command's memory per target face (a paste's painted mesh) needs the target's face count:
  // the target's control mesh is read first and checked before any surface is built (building
  // the limit surfaces and their search structures is the expensive part of loading).
  const std::string target_key = mesh_surface_key(job.target, job.scheme);
  std::optional<MeshReadResult> target_read;
  if (job.extra_bytes_per_target_face > 0.0) {
    size_t faces = 0;
    const auto cached = cache != nullptr ? cache->find(target_key) : SurfaceCache::iterator{};
    if (cache != nullptr && cached != cache->end()) {
      faces = cached->second.mesh->num_faces();
    } else {
      target_read = read_mesh(job.target);
      faces = target_read->mesh.num_faces();
    }
    check_memory(
        map_bytes + job.extra_bytes + job.extra_bytes_per_target_face * static_cast<double>(faces),
        map_what + " " + job.extra_what, job.max_memory_mb);
  }
  auto session = std::make_unique<MapSession>();
  MapSession& s = *session;
  // An image source is a plane carrying the image; its region is the rectangle or the inscribed
  // ellipse.
  if (!job.source_image.empty()) {
    if (job.source_region != "boundary" && job.source_region != "rectangle" &&
        job.source_region != "ellipse") {
      throw UsageError(
          "--source-region: with --source-image it is 'rectangle' (default) or "
          "'ellipse', got '" +
          job.source_region + "'");
    }
    s.image =
        make_image_plane(job.source_image,
                         {.width = job.image_width,
                          .shape = job.source_region == "ellipse" ? ImageRegionShape::Ellipse
                                                                  : ImageRegionShape::Rectangle},
                         image_read_options(job));
  }
  if (progress) {
    progress({.stage = "load"});
  }
  load_sides(job, s, std::move(target_read), cache);
  MapOptions options = make_map_options(job, progress);
  options.relaxation.frame = frame;
  options.relaxation.frame_interval = std::max(1L, frame_interval);
  if (!job.target_place.empty()) {
    s.seconds_loading = seconds_since(start);
    run_decal(job, options, s);
  } else {
    s.seconds_loading = seconds_since(start);
    s.result = map_regions(*s.source.projector, s.source_region, *s.target.projector,
                           s.target_region, options);
  }
  s.metrics = measure_placement(s, s.result.relaxation.positions, s.result.relaxation.points);
  s.naive_metrics = measure_placement(s, s.result.naive.positions, s.result.naive.points);
  s.seconds_total = seconds_since(start);
  return session;
}

void check_particles(long particles) {
  if (particles < kMinParticles || particles > kMaxParticles) {
    throw UsageError("--particles: must be between " + std::to_string(kMinParticles) + " and " +
                     std::to_string(kMaxParticles) + ", got " + std::to_string(particles));
  }
}

std::string effective_source_region(const MapJob& job) {
  // An image source's region is its rectangle unless the ellipse is asked for; "boundary" (the
  // flag's default for a mesh) means the rectangle there.
  if (!job.source_image.empty() && job.source_region != "ellipse") {
    return "rectangle";
  }
  return job.source_region;
}

nlohmann::json recorded_job(const MapJob& job, nlohmann::json job_json) {
  if (job_json.contains("source-region")) {
    job_json["source-region"] = effective_source_region(job);
  }
  return job_json;
}

nlohmann::json map_report(const MapJob& job, const MapSession& session,
                          const nlohmann::json& job_json) {
  const MapResult& r = session.result;
  const RelaxationResult& x = r.relaxation;
  const SamplingStatistics& s = r.sampling.statistics;
  return {
      {"job", recorded_job(job, job_json)},
      {"particles", s.particles},
      {"springs", s.normal_springs + s.angular_springs},
      {"springs_normal", s.normal_springs},
      {"springs_angular", s.angular_springs},
      {"boundary_particles", s.boundary_particles},
      {"solver", job.solver},
      {"preconditioner", x.solver == SolverKind::Fast ? std::string(to_string(x.preconditioner))
                                                      : std::string("none")},
      {"newton",
       {{"mode", job.newton},
        {"iterations", x.newton_iterations},
        {"factorisations", x.newton_factorisations}}},
      {"iterations", x.iterations},
      {"converged", x.converged},
      {"reason", std::string(to_string(x.reason))},
      {"seconds",
       {{"total", session.seconds_total},
        {"loading", session.seconds_loading},
        {"setup", r.seconds_sampling + r.seconds_coarse + r.seconds_naive + x.setup_seconds},
        {"solve", x.solve_seconds},
        {"sampling", r.seconds_sampling},
        {"naive_map", r.seconds_naive},
        {"solver_setup", x.setup_seconds},
        {"coarse_start", r.seconds_coarse},
        {"mapping", r.seconds_mapping}}},
      {"peak_mib", peak_resident_mib()},
      {"energy_kind", std::string(to_string(x.energy))},
      {"angular_stiffness", x.angular_stiffness},
      {"energy",
       {{"length", x.length_energy},
        {"angle", x.angular_energy},
        {"barrier", x.barrier_energy},
        {"distortion", x.distortion_energy},
        {"magnet", x.magnet_energy},
        {"initial", x.initial_energy}}},
      {"gradient", {{"relative", x.relative_gradient}, {"norm", x.gradient_norm}}},
      // The one fold count (docs/metrics.md), of the final and of the naive map.
      {"folds", session.metrics.folds},
      {"sigma_min", session.metrics.sigma_min},
      {"initial_folds", session.naive_metrics.folds},
      {"verdict", judge_map(job, session).to_json()},
      {"held_particles", x.held_particles.size()},
      {"untangle", {{"steps", x.untangle_steps}, {"taken", x.untangled}}},
      {"distortion_guard",
       {{"checked", r.guard.checked},
        {"taken", r.guard.taken},
        {"naive", r.guard.naive},
        {"relaxed", r.guard.relaxed},
        {"guarded", r.guard.guarded},
        {"iterations", r.guard.iterations}}},
      {"coarse_start",
       {{"above", job.coarse_start},
        {"hold_above", job.coarse_hold},
        {"particles", r.coarse_particles},
        {"iterations", r.coarse_iterations}}},
      {"boundary_residual", x.boundary_residual},
      {"rest_scale", {{"mode", job.rest_scale}, {"factor", r.rest_scale}}},
      {"boundary",
       {{"mode", std::string(to_string(x.boundary))},
        {"slide", x.boundary_slide},
        {"slide_iterations", x.slide_iterations},
        {"slide_reason", x.boundary == BoundaryMode::Slide ? std::string(to_string(x.slide_reason))
                                                           : std::string()}}},
      {"boundary_offset",
       {{"chosen", r.offset_chosen},
        {"offset", r.boundary_offset},
        {"naive_energy", r.offset_energy},
        {"naive_energy_at_zero", r.offset_energy_at_zero},
        {"naive_folds", r.offset_folds}}},
      {"subdivision", subdivision_report(r)},
      {"decal", decal_report(session)},
      {"sampling",
       {{"spacing_min", s.spacing_min},
        {"spacing_median", s.spacing_median},
        {"spacing_max", s.spacing_max},
        {"density_ratio", s.density_ratio},
        // Faces of the source grid with a corner turned over against the source's normal: the
        // grid does not follow the region there (a protrusion narrower than its spacing).
        {"inverted_faces", s.inverted_faces},
        {"min_corner_sine", s.min_corner_sine},
        // The adaptive sampling's own iteration (§4.3): a scan's creases can keep it from
        // settling (docs/sampling.md); the map is judged on its own all the same.
        {"iterations", r.sampling.sampling.iterations},
        {"converged", r.sampling.sampling.converged},
        {"stalled", r.sampling.sampling.stalled},
        {"last_move", r.sampling.sampling.max_move}}}};
}

MapMetrics measure_placement(const MapSession& session, const Eigen::Matrix3Xd& positions,
                             const std::vector<SurfacePoint>& points, std::vector<char> outside) {
  return measure_on_target(session.result.sampling.grid, *session.target.surface,
                           session.result.rest_scale, positions, points, std::move(outside));
}

void write_report(const std::string& path, const nlohmann::json& report) {
  if (path.empty()) {
    return;
  }
  write_file_atomically(path, [&](std::ofstream& out) { out << report.dump(2) << '\n'; });
}

void print_map_summary(const MapJob& job, const MapSession& session) {
  const MapResult& r = session.result;
  const RelaxationResult& x = r.relaxation;
  const SamplingStatistics& s = r.sampling.statistics;
  std::cout << "particles " << s.particles << ", springs " << s.normal_springs + s.angular_springs
            << ", solver " << job.solver << ", " << x.iterations << " iterations, "
            << (x.converged ? "converged" : "NOT converged") << " (" << to_string(x.reason) << ")\n"
            << "solver energy: length springs " << x.length_energy << ", angle springs "
            << x.angular_energy << ", relative gradient " << x.relative_gradient << ", folds "
            << session.metrics.folds << ", worst sigma_min " << session.metrics.sigma_min
            << ", boundary residual " << x.boundary_residual << '\n'
            << "seconds: total " << session.seconds_total << ", solve " << x.solve_seconds << '\n';
}

}  // namespace elastic::cli
