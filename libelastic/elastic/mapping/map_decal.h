#pragma once
/// \file
/// Decals with a free boundary: the source region is placed on the target by a point, an angle and
/// a size instead of a drawn target curve, and the target region is whatever the relaxed feature
/// covers there (Schmidt et al. 2006 place decals the same way, by the discrete exponential map).
///
/// 1. The source region is sampled as for map_regions (sample_region).
/// 2. Source frame: the region's area centroid c and area-weighted mean normal n_s, with
///    world_up_frame(n_s) (projection/exponential_map.h: "up" is the world +Y projected on the
///    plane). Each particle gets tangent coordinates u_i = ((x_i - c) . right, (x_i - c) . up):
///    exact for a planar source (an image, a region of a plane), the orthogonal projection on the
///    mean plane for a curved one (used only for the start; the springs keep the source's 3D
///    rest lengths either way).
/// 3. Target frame at the placement's centre p (the limit surface's closest point to the given
///    point): world_up_frame(n_p), turned counter-clockwise (seen from the normal side) by the
///    placement's angle. The start is the exponential-map decal: particle i at
///    exp_p(scale * (u_i.x right' + u_i.y up')), shot along the limit surface's geodesics.
/// 4. Relaxation with BoundaryMode::Free: every particle moves on the target, except two pinned
///    at their start: the one nearest the source centre (where the decal is) and the one nearest
///    a grid spacing above it (which way is up: on a sphere, rotation about the centre costs no
///    energy, and an unpinned decal was measured turning 37 degrees on its way to equilibrium).
///    Rest lengths are the source's times `scale` (sigma = scale). The robust energy, fold guard
///    and barrier hold as for drawn regions.
/// 5. The target region is cut along the relaxed boundary: the boundary particles, in order,
///    joined by shortest paths on the surface (a `points:` region, regions/region_spec.h), so the
///    boundary particles lie on the region's curve exactly.
///
/// A decal that would overlap itself on the target (it wraps around a thin part, or it is larger
/// than a closed surface allows) is refused with an InvalidInputError that says how much smaller
/// it must be; one that runs off an open surface's boundary likewise.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "elastic/core/progress.h"
#include "elastic/mapping/map_regions.h"
#include "elastic/projection/exponential_map.h"

namespace elastic {

/// Where a decal goes: `elastic paste --target-place X,Y,Z[,ANGLE_DEG[,SCALE]]`.
struct DecalPlacement {
  /// The source region's centre lands on the target limit surface's closest point to this.
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  /// The decal's up direction, in degrees counter-clockwise (seen from the normal side) from the
  /// target frame's up (world_up_frame: the world +Y projected on the tangent plane).
  double angle_degrees = 0.0;
  /// Size on the target relative to the source's own physical size; > 0.
  double scale = 1.0;
};

/// Parses "X,Y,Z[,ANGLE_DEG[,SCALE]]" (finite numbers, SCALE > 0).
/// \throws InvalidInputError naming `input` otherwise.
DecalPlacement parse_decal_placement(const std::string& text,
                                     const std::string& input = "--target-place");

/// C_a / C of a placed decal's angular springs when RelaxationOptions::angular_stiffness is not
/// set: the paper's C_a = C, not the robust energy's 0.3 (relaxation.h). With a free boundary the
/// angular springs are what keep the boundary's shape: on rectangles at half the feature size
/// (spot, the sphere, the vase, Nefertiti) C_a = C turned the edges 13-17% less than 0.3 did (less
/// than the exponential map's, where 0.3 turned them 5-15% more), kept the corners square to 0.05
/// degrees, and lowered the symmetric Dirichlet energy's excess by a third, for about twice the
/// length energy (still a median 3.4 times below the exponential map's over the decal bench).
inline constexpr double kDecalAngularStiffness = 1.0;

struct MapDecalOptions {
  /// Particle count, layout and curvature-adaptive sampling on the source (as map_regions).
  SampleRegionOptions sampling;
  /// Solver, energy and tolerances; `boundary` is set to BoundaryMode::Free, and an unset
  /// `angular_stiffness` to kDecalAngularStiffness times the stiffness.
  RelaxationOptions relaxation;
  /// The start's geodesic shooting; a step of 0 means half the grid's mean spacing on the target.
  ExponentialMapOptions shooting;
  /// The placement point may be at most this fraction of the target's bounding-box diagonal off
  /// the surface.
  double max_point_distance = 0.05;
  /// Name used in error messages (the flag the placement came from).
  std::string name = "--target-place";
  /// Called between stages ("sample", "place", "relax", "cut", "mapping"); false cancels.
  ProgressCallback progress;
};

/// What a decal's placement was, for reports and the exponential-map baseline.
struct DecalGeometry {
  DecalPlacement placement;  ///< as given
  /// The source's centre, frame and each particle's tangent coordinates u_i (#P).
  Eigen::Vector3d source_centre = Eigen::Vector3d::Zero();
  UpFrame source_frame;
  std::vector<Eigen::Vector2d> source_coordinates;
  double source_radius = 0.0;  ///< max |u_i|
  int pinned = -1;             ///< the particle held at the centre
  int pinned_up = -1;          ///< the particle held a grid spacing above it (the up direction)
  /// The target centre (closest point to placement.point) and the frame there, already turned by
  /// the placement's angle.
  SurfacePoint target_centre;
  Eigen::Vector3d target_centre_position = Eigen::Vector3d::Zero();
  UpFrame target_frame;
  /// How far the relaxation turned the outer half of the decal about its centre, degrees
  /// counter-clockwise: the mean turn of the particles' directions from the pinned particle,
  /// weighted by |u_i|^2 (0 on a plane; the pinned pair holds the centre's up direction exactly,
  /// this says how much the rest twists against it).
  double turned_degrees = 0.0;
  /// Particles that the cut left a snap's width outside the region (see map_decal.cpp): the
  /// queryable mapping puts them on the region's nearest boundary vertex (the relaxed map keeps
  /// them); how many, and the largest such move.
  int snapped_particles = 0;
  double snap_distance = 0.0;
  double seconds_shooting = 0.0;  ///< the exponential-map start
  double seconds_cut = 0.0;       ///< cutting the target region along the relaxed boundary
};

struct MapDecalResult {
  /// As map_regions' result; `naive` is the exponential-map start, `boundary_offset` 0.
  MapResult map;
  DecalGeometry geometry;
  /// The target region cut along the relaxed boundary (map.mapping and map.target_disk reference
  /// it; heap-held so the result can move).
  std::unique_ptr<Region> target_region;
};

/// Places `source_region` on `target` as a decal (see the file comment).
/// \throws InvalidInputError naming options.name for a placement far from the surface, a
///         non-positive or non-finite scale, a decal that runs off the target's boundary or
///         overlaps itself (saying how much smaller it must be); NumericalError when a stage fails.
MapDecalResult map_decal(const SurfaceProjector& source, const Region& source_region,
                         const SurfaceProjector& target, const DecalPlacement& placement,
                         const MapDecalOptions& options = {});

/// The exponential-map decal itself (step 3 of the file comment) for `geometry`'s coordinates and
/// frame: what map_decal starts from, and the baseline (baselines/decal_baseline.h).
/// `reached` receives, per particle, the fraction of its geodesic walked (1 unless the target's
/// boundary stopped it).
InitialMap exponential_map_placement(const LimitSurface& target, const DecalGeometry& geometry,
                                     const ExponentialMapOptions& options,
                                     std::vector<double>* reached = nullptr);

/// Particles of a placement that lie inside a grid triangle they are not a corner of, on the same
/// side of the surface (the placement overlaps itself there): their indices. `normals` are the
/// target's unit normals at the particles.
std::vector<int> self_overlapping_particles(const ParticleGrid& grid,
                                            const Eigen::Matrix3Xd& positions,
                                            const Eigen::Matrix3Xd& normals);

}  // namespace elastic
