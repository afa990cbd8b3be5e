#pragma once
/// \file
/// `sample_target`: the target region refined for transfer, every vertex knowing where it comes
/// from on the source.
///
/// A transfer evaluates the source feature (colour, height, detail) at points of the target region.
/// The region's own triangles come from the target's tessellation and may be much coarser than the
/// feature (a 1024^2 texture, a fine height map), so the region is refined first: every triangle
/// is split 1-to-4 at its edge midpoints *in (u, v)* of the ptex face it lies in
/// (Region::triangle_uv). Because (u, v) of a point of the triangle is the barycentric combination
/// of its corners' (u, v), the new vertices lie exactly on the limit surface, and the refined
/// boundary still runs along the region's boundary curve (the curve is straight in (u, v) between
/// its vertices).
///
/// Refinement is uniform (the same number of levels for every triangle, so the mesh stays
/// conforming, with no T-junctions): the smallest number of levels L such that, after L halvings,
///  - every 3D edge of the target triangles is at most `max_edge`, and
///  - every edge of the triangles' image on the source (the chord between the source points of the
///    corners) is at most `max_source_edge` (e.g. one source texel, see source_texel_length()),
/// and then more levels while the vertex count is below `min_vertices`, capped by `max_levels` and
/// `max_vertices`.
///
/// For every vertex: its target SurfacePoint, limit position, unit limit normal, and its source
/// location `mapping.inverse(point)`. Vertices the inverse reports outside are resolved honestly:
///  - boundary vertices (on the region's boundary curve) take the source boundary curve's point at
///    the same correspondence parameter s (normalised arc length from the anchor, §4.1), which is
///    how the mapping itself pairs the two boundaries; this needs `options.source_region`. The
///    relaxed grid's boundary chords cut small slivers off the disk, so boundary vertices between
///    particles are typically "outside" for the grid; with `source_region` every boundary vertex
///    is resolved this way, for consistency.
///  - interior vertices (in such a sliver, or outside by round-off): when the particles' positions
///    are given (see below), they take the grid triangle of an adjacent covered vertex, whose
///    3D-linear map extends a little past the grid's edge; otherwise the inverse of a point nudged
///    towards the centroid of an adjacent triangle (10%, 25%, then 50% of the way, in the ptex face
///    of that triangle), an error of at most half an edge. Both are counted in `nudged`.
/// What still has no source keeps `inside = false` and is counted in `unresolved`.
///
/// Piecewise-linear in 3D: Mapping::inverse is itself the particles' piecewise-linear map in 3D
/// (affine on each grid triangle, see mapping.h). When the particles' positions are given, the
/// weights are recomputed from them as the barycentric coordinates of the vertex's projection onto
/// the plane of the target particle triangle the inverse located, applied to the source particles,
/// and the resulting point is put on the source surface by Gauss-Newton steps from the inverse's
/// answer (closest point). For a vertex the inverse answered directly this reproduces the
/// inverse's own weights (with the given positions: grid.source_positions() has boundary particles
/// on the region's chord polyline where the Mapping uses their limit positions); what it adds is
/// extrapolation: for interior vertices that took an adjacent covered vertex's triangle, and for
/// vertices the inverse clamped onto a boundary triangle, the triangle's affine map is extended a
/// little past the grid's edge. Then a map that is rigid at the particles between flat regions is
/// rigid everywhere, and a colour field linear on a flat source arrives linearly interpolated
/// between particles.
///
/// The refinement and the inverse queries run in parallel (TBB); the result does not depend on the
/// number of threads.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "elastic/mapping/mapping.h"
#include "elastic/regions/region.h"

namespace elastic {

struct TargetSamplingOptions {
  /// > 0: refine until every 3D edge of the target triangles is at most this long. 0: no bound.
  double max_edge = 0.0;
  /// > 0: refine until the source image of every triangle has edges (3D chords on the source) at
  /// most this long, e.g. source_texel_length() for a texture. 0: no bound.
  double max_source_edge = 0.0;
  /// Upper bound on the refinement levels (each multiplies the triangle count by 4). 0..12.
  int max_levels = 8;
  /// Refine (within max_levels and max_vertices) at least until the region has this many vertices,
  /// e.g. for a smooth per-vertex colour mesh. 0: no lower bound.
  long min_vertices = 0;
  /// Upper bound on the refined vertex count: fewer levels are used when the next would exceed it
  /// (reported by `limited`).
  long max_vertices = 4'000'000;
  /// The mapped source region (the one the mapping was built from): resolves boundary vertices by
  /// arc length on its boundary curve. Null: boundary vertices use the inverse like the others.
  const Region* source_region = nullptr;
  /// Particle positions, 3 x #P, on the source (MapResult::sampling.grid.source_positions()) and
  /// on the target (MapResult::relaxation.positions). When both are given and `source_region` is
  /// set, each inverse is made piecewise linear in 3D (see the file comment). Empty: the
  /// mapping's own weights.
  Eigen::Matrix3Xd source_particles;
  Eigen::Matrix3Xd target_particles;
  /// Name used in error messages.
  std::string name = "target";
};

struct TargetSamples {
  std::vector<Eigen::Vector3d> positions;  ///< #V limit positions on the target
  std::vector<SurfacePoint> points;        ///< #V target surface points
  std::vector<Eigen::Vector3d> normals;    ///< #V unit limit normals (du x dv side)
  /// #V source location of each vertex (`inside` false only for the `unresolved` ones).
  std::vector<Mapping::Location> sources;
  std::vector<char> on_boundary;           ///< #V 1 for vertices on the region's boundary curve
  std::vector<Eigen::Vector3i> triangles;  ///< #T counter-clockwise vertex triples
  std::vector<int> triangle_face;          ///< #T ptex face containing each triangle
  std::vector<std::array<Eigen::Vector2d, 3>> triangle_uv;  ///< #T corners' (u,v) in that face
  std::vector<int> triangle_parent;  ///< #T the region triangle each triangle was cut from
  /// The region's boundary loop in the refined mesh, counter-clockwise (interior on the left).
  std::vector<int> boundary;

  int levels = 0;                ///< refinement levels applied
  bool limited = false;          ///< true when max_levels / max_vertices stopped the refinement
  double max_edge_length = 0.0;  ///< longest 3D target edge after refinement
  double max_source_edge_length = 0.0;  ///< longest source chord of a refined triangle
  int boundary_by_arc_length = 0;       ///< boundary vertices resolved on the source curve
  int nudged = 0;                       ///< interior vertices resolved by a nudged inverse
  int unresolved = 0;                   ///< vertices left without a source

  int num_vertices() const { return static_cast<int>(positions.size()); }
  int num_triangles() const { return static_cast<int>(triangles.size()); }
};

/// Refines `target_region` and maps every vertex back to the source through `mapping`.
/// `target_region` may be the region the mapping was built from or a re-cut of the same curve
/// (e.g. the inside of partition_surface() at another tessellation resolution).
/// \throws InvalidInputError naming options.name when the region is empty or not on a surface, or
///         the options are out of range.
TargetSamples sample_target(const Region& target_region, const Mapping& mapping,
                            const TargetSamplingOptions& options = {});

/// The 3D length of one texel of a `columns` x `rows` texture on the source region: sqrt(3D area /
/// texel count covered), where the texel count is the region's area in texture space times
/// columns * rows. Needs the region's texcoords (Region::texcoords); returns 0 without them or
/// for a region of zero texture area.
double source_texel_length(const Region& source_region, int columns, int rows);

}  // namespace elastic
