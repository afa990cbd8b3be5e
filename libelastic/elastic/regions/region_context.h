#pragma once
/// \file
/// Internal to regions/: what make_region (region_spec.h) needs about a surface's tessellation,
/// shared by the cut of each region kind (disk_region.cpp for `disk:`, region_spec.cpp for the
/// others).

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "elastic/projection/closest_point.h"
#include "elastic/regions/cut_mesh.h"
#include "elastic/regions/heat_geodesics.h"
#include "elastic/regions/region_spec.h"

namespace elastic {

struct RegionCache::Impl {
  regions_detail::LocalHeatCache disk_distance;  ///< `disk:` (disk_region.cpp)
};

}  // namespace elastic

namespace elastic::regions_detail {

/// Crossings and curve points closer than this (in barycentric terms of the triangle being cut) to
/// a vertex or an edge are moved onto it, so that cutting never leaves sliver triangles.
constexpr double kSnap = 1e-3;

/// The projector's tessellation with a ptex-face index of its triangles and its bounding-box
/// diagonal. Built once per make_region call.
struct RegionContext {
  const SurfaceProjector& projector;
  const LimitSurface& surface;
  const LimitTessellation& tess;
  const RegionOptions& options;
  std::vector<std::vector<int>> face_triangles;  ///< per ptex face, its tessellation triangles
  double diagonal = 0.0;                         ///< of the tessellation's bounding box

  RegionContext(const SurfaceProjector& projector, const RegionOptions& options);
  /// The context keeps a reference to the options: a temporary would dangle.
  RegionContext(const SurfaceProjector& projector, RegionOptions&& options) = delete;

  /// The corners' (u, v) of every tessellation triangle (tessellation_corner_uv), computed the
  /// first time a whole-surface cut needs them; a disk cuts only its neighbourhood.
  const std::vector<std::array<Eigen::Vector2d, 3>>& corner_uv() const;

  /// A cut mesh of the whole tessellation.
  CutMesh cut_mesh() const { return CutMesh(surface, tess, corner_uv(), options.name); }

  /// The tessellation triangle holding a surface point, with barycentric coordinates.
  MeshLocation locate(const SurfacePoint& p) const;

  /// Projects a user point onto the surface; error when it is far from it. The error names the
  /// nearest surface point, and `suggest` (when given) turns that point into a ready spec, e.g.
  /// "disk:X,Y,Z,R", so that the user can copy it.
  MeshLocation project(
      const Eigen::Vector3d& x, const std::string& what,
      const std::function<std::string(const Eigen::Vector3d&)>& suggest = {}) const;

 private:
  mutable std::vector<std::array<Eigen::Vector2d, 3>> corner_uv_;
};

/// \throws InvalidInputError "the region is not a disk", naming `name`.
[[noreturn]] void throw_not_disk(const std::string& name);

/// The geodesic disk `spec` (kind Disk) cut exactly from the tessellation (disk_region.cpp).
Region disk_region(const RegionContext& ctx, const RegionSpec& spec);

}  // namespace elastic::regions_detail
