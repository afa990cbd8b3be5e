// Camera: projection against hand-computed pinhole answers, ray/projection round trips, angles,
// and automatic framing (corners inside, and tight).
#include "elastic/render/camera.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "elastic/core/error.h"

namespace elastic {
namespace {

Camera head_on(int width, int height, double fov_deg) {
  Camera camera;
  camera.eye = {0.0, 0.0, 5.0};
  camera.target = {0.0, 0.0, 0.0};
  camera.up = {0.0, 1.0, 0.0};
  camera.fov_deg = fov_deg;
  camera.width = width;
  camera.height = height;
  return camera;
}

TEST(Camera, ProjectsKnownPointsOfAPinhole) {
  // fov 90: tan(45) = 1, so at depth 5 the image spans y in [-5, 5] and (aspect 2) x in [-10, 10].
  const Camera camera = head_on(200, 100, 90.0);
  const auto centre = project(camera, {0.0, 0.0, 0.0});
  EXPECT_NEAR(centre.depth, 5.0, 1e-12);
  EXPECT_NEAR(centre.pixel.x(), 100.0, 1e-9);
  EXPECT_NEAR(centre.pixel.y(), 50.0, 1e-9);
  const auto top = project(camera, {0.0, 5.0, 0.0});  // top edge, y down in the image
  EXPECT_NEAR(top.pixel.y(), 0.0, 1e-9);
  const auto right = project(camera, {10.0, 0.0, 0.0});
  EXPECT_NEAR(right.pixel.x(), 200.0, 1e-9);
  // Half the depth, half the offset: same pixel (perspective division).
  const auto near = project(camera, {2.5, -1.25, 2.5});
  const auto far = project(camera, {5.0, -2.5, 0.0});
  EXPECT_NEAR(near.pixel.x(), far.pixel.x(), 1e-9);
  EXPECT_NEAR(near.pixel.y(), far.pixel.y(), 1e-9);
  EXPECT_NEAR(far.pixel.x(), 150.0, 1e-9);  // x = 5 of 10 at depth 5 -> 3/4 of the width
  EXPECT_NEAR(far.pixel.y(), 75.0, 1e-9);
}

TEST(Camera, RayThroughAPixelProjectsBackOntoIt) {
  Camera camera;
  camera.eye = {1.0, -2.0, 3.0};
  camera.target = {0.3, 0.1, -0.2};
  camera.up = {0.0, 0.0, 1.0};
  camera.fov_deg = 35.0;
  camera.width = 90;
  camera.height = 60;
  const CameraFrame frame = camera_frame(camera);
  EXPECT_NEAR(frame.right.dot(frame.up), 0.0, 1e-14);
  EXPECT_NEAR(frame.right.cross(frame.up).dot(frame.forward), -1.0, 1e-14);  // right-handed
  for (double px : {0.0, 13.25, 45.0, 90.0}) {
    for (double py : {0.0, 7.5, 30.0, 60.0}) {
      const Eigen::Vector3d d = camera_ray_direction(camera, frame, px, py);
      EXPECT_NEAR(d.norm(), 1.0, 1e-14);
      const auto p = project(camera, camera.eye + 4.0 * d);
      // Round trip through a normalisation and a division: a few ulps of the pixel size.
      EXPECT_NEAR(p.pixel.x(), px, 1e-9);
      EXPECT_NEAR(p.pixel.y(), py, 1e-9);
      EXPECT_GT(p.depth, 0.0);
    }
  }
}

TEST(Camera, AnglesFollowTheDocumentedAxes) {
  const auto expect_vec = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    EXPECT_NEAR((a - b).norm(), 0.0, 1e-12) << a.transpose() << " vs " << b.transpose();
  };
  expect_vec(view_from_angles(0, 0), Eigen::Vector3d::UnitX());
  expect_vec(view_from_angles(90, 0), Eigen::Vector3d::UnitY());
  expect_vec(view_from_angles(0, 90), Eigen::Vector3d::UnitZ());
  expect_vec(view_from_angles(0, 0, Eigen::Vector3d::UnitY()), Eigen::Vector3d::UnitZ());
  expect_vec(view_from_angles(90, 0, Eigen::Vector3d::UnitY()), Eigen::Vector3d::UnitX());
  const double s = std::sqrt(0.5);
  expect_vec(view_from_angles(180, 45), Eigen::Vector3d(-s, 0.0, s));
  expect_vec(orbit_view(Eigen::Vector3d(2, 0, 0), 90, 0), Eigen::Vector3d::UnitY());
  expect_vec(orbit_view(Eigen::Vector3d(1, 0, 0), 0, 45), Eigen::Vector3d(s, 0.0, s));
  expect_vec(orbit_view(Eigen::Vector3d(1, 0, 0), 90, -45), Eigen::Vector3d(0.0, s, -s));
}

TEST(Camera, FrameBoxPutsEveryCornerInsideTheImageAndIsTight) {
  const Eigen::AlignedBox3d boxes[] = {
      {Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)},
      {Eigen::Vector3d(10, 20, 30), Eigen::Vector3d(14, 21, 30.5)},
      {Eigen::Vector3d(-2, -0.1, 0), Eigen::Vector3d(2, 0.1, 0)},  // flat
  };
  const Eigen::Vector3d views[] = {{0, 0, 1}, {1, 2, 3}, {-1, 0.2, -0.3}, {0, 0, -1}};
  const int sizes[][2] = {{64, 64}, {120, 40}, {30, 90}};
  for (const auto& box : boxes) {
    for (const auto& view : views) {
      for (const auto& size : sizes) {
        const double fill = 0.8;
        const Camera camera = frame_box(box, view, 40.0, size[0], size[1], fill);
        EXPECT_GT((camera.eye - camera.target).dot(view), 0.0);  // the eye is on the view side
        double widest = 0.0;  // largest |NDC| coordinate over the corners
        Eigen::AlignedBox2d extent;
        for (int k = 0; k < 8; ++k) {
          const auto p =
              project(camera, box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k)));
          EXPECT_GT(p.depth, 0.0);
          const double nx = 2.0 * p.pixel.x() / size[0] - 1.0,
                       ny = 2.0 * p.pixel.y() / size[1] - 1.0;
          // Inside the central `fill` part; 1e-9 absorbs round-off of the division by depth.
          EXPECT_LE(std::abs(nx), fill + 1e-9);
          EXPECT_LE(std::abs(ny), fill + 1e-9);
          widest = std::max({widest, std::abs(nx), std::abs(ny)});
          extent.extend(Eigen::Vector2d(nx, ny));
        }
        // Tight: the eye is as close as it can be, so some corner touches the fill boundary.
        EXPECT_NEAR(widest, fill, 1e-9);
        // Centred: along the axis that limits the distance, both margins are touched.
        const int axis = extent.max().x() > fill - 1e-9 ? 0 : 1;
        EXPECT_NEAR(extent.max()[axis], fill, 1e-9);
        EXPECT_NEAR(extent.min()[axis], -fill, 1e-9);
      }
    }
  }
}

TEST(Camera, FramePointsFitsThePointsTightly) {
  // Points on a unit circle in the plane z = 1 plus the origin, seen obliquely.
  std::vector<Eigen::Vector3d> points{Eigen::Vector3d::Zero()};
  for (int i = 0; i < 36; ++i) {
    const double a = 2.0 * std::numbers::pi * i / 36;
    points.emplace_back(std::cos(a), std::sin(a), 1.0);
  }
  const Eigen::Vector3d view(0.5, -1.0, 1.0);
  const double fill = 0.9;
  const Camera camera = frame_points(points, view, 30.0, 80, 60, fill);
  double widest = 0.0;
  Eigen::AlignedBox2d extent;
  for (const Eigen::Vector3d& p : points) {
    const auto q = project(camera, p);
    const double nx = 2.0 * q.pixel.x() / 80 - 1.0, ny = 2.0 * q.pixel.y() / 60 - 1.0;
    EXPECT_LE(std::abs(nx), fill + 1e-9);
    EXPECT_LE(std::abs(ny), fill + 1e-9);
    widest = std::max({widest, std::abs(nx), std::abs(ny)});
    extent.extend(Eigen::Vector2d(nx, ny));
  }
  EXPECT_NEAR(widest, fill, 1e-9);
  // Centred: along the axis that limits the distance, both margins are touched.
  const int axis = extent.max().x() > fill - 1e-9 ? 0 : 1;
  EXPECT_NEAR(extent.max()[axis], fill, 1e-9);
  EXPECT_NEAR(extent.min()[axis], -fill, 1e-9);
  // Nearer than the box framing, whose corners reach beyond the circle.
  Eigen::AlignedBox3d box;
  for (const auto& p : points) box.extend(p);
  const Camera boxed = frame_box(box, view, 30.0, 80, 60, fill);
  EXPECT_LT((camera.eye - camera.target).norm(), (boxed.eye - boxed.target).norm());
  EXPECT_THROW(frame_points({}, view, 30.0, 8, 8), InvalidInputError);
}

TEST(Camera, FrameBoxAvoidsAnUpVectorAlongTheView) {
  const Eigen::AlignedBox3d box(Eigen::Vector3d(-1, -1, 0), Eigen::Vector3d(1, 1, 0));
  const Camera camera = frame_box(box, Eigen::Vector3d::UnitZ(), 30.0, 32, 32);  // up hint is +z
  EXPECT_NO_THROW(camera_frame(camera));
  EXPECT_LT(std::abs(camera.up.dot(Eigen::Vector3d::UnitZ())), 0.5);
  EXPECT_NEAR(camera_frame(camera).up.y(), 1.0, 1e-12);  // looking down z: y up, as documented
}

TEST(Camera, RejectsBadInput) {
  Camera camera = head_on(10, 10, 40.0);
  camera.target = camera.eye;
  EXPECT_THROW(camera_frame(camera), InvalidInputError);
  camera = head_on(10, 10, 180.0);
  EXPECT_THROW(camera_frame(camera), InvalidInputError);
  camera = head_on(0, 10, 40.0);
  EXPECT_THROW(camera_frame(camera), InvalidInputError);
  camera = head_on(10, 10, 40.0);
  camera.up = {0.0, 0.0, 1.0};  // along the view axis
  EXPECT_THROW(camera_frame(camera), InvalidInputError);
  EXPECT_THROW(frame_box(Eigen::AlignedBox3d(), Eigen::Vector3d::UnitZ(), 40, 8, 8),
               InvalidInputError);
  const Eigen::AlignedBox3d box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  EXPECT_THROW(frame_box(box, Eigen::Vector3d::Zero(), 40, 8, 8), InvalidInputError);
  EXPECT_THROW(frame_box(box, Eigen::Vector3d::UnitX(), 40, 8, 8, 0.0), InvalidInputError);
}

}  // namespace
}  // namespace elastic
