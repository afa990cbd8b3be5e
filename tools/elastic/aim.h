#pragma once
// Aiming help shared by `elastic info`, `locate`, `region`, `render` and the paste previews: the up
// axis (--up, or guessed: render/up_axis.h), figures of a region a user can check (area,
// perimeter, geodesic radius), and the camera that shows a region with its surroundings, with a
// field of view that zooms.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"
#include "elastic/regions/region.h"
#include "elastic/render/camera.h"
#include "elastic/render/up_axis.h"

namespace elastic::cli {

/// The up direction `flag_value` asks for: "auto" guesses it from `mesh` (guess_up_axis), anything
/// else is parsed by parse_up_direction ("z", "-y", "0,0,1"). `reason` receives how it was chosen.
/// \throws UsageError naming `flag` for a malformed value.
Eigen::Vector3d resolve_up(const std::string& flag_value, const PolygonMesh& mesh,
                           std::string* reason = nullptr, const std::string& flag = "--up");

/// A direction for messages: "+y" for an axis, "(x, y, z)" otherwise.
std::string direction_name(const Eigen::Vector3d& d);

/// What `elastic region` reports about a region.
struct RegionFigures {
  double area = 0.0;       ///< sum of the region's triangle areas
  double perimeter = 0.0;  ///< length of its boundary polyline
  /// The largest distance from the boundary to a vertex inside, measured along the region's edges
  /// (Dijkstra from every boundary vertex): for a geodesic disk of radius R this is about R. Edge
  /// paths zigzag, so it overestimates the true geodesic distance by a few percent on a fine
  /// tessellation.
  double geodesic_radius = 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< area-weighted centroid of the triangles
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< unit vector area (mean normal)
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();    ///< where the correspondence starts
};
RegionFigures region_figures(const Region& region);

/// The default field of view of previews, in degrees. Framing is computed at this angle; a
/// different `fov` then zooms (narrower: closer look) from the same eye.
inline constexpr double kFramingFov = 35.0;

/// A camera that shows `points` seen along `normal` raised by 25 degrees towards `up` (a
/// three-quarter view), from where they fill `fill` of the picture at kFramingFov, with the image
/// up along `up`, then zoomed to `fov` degrees.
Camera aim_camera(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& normal,
                  const Eigen::Vector3d& up, double fov, int width, int height, double fill);

/// The outline of a region as a one-polygon mesh through its boundary loop (drawn as a wireframe).
PolygonMesh region_outline(const Region& region);

/// The region's triangles moved off the surface by `offset` along their vertex normals (so a tinted
/// copy drawn over the whole surface is not hidden by it).
PolygonMesh lifted_region(const Region& region, double offset);

}  // namespace elastic::cli
