#pragma once
// `elastic bench decals`: placed decals (--target-place, libelastic mapping/map_decal.h) against
// the exponential-map decal on the same grid (baselines/decal_baseline.h), over sources x sizes x
// targets from tools/benchmarks/decal_cases.json. Each case is judged: ElasticPaint converged,
// zero folds, and its length energy and symmetric Dirichlet energy both below the exponential
// map's. For rectangle sources the table adds how straight the decal's edges stay and how square
// its corners (boundary_shape). JSON report and a Markdown table (docs/results.md, "Decals").

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <functional>
#include <vector>

#include "elastic/particles/particle_grid.h"
#include "elastic/surface/limit_surface.h"

namespace elastic::cli {

/// The turn at every boundary particle (grid.boundary_loop order), degrees counter-clockwise: the
/// angle from the chord arriving at it to the chord leaving it, both projected on the surface's
/// tangent plane there (about the geodesic curvature times the spacing; 180 minus the interior
/// angle at a corner).
std::vector<double> boundary_turns(const ParticleGrid& grid, const LimitSurface& surface,
                                   const Eigen::Matrix3Xd& positions,
                                   const std::vector<SurfacePoint>& points);

/// How a placed polygon's edges and corners came out, against the source's own turns at the same
/// particles (on a plane source: the polygon as sampled).
struct BoundaryShape {
  /// Mean over the polygon's sides of sum |turn - source turn| at the side's particles between
  /// its corners (degrees): 0 for sides that stay as straight as in the source (geodesics).
  double edge_turning_deg = 0.0;
  /// Largest |turn - source turn| at a corner (degrees): how far a corner's angle changed.
  double corner_error_deg = 0.0;
};

/// `corners` are indices into grid.boundary_loop, in increasing order.
BoundaryShape boundary_shape(const std::vector<double>& turns,
                             const std::vector<double>& source_turns,
                             const std::vector<int>& corners);

/// Adds `decals` to the `bench` command and returns the function that runs it.
std::function<int()> add_decals_subcommand(CLI::App& bench);

}  // namespace elastic::cli
