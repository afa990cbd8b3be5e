#include "elastic/shapes/procedural_shapes.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <unordered_map>
#include <utility>

#include "elastic/core/error.h"
#include "elastic/shapes/detail/shape_building.h"

namespace elastic {

namespace shapes_detail {

void apply_scale(PolygonMesh& mesh, double scale) {
  if (scale == 1.0) {
    return;
  }
  for (Eigen::Vector3d& p : mesh.positions) {
    p *= scale;
  }
}

void reverse_faces(PolygonMesh& mesh) {
  for (int f = 0; f < mesh.num_faces(); ++f) {
    std::reverse(mesh.face_vertices.begin() + mesh.face_offsets[f],
                 mesh.face_vertices.begin() + mesh.face_offsets[f + 1]);
  }
}

}  // namespace shapes_detail

namespace {

using shapes_detail::apply_scale;
using shapes_detail::cube_sphere;
using shapes_detail::HermiteProfile;
using shapes_detail::icosphere;
using shapes_detail::kPi;
using shapes_detail::kTwoPi;
using shapes_detail::Profile;
using shapes_detail::sweep;

constexpr int kMinResolution = 3;
constexpr int kMaxResolution = 4096;

// ---------------------------------------------------------------------------------------------------
// Options

void check_options(const ShapeOptions& options) {
  if (options.resolution < kMinResolution || options.resolution > kMaxResolution) {
    throw InvalidInputError("resolution", "must be in " + std::to_string(kMinResolution) + ".." +
                                              std::to_string(kMaxResolution) + ", got " +
                                              std::to_string(options.resolution));
  }
  if (!std::isfinite(options.scale) || !(options.scale > 0.0)) {
    throw InvalidInputError("scale",
                            "must be a finite number > 0, got " + std::to_string(options.scale));
  }
  if (options.faces != ShapeFaces::Triangles && options.faces != ShapeFaces::Quads) {
    throw InvalidInputError("faces", "must be Triangles or Quads, got value " +
                                         std::to_string(static_cast<int>(options.faces)));
  }
}

}  // namespace

// -----------------------------------------------------------------------------------------------------

const std::vector<std::string>& shape_names() {
  static const std::vector<std::string> names{"plane",  "cylinder", "torus", "vase",
                                              "goblet", "cap",      "sphere"};
  return names;
}

PolygonMesh make_shape(std::string_view name, const ShapeOptions& options) {
  if (name == "plane") {
    return make_plane(options);
  }
  if (name == "cylinder") {
    return make_cylinder(options);
  }
  if (name == "torus") {
    return make_torus(options);
  }
  if (name == "vase") {
    return make_vase(options);
  }
  if (name == "goblet") {
    return make_goblet(options);
  }
  if (name == "cap") {
    return make_cap(options);
  }
  if (name == "sphere") {
    return make_sphere(options);
  }
  std::string known;
  for (const std::string& n : shape_names()) {
    known += (known.empty() ? "" : ", ") + n;
  }
  throw InvalidInputError(std::string(name), "unknown shape (known: " + known + ")");
}

PolygonMesh make_plane(const ShapeOptions& options) {
  check_options(options);
  const int N = options.resolution;
  PolygonMesh mesh;
  for (int j = 0; j <= N; ++j) {
    for (int i = 0; i <= N; ++i) {
      mesh.positions.emplace_back(2.0 * i / N - 1.0, 2.0 * j / N - 1.0, 0.0);
    }
  }
  auto id = [N](int i, int j) { return j * (N + 1) + i; };
  for (int j = 0; j < N; ++j) {
    for (int i = 0; i < N; ++i) {
      // Counter-clockwise seen from +z. Triangles: every quad split along the same diagonal, which
      // makes every interior vertex valence 6 -- a regular mesh for Loop subdivision (alternating
      // diagonals would give valences 4 and 8) -- and keeps the boundary straight.
      if (options.faces == ShapeFaces::Quads) {
        mesh.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        mesh.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        mesh.add_face({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  }
  apply_scale(mesh, options.scale);
  return mesh;
}

PolygonMesh make_cylinder(const ShapeOptions& options) {
  check_options(options);
  Profile profile;
  profile.at = [](double t) { return Eigen::Vector2d(0.5, -1.0 + 2.0 * t); };
  return sweep(profile, options);
}

PolygonMesh make_torus(const ShapeOptions& options) {
  check_options(options);
  constexpr double kMajor = 1.0;
  constexpr double kMinor = 0.35;
  Profile profile;
  profile.closed = true;
  // Tube circle traversed counter-clockwise in (r, z), starting at the outer equator: the solid is
  // on the left, so the default face convention points outward.
  profile.at = [](double t) {
    const double psi = kTwoPi * t;
    return Eigen::Vector2d(kMajor + kMinor * std::cos(psi), kMinor * std::sin(psi));
  };
  return sweep(profile, options);
}

// Vase profile (r, z): a closed, nearly flat bottom (pole at the origin) rounding into a bulging
// body (largest radius 0.55 at z ~ 0.45), narrowing to a neck (radius 0.22 at z ~ 1.2-1.3) and
// flaring out to a lip (radius 0.34 at the rim, z = 1.52). The mouth is the only boundary.
PolygonMesh make_vase(const ShapeOptions& options) {
  check_options(options);
  Profile profile;
  profile.pole_at_start = true;
  profile.at = HermiteProfile({{0.0, 0.0},
                               {0.2, 0.0},
                               {0.33, 0.02},
                               {0.41, 0.09},
                               {0.50, 0.25},
                               {0.55, 0.45},
                               {0.52, 0.65},
                               {0.42, 0.85},
                               {0.28, 1.05},
                               {0.22, 1.20},
                               {0.22, 1.32},
                               {0.27, 1.45},
                               {0.34, 1.52}});
  return sweep(profile, options);
}

// Goblet profile (r, z), one open surface from the centre of the foot's underside to the cup's rim:
// a slightly concave underside (centre raised to z = 0.03) out to the foot's edge (radius 0.53), a
// rounded edge ~0.08 thick, the foot's top rising into a thin stem (radius 0.06 for z in
// 0.38..0.55), a knot, and a cup whose wall bulges to radius 0.49 at z ~ 1.2 and narrows slightly
// to the rim (radius 0.44 at z = 1.55). The cup is a single sheet: its inside is the back of its
// outside.
PolygonMesh make_goblet(const ShapeOptions& options) {
  check_options(options);
  Profile profile;
  profile.pole_at_start = true;
  profile.at =
      HermiteProfile({{0.0, 0.03},   {0.2, 0.022},  {0.38, 0.008}, {0.48, 0.0},   {0.53, 0.035},
                      {0.50, 0.075}, {0.40, 0.095}, {0.25, 0.125}, {0.13, 0.175}, {0.075, 0.26},
                      {0.06, 0.38},  {0.06, 0.55},  {0.075, 0.65}, {0.11, 0.72},  {0.22, 0.78},
                      {0.36, 0.88},  {0.45, 1.02},  {0.49, 1.20},  {0.48, 1.38},  {0.44, 1.55}});
  return sweep(profile, options);
}

PolygonMesh make_cap(const ShapeOptions& options) {
  check_options(options);
  constexpr double kMaxPolar = 75.0 * kPi / 180.0;
  Profile profile;
  profile.pole_at_start = true;
  // From the pole down to the rim the solid (the ball) is on the right: flip to point outward.
  profile.flip = true;
  profile.at = [](double t) {
    const double polar = kMaxPolar * t;
    return Eigen::Vector2d(std::sin(polar), std::cos(polar));
  };
  return sweep(profile, options);
}

PolygonMesh make_sphere(const ShapeOptions& options) {
  check_options(options);
  // `resolution` counts segments around the equator, as for the surfaces of revolution: the cube's
  // equator has 4N edges; a great circle crosses about 2 pi / atan(2) ~ 5.67 icosahedron edges
  // (central angle atan(2)), each split k times.
  PolygonMesh mesh;
  if (options.faces == ShapeFaces::Quads) {
    mesh = cube_sphere(std::max(1, static_cast<int>(std::lround(options.resolution / 4.0))));
  } else {
    mesh = icosphere(
        std::max(1, static_cast<int>(std::lround(options.resolution * std::atan(2.0) / kTwoPi))));
  }
  apply_scale(mesh, options.scale);
  return mesh;
}

}  // namespace elastic
