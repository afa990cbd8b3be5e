// guess_up_axis against shapes whose up is known by construction: a four-legged dome (its legs
// stand on the floor) along each axis, a flat square, a symmetric tube, a ball; and the shared
// meshes whose convention is documented (spot and the bunny are y-up).
#include "elastic/render/up_axis.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"
#include "support.h"

namespace elastic {
namespace {

/// Points of a "cow" in z-up coordinates: a dome (the back, a half sphere of radius 1 over z = 1)
/// on four thin legs standing on z = 0. Upside down it would rest on the dome's top, a small patch.
std::vector<Eigen::Vector3d> four_legs() {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 48; ++i) {
    const double a = 2.0 * std::numbers::pi * i / 48.0;
    for (int j = 0; j <= 24; ++j) {
      const double b = 0.5 * std::numbers::pi * j / 24.0;  // 0 at the rim, pi/2 at the top
      p.emplace_back(std::cos(b) * std::cos(a), std::cos(b) * std::sin(a), 1.0 + std::sin(b));
    }
  }
  for (const double x : {-0.7, 0.7}) {
    for (const double y : {-0.7, 0.7}) {
      for (int k = 0; k <= 20; ++k) p.emplace_back(x, y, 1.0 * k / 20.0);  // a leg
    }
  }
  return p;
}

/// The shape turned so that its up (z) becomes `up` (a signed axis).
std::vector<Eigen::Vector3d> turned(const std::vector<Eigen::Vector3d>& points,
                                    const Eigen::Vector3d& up) {
  const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), up);
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& p : points) out.push_back(q * p);
  return out;
}

TEST(UpAxis, FourLeggedShapeStandsOnItsLegsWhicheverAxisIsUp) {
  for (int axis = 0; axis < 3; ++axis) {
    for (const int sign : {1, -1}) {
      const Eigen::Vector3d up = sign * Eigen::Vector3d::Unit(axis);
      SCOPED_TRACE(up.transpose());
      const UpAxisGuess guess = guess_up_axis(turned(four_legs(), up));
      EXPECT_EQ(guess.axis, axis) << guess.reason;
      EXPECT_EQ(guess.sign, sign) << guess.reason;
      EXPECT_NEAR((guess.direction - up).norm(), 0.0, 1e-12);
      // The legs' square, 1.4 x 1.4 of the 2 x 2 cross-section.
      EXPECT_NEAR(guess.footprints[static_cast<size_t>(2 * axis + (sign > 0 ? 0 : 1))], 0.49, 1e-9);
    }
  }
}

TEST(UpAxis, FlatSymmetricAndRoundShapesFollowTheDocumentedRules) {
  std::vector<Eigen::Vector3d> square, tube, ball;
  for (int i = 0; i <= 10; ++i) {
    for (int j = 0; j <= 10; ++j) square.emplace_back(0.1 * i, 0.0, 0.1 * j);  // flat along y
  }
  for (int k = 0; k < 64; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 64.0;
    for (int h = 0; h <= 10; ++h) tube.emplace_back(std::cos(a), 0.3 * h, std::sin(a));
    for (int h = 1; h < 32; ++h) {
      const double b = std::numbers::pi * h / 32.0;
      ball.emplace_back(std::sin(b) * std::cos(a), std::sin(b) * std::sin(a), std::cos(b));
    }
  }
  EXPECT_EQ(guess_up_axis(square).name(), "+y");
  EXPECT_EQ(guess_up_axis(tube).name(), "+y");  // both ends are bases: + taken
  const UpAxisGuess round = guess_up_axis(ball);
  EXPECT_EQ(round.name(), "+z") << round.reason;
  EXPECT_NE(round.reason.find("default"), std::string::npos) << round.reason;
  EXPECT_THROW(guess_up_axis({}), InvalidInputError);
}

TEST(UpAxis, SharedMeshesWithAKnownConvention) {
  ELASTIC_REQUIRE_SHARED_MESH(spot, "spot.obj");
  ELASTIC_REQUIRE_SHARED_MESH(bunny, "bunny.obj");
  EXPECT_EQ(guess_up_axis(read_mesh(spot).mesh.positions).name(), "+y");
  EXPECT_EQ(guess_up_axis(read_mesh(bunny).mesh.positions).name(), "+y");
  EXPECT_EQ(guess_up_axis(read_mesh(test::project_mesh("cap_quads.obj")).mesh.positions).name(),
            "+z");
}

TEST(UpAxis, DirectionsParse) {
  EXPECT_EQ(parse_up_direction("y", "--up"), Eigen::Vector3d::UnitY());
  EXPECT_EQ(parse_up_direction("-z", "--up"), -Eigen::Vector3d::UnitZ());
  EXPECT_EQ(parse_up_direction("+x", "--up"), Eigen::Vector3d::UnitX());
  EXPECT_NEAR((parse_up_direction("0,0,2", "--up") - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-15);
  for (const char* bad : {"", "w", "0,0,0", "1,2", "nan,0,1", "1,0,0,", "--y"}) {
    SCOPED_TRACE(bad);
    EXPECT_THROW(parse_up_direction(bad, "--up"), InvalidInputError);
  }
}

}  // namespace
}  // namespace elastic
