#pragma once
/// \file
/// Curvature-adaptive sampling of §4.3 (eqs. 6-8): particles of a laid-out grid migrate, with the
/// grid's connectivity unchanged, towards where the surface bends.
///
/// Each interior particle i is pulled towards its grid neighbours j (the edges of the grid) with
/// weights built on the paper's curvature measure r = sqrt((k1^2 + k2^2) / 2) (§4.3), averaged over
/// about one grid spacing (`curvature_radius`, curvature_field.h):
///
///     w_j = min(r(x_j), max_weight * rbar0) + floor * rbar0
///
/// rbar0 is the mean of r over the particles as laid out (evenly spread, so about the area mean of
/// r over the region), kept fixed while they move. The floor term is ours: with the bare r (floor =
/// 0) a flat part (r = 0) exerts no pull and its particles drain into the curved parts. In one
/// dimension the equilibrium spacing is inversely proportional to w, so density contrasts are about
/// the weight ratio along a line and its square over an area; `max_weight` optionally bounds them.
/// One Jacobi step moves every particle by
///
///     dx_i = relaxation * T_i( sum_j w_j (x_j - x_i) / sum_j w_j ),                  (eq. 8)
///
/// T_i the projection onto the tangent plane at x_i; the magnet (SurfaceProjector::closest,
/// warm-started at the particle's surface point) then puts it back on the surface. The fixed point
/// is eq. 8's equilibrium sum_j w_j T_i(x_i - x_j) = 0.
///
/// Boundary particles slide along the boundary curve only: the same force's component along the
/// curve tangent changes their arc-length parameter s, clamped so that they never pass a neighbour;
/// their positions stay on the curve's chords (boundary_sampler.h) and `boundary_parameter`
/// follows.
///
/// A move that would invert or nearly collapse a face (a corner whose sine, measured against the
/// surface normal at that corner, drops to <= `min_corner_sine` and below its previous value) is
/// halved once and otherwise rejected for that iteration; moves are accepted particle by particle
/// in index order, so the result does not depend on the number of threads. Around a face that is
/// already turned over (a layout can leave a few in a crease of a scan) the test is made face by
/// face: that face may change (and unfold), the particle's other faces keep the rule.
///
/// Iterations stop when the largest move is below `tolerance` times the mean spring length, after
/// `max_iterations`, when the Newton steps stall (below), or when the progress callback asks to
/// stop. Springs' rest values are rebuilt
/// on the final positions (ParticleGrid::build_springs). Source UVs (when present) are
/// re-interpolated from the region's vertex texture coordinates at each particle's new surface
/// point.
///
/// Method (`method`): by default every iteration is a *tangent Newton step* instead of a sweep.
/// With the weights frozen at the current positions, eq. 8 is (up to the factor w_i) the
/// tangential gradient of E(a) = 1/2 sum_{edges ij} w_i w_j |(x_i + B_i a_i) - (x_j + B_j a_j)|^2,
/// a_i an interior particle's displacement in its tangent basis B_i. One step minimises E by
/// preconditioned conjugate gradients (numerics/conjugate_gradient.h; preconditioner: a multigrid
/// V-cycle of the scalar weighted Laplacian, numerics/multigrid.h), puts the particles back on the
/// surface (the magnet), and is accepted as a whole when no face corner turns or thins as above
/// (else half, then a quarter of it; if all three fail, the quarter step is taken with the
/// particles of the failing faces held still for that iteration, and as a last resort with each
/// particle's move guarded as in a sweep). An iteration whose largest move does not shrink by 10%
/// halves the following steps (down to 1/16): on a scan the fixed point can cycle between two
/// states. The weights are then re-evaluated, so the iteration is a fixed point on w with a Newton
/// step inside (it contracted by about 3x per step on spot.obj); its fixed point is eq. 8's. Newton
/// steps hold the boundary particles at their equal-arc-length layout
/// (`move_boundary` applies to the sweeps): with sliding boundary unknowns the step follows the
/// near-null mode of a disk's rotation (11 spacings in one step on spot.obj), and sliding after
/// each step drifted by 0.1 spacing per step without converging. A Jacobi step diffuses
/// information by about one grid ring, so the sweeps (`SamplingMethod::Jacobi`, the paper's
/// scheme) need O(n^2) steps on an n x n grid; the Newton steps converge in 10-20 iterations at
/// any size.

#include <cstdint>

#include "elastic/core/progress.h"
#include "elastic/particles/particle_grid.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/region.h"

namespace elastic {

/// How each iteration moves the particles (see the file comment).
enum class SamplingMethod {
  Newton,  ///< tangent Newton steps on eq. 8 with frozen weights (default)
  Jacobi,  ///< the paper's relaxation sweeps only
};

struct AdaptiveSamplingOptions {
  /// Newton steps (default) or Jacobi sweeps; both stop at eq. 8's equilibrium.
  SamplingMethod method = SamplingMethod::Newton;
  /// Weight floor alpha, as a fraction of the mean curvature weight of the initial (evenly spread)
  /// particles, see the file comment; 0 is the paper's bare weighting. Must be >= 0.
  double floor = 1.0;
  /// Curvature weights above max_weight times that mean are clamped to it (0: no clamp). Bounds the
  /// density contrast near sharp features, where r is huge and would drain everything else.
  double max_weight = 0.0;
  /// Width s of the kernel over which the curvature measure r is averaged (that of a Gaussian of
  /// standard deviation s; it reaches 3 s), in mean grid spacings of the layout
  /// (curvature_field.h); 0 is the paper's pointwise r. Particles
  /// cannot follow curvature that changes within a spacing: on a scan the pointwise r is noise at
  /// that scale and the iteration does not settle. Must be >= 0.
  double curvature_radius = 1.0;
  /// Fraction of the Jacobi displacement applied per sweep, in (0, 1] (Newton steps are taken in
  /// full, then halved when a face would fold).
  double relaxation = 0.8;
  /// Iteration budget.
  int max_iterations = 300;
  /// Converged when the largest move is below this fraction of the mean spring length.
  double tolerance = 1e-3;
  /// Let boundary particles slide along the curve in Jacobi sweeps (false keeps them at equal arc
  /// length; Newton steps always keep them).
  bool move_boundary = true;
  /// Smallest accepted corner sine of a face, against the surface normal (guards against
  /// inversion).
  double min_corner_sine = 0.05;
  /// Random tangent displacement of the interior particles before relaxing, as a fraction of the
  /// mean spring length (0: none). Makes the start a perturbed grid; deterministic for a given
  /// seed.
  double jitter = 0.0;
  /// Seed of the jitter.
  std::uint64_t seed = 0;
  /// Called once per iteration (stage "adaptive sampling", gradient = largest move / mean spring
  /// length).
  ProgressCallback progress;
  /// Name used in error messages.
  std::string name = "region";
};

struct AdaptiveSamplingResult {
  ParticleGrid grid;       ///< the sampled grid (same connectivity as the input, springs rebuilt)
  int iterations = 0;      ///< iterations done (Newton steps + Jacobi sweeps)
  int newton_steps = 0;    ///< iterations that were Newton steps (whole, held or guarded)
  long cg_iterations = 0;  ///< conjugate-gradient iterations of all Newton steps
  double max_move = 0.0;   ///< largest move of the last iteration / mean spring length
  bool converged = false;  ///< max_move fell below the tolerance
  bool cancelled = false;  ///< the progress callback asked to stop
  /// Stopped before max_iterations without converging: the Newton steps, at their smallest
  /// damping, did not shrink the largest move by 10% for 30 iterations.
  bool stalled = false;
  long rejected_moves =
      0;  ///< moves rejected (not merely halved) to keep faces valid, all iterations
  double mean_curvature_weight = 0.0;  ///< mean r over the particles at the end
};

/// Runs eq. 8 on `grid` (laid out on `region`, whose surface is `projector.surface()`).
/// \throws InvalidInputError naming options.name when the options are out of range or the grid does
/// not match the region (no source points, a boundary particle without parameter).
AdaptiveSamplingResult adaptive_sampling(const ParticleGrid& grid, const Region& region,
                                         const SurfaceProjector& projector,
                                         const AdaptiveSamplingOptions& options = {});
/// The same on a grid the caller gives up: its springs and per-particle arrays are taken, not
/// copied (the OpenMesh connectivity still is: its kernels declare destructors and so have no
/// move). `elastic sample` of a million-particle flat disk: peak 1,735 -> 1,502 MB.
AdaptiveSamplingResult adaptive_sampling(ParticleGrid&& grid, const Region& region,
                                         const SurfaceProjector& projector,
                                         const AdaptiveSamplingOptions& options = {});

}  // namespace elastic
