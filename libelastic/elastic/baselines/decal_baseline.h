#pragma once
/// \file
/// The decal baseline of the kind ElasticPaint's placed decals (mapping/map_decal.h) compete
/// with: the exponential-map decal (Schmidt et al. 2006, "Interactive decal compositing with
/// discrete exponential maps"; the log-map decals of the vector heat method). Every particle of the
/// grid goes to exp_c(scale * R(angle) u_i): its source tangent coordinates u_i, turned and scaled
/// as the placement says, walked from the centre c along the target limit surface's geodesic in
/// that direction (projection/exponential_map.h). Schmidt et al. approximate these geodesic polar
/// coordinates on a mesh by upwind averaging; here they are shot on the smooth surface with steps
/// of `step_fraction` times the decal's radius (at most a quarter of a particle's own distance), so
/// the baseline is the exponential map itself up to O(step^2), not a discretisation of it.
///
/// Distortion grows with the decal's size and the surface's curvature: radial lengths are kept
/// exactly, lengths across the rays scale by the Jacobi field (sin(r k)/(r k) on a sphere of
/// curvature k^2).

#include <Eigen/Core>
#include <vector>

#include "elastic/mapping/map_decal.h"

namespace elastic {

struct DecalBaselineOptions {
  /// Step of the geodesic shooting as a fraction of the decal's radius on the target.
  double step_fraction = 1.0 / 64.0;
};

struct DecalBaselineResult {
  Eigen::Matrix3Xd positions;        ///< 3 x #P target positions of the grid's particles
  std::vector<SurfacePoint> points;  ///< #P their surface points
  /// Particles whose geodesic met the target's boundary before its length (they sit there).
  int stopped = 0;
  double seconds = 0.0;  ///< the shooting of every particle
};

/// The exponential-map decal of `geometry` (a MapDecalResult's) on `target`.
DecalBaselineResult exponential_map_decal(const LimitSurface& target, const DecalGeometry& geometry,
                                          const DecalBaselineOptions& options = {});

}  // namespace elastic
