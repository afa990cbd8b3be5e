#pragma once
/// \file
/// `partition_surface`: a limit tessellation cut exactly along a region's boundary curve, both
/// sides returned. Outputs that show a region *on* its surface (a decal, a painted mesh) need the
/// rest of the surface too, and need the two sides to share the curve's vertices so the result is
/// watertight.
///
/// The region's boundary is a closed chain of points on the limit surface, straight in (u, v)
/// between consecutive points inside the ptex face of the region triangle holding that segment
/// (Region::triangle_uv). The chain is embedded into a copy of `tessellation` exactly as
/// make_region embeds a curve (regions/cut_mesh.h): each point is inserted where it lies, and each
/// segment is walked in its ptex face, splitting the triangles it crosses. New vertices are
/// interpolated in (u, v), so they lie on the limit surface. The side holding the region's interior
/// (found from the centroid of the region's largest triangle) becomes `inside`, everything else
/// `outside`.
///
/// `tessellation` may have any resolution (it need not be the one the region was cut from): the
/// inside is then a re-cut of the same curve. Points closer than `snap` (barycentric, relative to
/// a tessellation triangle) to a tessellation vertex or edge move onto it, which moves the curve by
/// at most that fraction of an edge; the inside's boundary therefore holds the region's boundary
/// points (up to that snap) plus the points where the curve crosses the tessellation's edges.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "elastic/regions/region.h"
#include "elastic/surface/limit_tessellation.h"

namespace elastic {

struct PartitionOptions {
  /// Snap distance for inserting curve points, in barycentric units of a tessellation triangle.
  double snap = 1e-6;
  /// Name used in error messages.
  std::string name = "region";
};

struct SurfacePartition {
  /// The region re-cut from the tessellation: boundary counter-clockwise, `anchor` at the
  /// original anchor's position.
  Region inside;
  /// #V every vertex of the cut tessellation (both sides), on the limit surface.
  std::vector<Eigen::Vector3d> positions;
  std::vector<SurfacePoint> points;  ///< #V their surface points
  /// For each vertex of `inside`, its index in `positions` (boundary vertices are shared with the
  /// outside triangles).
  std::vector<int> inside_vertices;
  std::vector<Eigen::Vector3i> outside_triangles;  ///< counter-clockwise, indices into positions
  std::vector<int> outside_face;                   ///< ptex face of each outside triangle
  std::vector<std::array<Eigen::Vector2d, 3>> outside_uv;  ///< corners' (u, v) in that face
};

/// Cuts `tessellation` (of `surface`) along `region`'s boundary.
/// \throws InvalidInputError naming options.name when the region is not on `surface`, is empty or
///         has fewer than 3 boundary points, or when the tessellation does not belong to the
///         surface; NumericalError when the embedded curve does not separate the surface.
SurfacePartition partition_surface(const LimitSurface& surface,
                                   const LimitTessellation& tessellation, const Region& region,
                                   const PartitionOptions& options = {});

}  // namespace elastic
