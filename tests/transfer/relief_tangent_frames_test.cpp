// Vectors across the map: the triangle differential J, its rotation part, and the transport T
// between limit tangent planes (transfer/tangent_frames.h).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <random>

#include "elastic/core/error.h"
#include "elastic/regions/region_spec.h"
#include "elastic/shapes/procedural_shapes.h"
#include "elastic/transfer/tangent_frames.h"
#include "mapped_pair.h"
#include "rigid_motion.h"

namespace elastic {
namespace {

using test::map_pair;
using test::Mapped;

// A disk on a plane and the same disk on a rigidly moved copy: the map is the rigid motion.
std::unique_ptr<Mapped> rigid_plane_pair(const Eigen::Isometry3d& motion) {
  const PolygonMesh plane = make_plane({.faces = ShapeFaces::Quads, .resolution = 12});
  RegionSpec source_spec = parse_region_spec("disk:0.1,0.05,0,0.6");
  source_spec.anchor = Eigen::Vector3d(1, 0, 0);
  RegionSpec target_spec = source_spec;
  target_spec.center = motion * source_spec.center;
  target_spec.anchor = motion * *source_spec.anchor;
  return map_pair(plane, test::moved(plane, motion), source_spec, target_spec);
}

// Random source points inside a disk of the xy plane (projected onto the source surface).
std::vector<ClosestPoint> points_in_disk(const SurfaceProjector& projector,
                                         const Eigen::Vector3d& center, double radius, int count,
                                         unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * std::numbers::pi), r01(0.0, 1.0);
  std::vector<ClosestPoint> points;
  for (int k = 0; k < count; ++k) {
    const double a = angle(rng), r = radius * std::sqrt(r01(rng));
    points.push_back(
        projector.closest(center + Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0)));
  }
  return points;
}

TEST(ReliefFrames, MinimalRotationTakesAToBAndFixesTheAxis) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector3d a = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const Eigen::Vector3d b = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const Eigen::Matrix3d r = minimal_rotation(a, b);
    // Round-off of a few products of unit vectors, amplified by 1 / (1 + a.b) in Rodrigues'
    // formula (large only for nearly opposite vectors; transport uses it for small tilts).
    const double tolerance = 2e-15 * (1.0 + 10.0 / (1.0 + a.dot(b)));
    EXPECT_LT((r * a - b).norm(), tolerance);
    EXPECT_LT((r * a.cross(b) - a.cross(b)).norm(), tolerance);
    EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), tolerance);
    EXPECT_NEAR(r.determinant(), 1.0, tolerance);
  }
  const Eigen::Vector3d a(0, 0, 1);
  const Eigen::Matrix3d half = minimal_rotation(a, -a);
  EXPECT_LT((half * a + a).norm(), 1e-15);
  EXPECT_NEAR(half.determinant(), 1.0, 1e-15);
}

TEST(ReliefFrames, TangentFramesAreRightHandedOrthonormal) {
  const TangentFrame f = make_tangent_frame(Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(1, 1, 5));
  EXPECT_LT((f.tangent - Eigen::Vector3d(1, 1, 0).normalized()).norm(), 1e-15);
  EXPECT_LT((f.tangent.cross(f.bitangent) - f.normal).norm(), 1e-15);
  EXPECT_LT((f.matrix().transpose() * f.matrix() - Eigen::Matrix3d::Identity()).norm(), 1e-15);
  const Eigen::Vector3d v(0.3, -2, 4);
  EXPECT_LT((f.to_world(f.to_local(v)) - v).norm(), 1e-14);
  EXPECT_THROW(make_tangent_frame(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, 3)),
               NumericalError);
  EXPECT_THROW(make_tangent_frame(Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 0)),
               NumericalError);

  // On the plane z = 0 the surface frame's normal is +z (make_plane's orientation).
  const LimitSurface plane(make_plane({.resolution = 4}));
  const TangentFrame s = surface_frame(plane, plane.face_center(3));
  EXPECT_LT((s.normal - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_NEAR(s.tangent.z(), 0.0, 1e-12);
}

// J of an affine map restricted to a triangle's plane is the affine map's matrix there, and zero
// on the triangle's normal.
TEST(ReliefFrames, TriangleJacobianIsTheAffineMapOnThePlane) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  for (int k = 0; k < 20; ++k) {
    Eigen::Matrix3d a;
    for (int i = 0; i < 9; ++i) a(i) = g(rng);
    a += 3.0 * Eigen::Matrix3d::Identity();  // well conditioned
    Eigen::Matrix3d s;
    for (int i = 0; i < 9; ++i) s(i) = g(rng);
    const Eigen::Matrix3d t = (a * s).colwise() + Eigen::Vector3d(1, 2, 3);
    const Eigen::Matrix3d j = triangle_jacobian(s, t);
    const Eigen::Vector3d e1 = s.col(1) - s.col(0), e2 = s.col(2) - s.col(0);
    const Eigen::Vector3d m = e1.cross(e2).normalized();
    // Round-off amplified by the triangle's conditioning (random triangles; 1e-9 is generous).
    for (const double w : {0.0, 0.3, 1.0}) {
      const Eigen::Vector3d d = w * e1 + (1.0 - w) * e2;
      EXPECT_LT((j * d - a * d).norm(), 1e-9 * (a * d).norm());
    }
    EXPECT_LT((j * m).norm(), 1e-9 * a.norm());
  }
  Eigen::Matrix3d flat;
  flat << 0, 1, 2, 0, 0, 0, 0, 0, 0;  // collinear corners
  EXPECT_THROW(triangle_jacobian(flat, flat), NumericalError);
}

// Target = R * S * source with S a stretch in the source plane: the rotation part is R (polar
// decomposition), also when S reverses orientation (then R * reflection).
TEST(ReliefFrames, TriangleRotationIsThePolarFactor) {
  Eigen::Matrix3d s;  // a triangle in the plane z = 0
  s << 0.0, 1.0, 0.2, 0.0, 0.1, 0.9, 0.0, 0.0, 0.0;
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, -1, 0.5).normalized()).toRotationMatrix();
  // Symmetric positive stretch in the plane, axes rotated by 0.4 rad.
  const Eigen::Matrix3d axes = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d stretch =
      axes * Eigen::Vector3d(2.0, 0.5, 1.0).asDiagonal() * axes.transpose();
  EXPECT_LT((triangle_rotation(s, r * stretch * s) - r).norm(), 1e-12);
  // A reflection across the plane's x axis followed by the stretch: the nearest orthogonal map of
  // the planar part is the reflection, and the normal still goes to the target triangle's normal.
  const Eigen::Matrix3d mirror = Eigen::Vector3d(1.0, -1.0, 1.0).asDiagonal();
  const Eigen::Matrix3d target = r * stretch * mirror * s;
  const Eigen::Matrix3d q = triangle_rotation(s, target);
  const Eigen::Vector3d mt =
      (target.col(1) - target.col(0)).cross(target.col(2) - target.col(0)).normalized();
  EXPECT_LT((q * Eigen::Vector3d::UnitZ() - mt).norm(), 1e-12);
  EXPECT_LT((q.transpose() * q - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  // r * stretch * mirror = (r * mirror) * (mirror * stretch * mirror), the second factor symmetric
  // positive definite: the polar factor on the plane is r * mirror.
  EXPECT_LT((q * Eigen::Vector3d::UnitX() - r * mirror * Eigen::Vector3d::UnitX()).norm(), 1e-12);
  EXPECT_LT((q * Eigen::Vector3d::UnitY() - r * mirror * Eigen::Vector3d::UnitY()).norm(), 1e-12);
}

// The identity map (a plane region onto itself) leaves vectors unchanged, in both modes.
TEST(ReliefFrames, IdentityMapLeavesVectorsUnchanged) {
  const auto m = rigid_plane_pair(Eigen::Isometry3d::Identity());
  ASSERT_TRUE(m->result.relaxation.converged);
  int checked = 0;
  for (const ClosestPoint& p :
       points_in_disk(*m->source, Eigen::Vector3d(0.1, 0.05, 0), 0.5, 40, 1)) {
    const Mapping::Location image = m->result.mapping.forward(p.point);
    ASSERT_TRUE(image.inside);
    for (const VectorTransport mode : {VectorTransport::Stretch, VectorTransport::Rotation}) {
      const Eigen::Matrix3d t = m->differential->transport_forward(p.point, image, mode);
      // The relaxed particles are the source particles to ~1e-8 of the region size (the solver's
      // stopping gradient); J inherits that relative to the spacing (~0.05): 1e-6.
      EXPECT_LT((t - Eigen::Matrix3d::Identity()).norm(), 1e-6);
    }
    ++checked;
  }
  EXPECT_EQ(checked, 40);
}

// A rigid map rotates vectors by its rotation, in both modes, for tangent and normal vectors
// alike; frame components are kept.
TEST(ReliefFrames, RigidMapRotatesVectorsByTheRotation) {
  const Eigen::Isometry3d motion = test::rigid_motion();
  const auto m = rigid_plane_pair(motion);
  ASSERT_TRUE(m->result.relaxation.converged);
  const Eigen::Matrix3d rotation = motion.linear();
  std::vector<SurfacePoint> targets;
  std::vector<Mapping::Location> sources;
  std::vector<Eigen::Vector3d> vectors;
  std::vector<TangentFrame> source_frames, target_frames;
  for (const ClosestPoint& p :
       points_in_disk(*m->source, Eigen::Vector3d(0.1, 0.05, 0), 0.5, 40, 2)) {
    const Mapping::Location image = m->result.mapping.forward(p.point);
    ASSERT_TRUE(image.inside);
    for (const VectorTransport mode : {VectorTransport::Stretch, VectorTransport::Rotation}) {
      const Eigen::Matrix3d t = m->differential->transport_forward(p.point, image, mode);
      // As for the identity: the relaxed grid is the rigid image to ~1e-8.
      EXPECT_LT((t - rotation).norm(), 1e-6);
    }
    // The same through the batch form, going target -> source as transfers do.
    const Mapping::Location back = m->result.mapping.inverse(image.point);
    ASSERT_TRUE(back.inside);
    targets.push_back(image.point);
    sources.push_back(back);
    vectors.emplace_back(0.3, -0.2, 0.9);  // components in the source surface frame
    source_frames.push_back(surface_frame(*m->source_surface, back.point));
    target_frames.push_back(m->differential->transport_frame(
        source_frames.back(), back.point, image.point, back.triangle, VectorTransport::Rotation));
  }
  const VectorTransferResult world =
      transfer_vectors(*m->differential, targets, sources, vectors, source_frames, {},
                       {.mode = VectorTransport::Rotation});
  const VectorTransferResult local =
      transfer_vectors(*m->differential, targets, sources, vectors, source_frames, target_frames,
                       {.mode = VectorTransport::Rotation});
  EXPECT_EQ(world.without_source, 0);
  EXPECT_EQ(world.folded, 0);
  for (size_t i = 0; i < targets.size(); ++i) {
    EXPECT_LT((world.vectors[i] - rotation * source_frames[i].to_world(vectors[i])).norm(), 1e-6);
    // Components in the transported frame are the source components (Rotation keeps them
    // exactly; round-off only).
    EXPECT_LT((local.vectors[i] - vectors[i]).norm(), 1e-12);
  }
}

// On a curved surface: a disk on the cylinder mapped onto the same disk of a rigidly moved
// cylinder. T at a point and its rigid image is the rotation, so tangent vectors arrive tangent
// and rotated. (The image point is the exact rigid image found by the target's magnet, not
// Mapping::forward's, which goes through the grid's chord triangles and, on a curved surface,
// lands slightly off the rigid image; there the target normal differs by curvature times that.)
TEST(ReliefFrames, RigidMapOfACylinderRotatesTangentVectors) {
  const Eigen::Isometry3d motion = test::rigid_motion();
  const PolygonMesh cylinder = make_cylinder({.resolution = 24});
  RegionSpec source_spec = parse_region_spec("disk:0.5,0,0,0.4");
  source_spec.anchor = Eigen::Vector3d(0.5, 0, 1);
  RegionSpec target_spec = source_spec;
  target_spec.center = motion * source_spec.center;
  target_spec.anchor = motion * *source_spec.anchor;
  const auto m = map_pair(cylinder, test::moved(cylinder, motion), source_spec, target_spec);
  ASSERT_TRUE(m->result.relaxation.converged)
      << to_string(m->result.relaxation.reason) << ", relative gradient "
      << m->result.relaxation.relative_gradient << ", held "
      << m->result.relaxation.held_particles.size();
  const Eigen::Matrix3d rotation = motion.linear();
  // How congruent the relaxed grid is to the source grid. On this curved surface the boundary
  // particles' arc-length placement is off the rigid image by ~2e-4 (chords of the cut curve vs
  // the limit curve; not this module's), interior particles by ~4e-6. Points are taken well
  // inside (grid triangles of interior particles); J's error is the particles' error over a
  // triangle's edge (~spacing) times the triangle's conditioning (~3).
  const ParticleGrid& grid = m->result.sampling.grid;
  const Eigen::VectorXd deviation =
      (m->result.relaxation.positions - motion * grid.source_positions()).colwise().norm();
  double rigid_error = 0.0;
  for (int i = 0; i < grid.num_particles(); ++i) {
    if (!grid.is_boundary[static_cast<size_t>(i)])
      rigid_error = std::max(rigid_error, deviation[i]);
  }
  const double tolerance = 1e-9 + 6.0 * rigid_error / m->result.sampling.statistics.spacing_median;
  EXPECT_LT(rigid_error, 1e-5);
  std::mt19937 rng(5);
  // Within geodesic distance ~0.25 of the centre (the region's radius is 0.4).
  std::uniform_real_distribution<double> angle(-0.35, 0.35), height(-0.17, 0.17), dir(0.0, 6.3);
  for (int k = 0; k < 30; ++k) {
    const double a = angle(rng);
    const ClosestPoint p =
        m->source->closest(Eigen::Vector3d(0.5 * std::cos(a), 0.5 * std::sin(a), height(rng)));
    const Mapping::Location image = m->result.mapping.forward(p.point);
    ASSERT_TRUE(image.inside);
    const SurfacePoint q = m->target->closest(motion * p.position).point;
    const TangentFrame f = surface_frame(*m->source_surface, p.point);
    const double d = dir(rng);
    const Eigen::Vector3d v = std::cos(d) * f.tangent + std::sin(d) * f.bitangent;
    const Eigen::Vector3d nt = surface_frame(*m->target_surface, q).normal;
    for (const VectorTransport mode : {VectorTransport::Stretch, VectorTransport::Rotation}) {
      const Eigen::Vector3d w = m->differential->transport(p.point, q, image.triangle, mode) * v;
      EXPECT_LT((w - rotation * v).norm(), tolerance);
      EXPECT_LT(std::abs(w.dot(nt)), 1e-12);  // tangent by construction, up to round-off
    }
  }
}

// J against central finite differences of Mapping::forward, on a non-rigid plane -> plane map (a
// disk of radius 0.5 onto one of radius 0.7 on a tilted plane; the target is flat, so the magnet
// adds nothing). J is the affine map between the particle triangles, and forward is exactly that
// affine map on each grid triangle (mapping/mapping.h), so the central difference has no
// truncation error: what is left is round-off, ~1e-16 of the positions over the step 1e-5
// (measured 4e-12 median, 1.4e-11 at worst). The bounds leave a factor of ~1000; interpolating in
// the disk maps' coordinates instead was off by 0.25% median and 2% at worst, and a wrong J (e.g.
// transposed or without the scale) is off by 30% or more.
TEST(ReliefFrames, JacobianMatchesFiniteDifferencesOfForward) {
  const PolygonMesh plane = make_plane({.resolution = 8});
  Eigen::Isometry3d tilt = Eigen::Isometry3d::Identity();
  tilt.rotate(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()));
  const auto m = map_pair(plane, test::moved(plane, tilt), parse_region_spec("disk:0,0,0,0.5"),
                          parse_region_spec("disk:0,0,0,0.7"), 300);
  const double h = 1e-5;
  std::vector<double> errors;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> dir(0.0, 6.3);
  for (const ClosestPoint& p : points_in_disk(*m->source, Eigen::Vector3d::Zero(), 0.4, 100, 4)) {
    const double a = dir(rng);
    const Eigen::Vector3d d(std::cos(a), std::sin(a), 0.0);
    const Mapping::Location centre = m->result.mapping.forward(p.point);
    const Mapping::Location plus =
        m->result.mapping.forward(m->source->closest(p.position + h * d).point);
    const Mapping::Location minus =
        m->result.mapping.forward(m->source->closest(p.position - h * d).point);
    ASSERT_TRUE(centre.inside && plus.inside && minus.inside);
    if (plus.triangle != centre.triangle || minus.triangle != centre.triangle) continue;
    const Eigen::Vector3d fd = (plus.position - minus.position) / (2.0 * h);
    const Eigen::Vector3d jd = m->differential->jacobian(centre.triangle) * d;
    errors.push_back((fd - jd).norm() / jd.norm());
    // The map scales by ~0.7/0.5 on average, and J lies in the target plane.
    EXPECT_GT(jd.norm(), 1.1);
    EXPECT_LT(std::abs(jd.dot(tilt.linear() * Eigen::Vector3d::UnitZ())), 1e-9);
  }
  ASSERT_GT(errors.size(), 60u);  // most points lie away from the triangles' edges
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2];
  RecordProperty("median_relative_error", std::to_string(median));
  RecordProperty("max_relative_error", std::to_string(errors.back()));
  EXPECT_LT(median, 1e-9);
  EXPECT_LT(errors.back(), 1e-8);
}

// On a curved target forward is the affine map followed by the magnet, whose differential is the
// projection onto the target tangent plane; Stretch transport rotates instead of projecting. They
// agree to the tilt between chord plane and tangent plane (about spacing / radius), squared.
TEST(ReliefFrames, StretchTransportMatchesFiniteDifferencesOnACylinder) {
  const auto m =
      map_pair(make_plane({.resolution = 8}), make_cylinder({.resolution = 24}),
               parse_region_spec("disk:0,0,0,0.4"), parse_region_spec("disk:0.5,0,0,0.4"), 400);
  const double h = 1e-5;
  const double spacing = m->result.sampling.statistics.spacing_median;
  // Tilt angle ~ spacing / (2 r) at most (r = 0.5); its square bounds the rotation-vs-projection
  // difference, and the magnet's normal-distance term (chord sagitta * curvature) is of the same
  // order.
  const double tolerance = 2.0 * spacing * spacing / (0.5 * 0.5);
  int checked = 0;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> dir(0.0, 6.3);
  for (const ClosestPoint& p : points_in_disk(*m->source, Eigen::Vector3d::Zero(), 0.3, 60, 6)) {
    const double a = dir(rng);
    const Eigen::Vector3d d(std::cos(a), std::sin(a), 0.0);
    const Mapping::Location centre = m->result.mapping.forward(p.point);
    const Mapping::Location plus =
        m->result.mapping.forward(m->source->closest(p.position + h * d).point);
    const Mapping::Location minus =
        m->result.mapping.forward(m->source->closest(p.position - h * d).point);
    ASSERT_TRUE(centre.inside && plus.inside && minus.inside);
    if (plus.triangle != centre.triangle || minus.triangle != centre.triangle) continue;
    const Eigen::Vector3d fd = (plus.position - minus.position) / (2.0 * h);
    const Eigen::Vector3d td = m->differential->transport_forward(p.point, centre) * d;
    EXPECT_LT((fd - td).norm(), tolerance * td.norm());
    ++checked;
  }
  EXPECT_GT(checked, 40);
  EXPECT_LT(tolerance, 0.05);  // the test means something only with a fine enough grid
}

// Issue 6: a vector field tangent to a cylinder arrives tangent to the target with the right angle
// to the boundary. A geodesic disk on the cylinder is isometric to a flat disk of the same radius
// (the cylinder unrolls), so the least-distortion map onto that disk is nearly an isometry and
// keeps angles. At every boundary particle the field makes 60 degrees with the boundary.
TEST(ReliefFrames, CylinderFieldArrivesTangentWithItsAngleToTheBoundary) {
  const auto m =
      map_pair(make_cylinder({.resolution = 24}), make_plane({.resolution = 8}),
               parse_region_spec("disk:0.5,0,0,0.4"), parse_region_spec("disk:0,0,0,0.4"), 500);
  ASSERT_TRUE(m->result.relaxation.converged);
  const ParticleGrid& grid = m->result.sampling.grid;
  const Eigen::Matrix3Xd source = grid.source_positions();
  const Eigen::Matrix3Xd& target = m->result.relaxation.positions;
  const std::vector<int>& loop = grid.boundary_loop;
  const double alpha = std::numbers::pi / 3.0;
  double worst_angle = 0.0, worst_normal = 0.0;
  for (size_t k = 0; k < loop.size(); ++k) {
    const int i = loop[k], prev = loop[(k + loop.size() - 1) % loop.size()],
              next = loop[(k + 1) % loop.size()];
    const TangentFrame fs = make_tangent_frame(
        surface_frame(*m->source_surface, grid.source_points[static_cast<size_t>(i)]).normal,
        source.col(next) - source.col(prev));
    // Boundary counter-clockwise seen from the normal: the interior is on the left, n x t.
    const Eigen::Vector3d v = std::cos(alpha) * fs.tangent + std::sin(alpha) * fs.bitangent;
    const SurfacePoint& q = m->result.relaxation.points[static_cast<size_t>(i)];
    const Eigen::Vector3d w =
        m->differential->transport(grid.source_points[static_cast<size_t>(i)], q, -1) * v;
    const TangentFrame ft = make_tangent_frame(surface_frame(*m->target_surface, q).normal,
                                               target.col(next) - target.col(prev));
    worst_normal = std::max(worst_normal, std::abs(w.dot(ft.normal)) / w.norm());
    const double angle = std::atan2(w.dot(ft.bitangent), w.dot(ft.tangent));
    worst_angle = std::max(worst_angle, std::abs(angle - alpha));
  }
  RecordProperty("worst_angle_error_degrees",
                 std::to_string(worst_angle * 180.0 / std::numbers::pi));
  EXPECT_LT(worst_normal, 1e-12);  // tangent to the target (round-off)
  // The map is an isometry up to the chord-vs-arc difference of the springs and the boundary
  // correspondence's discretisation: 3 degrees bounds the measured 1.7.
  EXPECT_LT(worst_angle, 3.0 * std::numbers::pi / 180.0) << "worst angle error (rad)";
}

TEST(ReliefFrames, BatchTransferChecksItsInputs) {
  const auto m = rigid_plane_pair(Eigen::Isometry3d::Identity());
  std::vector<SurfacePoint> targets(2);
  std::vector<Mapping::Location> sources(1);
  std::vector<Eigen::Vector3d> vectors(2, Eigen::Vector3d::UnitX());
  EXPECT_THROW(transfer_vectors(*m->differential, targets, sources, vectors), InvalidInputError);
  sources.resize(2);  // two Locations that are not inside: no source, vectors stay zero
  const VectorTransferResult r = transfer_vectors(*m->differential, targets, sources, vectors);
  EXPECT_EQ(r.without_source, 2);
  EXPECT_EQ(r.vectors[0], Eigen::Vector3d::Zero());
  EXPECT_THROW(m->differential->jacobian(-1), InvalidInputError);
  EXPECT_THROW(m->differential->jacobian(m->differential->num_triangles()), InvalidInputError);
}

}  // namespace
}  // namespace elastic
