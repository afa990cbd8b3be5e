#pragma once
/// \file
/// A dense triangle tessellation of a limit surface whose every vertex knows its SurfacePoint. It
/// serves the closest-point BVH (projection/), geodesics and region cutting (regions/) and
/// rendering.
///
/// The tessellation is watertight and welded: a vertex on an edge shared by two ptex faces is one
/// vertex (its `points` entry uses one of the faces), so the result has the topology of the control
/// mesh (same boundary loops, same genus). Vertex positions lie exactly on the limit surface;
/// triangles are wound like the control mesh.

#include <Eigen/Core>
#include <vector>

#include "elastic/surface/limit_surface.h"

namespace elastic {

struct TessellationOptions {
  /// Segments along each control-mesh edge: each control quad becomes resolution^2 * 2 triangles,
  /// each Loop triangle resolution^2 triangles, and each of an n-gon's n ptex sub-faces (whose
  /// edges are half control edges) (resolution/2)^2 * 2 triangles. Under Catmull-Clark with
  /// non-quad faces an odd resolution is rounded up to the next even one. Used when
  /// `target_triangles` is 0. 1..1024.
  int resolution = 8;
  /// When > 0, choose the resolution (within 1..1024) so that the tessellation has about this many
  /// triangles.
  long target_triangles = 0;
  /// When > 0 and `target_triangles` is 0: `resolution` is lowered (to no less than 1, or 2 where
  /// it must be even) while the tessellation would have more triangles than this. A dense control
  /// mesh, such as a scan, is already finer than what a coarser tessellation of it needs to
  /// resolve.
  long max_triangles = 0;
};

struct LimitTessellation {
  std::vector<Eigen::Vector3d> positions;  ///< #V limit positions
  std::vector<SurfacePoint> points;        ///< #V surface point of each vertex
  std::vector<Eigen::Vector3i> triangles;  ///< #T vertex triples, counter-clockwise
  std::vector<int> triangle_face;          ///< #T ptex face each triangle lies in
  int resolution = 0;                      ///< the resolution used
};

/// Tessellates `surface` uniformly in each ptex face's parameter domain.
/// \throws InvalidInputError when the options are out of range.
LimitTessellation tessellate(const LimitSurface& surface, const TessellationOptions& options = {});

/// The resolution tessellate() uses for `options` (the same rounding, without tessellating).
/// \throws InvalidInputError when the options are out of range.
int tessellation_resolution(const LimitSurface& surface, const TessellationOptions& options);

}  // namespace elastic
