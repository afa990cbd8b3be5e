#pragma once
/// \file
/// Flattening a Region into the plane. Used to lay out the particle grid (sampling/), for the naive
/// initial map (both regions mapped to the unit disk and composed, Fig. 9a of the paper), and as a
/// building block of the baselines.
///
/// - Disk: Floater's mean-value coordinates with the boundary fixed on the unit circle by
///   normalised arc length starting at the region's anchor (angle 0), counter-clockwise. Bijective
///   for any valid region (Floater 2003: mean-value weights are positive on a convex boundary), so
///   it never folds.
/// - Conformal: least-squares conformal map with a free boundary, scaled to the region's 3D area;
///   falls back to Disk if it folds (result says so).
/// - BoundaryFirst: boundary first flattening (boundary_first_flattening.h), a conformal map that
///   keeps the boundary's lengths, scaled to the region's 3D area; falls back to Conformal when it
///   does not apply or folds (and from there to Disk).

#include <Eigen/Core>
#include <vector>

#include "elastic/regions/region.h"

namespace elastic {

enum class FlatteningMethod { Disk, Conformal, BoundaryFirst };

struct FlatteningOptions {
  FlatteningMethod method = FlatteningMethod::Disk;  ///< which map
};

struct RegionFlattening {
  std::vector<Eigen::Vector2d> uv;                   ///< #V planar position of each region vertex
  FlatteningMethod method = FlatteningMethod::Disk;  ///< the method actually used
  int folded_triangles =
      0;  ///< triangles with non-positive signed area in the plane (0 when bijective)
};

/// \throws NumericalError when the linear system cannot be solved.
RegionFlattening flatten_region(const Region& region, const FlatteningOptions& options = {});

}  // namespace elastic
