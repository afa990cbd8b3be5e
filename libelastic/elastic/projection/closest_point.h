#pragma once
/// \file
/// The paper's "magnet" (§4.4): the closest point on the limit surface to any 3D point.
///
/// An Embree point query (`rtcPointQuery`) over a dense tessellation of the limit surface finds the
/// nearest tessellation triangle; the triangle's corners give a starting (face, u, v); Newton
/// iterations on the patch, minimising |d(u,v) - x|^2 and walking across ptex edges when a step
/// leaves the face (LimitSurface::walk), make the answer exact to round-off. The warm-started form
/// skips the BVH and starts Newton from a previous SurfacePoint (a particle's last position),
/// falling back to the BVH when Newton does not converge near the hint.
///
/// Behaviour at the edges of the problem:
/// - On an open surface the closest point may lie on the boundary curve; Newton is then
///   constrained to the boundary edge (1D Newton along it, stopping at a boundary corner) and
///   `on_boundary` is set.
/// - Far from the surface the answer is still the global closest point (no radius limit).
/// - A non-finite query point throws InvalidInputError.
///
/// Seeding: the tessellation's vertices carry the SurfacePoint of whichever ptex face they were
/// welded from. At construction the projector re-expresses each triangle's corners in the
/// triangle's own ptex face (`triangle_face`) as nodes of that face's uniform grid (resolution n,
/// n/2 for the sub-faces of Catmull-Clark n-gons, as tessellate() documents); a corner from another
/// face is the boundary node of this face with the same limit position. A seed is then the
/// barycentric blend of three (u, v) in one face.
///
/// Global query: BVH closest triangle -> Newton -> answer at distance D. The limit surface lies
/// within about `eps` of the tessellation (`eps` estimated at construction from the triangle
/// centroids), so only triangles closer than D + eps can hide a closer limit point; a second BVH
/// query collects them and Newton runs from up to `max_global_seeds` of those not next to an
/// answer already found. The nearest converged answer wins.
///
/// Warm start: the answer is the local minimum of the distance that Newton reaches from the hint.
/// It is the global closest point when the query is closer to the surface than the medial axis
/// (particles that move a little per step); it falls back to the global query when Newton does not
/// converge or travels farther than `warm_start_max_travel`. An unset hint (face -1) means "no
/// hint".
///
/// Ownership and threads: a SurfaceProjector keeps a reference to the LimitSurface, which must
/// outlive it, and owns its tessellation and Embree scene. It can be moved, not copied. All const
/// queries are thread-safe (Embree point queries on a committed scene are); the batched form runs
/// on all threads of the TBB arena it is called from. One Embree device is shared by all
/// projectors of the process; it is created with the first projector and released with the last.

#include <Eigen/Core>
#include <memory>
#include <span>

#include "elastic/surface/limit_surface.h"
#include "elastic/surface/limit_tessellation.h"

namespace elastic {

/// The default projector tessellation's triangle budget (ProjectionOptions::tessellation). Every
/// shared mesh of up to 40,000 control triangles or 20,000 quads keeps 4 segments per edge; the
/// 70,000-triangle nefertiti-lowres.obj gets 3 (630,000 triangles instead of 1.12 million): its
/// face disk mapped onto spot's flank at 2,000 particles took 14.2 s before, 7.9 s with it
/// (loading 4.5 -> 1.8 s, the sampling's curvature field over the region 7.4 -> 3.8 s). With 2
/// segments (a budget of 400,000) it took 4.5 s, but Table 1's Plane -> Head row lost accuracy
/// (its geodesic disk is cut on the coarser mesh: length energy +45%, area distortion +58%); with 3
/// that row moves both ways (length energy -6%, area distortion +11%, sigma_min 0.936 -> 0.931).
inline constexpr long kProjectorMaxTriangles = 650'000;

struct ProjectionOptions {
  /// Tessellation the BVH is built on (finer: better seeds, more memory and build time). It is also
  /// the mesh that regions are cut on, flattened and sampled over (regions/, sampling/). Four
  /// segments per control edge, fewer on dense control meshes: at most kProjectorMaxTriangles
  /// triangles (a scan's control mesh is already finer than the particle grids mapped on it).
  TessellationOptions tessellation{
      .resolution = 4, .target_triangles = 0, .max_triangles = kProjectorMaxTriangles};
  /// Newton iterations before giving up on a seed.
  int max_newton_iterations = 30;
  /// Stop when the parameter step is below this (in ptex units; 1e-12 is near double round-off).
  double parameter_tolerance = 1e-12;
  /// Largest Newton step, in ptex units (a face is 1 wide); longer steps are shortened to this.
  double max_step = 0.5;
  /// Warm start is distrusted (and the global query used) when Newton's path from the hint is
  /// longer than this, in ptex units summed over the steps, or when it does not converge.
  double warm_start_max_travel = 1.0;
  /// Global query: at most this many BVH candidates (triangles that may hide a closer limit point
  /// than the first answer) get their own Newton run.
  int max_global_seeds = 8;
};

/// The closest point on the limit surface to a query point.
struct ClosestPoint {
  SurfacePoint point;                                  ///< where on the surface
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< d(point)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< unit surface normal at point
  double distance = 0.0;                               ///< |query - position|
  bool on_boundary = false;                            ///< the answer lies on the surface boundary
  /// Newton converged: its step fell below parameter_tolerance (or a Newton step short enough to
  /// end within it was taken), the gradient vanished to round-off, or a boundary corner is a
  /// constrained minimum. False only when every seed ran out of iterations.
  bool converged = false;
};

class SurfaceProjector {
 public:
  /// Builds the tessellation and the Embree scene for `surface` (which must outlive the projector).
  /// \throws InvalidInputError when the options are out of range; Error when Embree fails.
  explicit SurfaceProjector(const LimitSurface& surface, const ProjectionOptions& options = {});
  ~SurfaceProjector();
  SurfaceProjector(SurfaceProjector&&) noexcept;
  SurfaceProjector& operator=(SurfaceProjector&&) noexcept;
  SurfaceProjector(const SurfaceProjector&) = delete;
  SurfaceProjector& operator=(const SurfaceProjector&) = delete;

  const LimitSurface& surface() const;
  const LimitTessellation& tessellation() const;

  /// Global closest point (BVH seed + Newton).
  /// \throws InvalidInputError (naming the surface) when x is not finite.
  ClosestPoint closest(const Eigen::Vector3d& x) const;
  /// Warm-started closest point: Newton from `hint`; falls back to the global query when needed.
  /// \throws InvalidInputError when x is not finite, or the hint is set but is not a point of the
  ///         surface (face out of range, (u, v) outside the face's domain).
  ClosestPoint closest(const Eigen::Vector3d& x, const SurfacePoint& hint) const;
  /// Batched form: out[i] = closest(xs[i]) or closest(xs[i], hints[i]) when `hints` is not empty.
  /// Runs in parallel; gives the same results as the single queries.
  /// \throws InvalidInputError as the single queries do, or when `out` or a non-empty `hints`
  ///         does not have xs.size() entries.
  void closest(std::span<const Eigen::Vector3d> xs, std::span<ClosestPoint> out,
               std::span<const SurfacePoint> hints = {}) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace elastic
