// guess_up_axis against shapes whose up is known by construction: a four-legged dome (its legs
// stand on the floor) along each axis, a flat square, a symmetric tube, a ball; and every mesh
// whose up was established by looking at it (renders along the six axes), with its turned copies.
#include "elastic/render/up_axis.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <utility>
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
  EXPECT_EQ(guess_up_axis(tube).confidence, UpAxisConfidence::Medium);
  // No side to stand on: the convention decides, and says so.
  const UpAxisGuess round = guess_up_axis(ball);
  EXPECT_EQ(round.name(), "+y") << round.reason;
  EXPECT_EQ(round.confidence, UpAxisConfidence::Low);
  EXPECT_NE(round.reason.find("convention"), std::string::npos) << round.reason;
  EXPECT_EQ(guess_up_axis(ball, {.convention = Eigen::Vector3d::UnitZ()}).name(), "+z");
  EXPECT_THROW(guess_up_axis(std::vector<Eigen::Vector3d>{}), InvalidInputError);
  EXPECT_THROW(guess_up_axis(PolygonMesh{}), InvalidInputError);
}

/// The mesh turned by a rotation.
PolygonMesh rotated(PolygonMesh mesh, const Eigen::Matrix3d& rotation) {
  for (Eigen::Vector3d& p : mesh.positions) p = rotation * p;
  return mesh;
}

/// Quarter turns about x, y and z, and a half turn about x (entries exactly 0 and +-1): each axis
/// goes to each other one, and a sign flips.
std::vector<Eigen::Matrix3d> quarter_turns() {
  std::vector<Eigen::Matrix3d> turns;
  for (const auto& [axis, quarters] : {std::pair{0, 1}, {1, 1}, {2, 1}, {0, 2}}) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(quarters * std::numbers::pi / 2.0, Eigen::Vector3d::Unit(axis))
            .toRotationMatrix();
    turns.push_back(r.array().round().matrix());
  }
  return turns;
}

/// Meshes whose up was established by looking at them (renders of the six axis views): the
/// animals, figures and busts stand on their feet or cut, the terrain's peak is up, the vases,
/// pawn, dome and goblet stand on their foot, the tubes and tori lie along their axis (either
/// sign: + is the documented choice).
struct KnownUp {
  const char* file;
  bool shared;  ///< ../shared/meshes (else the project's meshes/)
  const char* up;
  UpAxisConfidence confidence;
};
const KnownUp kKnownUps[] = {
    {"armadillo.obj", true, "+y", UpAxisConfidence::High},
    {"beetle.obj", true, "+y", UpAxisConfidence::High},
    {"bob_tri.obj", true, "+y", UpAxisConfidence::High},
    {"bunny.obj", true, "+y", UpAxisConfidence::High},
    {"camelhead.off", true, "+y", UpAxisConfidence::Medium},  // its crown is flat too
    {"cylinder.obj", true, "+z", UpAxisConfidence::Medium},
    {"decimated-max.obj", true, "+y", UpAxisConfidence::Low},  // the convention decides
    {"grid.off", true, "+z", UpAxisConfidence::High},
    {"hand_lowres.obj", true, "+y", UpAxisConfidence::High},
    {"hemisphere.off", true, "+z", UpAxisConfidence::High},
    {"mountain.obj", true, "+y", UpAxisConfidence::High},
    {"nefertiti-lowres.obj", true, "+y", UpAxisConfidence::High},
    {"osd_catmark_pawn.obj", true, "+z", UpAxisConfidence::High},
    {"osd_catmark_torus.obj", true, "+y", UpAxisConfidence::Medium},
    {"spot.obj", true, "+y", UpAxisConfidence::High},
    {"spot_control_mesh.obj", true, "+y", UpAxisConfidence::High},
    {"torus.obj", true, "+y", UpAxisConfidence::Medium},
    {"wavy_vase_open_low_res.obj", true, "+z", UpAxisConfidence::High},
    {"cap_quads.obj", false, "+z", UpAxisConfidence::High},
    {"cylinder_quads.obj", false, "+z", UpAxisConfidence::Medium},
    {"goblet_quads.obj", false, "+z", UpAxisConfidence::Medium},
    {"plane_quads.obj", false, "+z", UpAxisConfidence::High},
    {"torus_quads.obj", false, "+z", UpAxisConfidence::Medium},
    {"vase_quads.obj", false, "+z", UpAxisConfidence::Medium},
};

TEST(UpAxis, EveryMeshWhoseUpIsKnownAndItsTurnedCopies) {
  int checked = 0;
  for (const KnownUp& known : kKnownUps) {
    SCOPED_TRACE(known.file);
    const std::filesystem::path path =
        known.shared ? test::shared_mesh(known.file) : test::project_mesh(known.file);
    if (path.empty()) continue;  // ../shared is optional for a clone
    ++checked;
    const PolygonMesh mesh = read_mesh(path).mesh;
    const UpAxisGuess guess = guess_up_axis(mesh);
    EXPECT_EQ(guess.name(), known.up) << guess.reason;
    EXPECT_EQ(guess.confidence, known.confidence) << guess.reason;
    // A turned copy turns the guess: exactly where the shape decides (high), up to the sign where
    // the + of an axis is taken (medium, and a flat model). A low guess rests on the convention,
    // which does not turn with the mesh.
    if (guess.confidence == UpAxisConfidence::Low) continue;
    const bool signed_guess = guess.confidence == UpAxisConfidence::High &&
                              guess.reason.find("flat") == std::string::npos;
    for (const Eigen::Matrix3d& turn : quarter_turns()) {
      const UpAxisGuess turned_guess = guess_up_axis(rotated(mesh, turn));
      const Eigen::Vector3d expected = turn * guess.direction;
      SCOPED_TRACE(expected.transpose());
      EXPECT_EQ(turned_guess.confidence, guess.confidence) << turned_guess.reason;
      if (signed_guess) {
        EXPECT_NEAR((turned_guess.direction - expected).norm(), 0.0, 1e-12) << turned_guess.reason;
      } else {
        EXPECT_NEAR(std::abs(turned_guess.direction.dot(expected)), 1.0, 1e-12)
            << turned_guess.reason;
      }
    }
  }
  EXPECT_GE(checked, 6);  // the project's meshes at least
}

TEST(UpAxis, ThePointsAloneMissWhatTheFacesShow) {
  // The footprints alone put the wavy vase on its wide, wavy rim and the mountain on its side;
  // the open end (the vase's flat foot rim) and the height field (the terrain) set them right.
  ELASTIC_REQUIRE_SHARED_MESH(vase, "wavy_vase_open_low_res.obj");
  ELASTIC_REQUIRE_SHARED_MESH(mountain, "mountain.obj");
  EXPECT_EQ(guess_up_axis(read_mesh(vase).mesh.positions).name(), "-z");
  EXPECT_EQ(guess_up_axis(read_mesh(vase).mesh).name(), "+z");
  EXPECT_EQ(guess_up_axis(read_mesh(mountain).mesh.positions).name(), "+x");
  EXPECT_EQ(guess_up_axis(read_mesh(mountain).mesh).name(), "+y");
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
