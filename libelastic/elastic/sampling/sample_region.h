#pragma once
/// \file
/// Particles on a source region in one call (§4.1 + §4.3): grid layout (grid_layout.h),
/// curvature-adaptive sampling (adaptive_sampling.h), springs' rest values on the sampled
/// positions, and statistics of the result. The CLI (`elastic sample`) and the mapping pipeline
/// call this.
///
/// Example:
///
///     const LimitSurface surface(read_mesh("cap.obj").mesh);
///     const SurfaceProjector projector(surface);
///     const Region region = make_region(projector, parse_region_spec("disk:0,0,1,0.5"));
///     SampleRegionOptions options;
///     options.layout.particles = 5000;
///     const SampleRegionResult sampled = sample_region(region, projector, options);
///     // sampled.grid: particles, normal springs (edges), angular springs (face corners)

#include "elastic/particles/particle_grid.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/region.h"
#include "elastic/sampling/adaptive_sampling.h"
#include "elastic/sampling/grid_layout.h"

namespace elastic {

/// Measured properties of a particle grid on its source surface.
///
/// Local spacing of a particle = mean length of its normal springs (3D); local density = 1 /
/// spacing^2 (particles per unit area for a square grid). The density ratio compares the quarter of
/// the interior particles with the largest curvature weight r = sqrt((k1^2 + k2^2) / 2) against the
/// quarter with the smallest: mean density of the first over mean density of the second (1 for a
/// uniform grid; large when particles gathered where the surface bends, Fig. 3).
struct SamplingStatistics {
  int particles = 0;
  int interior_particles = 0;
  int boundary_particles = 0;
  int normal_springs = 0;   ///< mesh edges
  int angular_springs = 0;  ///< face corners
  int quads = 0;            ///< faces with 4 corners
  int triangles = 0;        ///< faces with 3 corners
  double spacing_min = 0.0;
  double spacing_median = 0.0;
  double spacing_max = 0.0;
  double density_ratio = 1.0;  ///< high-curvature quarter over low-curvature quarter, see above
  /// Smallest corner sine over all faces, signed by the surface normal at the corner (> 0: no
  /// inverted or degenerate corner).
  double min_corner_sine = 1.0;
  int inverted_faces = 0;  ///< faces with a corner sine <= 0
};

/// Measures a grid whose source points lie on `surface`.
SamplingStatistics measure_sampling(const ParticleGrid& grid, const LimitSurface& surface);

struct SampleRegionOptions {
  /// Count, flattening and band options (layout.name is also used for messages of the later
  /// stages).
  GridLayoutOptions layout;
  /// Run adaptive sampling (false: the laid-out grid, boundary at equal arc length).
  bool adaptive = true;
  /// Adaptive sampling options (its `name` is overridden by layout.name).
  AdaptiveSamplingOptions sampling;
};

struct SampleRegionResult {
  ParticleGrid grid;                ///< particles and springs, rest values on the sampled positions
  GridLayoutResult layout;          ///< the layout (its grid is moved out into `grid`; left empty)
  AdaptiveSamplingResult sampling;  ///< iterations etc. (its grid is moved out; left empty)
  SamplingStatistics statistics;    ///< of `grid`
};

/// Lays out options.layout.particles particles on `region`, adapts them to curvature, rebuilds
/// springs. `region.surface` must be `&projector.surface()`. \throws InvalidInputError /
/// NumericalError as layout_particle_grid and adaptive_sampling do, and
///         InvalidInputError when the region is not on the projector's surface.
SampleRegionResult sample_region(const Region& region, const SurfaceProjector& projector,
                                 const SampleRegionOptions& options = {});

}  // namespace elastic
