#pragma once
/// \file
/// `Mapping`: the result of mapping a source region onto a target region, queryable both ways.
///
/// The relaxed particle grid defines a piecewise-linear correspondence: each grid face (quads split
/// into triangles) spans a triangle of source particles and the same triangle of target particles.
/// A query is located in the grid through the regions' disk maps (mapping/initial_map.h): a source
/// point goes to the source disk, is located among the grid triangles laid out by their particles'
/// source-disk coordinates, and its barycentric coordinates there are applied to the target
/// particles; the result is put on the target surface by the magnet. The inverse does the same with
/// target-disk coordinates of the relaxed particles. Points outside the region (or outside the
/// grid, which covers the region up to the boundary curve) answer "outside", never a guess.
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
    bool inside = false;                                 ///< false: the query is outside the region
    SurfacePoint point;                                  ///< on the other surface (when inside)
    Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< its limit position
    int triangle = -1;                                   ///< grid triangle (index into triangles())
    Eigen::Vector3d barycentric =
        Eigen::Vector3d::Zero();  ///< weights of that triangle's particles
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
