#pragma once
/// \file
/// Texture coordinates at a surface point of a region, interpolated in the region triangle (of the
/// same ptex face) that contains the point's (u, v). Used to carry source UVs along with particles
/// that moved on the surface (adaptive_sampling.h).

#include <Eigen/Core>
#include <vector>

#include "elastic/regions/region.h"

namespace elastic {

class RegionTexcoords {
 public:
  /// Indexes the region's triangles by ptex face; `region` must outlive this object.
  explicit RegionTexcoords(const Region& region);
  /// False (and `uv` untouched) when the region has no texture coordinates or no triangle of the
  /// point's ptex face holds it (within 1e-3 in barycentric coordinates: round-off on the region's
  /// edge still takes the nearest triangle).
  bool at(const SurfacePoint& p, Eigen::Vector2d& uv) const;

 private:
  const Region& region_;
  std::vector<std::vector<int>> by_face_;
};

}  // namespace elastic
