#pragma once
/// \file
/// The whole mapping job of the paper in one call: sample the source region with particles (§4.1,
/// §4.3), place them on the target by the naive map (Fig. 9a), relax them to least distortion
/// (§4.2, §4.4-4.6), and return a queryable `Mapping` together with everything a report needs.
///
/// Example:
///
///     const LimitSurface plane(make_plane()), cap(make_cap());
///     const SurfaceProjector source(plane), target(cap);
///     const Region from = make_region(source, parse_region_spec("boundary"));
///     const Region to = make_region(target, parse_region_spec("boundary"));
///     MapOptions options;
///     options.sampling.layout.particles = 5775;
///     const MapResult result = map_regions(source, from, target, to, options);
///     // result.relaxation.length_energy, result.mapping.forward(p), ...

#include <memory>
#include <string>

#include "elastic/core/progress.h"
#include "elastic/mapping/initial_map.h"
#include "elastic/mapping/mapping.h"
#include "elastic/mapping/refine_map.h"
#include "elastic/regions/region.h"
#include "elastic/sampling/sample_region.h"
#include "elastic/solvers/relaxation.h"

namespace elastic {

struct MapOptions {
  /// Particle count, layout and curvature-adaptive sampling on the source
  /// (sampling/sample_region.h).
  SampleRegionOptions sampling;
  /// Solver, stiffnesses, tolerances, threads, callbacks (solvers/relaxation.h).
  RelaxationOptions relaxation;
  /// How rest lengths are scaled between source and target sizes (particles/spring_energy.h).
  RestScale rest_scale = RestScale::Auto;
  /// Choose where the boundary correspondence starts on the target (choose_boundary_offset) when
  /// neither region's anchor was given by the user; given anchors always win.
  bool choose_offset = true;
  /// Offsets tried by that choice.
  int offset_candidates = 24;
  /// Levels of 1-to-4 grid subdivision after the relaxation (end of §4.3, mapping/refine_map.h),
  /// each followed by a brief relaxation; every level multiplies the particles by about 4. 0: none.
  int subdivisions = 0;
  /// L-BFGS iteration budget of each level's brief relaxation (fast solver; the other fields of
  /// `relaxation` are used as given).
  long subdivision_iterations = 200;
  /// The distortion guard (robust energy without a distortion term only): when the relaxed map's
  /// symmetric Dirichlet excess is above `distortion_guard_ratio` times its naive start's, the
  /// relaxation continues with the distortion term at kGuardDistortionStiffness (MapResult::guard).
  /// Cold maps only: a warm start's start is a relaxed map, not the naive one the guard compares
  /// against.
  bool distortion_guard = true;
  double distortion_guard_ratio = 1.0;
  /// The multilevel start (fast solver, no subdivision): a grid of more than `coarse_start_above`
  /// particles relaxes from the relaxed map of a grid of 1/`coarse_start_ratio` as many particles
  /// of the same source region (mapped by these options, so a million particles go through 125,000
  /// and 15,625), carried onto it by prolonged_map (mapping/initial_map.h), instead of from the
  /// naive map. The coarsest map decides the boundary offset. A sliding boundary slides on each
  /// coarse level from the one below, and on this grid too unless `coarse_hold_above` holds it. On
  /// the Plane -> Cap benchmark at 1,001,732 particles the naive start's slide crept for 222
  /// iterations at 0.7 s each, its first ring crowded against the hemisphere's rim: 186 s for the
  /// whole map, 21 s with this start, the energy 0.003% above (docs/results.md, Speed). 0: never.
  int coarse_start_above = 50000;
  /// A multilevel start's sliding boundary on the grid asked for: held where the level below slid
  /// it (only the interior relaxes) when the grid has more than `coarse_hold_above` particles;
  /// otherwise it slides on from there. Holding skips the finest slide, but leaves the boundary
  /// where a grid of 1/8 as many particles put it: on the compressed hemisphere -> spot side map
  /// that cost 1.2% of energy and sigma_min 0.547 against 0.748 at 100,536 particles (5.4 against
  /// 8.5 s), 0.47% and 0.602 against 0.685 at 1,001,732 (47 against 189 s); on Plane -> Cap at
  /// 1,001,732 particles 0.003% of energy (15 against 27 s; docs/results.md, Speed). 0: held at
  /// every size.
  int coarse_hold_above = 500000;
  /// Particles of the fine grid per particle of the coarse one (at least 2).
  int coarse_start_ratio = 8;
  /// Called between stages ("sample", "naive map", "relax", "subdivide", "relax refined",
  /// "mapping"; a multilevel start's coarse map reports its own as "coarse sample", ...); return
  /// false to cancel.
  ProgressCallback progress;
};

/// The distortion term's weight (RelaxationOptions::distortion_stiffness) of the guard's second
/// relaxation.
inline constexpr double kGuardDistortionStiffness = 0.2;

/// What the distortion guard found (MapOptions::distortion_guard).
struct DistortionGuard {
  bool checked = false;  ///< the guard measured the map (robust energy, converged, fold-free)
  bool taken = false;    ///< the second relaxation ran, converged fold-free and was taken
  double naive = 0.0;    ///< E_sd (lambda 1) of the naive start
  double relaxed = 0.0;  ///< ... of the relaxed map
  double guarded = 0.0;  ///< ... of the guarded map (when taken)
  long iterations = 0;   ///< the second relaxation's iterations (0 when it did not run)
};

/// With `subdivisions` > 0, `sampling.grid` (and `sampling.statistics`), `naive`, `relaxation` and
/// `mapping` all describe the final refined grid; the sampled grid's own relaxation is kept in
/// `coarse_relaxation`.
struct MapResult {
  SampleRegionResult sampling;  ///< the particle grid on the source and its statistics
  /// The naive map of the grid (recomputed for the refined grid after subdivision, so it has one
  /// entry per particle of sampling.grid; the relaxation started from the sampled grid's). After
  /// a warm start: the relaxation's start, the previous map carried onto the new target region
  /// (transported_map).
  InitialMap naive;
  /// Whether this map was warm-started from a previous one (the map_regions overload with
  /// `previous`): then the grid is the previous one's and `seconds_sampling` is 0.
  bool warm_started = false;
  RelaxationResult relaxation;  ///< the relaxed placement and the solver's report
  DistortionGuard guard;        ///< what the distortion guard found and did
  double rest_scale = 1.0;      ///< sigma actually used
  /// The turn of the boundary correspondence on the target (RegionDiskMap::set_offset), a
  /// fraction of the boundary: 0 unless chosen (MapOptions::choose_offset).
  double boundary_offset = 0.0;
  bool offset_chosen = false;  ///< whether choose_boundary_offset ran (no anchor given)
  /// The naive map's paper energy with the chosen offset and with offset 0 (when chosen).
  double offset_energy = 0.0, offset_energy_at_zero = 0.0;
  /// Faces the chosen offset's naive map folds (0 unless every candidate folds).
  int offset_folds = 0;
  double seconds_sampling = 0.0;  ///< source sampling (layout + adaptive sampling + springs)
  double seconds_naive =
      0.0;  ///< naive placement + the wait for the disk maps (built beside the sampling)
  double seconds_mapping = 0.0;  ///< building the queryable mapping
  /// The multilevel start (MapOptions::coarse_start_above), when it ran: the coarse grid's
  /// particles, its L-BFGS iterations (the levels below it included) and its whole map's seconds
  /// (0 otherwise). `naive` is still the naive map of the grid (the distortion guard's yardstick).
  int coarse_particles = 0;
  long coarse_iterations = 0;
  double seconds_coarse = 0.0;
  // Subdivision (MapOptions::subdivisions > 0; otherwise these stay empty / equal the sampled
  // grid).
  int sampled_particles = 0;  ///< particles of the sampled grid, before subdivision
  int subdivisions = 0;       ///< subdivision levels run
  /// Per level: particles before/after, the brief relaxation's iterations, convergence, folds,
  /// energies and seconds.
  std::vector<RefinementLevel> subdivision_levels;
  long subdivision_iterations = 0;   ///< L-BFGS iterations summed over the levels
  double seconds_subdivision = 0.0;  ///< all levels: subdivision, placement, brief relaxations
  /// The main relaxation of the sampled grid when subdivisions > 0 (then `relaxation` is the last
  /// level's); default-constructed (no positions) when subdivisions is 0.
  RelaxationResult coarse_relaxation;
  /// Disk maps of the two regions (owned here so `mapping` can reference them).
  std::unique_ptr<RegionDiskMap> source_disk;
  std::unique_ptr<RegionDiskMap> target_disk;
  /// The relaxed map, queryable both ways. References the projectors, the regions and the disk maps
  /// above.
  Mapping mapping;
};

/// Maps `source_region` (on `source`) onto `target_region` (on `target`).
/// The regions must lie on the projectors' surfaces and outlive the result, as must the projectors.
/// \throws InvalidInputError for inconsistent inputs or options (naming them); NumericalError
///         when a stage fails numerically.
/// The boundary mode a caller's "auto" means (`elastic map --boundary auto`, the Python binding's
/// boundary="auto"): sliding, except with subdivision, whose refinement places the new boundary
/// particles by their source parameters and so needs the fixed correspondence.
inline BoundaryMode auto_boundary_mode(int subdivisions) {
  return subdivisions > 0 ? BoundaryMode::Fixed : BoundaryMode::Slide;
}

MapResult map_regions(const SurfaceProjector& source, const Region& source_region,
                      const SurfaceProjector& target, const Region& target_region,
                      const MapOptions& options = {});

/// Warm start: maps the same source region onto `target_region` (a region that moved, grew or
/// shrank since `previous`, possibly on another target surface) starting from `previous`'s relaxed
/// map instead of the naive map. The source grid, its disk map and the boundary offset are
/// reused (no sampling, no offset search); the previous placement is carried onto the new region
/// through the two target disk maps (transported_map), boundary particles at their previous
/// correspondence parameters (slid ones where they slid), and relaxed with `options.relaxation`.
/// Its stopping test is relative to `previous`'s initial gradient (scaled by the change of the
/// rest scale; RelaxationProblem::reference_gradient_norm; a relaxation given a reference reports
/// it as its initial gradient, so a chain of warm starts keeps the first cold map's scale): a small
/// change of the region is judged by the problem's scale, so it takes few iterations, and an
/// unchanged region none. `previous` must have been made from `source_region` (the same object) and
/// its target region must still be alive; `options.sampling`, `choose_offset` and
/// `offset_candidates` are not used. \throws InvalidInputError when `previous` has no relaxed map,
/// was made from another source
///         region or with subdivision, or `options.subdivisions` > 0 (not combined yet); as the
///         cold map_regions otherwise.
MapResult map_regions(const SurfaceProjector& source, const Region& source_region,
                      const SurfaceProjector& target, const Region& target_region,
                      const MapResult& previous, const MapOptions& options = {});

}  // namespace elastic
