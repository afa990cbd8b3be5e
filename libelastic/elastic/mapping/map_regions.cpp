#include "elastic/mapping/map_regions.h"

#include <tbb/parallel_invoke.h>
#include <tbb/task_group.h>

#include <chrono>
#include <optional>

#include "elastic/core/error.h"
#include "elastic/solvers/solver_common.h"

namespace elastic {

namespace {
double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void check_surfaces(const SurfaceProjector& source, const Region& source_region,
                    const SurfaceProjector& target, const Region& target_region) {
  if (source_region.surface != &source.surface()) {
    throw InvalidInputError("source region", "does not lie on the source surface");
  }
  if (target_region.surface != &target.surface()) {
    throw InvalidInputError("target region", "does not lie on the target surface");
  }
}

double region_rest_scale(RestScale mode, const Region& source_region, const Region& target_region) {
  const RegionSizes sizes{.source_boundary_length = source_region.boundary_curve().length(),
                          .target_boundary_length = target_region.boundary_curve().length(),
                          .source_area = source_region.area(),
                          .target_area = target_region.area()};
  return rest_scale_factor(mode, sizes);
}

// The relaxation problem of `grid` on `target` from `start`, the boundary's targets being the
// start's boundary positions.
RelaxationProblem relaxation_problem(const ParticleGrid& grid, const SurfaceProjector& target,
                                     const InitialMap& start, const MapResult& result,
                                     RestScale mode) {
  RelaxationProblem problem;
  problem.grid = &grid;
  problem.target = &target;
  problem.initial_positions = start.positions;
  problem.initial_points = start.points;
  problem.rest_scale = result.rest_scale;
  problem.rest_scale_mode = mode;
  problem.boundary_targets.resize(3, static_cast<Eigen::Index>(grid.boundary_loop.size()));
  for (size_t k = 0; k < grid.boundary_loop.size(); ++k) {
    problem.boundary_targets.col(static_cast<Eigen::Index>(k)) =
        start.positions.col(grid.boundary_loop[k]);
  }
  const RegionDiskMap* target_disk = result.target_disk.get();
  problem.boundary_curve = [target_disk](double s) { return target_disk->boundary_point(s); };
  return problem;
}
// The distortion guard (MapOptions::distortion_guard): when the relaxed map's symmetric Dirichlet
// excess E_sd (particles/spring_energy.h, lambda = 1) is above its naive start's, the length
// energy's minimum traded angles for lengths (a flat disk onto a hump); the relaxation then goes on
// from there with the distortion term at kGuardDistortionStiffness and is taken when it converges
// fold-free.
void guard_distortion(const ParticleGrid& grid, const MapOptions& options,
                      const RelaxationProblem& problem, MapResult& result) {
  const RelaxationOptions& relaxation = options.relaxation;
  if (!options.distortion_guard || relaxation.energy != EnergyKind::Robust ||
      relaxation.distortion_stiffness > 0.0 || !result.relaxation.converged ||
      result.relaxation.folded_faces > 0) {
    return;
  }
  const SpringEnergyOptions measure{
      .stiffness = 1.0, .rest_scale = result.rest_scale, .distortion_stiffness = 1.0};
  const SpringSystem springs(grid, measure);  // built once, evaluated up to three times
  result.guard.relaxed = springs.evaluate(result.relaxation.positions).distortion;
  result.guard.naive = springs.evaluate(result.naive.positions).distortion;
  result.guard.checked = true;
  if (!(result.guard.relaxed > options.distortion_guard_ratio * result.guard.naive)) {
    return;
  }
  RelaxationProblem again = problem;
  again.initial_positions = result.relaxation.positions;
  again.initial_points = result.relaxation.points;
  if (relaxation.boundary == BoundaryMode::Slide) {
    again.boundary_parameters = result.relaxation.boundary_parameters;
  }
  again.reference_gradient_norm = result.relaxation.initial_gradient_norm;
  RelaxationOptions with_term = relaxation;
  with_term.distortion_stiffness = kGuardDistortionStiffness;
  RelaxationResult guarded = relax(again, with_term);
  result.guard.iterations = guarded.iterations;
  if (!guarded.converged || guarded.folded_faces > 0) {
    return;
  }
  result.guard.taken = true;
  result.guard.guarded = springs.evaluate(guarded.positions).distortion;
  guarded.iterations += result.relaxation.iterations;
  guarded.setup_seconds += result.relaxation.setup_seconds;
  guarded.solve_seconds += result.relaxation.solve_seconds;
  guarded.initial_energy = result.relaxation.initial_energy;
  guarded.initial_folded_faces = result.relaxation.initial_folded_faces;
  result.relaxation = std::move(guarded);
}

// Whether MapOptions::coarse_start_above applies to a cold map of `grid`.
bool uses_coarse_start(const MapOptions& options, const ParticleGrid& grid) {
  return options.coarse_start_above > 0 && grid.num_particles() > options.coarse_start_above &&
         options.relaxation.solver == SolverKind::Fast && options.subdivisions == 0 &&
         options.sampling.layout.particles / options.coarse_start_ratio >= 16;
}

// The two regions' disk maps (the naive map's, Fig. 9a); a multilevel start's top level hands its
// own to the coarse level, which returns them in its result.
struct DiskMaps {
  std::unique_ptr<RegionDiskMap> source, target;
};

MapResult map_cold(const SurfaceProjector& source, const Region& source_region,
                   const SurfaceProjector& target, const Region& target_region,
                   const MapOptions& options, bool top, DiskMaps disks);

// The coarse map of a multilevel start: the same job with 1/ratio of the particles, its stages
// reported as "coarse <stage>" and no animation frames (they would have the coarse grid's size).
MapResult coarse_map(const SurfaceProjector& source, const Region& source_region,
                     const SurfaceProjector& target, const Region& target_region,
                     const MapOptions& options, DiskMaps disks) {
  MapOptions coarse = options;
  coarse.sampling.layout.particles = options.sampling.layout.particles / options.coarse_start_ratio;
  coarse.relaxation.frame = nullptr;
  const auto prefixed = [](const ProgressCallback& callback) -> ProgressCallback {
    if (!callback) {
      return {};
    }
    return [callback](const Progress& p) {
      const std::string stage = "coarse " + std::string(p.stage);
      Progress q = p;
      q.stage = stage;
      return callback(q);
    };
  };
  coarse.progress = prefixed(options.progress);
  coarse.relaxation.progress = prefixed(options.relaxation.progress);
  return map_cold(source, source_region, target, target_region, coarse, /*top=*/false,
                  std::move(disks));
}

// Starts `problem` (the naive map's) from the coarse map carried onto `grid` (prolonged_map) and
// returns the options to relax it with. The stopping tests refer to the coarse start's gradient, as
// a warm start's do to its previous map's (|P g| of the naive map hardly depends on the particle
// count: 0.26, 0.24 and 0.20 at 5,777, 24,984 and 100,536 particles on Plane -> Cap). A fixed
// boundary keeps the naive map's arc-length positions exactly. With `hold` (the grid the caller
// asked for, above MapOptions::coarse_hold_above), a sliding boundary is held where the coarse map
// slid it (its parameters interpolated): on Plane -> Cap, sliding again on that grid lowered the
// energy by 0.003% at 1,001,732 particles, for a solve of 13.8 instead of 5.8 s; on the compressed
// hemisphere -> spot side map, whose coarse slide stopped at its settle test, by 0.47% (sigma_min
// 0.602 -> 0.685) for 189 instead of 47 s. Every other level slides from the carried start, so
// that the boundary is its own grid's: held from 1/8 as many particles, hemisphere -> spot side
// ended 1.2% above (100,536 particles) and 10% above (24,984).
// Left on the naive start (and the options as given) when a particle could not be carried.
RelaxationOptions start_from_coarse(const ParticleGrid& grid, const MapResult& coarse,
                                    const RelaxationOptions& options, bool hold,
                                    const MapResult& result, RelaxationProblem& problem) {
  const bool slide = options.boundary == BoundaryMode::Slide;
  const std::vector<double>& parameters = slide && !coarse.relaxation.boundary_parameters.empty()
                                              ? coarse.relaxation.boundary_parameters
                                              : coarse.sampling.grid.boundary_parameter;
  std::vector<double> boundary;
  InitialMap start = prolonged_map(grid, coarse.sampling.grid, coarse.relaxation.points, parameters,
                                   *result.source_disk, *result.target_disk, boundary);
  if (start.outside > 0) {
    return options;
  }
  RelaxationOptions held = options;
  if (slide) {
    held.boundary = hold ? BoundaryMode::Fixed : BoundaryMode::Slide;
    problem.boundary_parameters = std::move(boundary);  // the start (held: where it went)
  }
  for (std::size_t k = 0; k < grid.boundary_loop.size(); ++k) {
    const int p = grid.boundary_loop[k];
    if (slide) {
      problem.boundary_targets.col(static_cast<Eigen::Index>(k)) = start.positions.col(p);
    } else {
      start.positions.col(p) = result.naive.positions.col(p);
      start.points[static_cast<std::size_t>(p)] = result.naive.points[static_cast<std::size_t>(p)];
    }
  }
  problem.initial_positions = std::move(start.positions);
  problem.initial_points = std::move(start.points);
  problem.reference_gradient_norm =
      coarse.relaxation.initial_gradient_norm * result.rest_scale / coarse.rest_scale;
  return held;
}

// A sliding boundary held on the fine grid where the coarse map slid it: the report says how far
// it slid from the arc-length correspondence (as a fraction of the curve, as the solver measures
// it) and why the coarse slide stopped.
void report_coarse_slide(const ParticleGrid& grid, const RelaxationResult& coarse,
                         RelaxationResult& relaxation) {
  relaxation.boundary = BoundaryMode::Slide;
  relaxation.boundary_slide =
      solver_detail::boundary_slide(grid.boundary_parameter, relaxation.boundary_parameters);
  relaxation.slide_iterations = 0;  // none on this grid
  relaxation.slide_reason = coarse.slide_reason;
  relaxation.boundary_residual = 0.0;
}

// The relaxation of a multilevel start (result.relaxation): from the coarse map carried onto
// `grid`, or from the naive map (`problem` as given, built again from result.naive) when it could
// not be carried or did not settle there (converged and fold-free), the time tried counting. Once
// the coarse map is carried over, its queryable mapping and naive map go: with the copy of the
// naive problem this kept before, 80 MB that lived through a million-particle relaxation.
void relax_from_coarse(const ParticleGrid& grid, MapResult& coarse, const MapOptions& options,
                       bool hold, MapResult& result, RelaxationProblem& problem) {
  const RelaxationOptions held =
      start_from_coarse(grid, coarse, options.relaxation, hold, result, problem);
  coarse.mapping = Mapping();
  coarse.naive = InitialMap();
  result.relaxation = relax(problem, held);
  if (held.boundary != options.relaxation.boundary) {
    report_coarse_slide(grid, coarse.relaxation, result.relaxation);
  } else if (held.boundary == BoundaryMode::Slide) {
    // Slid on this grid from where the coarse map had slid it: measured from the arc-length
    // correspondence, as a cold map's slide is.
    result.relaxation.boundary_slide = solver_detail::boundary_slide(
        grid.boundary_parameter, result.relaxation.boundary_parameters);
  }
  if (result.relaxation.reason == StopReason::Cancelled ||
      (result.relaxation.converged && result.relaxation.folded_faces == 0)) {
    return;
  }
  const RelaxationResult tried = std::move(result.relaxation);
  problem = relaxation_problem(grid, *problem.target, result.naive, result, options.rest_scale);
  result.relaxation = relax(problem, options.relaxation);
  result.relaxation.iterations += tried.iterations;
  result.relaxation.setup_seconds += tried.setup_seconds;
  result.relaxation.solve_seconds += tried.solve_seconds;
}

// The queryable mapping of the relaxed grid (the last stage of both entry points).
void build_mapping(const SurfaceProjector& source, const SurfaceProjector& target,
                   MapResult& result) {
  const auto start = std::chrono::steady_clock::now();
  result.mapping = Mapping(result.sampling.grid, source, *result.source_disk, target,
                           *result.target_disk, result.relaxation.points);
  result.seconds_mapping = seconds_since(start);
}

// The options map_regions refuses, naming them.
void check_options(const MapOptions& options) {
  if (options.subdivisions < 0) {
    throw InvalidInputError("subdivisions", "must be 0 or more");
  }
  if (options.coarse_start_above < 0 || options.coarse_hold_above < 0 ||
      options.coarse_start_ratio < 2) {
    throw InvalidInputError("coarse start",
                            "needs particle counts of 0 or more and a ratio of at least 2");
  }
  if (options.subdivisions > 0 && options.relaxation.boundary == BoundaryMode::Slide) {
    // refine_map places new boundary particles at the source parameters' midpoints.
    throw InvalidInputError("subdivisions", "cannot be combined with a sliding boundary yet");
  }
}

// The naive map of `grid` (result.naive) on the result's disk maps, turned by the offset chosen
// among the candidates when no anchor was given (MapOptions::choose_offset), or by the one the
// coarse map of a multilevel start chose (its figures are then the coarse grid's).
void place_naive(const ParticleGrid& grid, const MapOptions& options, bool anchored,
                 const MapResult* coarse, MapResult& result) {
  if (coarse != nullptr) {
    result.boundary_offset = coarse->boundary_offset;
    result.offset_chosen = coarse->offset_chosen;
    result.offset_energy = coarse->offset_energy;
    result.offset_energy_at_zero = coarse->offset_energy_at_zero;
    result.offset_folds = coarse->offset_folds;
    result.naive = naive_map(grid, *result.source_disk, *result.target_disk);
  } else if (options.choose_offset && !anchored) {
    BoundaryOffsetResult offset = choose_boundary_offset(
        grid, *result.source_disk, *result.target_disk,
        {.candidates = options.offset_candidates,
         .energy = {.stiffness = options.relaxation.stiffness,
                    .angular_stiffness = angular_stiffness(options.relaxation),
                    .rest_scale = result.rest_scale}});
    result.boundary_offset = offset.offset;
    result.offset_chosen = true;
    result.offset_energy = offset.energy;
    result.offset_energy_at_zero = offset.energy_at_zero;
    result.offset_folds = offset.folds;
    result.naive = std::move(offset.naive);  // already placed with the chosen offset
  } else {
    result.naive = naive_map(grid, *result.source_disk, *result.target_disk);
  }
}

// Subdivision (end of §4.3): refines the grid on the source and the map on the target, relaxing
// briefly after each level. Everything in `result` then describes the refined grid.
void subdivide(const SurfaceProjector& source, const SurfaceProjector& target,
               const MapOptions& options, MapResult& result) {
  const auto start = std::chrono::steady_clock::now();
  RefineMapOptions refine;
  refine.levels = options.subdivisions;
  refine.relaxation = options.relaxation;
  refine.relaxation.solver = SolverKind::Fast;
  refine.relaxation.max_iterations = options.subdivision_iterations;
  refine.progress = options.progress;
  refine.name = options.sampling.layout.name;
  RefineMapResult refined = refine_map(result.sampling.grid, result.relaxation, source,
                                       *result.source_disk, target, *result.target_disk, refine);
  result.coarse_relaxation = std::move(result.relaxation);
  result.relaxation = std::move(refined.relaxation);
  result.sampling.grid = std::move(refined.grid);
  result.sampling.statistics = measure_sampling(result.sampling.grid, source.surface());
  result.naive = naive_map(result.sampling.grid, *result.source_disk, *result.target_disk);
  result.subdivisions = options.subdivisions;
  result.subdivision_levels = std::move(refined.levels);
  result.subdivision_iterations = refined.iterations;
  result.seconds_subdivision = seconds_since(start);
}

// The cold map; `top`: the grid the caller asked for (not a multilevel start's coarse level);
// `disks`: the regions' disk maps when the caller has them (else built here).
MapResult map_cold(const SurfaceProjector& source, const Region& source_region,
                   const SurfaceProjector& target, const Region& target_region,
                   const MapOptions& options, bool top, DiskMaps disks) {
  check_options(options);
  auto stage = [&](std::string_view name) {
    if (!report_progress(options.progress, {.stage = name})) {
      throw Error("map", "cancelled during " + std::string(name));
    }
  };
  MapResult result;

  // 1. Particles on the source (§4.1, §4.3). The two disk maps of step 2 depend only on the
  // regions, so they are built beside the sampling, whose layout (a serial factorisation on a
  // curved source) leaves a core free; the two are independent sparse solves, side by side too.
  // The sampling stays on the calling thread, which reports its progress.
  stage("sample");
  auto start = std::chrono::steady_clock::now();
  tbb::task_group disk_work;
  if (!disks.source || !disks.target) {
    disk_work.run([&] {
      tbb::parallel_invoke([&] { disks.source = std::make_unique<RegionDiskMap>(source_region); },
                           [&] { disks.target = std::make_unique<RegionDiskMap>(target_region); });
    });
  }
  try {
    result.sampling = sample_region(source_region, source, options.sampling);
  } catch (...) {
    disk_work.cancel();
    try {
      disk_work.wait();
    } catch (...) {  // NOLINT(bugprone-empty-catch): the sampling's error is the one to report
    }
    throw;
  }
  result.seconds_sampling = seconds_since(start);
  start = std::chrono::steady_clock::now();
  disk_work.wait();  // rethrows a disk map's error
  const double seconds_disks = seconds_since(start);
  const ParticleGrid& grid = result.sampling.grid;
  result.source_disk = std::move(disks.source);
  result.target_disk = std::move(disks.target);

  // 2a. The multilevel start's coarse map (MapOptions::coarse_start_above) on these disk maps: its
  // boundary offset is this map's too, and it returns the disk maps.
  std::optional<MapResult> coarse;
  if (uses_coarse_start(options, grid)) {
    start = std::chrono::steady_clock::now();
    coarse.emplace(coarse_map(source, source_region, target, target_region, options,
                              DiskMaps{.source = std::move(result.source_disk),
                                       .target = std::move(result.target_disk)}));
    result.source_disk = std::move(coarse->source_disk);
    result.target_disk = std::move(coarse->target_disk);
    result.coarse_particles = coarse->sampling.grid.num_particles();
    result.coarse_iterations = coarse->relaxation.iterations + coarse->coarse_iterations;
    result.seconds_coarse = seconds_since(start);
  }

  // 2. The naive map: both regions to the unit disk, composed (Fig. 9a).
  stage("naive map");
  start = std::chrono::steady_clock::now();

  // 3. Rest scale sigma between the two regions' sizes.
  result.rest_scale = region_rest_scale(options.rest_scale, source_region, target_region);

  place_naive(grid, options, source_region.anchor_given || target_region.anchor_given,
              coarse ? &*coarse : nullptr, result);
  if (result.naive.outside > 0) {
    throw NumericalError("map", std::to_string(result.naive.outside) +
                                    " particles could not be placed in the target region");
  }
  result.seconds_naive = seconds_disks + seconds_since(start);

  // 4. Relaxation on the target (§4.2, §4.4-4.6). Boundary particles stay at their arc-length
  // positions.
  stage("relax");
  RelaxationProblem problem =
      relaxation_problem(grid, target, result.naive, result, options.rest_scale);
  if (coarse) {
    const bool hold = top && grid.num_particles() > options.coarse_hold_above;
    relax_from_coarse(grid, *coarse, options, hold, result, problem);
    coarse.reset();  // its grid and mapping are not needed any more (its disk maps are ours)
  } else {
    result.relaxation = relax(problem, options.relaxation);
  }
  result.sampled_particles = grid.num_particles();
  guard_distortion(grid, options, problem, result);

  // 5. Subdivision (end of §4.3): refine the grid on the source and the map on the target, relax
  // briefly after each level. Everything returned then describes the refined grid.
  if (options.subdivisions > 0) {
    subdivide(source, target, options, result);
  }

  // 6. The queryable mapping.
  stage("mapping");
  build_mapping(source, target, result);
  return result;
}

}  // namespace

MapResult map_regions(const SurfaceProjector& source, const Region& source_region,
                      const SurfaceProjector& target, const Region& target_region,
                      const MapOptions& options) {
  check_surfaces(source, source_region, target, target_region);
  return map_cold(source, source_region, target, target_region, options, /*top=*/true, {});
}

MapResult map_regions(const SurfaceProjector& source, const Region& source_region,
                      const SurfaceProjector& target, const Region& target_region,
                      const MapResult& previous, const MapOptions& options) {
  check_surfaces(source, source_region, target, target_region);
  const ParticleGrid& previous_grid = previous.sampling.grid;
  if (!previous.source_disk || !previous.target_disk || previous_grid.num_particles() == 0 ||
      previous.relaxation.points.size() !=
          static_cast<std::size_t>(previous_grid.num_particles())) {
    throw InvalidInputError("previous map", "has no relaxed map to start from");
  }
  if (&previous.source_disk->region() != &source_region) {
    throw InvalidInputError("previous map",
                            "was made from another source region: a warm start keeps the source "
                            "grid, so map a new source region without one");
  }
  if (previous.subdivisions > 0 || options.subdivisions != 0) {
    throw InvalidInputError("previous map", "warm starts do not combine with subdivision yet");
  }
  const auto stage = [&](std::string_view name) {
    if (!report_progress(options.progress, {.stage = name})) {
      throw Error("map", "cancelled during " + std::string(name));
    }
  };
  MapResult result;
  result.warm_started = true;

  // 1-3. The previous grid and source disk; the new target's disk map with the previous turn;
  // the previous placement carried over.
  stage("warm start");
  auto start = std::chrono::steady_clock::now();
  result.sampling = previous.sampling;
  const ParticleGrid& grid = result.sampling.grid;
  result.source_disk = std::make_unique<RegionDiskMap>(*previous.source_disk);
  result.target_disk = std::make_unique<RegionDiskMap>(target_region);
  result.target_disk->set_offset(previous.boundary_offset);
  result.boundary_offset = previous.boundary_offset;
  result.rest_scale = region_rest_scale(options.rest_scale, source_region, target_region);
  std::vector<double> boundary = previous.relaxation.boundary_parameters;
  if (options.relaxation.boundary == BoundaryMode::Fixed ||
      boundary.size() != grid.boundary_loop.size()) {
    boundary = grid.boundary_parameter;  // the arc-length correspondence
  }
  result.naive = transported_map(grid, previous.relaxation.points, boundary, *previous.target_disk,
                                 *result.target_disk);
  if (result.naive.outside > 0) {
    throw NumericalError("map", std::to_string(result.naive.outside) +
                                    " particles of the previous map could not be carried over");
  }
  result.seconds_naive = seconds_since(start);

  // 4. Relaxation, judged against the previous start's gradient at the new rest scale (the
  // springs' forces scale with sigma).
  stage("relax");
  RelaxationProblem problem =
      relaxation_problem(grid, target, result.naive, result, options.rest_scale);
  if (options.relaxation.boundary == BoundaryMode::Slide) {
    problem.boundary_parameters = boundary;
  }
  problem.reference_gradient_norm =
      previous.relaxation.initial_gradient_norm * result.rest_scale / previous.rest_scale;
  result.relaxation = relax(problem, options.relaxation);
  result.sampled_particles = grid.num_particles();
  // No distortion guard: its yardstick is the naive map, and this start is a relaxed map already.

  stage("mapping");
  build_mapping(source, target, result);
  return result;
}

}  // namespace elastic
