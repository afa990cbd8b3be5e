#pragma once
/// \file
/// `Camera`: a pinhole (perspective) camera for render/render.h, and automatic framing of a
/// bounding box.
///
/// Conventions:
/// - Image pixels are addressed as in image/image.h: x to the right, y **down** from the top row.
///   Continuous pixel coordinates put pixel (x, y)'s centre at (x + 0.5, y + 0.5).
/// - `fov_deg` is the **vertical** field of view (full angle); the horizontal one follows from the
///   aspect ratio width / height (square pixels).
/// - A "view direction" in this file points **from the scene towards the eye**, so passing a
///   region's mean outward normal shows its front side.
/// - World units are the meshes' units; nothing is rescaled.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace elastic {

struct Camera {
  Eigen::Vector3d eye{0.0, 0.0, 5.0};     ///< centre of projection
  Eigen::Vector3d target{0.0, 0.0, 0.0};  ///< the point seen at the image centre
  Eigen::Vector3d up{0.0, 1.0, 0.0};      ///< approximate up; made orthogonal to the view axis
  double fov_deg = 40.0;                  ///< vertical field of view in degrees, in (0, 180)
  int width = 512;                        ///< image width in pixels, > 0
  int height = 512;                       ///< image height in pixels, > 0
};

/// The camera's orthonormal frame: `right` (image +x), `up` (image -y), `forward` (into the scene).
struct CameraFrame {
  Eigen::Vector3d right;
  Eigen::Vector3d up;
  Eigen::Vector3d forward;
  /// tan(fov/2) vertically and horizontally: a point at depth z along `forward` is at the image's
  /// top edge when its `up` coordinate is z * tan_half_height.
  double tan_half_height = 0.0;
  double tan_half_width = 0.0;
};

/// The frame of a camera.
/// \throws InvalidInputError ("camera") when the eye equals the target, `up` is parallel to the
///         view axis, the field of view is outside (0, 180) degrees or the size is not positive.
CameraFrame camera_frame(const Camera& camera);

/// The unit direction of the ray through continuous pixel coordinates (px, py) (see the file
/// comment); the ray starts at `camera.eye`.
Eigen::Vector3d camera_ray_direction(const Camera& camera, const CameraFrame& frame, double px,
                                     double py);

/// Where a world point lands: continuous pixel coordinates (x right, y down) and the depth along
/// the view axis (positive in front of the eye). A point with depth <= 0 has no meaningful pixel.
struct Projection {
  Eigen::Vector2d pixel;
  double depth = 0.0;
};
Projection project(const Camera& camera, const Eigen::Vector3d& point);

/// The unit direction from the scene towards the eye for an azimuth and an elevation in degrees,
/// measured about the axis `up`: elevation 0 looks horizontally, +90 looks straight down from
/// above; azimuth turns the eye counter-clockwise about `up` (right-handed). With up = +z,
/// azimuth 0 puts the eye on +x; with up = +y, azimuth 0 puts the eye on +z.
Eigen::Vector3d view_from_angles(double azimuth_deg, double elevation_deg,
                                 const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

/// `view` turned by `azimuth_deg` about `up` and then raised by `elevation_deg` towards `up` (an
/// orbit around the target: e.g. to look at a region a little from the side of its normal).
Eigen::Vector3d orbit_view(const Eigen::Vector3d& view, double azimuth_deg, double elevation_deg,
                           const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

/// A camera that looks at `box` along `view_direction` (from the scene towards the eye; need not
/// be unit) with the given vertical field of view and image size, placed at the smallest distance
/// at which all eight corners of the box project inside the central `fill` fraction of the image
/// in both directions (so a margin of (1 - fill) / 2 of the image is left on each side where the
/// box is widest). The target is the box centre moved sideways (across the view) so that the
/// picture is centred: along the image axis that limits the distance, the outermost corners touch
/// both margins (along the other axis the slack is shared between the sides, so that picture is
/// nearly centred). Exact (a closed-form minimum; see the .cpp). The camera's up is `up` made
/// orthogonal to the view, unless the view is within ~8 degrees of `up`; then the coordinate axis
/// most orthogonal to the view (ties: y, z, x) is used instead. A box that is a single point gets
/// the eye at distance 1.
/// \throws InvalidInputError ("camera") for an empty or non-finite box, a zero or non-finite view
///         direction, a field of view outside (0, 180), a non-positive size or fill outside (0, 1].
Camera frame_box(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& view_direction,
                 double fov_deg, int width, int height, double fill = 0.9,
                 const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

/// The same framing for a set of points (e.g. the vertices of a region) instead of a box's
/// corners: the eye is at the smallest distance at which every point projects inside the central
/// `fill` fraction, and the points' projection is centred as in frame_box. Tighter than frame_box
/// for rounded shapes seen obliquely, whose bounding-box corners stick out far beyond the shape.
/// \throws InvalidInputError ("camera") as frame_box, and for no points or a non-finite point.
Camera frame_points(const std::vector<Eigen::Vector3d>& points,
                    const Eigen::Vector3d& view_direction, double fov_deg, int width, int height,
                    double fill = 0.9, const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

}  // namespace elastic
