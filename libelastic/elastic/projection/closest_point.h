#pragma once
/// \file
/// The paper's "magnet" (§4.4): the closest point on the limit surface to any 3D point.
///
/// An Embree point query (`rtcPointQuery`) over a dense tessellation of the limit surface finds the
/// nearest tessellation triangle; the triangle's vertex SurfacePoints give a starting (face, u, v);
/// Newton iterations on the patch, minimising |d(u,v) - x|^2 and walking across ptex edges when a step
/// leaves the face (LimitSurface::walk), make the answer exact to round-off. The warm-started form skips
/// the BVH and starts Newton from a previous SurfacePoint (a particle's last position), falling back to
/// the BVH when Newton does not converge near the hint.
///
/// Behaviour at the edges of the problem:
/// - On an open surface the closest point may lie on the boundary curve; Newton is then constrained to
///   the boundary edge and `on_boundary` is set.
/// - Far from the surface the answer is still the global closest point (the BVH has no radius limit).
/// - A non-finite query point throws InvalidInputError.
///
/// Ownership and threads: a SurfaceProjector keeps a reference to the LimitSurface, which must outlive it,
/// and owns its tessellation and Embree scene. It can be moved, not copied. All const queries are
/// thread-safe; the batched form runs on all threads of the TBB arena it is called from.

#include <Eigen/Core>
#include <memory>
#include <span>

#include "elastic/surface/limit_surface.h"
#include "elastic/surface/limit_tessellation.h"

namespace elastic {

struct ProjectionOptions {
  /// Tessellation the BVH is built on (finer gives a better Newton seed, costs memory and build time).
  TessellationOptions tessellation{.resolution = 4, .target_triangles = 0};
  /// Newton iterations before giving up on a seed.
  int max_newton_iterations = 30;
  /// Stop when the parameter step is below this (in ptex units; 1e-12 is near double round-off).
  double parameter_tolerance = 1e-12;
};

/// The closest point on the limit surface to a query point.
struct ClosestPoint {
  SurfacePoint point;                                  ///< where on the surface
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< d(point)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< unit surface normal at point
  double distance = 0.0;                               ///< |query - position|
  bool on_boundary = false;                            ///< the answer lies on the surface boundary
  bool converged = false;                              ///< Newton reached parameter_tolerance
};

class SurfaceProjector {
 public:
  /// Builds the tessellation and the Embree scene for `surface` (which must outlive the projector).
  explicit SurfaceProjector(const LimitSurface& surface, const ProjectionOptions& options = {});
  ~SurfaceProjector();
  SurfaceProjector(SurfaceProjector&&) noexcept;
  SurfaceProjector& operator=(SurfaceProjector&&) noexcept;
  SurfaceProjector(const SurfaceProjector&) = delete;
  SurfaceProjector& operator=(const SurfaceProjector&) = delete;

  const LimitSurface& surface() const;
  const LimitTessellation& tessellation() const;

  /// Global closest point (BVH seed + Newton).
  ClosestPoint closest(const Eigen::Vector3d& x) const;
  /// Warm-started closest point: Newton from `hint`; falls back to the global query when needed.
  ClosestPoint closest(const Eigen::Vector3d& x, const SurfacePoint& hint) const;
  /// Batched form: out[i] = closest(xs[i]) or closest(xs[i], hints[i]) when `hints` is not empty.
  /// Runs in parallel. `out` and `hints` (if given) must have xs.size() entries.
  void closest(std::span<const Eigen::Vector3d> xs, std::span<ClosestPoint> out,
               std::span<const SurfacePoint> hints = {}) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace elastic
