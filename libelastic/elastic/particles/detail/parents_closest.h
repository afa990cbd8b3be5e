#pragma once
/// \file
/// Where a grid subdivision puts a new particle that no plane or curve places: the closest point
/// of its parents' mean position. Shared by the subdivision on the source (grid_subdivision.cpp)
/// and the refined map's start on the target (mapping/refine_map.cpp); private to the library.

#include <Eigen/Core>
#include <vector>

#include "elastic/particles/grid_subdivision.h"
#include "elastic/projection/closest_point.h"

namespace elastic::detail {

/// For each refined particle in `particles`: the closest point on `surface` of the mean of its
/// parents' `coarse_positions`, warm-started at its first parent's `coarse_points` entry (one
/// batched query).
std::vector<ClosestPoint> closest_to_parents_mean(const SurfaceProjector& surface,
                                                  const std::vector<SubdivisionParents>& parents,
                                                  const std::vector<int>& particles,
                                                  const Eigen::Matrix3Xd& coarse_positions,
                                                  const std::vector<SurfacePoint>& coarse_points);

}  // namespace elastic::detail
