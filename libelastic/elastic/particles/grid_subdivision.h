#pragma once
/// \file
/// One level of 1-to-4 refinement of a particle grid on its source surface: the "subdivision of the
/// grid of particles over the region after the minimum distortion mapping is found" suggested at
/// the end of §4.3 of the paper, for a finer sampling of the target.
///
/// Connectivity (the same rules as the first step of Catmull-Clark / Loop subdivision, without
/// their smoothing, which would pull the particles off the surface):
/// - every edge gets one new particle, its *edge particle*;
/// - a triangle (the boundary band) becomes 4 triangles: one at each corner and the middle one
///   spanned by the three edge particles;
/// - a quad becomes 4 quads (corner, edge particle, face particle, edge particle) around one new
///   *face particle* at its centre.
/// Grids have only quads and triangles (particle_grid.h); other faces are rejected.
/// So #F' = 4 #F for quad/triangle grids, #V' = #V + #E + #quads, #E' = 2 #E + 4 #quads + 3 #tris,
/// and V - E + F is unchanged. Old particles keep their indices 0 .. #V-1; edge particles follow
/// in edge order, then face particles in face order (deterministic). Faces stay counter-clockwise.
///
/// Source placement (every new particle lies exactly on the source limit surface):
/// - an edge particle of a boundary edge (both ends on the boundary curve, consecutive in
///   `boundary_loop`) is a new boundary particle at the *mid-parameter* of its two neighbours'
///   correspondence parameters s (normalised arc length along the curve, wrapping past 1). Its
///   position is the curve point at that s (`SurfaceCurve::locate`: on the chord polyline, like the
///   boundary particles of the layout), its SurfacePoint comes from `boundary_point(s)` when given
///   (e.g. the region's disk map), else from the magnet at that position;
/// - any other new particle is interior. Its parents' coordinates in a parameter plane (e.g. the
///   source region's disk map) are averaged (edge: midpoint, face: centroid) and mapped to the
///   surface by `plane_to_surface`; when no plane is given, or the mapping fails, the particle is
///   the magnet (closest source point) of the average of its parents' source positions,
///   warm-started at the first parent. Both keep an interior particle of a fine grid inside the
///   region: a convex combination of points of a disk-like region's flattening stays in it.
/// Source UVs are interpolated the same way (average of the parents'). Springs are rebuilt from the
/// new source positions (`ParticleGrid::build_springs`).

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "elastic/particles/particle_grid.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/surface_curve.h"

namespace elastic {

struct GridSubdivisionOptions {
  /// #P coordinates of the input grid's particles in a parameter plane of the source region (e.g.
  /// RegionDiskMap::to_disk); empty: new interior particles are placed by the magnet.
  std::vector<Eigen::Vector2d> plane_coordinates;
  /// Maps a point of that plane to the source surface; returns false when it cannot (the magnet is
  /// used then). Needed when `plane_coordinates` is given.
  std::function<bool(const Eigen::Vector2d&, SurfacePoint&)> plane_to_surface;
  /// The source SurfacePoint of the boundary curve at correspondence parameter s (e.g.
  /// RegionDiskMap::boundary_point); empty: the magnet of the curve point.
  std::function<SurfacePoint(double)> boundary_point;
  /// Name of the grid in error messages.
  std::string name = "particle grid";
};

/// Where a particle of the refined grid comes from: the average of 1 to 4 particles of the coarse
/// grid (1: an old particle kept; 2: an edge particle, the edge's ends; 4: a face particle, the
/// quad's corners in face order).
struct SubdivisionParents {
  std::array<int, 4> parent = {-1, -1, -1, -1};  ///< coarse particle indices, `count` of them
  int count = 0;                                 ///< 1, 2 or 4
};

struct GridSubdivisionResult {
  ParticleGrid grid;  ///< the refined grid, springs built
  /// #P' (refined) parents of each particle in the input grid, in the refined grid's order.
  std::vector<SubdivisionParents> parents;
  int coarse_particles = 0;    ///< #P of the input
  int edge_particles = 0;      ///< new particles on edges (interior and boundary)
  int face_particles = 0;      ///< new particles at quad centres
  int boundary_particles = 0;  ///< new particles on the boundary curve (subset of edge_particles)
  /// New interior particles placed by the magnet (no plane given, or the plane mapping failed).
  int magnet_placements = 0;
};

/// Refines `grid` (which lies on `source`, its boundary on `source_curve`) by one level of 1-to-4
/// subdivision; see the file comment.
/// \throws InvalidInputError naming options.name when the grid is inconsistent (empty, sizes of
///         source_points / boundary arrays / plane_coordinates differ from the particle count, a
///         mesh boundary edge whose ends are not consecutive in boundary_loop, a face that is not a
///         triangle or a quad, no plane_to_surface with plane_coordinates, an empty curve);
///         NumericalError when the refined connectivity cannot be built (a non-manifold input).
GridSubdivisionResult subdivide_grid(const ParticleGrid& grid, const SurfaceProjector& source,
                                     const SurfaceCurve& source_curve,
                                     const GridSubdivisionOptions& options = {});

}  // namespace elastic
