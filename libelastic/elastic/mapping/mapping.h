#pragma once
/// \file
/// `Mapping`: the result of mapping a source region onto a target region, queryable both ways.
///
/// The correspondence is the relaxed particle grid's piecewise-linear map in 3D, composed with the
/// magnet. Each grid face (quads split into triangles, see triangles()) spans a triangle of source
/// particles and the same triangle of target particles, and the map is exactly the affine map
/// between the two triangles: a query x on the source is projected orthogonally onto the plane of
/// its source particle triangle, its barycentric weights there are applied to the target particles,
/// and the resulting point is put on the target surface by the magnet (closest point, warm-started
/// at the triangle's heaviest particle). The inverse is the same with the roles swapped. So a
/// particle maps exactly onto its partner, a map that is rigid at the particles between flat
/// regions is rigid everywhere, and a field linear on a flat source arrives linearly interpolated.
/// Particle positions are the limit positions of their surface points.
///
/// Locating the triangle: the regions' disk maps (mapping/initial_map.h) give a cheap, robust first
/// guess (the grid triangle containing the query's disk coordinates among the particles' disk
/// coordinates, or the nearest one when none does). Disk maps are not affine on a grid triangle, so
/// the guess can be a neighbour; from it the query walks in 3D: plane weights in the current
/// triangle; if one is negative beyond round-off (1e-10), step across the edge opposite the most
/// negative weight (or, when that edge is the grid's boundary, the next negative one), up to 64
/// steps, never revisiting a triangle. Outcomes:
/// - all weights >= -1e-10: the answer, with those (unclamped) weights;
/// - otherwise (no triangle holds the query's projection): if the walk met the grid's boundary (a
///   negative weight opposite a boundary edge) and the query's disk coordinates were outside the
///   grid too, the query is *outside*. Else it is clamped: the weights of the nearest point of the
///   least-outside triangle visited (all >= 0). This covers a query beyond the grid's boundary in
///   3D that the disk map puts inside (a sliver along the boundary where the disk maps and the 3D
///   chords disagree), a walk cycling between triangles whose planes leave a gap (a query above an
///   edge where the grid bends; both sides of the edge clamp to the same point of it, so this is
///   continuous), and a walk out of steps.
/// "Outside" therefore means: outside the region (no disk coordinates), or outside the grid (whose
/// boundary particles lie on the boundary curve, joined by chords) both in 3D and in the disk map.
/// Never a guess. Location::triangle and Location::barycentric report the final triangle and 3D
/// weights. A grid triangle that is degenerate in 3D on the query's side keeps the disk map's
/// weights.
///
/// A Mapping references the two projectors and regions it was built from; they must outlive it.
/// Queries are const and thread-safe.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "elastic/mapping/initial_map.h"
#include "elastic/particles/particle_grid.h"
#include "elastic/projection/closest_point.h"

namespace elastic {

class Mapping {
 public:
  /// Where a query lands.
  struct Location {
    bool inside = false;  ///< false: the query is outside (see the file comment)
    SurfacePoint point;   ///< on the other surface (when inside)
    Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< its limit position
    int triangle = -1;  ///< grid triangle (index into triangles()) the query was located in
    /// Weights of that triangle's particles: the query's affine (plane-projected) coordinates in
    /// the query side's particle triangle (clamped when the query was, see the file comment),
    /// applied unchanged to the other side's particles.
    Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
  };

  Mapping() = default;
  /// \param source_disk, target_disk disk maps of the source and target regions
  /// \param target_points #P relaxed target surface points of the grid's particles
  Mapping(const ParticleGrid& grid, const SurfaceProjector& source,
          const RegionDiskMap& source_disk, const SurfaceProjector& target,
          const RegionDiskMap& target_disk, const std::vector<SurfacePoint>& target_points);

  /// Source surface point -> target.
  Location forward(const SurfacePoint& source_point) const;
  /// Target surface point -> source.
  Location inverse(const SurfacePoint& target_point) const;

  /// The grid's faces split into triangles (particle index triples), as the queries use them.
  const std::vector<Eigen::Vector3i>& triangles() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace elastic
