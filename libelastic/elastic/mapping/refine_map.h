#pragma once
/// \file
/// Refining a relaxed map (end of §4.3 of the paper: "subdividing the grid of particles over the
/// region after the minimum distortion mapping is found", for a finer sampling of the target).
///
/// One level:
/// 1. The grid is subdivided 1-to-4 on the source (particles/grid_subdivision.h), new interior
///    particles placed at the average of their parents' coordinates on the source region's disk map
///    (RegionDiskMap::from_disk), new boundary particles on the source curve at the mid-parameter
///    of their neighbours (RegionDiskMap::boundary_point for their SurfacePoint).
/// 2. Target placement: an old particle keeps its relaxed target point. A new boundary particle
///    goes to the target curve at its correspondence parameter s, exactly as the naive map puts
///    boundary particles there (RegionDiskMap::boundary_point of the target region, at its limit
///    position), so the boundary correspondence stays the arc-length one of §4.1. A new interior
///    particle goes to the magnet (closest target point) of the average of its parents' relaxed
///    target positions (edge: midpoint, quad: centroid), warm-started at its first parent's target
///    point. On a fold-free map this start is fold-free: the sub-faces of a convex quad or a
///    triangle around its centroid and edge midpoints are convex, up to the surface's curvature
///    over a cell.
/// 3. The refined grid relaxes briefly on the target with the same energies, rest scale and
///    tolerances, the fast solver and a small iteration budget (the start is already close to the
///    refined grid's minimum: it differs from it by the coarse grid's discretisation error).
///
/// Iterations are reported per level (`levels`), and summed over the levels in `iterations`; the
/// returned `relaxation` is the last level's own solver report (its `iterations` are that level's).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "elastic/core/progress.h"
#include "elastic/mapping/initial_map.h"
#include "elastic/particles/grid_subdivision.h"
#include "elastic/projection/closest_point.h"
#include "elastic/solvers/relaxation.h"

namespace elastic {

/// The default brief relaxation of a refined grid: the default RelaxationOptions (fast solver,
/// default tolerances) with a budget of 200 L-BFGS iterations (the main relaxation takes about 20).
inline RelaxationOptions brief_relaxation_options() {
  RelaxationOptions options;
  options.max_iterations = 200;
  return options;
}

struct RefineMapOptions {
  /// Number of 1-to-4 subdivision levels (each multiplies the faces by 4). 0 returns the input.
  int levels = 1;
  /// The brief relaxation after each level (see brief_relaxation_options). `solver` must be Fast.
  RelaxationOptions relaxation = brief_relaxation_options();
  /// Called before each level's stages ("subdivide", "relax refined"); return false to cancel.
  ProgressCallback progress;
  /// Name of the map in error messages.
  std::string name = "map";
};

/// What one level of refinement did.
struct RefinementLevel {
  int particles_before = 0;    ///< #P of the grid that was subdivided
  int particles_after = 0;     ///< #P of the refined grid
  int faces_after = 0;         ///< faces of the refined grid (4x those before)
  int boundary_particles = 0;  ///< boundary particles of the refined grid
  /// New source particles placed by the source magnet because the disk map could not place them.
  int source_magnet_placements = 0;
  long iterations = 0;                            ///< L-BFGS iterations of the brief relaxation
  bool converged = false;                         ///< that relaxation converged
  StopReason reason = StopReason::MaxIterations;  ///< why it stopped
  int initial_folded_faces = 0;                   ///< folded faces of the placement before relaxing
  int folded_faces = 0;                           ///< folded faces after relaxing
  double initial_energy = 0.0;     ///< E_len + E_ang of the placement before relaxing
  double energy = 0.0;             ///< E_len + E_ang after relaxing
  double seconds_subdivide = 0.0;  ///< subdivision and target placement
  double seconds_relax = 0.0;      ///< the brief relaxation (set-up included)
};

struct RefineMapResult {
  ParticleGrid grid;                    ///< the refined grid on the source, springs built
  RelaxationResult relaxation;          ///< the last level's relaxation: target positions of `grid`
  std::vector<RefinementLevel> levels;  ///< one per level, in order
  long iterations = 0;                  ///< L-BFGS iterations summed over the levels
  double seconds = 0.0;                 ///< all levels
};

/// Refines the map given by `grid` (on `source`, inside `source_disk`'s region) and its relaxed
/// target placement `relaxed` (on `target`, inside `target_disk`'s region) by options.levels
/// levels. The rest scale and its mode are taken from `relaxed`.
/// \throws InvalidInputError when `relaxed` does not have one position and point per particle, the
///         options are invalid (negative levels, another solver than Fast), or the grid is
///         inconsistent (subdivide_grid); NumericalError as relax() does; Error("map", "cancelled
///         ...") when the progress callback cancels.
RefineMapResult refine_map(const ParticleGrid& grid, const RelaxationResult& relaxed,
                           const SurfaceProjector& source, const RegionDiskMap& source_disk,
                           const SurfaceProjector& target, const RegionDiskMap& target_disk,
                           const RefineMapOptions& options = {});

}  // namespace elastic
