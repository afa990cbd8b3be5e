// Pinhole camera, angles and automatic framing; see camera.h for the conventions.
#include "elastic/render/camera.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "elastic/core/error.h"

namespace elastic {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kInf = std::numeric_limits<double>::infinity();

void check_fov_and_size(double fov_deg, int width, int height) {
  if (!(fov_deg > 0.0 && fov_deg < 180.0)) {
    throw InvalidInputError(
        "camera", "field of view " + std::to_string(fov_deg) + " degrees is outside (0, 180)");
  }
  if (width <= 0 || height <= 0) {
    throw InvalidInputError("camera", "image size " + std::to_string(width) + " x " +
                                          std::to_string(height) + " is not positive");
  }
}

/// The coordinate axis least aligned with `v` (a safe fallback for an up vector parallel to v).
/// Ties go to y, then z, then x, so a view straight along z gets the usual y-up picture.
Eigen::Vector3d most_orthogonal_axis(const Eigen::Vector3d& v) {
  int best = 1;
  for (int axis : {2, 0}) {
    if (std::abs(v[axis]) < std::abs(v[best])) {
      best = axis;
    }
  }
  return Eigen::Vector3d::Unit(best);
}

}  // namespace

CameraFrame camera_frame(const Camera& camera) {
  check_fov_and_size(camera.fov_deg, camera.width, camera.height);
  const Eigen::Vector3d axis = camera.target - camera.eye;
  if (!axis.allFinite() || !(axis.norm() > 0.0)) {
    throw InvalidInputError("camera", "the eye and the target are the same point");
  }
  CameraFrame frame;
  frame.forward = axis.normalized();
  const Eigen::Vector3d right = frame.forward.cross(camera.up);
  // sin of the angle between up and the view axis; below ~1e-9 the frame is undefined.
  if (!right.allFinite() || !(right.norm() > 1e-9 * camera.up.norm())) {
    throw InvalidInputError("camera", "the up vector is parallel to the view direction");
  }
  frame.right = right.normalized();
  frame.up = frame.right.cross(frame.forward);
  frame.tan_half_height = std::tan(0.5 * camera.fov_deg * kDegree);
  frame.tan_half_width = frame.tan_half_height * camera.width / camera.height;
  return frame;
}

Eigen::Vector3d camera_ray_direction(const Camera& camera, const CameraFrame& frame, double px,
                                     double py) {
  // Normalised device coordinates in [-1, 1], y flipped (image rows go down, `up` goes up).
  const double ndc_x = 2.0 * px / camera.width - 1.0;
  const double ndc_y = 1.0 - 2.0 * py / camera.height;
  return (frame.forward + ndc_x * frame.tan_half_width * frame.right +
          ndc_y * frame.tan_half_height * frame.up)
      .normalized();
}

Projection project(const Camera& camera, const Eigen::Vector3d& point) {
  const CameraFrame frame = camera_frame(camera);
  const Eigen::Vector3d q = point - camera.eye;
  Projection result;
  result.depth = q.dot(frame.forward);
  // Inverse of camera_ray_direction: divide by depth, then undo the NDC scaling.
  const double ndc_x = q.dot(frame.right) / (result.depth * frame.tan_half_width);
  const double ndc_y = q.dot(frame.up) / (result.depth * frame.tan_half_height);
  result.pixel = {0.5 * (ndc_x + 1.0) * camera.width, 0.5 * (1.0 - ndc_y) * camera.height};
  return result;
}

Eigen::Vector3d view_from_angles(double azimuth_deg, double elevation_deg,
                                 const Eigen::Vector3d& up) {
  if (!up.allFinite() || !(up.norm() > 0.0)) {
    throw InvalidInputError("camera", "the up vector is zero or not finite");
  }
  const Eigen::Vector3d n = up.normalized();
  // Azimuth 0 is the cyclic successor of up's dominant axis (z -> x, y -> z, x -> y), projected
  // onto the plane orthogonal to up; azimuth 90 is up x e0 (counter-clockwise about up).
  int dominant = 0;
  n.cwiseAbs().maxCoeff(&dominant);
  const Eigen::Vector3d reference = Eigen::Vector3d::Unit((dominant + 1) % 3);
  const Eigen::Vector3d e0 = (reference - reference.dot(n) * n).normalized();
  const Eigen::Vector3d e1 = n.cross(e0);
  const double az = azimuth_deg * kDegree, el = elevation_deg * kDegree;
  return std::cos(el) * (std::cos(az) * e0 + std::sin(az) * e1) + std::sin(el) * n;
}

Eigen::Vector3d orbit_view(const Eigen::Vector3d& view, double azimuth_deg, double elevation_deg,
                           const Eigen::Vector3d& up) {
  if (!up.allFinite() || !(up.norm() > 0.0) || !view.allFinite() || !(view.norm() > 0.0)) {
    throw InvalidInputError("camera", "the view or up vector is zero or not finite");
  }
  const Eigen::Vector3d n = up.normalized();
  const Eigen::Vector3d turned = Eigen::AngleAxisd(azimuth_deg * kDegree, n) * view.normalized();
  // Raise towards up: rotate about turned x up (positive angles move the view towards up). A view
  // along up has no such axis; it is returned turned only.
  const Eigen::Vector3d axis = turned.cross(n);
  if (!(axis.norm() > 1e-12)) {
    return turned;
  }
  return Eigen::AngleAxisd(elevation_deg * kDegree, axis.normalized()) * turned;
}

namespace {

/// frame_box / frame_points: `points` are what must fit, `box` their bounding box.
Camera frame(const Eigen::AlignedBox3d& box, const std::vector<Eigen::Vector3d>& points,
             const Eigen::Vector3d& view_direction, double fov_deg, int width, int height,
             double fill, const Eigen::Vector3d& up) {
  check_fov_and_size(fov_deg, width, height);
  if (box.isEmpty() || !box.min().allFinite() || !box.max().allFinite()) {
    throw InvalidInputError("camera", "cannot frame an empty or non-finite bounding box");
  }
  if (!view_direction.allFinite() || !(view_direction.norm() > 0.0)) {
    throw InvalidInputError("camera", "the view direction is zero or not finite");
  }
  if (!(fill > 0.0 && fill <= 1.0)) {
    throw InvalidInputError("camera", "fill " + std::to_string(fill) + " is outside (0, 1]");
  }
  const Eigen::Vector3d w = view_direction.normalized();  // towards the eye
  Eigen::Vector3d up_hint =
      up.allFinite() && up.norm() > 0.0 ? up.normalized() : most_orthogonal_axis(w);
  if (std::abs(up_hint.dot(w)) > std::cos(8.0 * kDegree)) {
    up_hint = most_orthogonal_axis(w);
  }

  Camera camera;
  camera.target = box.center();
  camera.up = up_hint;
  camera.fov_deg = fov_deg;
  camera.width = width;
  camera.height = height;
  const Eigen::Vector3d forward = -w;
  const Eigen::Vector3d right = forward.cross(up_hint).normalized();
  const Eigen::Vector3d image_up = right.cross(forward);
  const double tan_h = std::tan(0.5 * fov_deg * kDegree) * fill;
  const double tan_w = tan_h * width / height;

  // Put the eye at e = c + a right + b up + d w (c the box centre) looking along -w. A point q
  // (relative to c) is at depth d - q.w, and inside the shrunk frustum iff
  //   |q.right - a| <= (d - q.w) tan_w   and   |q.up - b| <= (d - q.w) tan_h.
  // For the x part, d >= max_i (s_i + |x_i - a| / t) = max(A - a/t, B + a/t) with s_i = q_i.w,
  // x_i = q_i.right, t = tan_w, A = max_i (x_i/t + s_i), B = max_i (s_i - x_i/t): a convex
  // function of a, smallest at a = t (A - B) / 2 with value (A + B) / 2. Likewise for y and b.
  // The smallest distance is the larger of the two minima, and the sideways offsets (a, b) centre
  // the picture: on the binding axis the extreme points touch both margins.
  const double diagonal = box.diagonal().norm();
  const Eigen::Vector3d centre = box.center();
  const auto fit_axis = [&](const Eigen::Vector3d& axis, double t, double& offset) {
    double a_max = -kInf, b_max = -kInf;
    for (const Eigen::Vector3d& point : points) {
      const Eigen::Vector3d q = point - centre;
      const double s = q.dot(w), x = q.dot(axis);
      a_max = std::max(a_max, x / t + s);
      b_max = std::max(b_max, s - x / t);
    }
    offset = 0.5 * t * (a_max - b_max);
    return 0.5 * (a_max + b_max);
  };
  double offset_x = 0.0, offset_y = 0.0;
  double distance = std::max(fit_axis(right, tan_w, offset_x), fit_axis(image_up, tan_h, offset_y));
  for (const Eigen::Vector3d& point : points) {
    // keep every point at least 1% of the diagonal in front of the eye
    distance = std::max(distance, (point - centre).dot(w) + 0.01 * diagonal);
  }
  camera.target = centre + offset_x * right + offset_y * image_up;
  if (!(diagonal > 0.0)) {
    distance = 1.0;
  }
  camera.eye = camera.target + distance * w;
  return camera;
}

}  // namespace

Camera frame_box(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& view_direction,
                 double fov_deg, int width, int height, double fill, const Eigen::Vector3d& up) {
  std::vector<Eigen::Vector3d> corners;
  if (!box.isEmpty()) {
    for (int k = 0; k < 8; ++k) {
      corners.push_back(box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k)));
    }
  }
  return frame(box, corners, view_direction, fov_deg, width, height, fill, up);
}

Camera frame_points(const std::vector<Eigen::Vector3d>& points,
                    const Eigen::Vector3d& view_direction, double fov_deg, int width, int height,
                    double fill, const Eigen::Vector3d& up) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) {
      throw InvalidInputError("camera", "a point to frame is not finite");
    }
    box.extend(p);
  }
  if (points.empty()) {
    throw InvalidInputError("camera", "no points to frame");
  }
  return frame(box, points, view_direction, fov_deg, width, height, fill, up);
}

}  // namespace elastic
