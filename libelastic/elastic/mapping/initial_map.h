#pragma once
/// \file
/// The paper's "naive mapping" (Fig. 9a): the starting configuration of the relaxation, and a
/// baseline.
///
/// Both regions are mapped to the unit disk by `flatten_region` (Disk: mean-value coordinates,
/// boundary on the circle by normalised arc length from the anchor), and the two disk maps are
/// composed: source point -> source disk -> target disk (the same point) -> target surface. Each
/// disk map is a bijection of the region onto the disk, so the composition is bijective and
/// orientation-preserving (both boundaries are counter-clockwise seen from their normals). Boundary
/// particles land at their correspondence parameter s on the target curve (angle 2 pi s), so the
/// boundary correspondence is the arc-length one of §4.1 by construction.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "elastic/particles/particle_grid.h"
#include "elastic/particles/spring_energy.h"
#include "elastic/regions/region.h"
#include "elastic/regions/region_flattening.h"

namespace elastic {

/// Where a region point lies on the region's disk map, and back.
class RegionDiskMap {
 public:
  RegionDiskMap() = default;
  /// Flattens `region` to the unit disk. The region must outlive the map.
  explicit RegionDiskMap(const Region& region);

  const Region& region() const { return *region_; }
  const RegionFlattening& flattening() const { return flattening_; }

  /// Disk coordinates of a surface point of the region; false when the point is not in the region.
  bool to_disk(const SurfacePoint& p, Eigen::Vector2d& disk) const;
  /// The region's surface point at disk coordinates `disk` (clamped to the disk); false when the
  /// point is farther than `tolerance` outside the disk.
  bool from_disk(const Eigen::Vector2d& disk, SurfacePoint& p, double tolerance = 1e-9) const;
  /// The point of the boundary curve at correspondence parameter s (angle 2 pi s on the disk).
  SurfacePoint boundary_point(double s) const;

  /// Turns the correspondence by `offset` (a fraction of the boundary, in [0, 1)): parameter s
  /// then means the curve point at s + offset from the region's anchor, and disk coordinates turn
  /// with it (by 2 pi offset), so the three queries above stay one consistent bijection.
  void set_offset(double offset);
  double offset() const { return offset_; }

 private:
  const Region* region_ = nullptr;
  double offset_ = 0.0;
  Eigen::Matrix2d turn_ =
      Eigen::Matrix2d::Identity();  // flattening coordinates of disk point z: turn_ z
  RegionFlattening flattening_;
  struct Locators;
  std::shared_ptr<const Locators> locators_;
};

struct InitialMap {
  Eigen::Matrix3Xd positions;  ///< 3 x #P target positions (exactly on the target limit surface)
  std::vector<SurfacePoint> points;  ///< #P target surface points
  int outside =
      0;  ///< particles whose source point could not be placed in the source region's disk map
};

/// Places every particle of `grid` (which lies on `source`) on `target` by the composed disk maps.
/// \throws NumericalError when a disk map cannot be built.
InitialMap naive_map(const ParticleGrid& grid, const RegionDiskMap& source,
                     const RegionDiskMap& target);

/// Carries a map of `grid` from one region to another through their disk maps (a warm start:
/// the relaxed placement on a region that then moved or changed size): each interior particle's
/// surface point `points[i]` (on `from`'s region) goes to its disk coordinates on `from` and comes
/// back from `to`'s disk; boundary particle k (grid.boundary_loop order) lands at
/// `to.boundary_point(boundary_parameters[k])` (taken modulo 1). The disk maps' offsets should
/// agree so the disk means the same turn on both. On `from` == `to` interior particles return to
/// their points (to the disk maps' round-off). Particles not in `from`'s region land at the
/// disk's centre and are counted in `outside`.
/// \throws InvalidInputError when `points` or `boundary_parameters` do not match the grid.
InitialMap transported_map(const ParticleGrid& grid, const std::vector<SurfacePoint>& points,
                           const std::vector<double>& boundary_parameters,
                           const RegionDiskMap& from, const RegionDiskMap& to);

/// The multilevel start (MapOptions::coarse_start): a relaxed map of a coarser grid of the same
/// source region carried onto `grid`. The coarse map is read as a map of the unit disk onto itself:
/// each coarse particle goes from its point on `source`'s disk to its relaxed point on `target`'s
/// (`coarse_points`; boundary particle k at angle 2 pi coarse_parameters[k], where it slid), and
/// between the particles it is affine on each coarse grid triangle of the source disk. Each
/// interior particle of `grid` goes through that map and back from `target`'s disk; one in the
/// sliver between the coarse boundary polygon and the circle takes the nearest coarse triangle's
/// affine map, extrapolated. Boundary particle k of `grid`, at source parameter t, lands at
/// parameter s(t), the coarse (t, s) pairs interpolated linearly around the loop, returned in
/// `boundary_parameters` (the relaxation's start on the curve). `target` must carry the turn the
/// coarse map was made with. Particles the disk maps cannot place are counted in `outside`.
/// 	hrows InvalidInputError when the coarse points or parameters do not match `coarse`.
InitialMap prolonged_map(const ParticleGrid& grid, const ParticleGrid& coarse,
                         const std::vector<SurfacePoint>& coarse_points,
                         const std::vector<double>& coarse_parameters, const RegionDiskMap& source,
                         const RegionDiskMap& target, std::vector<double>& boundary_parameters);

struct BoundaryOffsetOptions {
  /// Offsets tried: k / candidates of the boundary, k = 0 .. candidates - 1.
  int candidates = 24;
  /// The energy that judges a naive map (the paper's E_len + E_ang at the relaxation's sigma).
  SpringEnergyOptions energy;
};

struct BoundaryOffsetResult {
  double offset = 0.0;          ///< the chosen offset, as set on the target disk map
  double energy = 0.0;          ///< E_len + E_ang of the naive map with that offset
  double energy_at_zero = 0.0;  ///< the same with the region's own anchor (offset 0)
  int folds = 0;                ///< faces the chosen offset's naive map folds
  int candidates = 0;           ///< offsets tried
  InitialMap naive;             ///< the naive map with the chosen offset (naive_map's answer)
};

/// Chooses where the boundary correspondence starts on the target (when no anchor says so): the
/// offset among `candidates` equally spaced ones whose naive map has the least paper energy among
/// those that fold no face (else the fewest folds), set on `target` (RegionDiskMap::set_offset). A
/// rotation of the correspondence the user did not ask for costs nothing, and a bad one (a
/// rectangle's corners landing where the target curve bends, a shape turned against the target's)
/// forces distortion that no relaxation with a fixed boundary can remove.
BoundaryOffsetResult choose_boundary_offset(const ParticleGrid& grid, const RegionDiskMap& source,
                                            RegionDiskMap& target,
                                            const BoundaryOffsetOptions& options = {});

}  // namespace elastic
