#pragma once
/// \file
/// Region specifications, as a user gives them on the command line or in the API, and building a
/// Region from one on a surface:
///
// clang-format off
///   disk:X,Y,Z,R     the geodesic disk of radius R around the surface point nearest to (X,Y,Z)
///   points:FILE      a closed curve through 3+ points (one "x y z" per line), each projected
///                    onto the surface, joined in order by shortest paths on the surface
///   boundary         the surface's own boundary loop (an open surface with exactly one)
///   uv:FILE          a closed polygon (one "u v" per line) in the texture domain of a mesh
///                    with UVs
// clang-format on
///
/// The region is the side of the curve that is a disk; when both sides are disks (a closed genus-0
/// surface) the smaller one by area. Its boundary is oriented counter-clockwise seen from the
/// normal side. Any spec may end with ";anchor=X,Y,Z". The anchor (start of the boundary
/// correspondence) is the curve point nearest to `anchor` when given; otherwise it is chosen
/// automatically (see make_region).
///
/// The region is cut out of the projector's tessellation along the curve exactly (docs/regions.md):
/// `disk` distances come from the heat method (Crane et al. 2013), `points` are joined by exact
/// shortest paths on the tessellation (CGAL's, regions/polygon_sides.h), `uv` polygon edges are
/// straight in texture space.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "elastic/regions/region.h"

namespace elastic {

class SurfaceProjector;

struct RegionSpec {
  enum class Kind { Disk, Points, Boundary, UvPolygon };
  Kind kind = Kind::Boundary;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< Disk: point near the surface
  double radius = 0.0;                               ///< Disk: geodesic radius
  std::vector<Eigen::Vector3d> points;               ///< Points: the curve's points, in order
  std::vector<Eigen::Vector2d> uv_polygon;           ///< UvPolygon: the polygon in texture space
  std::optional<Eigen::Vector3d> anchor;  ///< start of the correspondence, if the user gave one
  std::string text;                       ///< the spec as written, for messages
};

/// Parses a spec string. `flag` names where it came from (for messages), e.g. "--source-region".
/// Reads FILE for points: and uv:. \throws InvalidInputError / IoError naming the flag or the file.
RegionSpec parse_region_spec(std::string_view text, std::string_view flag = "region");

/// What make_region may keep from one call to the next for speed (RegionOptions::cache): the heat
/// method's two factorisations on a `disk:`'s neighbourhood, somewhat larger than the disk needs,
/// reused while later disks on the same tessellation fit inside it (a disk dragged in small steps:
/// the live re-solve of `elastic studio`). A disk cut with a cache can differ from the same disk
/// cut without one within the heat method's error (about one tessellation edge on its boundary),
/// so cut a result that must repeat from its spec without one. Not thread-safe: one per caller.
class RegionCache {
 public:
  RegionCache();
  ~RegionCache();
  RegionCache(RegionCache&&) noexcept;
  RegionCache& operator=(RegionCache&&) noexcept;

  struct Impl;  ///< internal (regions/region_context.h)
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

struct RegionOptions {
  /// A spec point farther from the surface than this fraction of the surface's bounding-box
  /// diagonal is an error ("point is far from the surface").
  double max_point_distance = 0.05;
  /// Name used in error messages, e.g. "--target-region".
  std::string name = "region";
  /// `disk:` only. The heat method runs on the tessellation within twice the radius of the disk's
  /// centre, whose two sparse factorisations cost O(n^1.5) in its vertices (7 s for a large disk
  /// on a 228,000-vertex tessellation). Above this many vertices it runs instead on a coarser
  /// tessellation of the same surface (within this budget) and its distance is interpolated; the
  /// disk is still cut on the full tessellation (docs/regions.md). 0: never.
  long max_heat_vertices = 150000;
  /// Kept between calls (RegionCache), or none: every call computes afresh.
  RegionCache* cache = nullptr;
};

/// Builds the region of `spec` on the projector's surface, boundary counter-clockwise seen from the
/// normal side. Automatic anchor: the boundary vertex in the direction, from the region's centroid,
/// of the world axis least aligned with the region's mean normal (x, y, z on ties), projected onto
/// the plane normal to it. \throws InvalidInputError naming options.name for: a curve that crosses
/// itself, a region that is not
///         a disk (holds a handle or a hole), a disk that covers a whole closed surface, a point
///         far from the surface, `boundary` on a surface without exactly one boundary loop, `uv:`
///         on a mesh without UVs, a degenerate curve (fewer than 3 distinct points, zero length).
Region make_region(const SurfaceProjector& projector, const RegionSpec& spec,
                   const RegionOptions& options = {});

}  // namespace elastic
