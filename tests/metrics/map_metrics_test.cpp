// Tests of measure_map against answers it did not produce: rigid motions (perfect values by
// definition), a known linear map (its singular values are the analytic ones), brute-force sums of
// the length energy and the corner angles, a fold made by hand, the rest-scale convention.

#include "elastic/metrics/map_metrics.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "elastic/core/error.h"
#include "elastic/particles/face_folds.h"

namespace elastic {
namespace {

// A (cols+1) x (rows+1) grid of quads on [0, cols] x [0, rows] in the plane z = 0, with one extra
// triangle fan along the bottom edge replaced by triangles so that triangles and quads both occur.
// `bump` lifts the vertices off the plane (z = bump * sin x cos y) for a curved source.
ParticleGrid make_grid(int cols, int rows, double bump = 0.0) {
  ParticleGrid grid;
  std::vector<GridMesh::VertexHandle> v;
  for (int r = 0; r <= rows; ++r) {
    for (int c = 0; c <= cols; ++c) {
      const double x = c, y = r;
      v.push_back(grid.mesh.add_vertex(
          GridMesh::Point(x, y, bump * std::sin(0.7 * x) * std::cos(0.5 * y))));
    }
  }
  const auto at = [&](int c, int r) { return v[r * (cols + 1) + c]; };
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (r == 0) {  // the first row as two triangles per square
        grid.mesh.add_face(at(c, r), at(c + 1, r), at(c + 1, r + 1));
        grid.mesh.add_face(at(c, r), at(c + 1, r + 1), at(c, r + 1));
      } else {
        grid.mesh.add_face(at(c, r), at(c + 1, r), at(c + 1, r + 1), at(c, r + 1));
      }
    }
  }
  grid.source_points.assign(grid.mesh.n_vertices(), SurfacePoint{});
  grid.is_boundary.assign(grid.mesh.n_vertices(), 0);
  grid.build_springs();
  return grid;
}

Eigen::Matrix3Xd transformed(const Eigen::Matrix3Xd& x, const Eigen::Matrix3d& a,
                             const Eigen::Vector3d& t) {
  return (a * x).colwise() + t;
}

Eigen::Matrix3Xd constant_normals(int n, const Eigen::Vector3d& normal) {
  Eigen::Matrix3Xd out(3, n);
  out.colwise() = normal;
  return out;
}

// Round-off bound for quantities computed from O(1) coordinates through a few products and a
// square root: a few hundred ulps of 1.
constexpr double kTight = 1e-12;

void expect_perfect(const MapMetrics& m) {
  EXPECT_NEAR(m.length_energy, 0.0, kTight);
  EXPECT_NEAR(m.angle_error_mean_deg, 0.0, 1e-9);  // degrees: atan2 of O(1e-16) errors * 57
  EXPECT_NEAR(m.angle_error_max_deg, 0.0, 1e-9);
  EXPECT_NEAR(m.stretch_l2, 1.0, kTight);
  // s1 comes from sqrt(sum_sq - 2 prod), which amplifies round-off e to sqrt(e) ~ 1e-8 at a
  // double-root (s1 = s2): the square root of a quantity that is zero up to round-off.
  EXPECT_NEAR(m.stretch_linf, 1.0, 1e-7);
  EXPECT_NEAR(m.inverse_stretch_l2, 1.0, kTight);
  EXPECT_NEAR(m.inverse_stretch_linf, 1.0, 1e-7);
  EXPECT_NEAR(m.area_distortion, 0.0, kTight);
  EXPECT_NEAR(m.conformal_distortion, 1.0, 1e-7);
  EXPECT_NEAR(m.symmetric_dirichlet, 4.0, kTight);
  EXPECT_EQ(m.folds, 0);
  EXPECT_EQ(m.degenerate, 0);
  EXPECT_EQ(m.outside, 0);
  // Same double-root amplification as stretch_linf: s2 = prod / s1.
  EXPECT_NEAR(m.sigma_min, 1.0, 1e-7);
}

TEST(MapMetrics, IdentityIsPerfect) {
  const ParticleGrid grid = make_grid(5, 4);
  const Eigen::Matrix3Xd x = grid.source_positions();
  MapMetricsOptions options;
  options.target_normals = constant_normals(grid.num_particles(), Eigen::Vector3d::UnitZ());
  const MapMetrics m = measure_map(grid, x, options);
  expect_perfect(m);
  // 5 first-row squares as 2 triangles each, 15 quads split in 2.
  EXPECT_EQ(m.measured_triangles, 10 + 30);
  EXPECT_EQ(static_cast<int>(m.triangles.size()), 40);
  EXPECT_EQ(m.measured_springs, static_cast<int>(grid.springs.size()));
}

TEST(MapMetrics, RigidMotionsOfACurvedGridArePerfect) {
  // A curved source: each triangle has its own plane, and a rigid motion maps each one
  // isometrically onto its image, whatever the planes.
  const ParticleGrid grid = make_grid(6, 5, 0.4);
  const Eigen::Matrix3Xd x = grid.source_positions();
  for (const double angle : {0.3, 1.7, -2.9}) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(angle, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
    const Eigen::Matrix3Xd y = transformed(x, r, Eigen::Vector3d(3.0, -1.0, 7.5));
    // Normals of the moved surface: the rotated normals of the source triangles' average plane.
    // Here the grid is only gently curved (|grad z| <= 0.28), so the rotated +z is on the same side
    // as every triangle normal.
    MapMetricsOptions options;
    options.target_normals = constant_normals(grid.num_particles(), r * Eigen::Vector3d::UnitZ());
    expect_perfect(measure_map(grid, y, options));
  }
}

TEST(MapMetrics, KnownLinearMapGivesItsSingularValues) {
  // Planar grid, map = R * diag(a, b, 1): every triangle has singular values exactly a and b.
  const double a = 2.0, b = 0.75;
  const ParticleGrid grid = make_grid(4, 4);
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.8, Eigen::Vector3d(0.2, 0.3, 1.0).normalized()).toRotationMatrix();
  const Eigen::Matrix3d map = r * Eigen::Vector3d(a, b, 1.0).asDiagonal();
  const Eigen::Matrix3Xd x = grid.source_positions();
  const Eigen::Matrix3Xd y = transformed(x, map, Eigen::Vector3d(0.1, 0.2, 0.3));
  MapMetricsOptions options;
  options.target_normals = constant_normals(grid.num_particles(), r * Eigen::Vector3d::UnitZ());
  const MapMetrics m = measure_map(grid, y, options);

  for (size_t t = 0; t < m.triangles.size(); ++t) {
    EXPECT_NEAR(m.per_triangle.s1[t], a, kTight);
    EXPECT_NEAR(m.per_triangle.s2[t], b, kTight);
    EXPECT_EQ(m.per_triangle.folded[t], 0);
  }
  // The formulas with s1 = a, s2 = b (the same on every triangle, so weights do not matter).
  EXPECT_NEAR(m.stretch_l2, std::sqrt((a * a + b * b) / 2.0), kTight);
  EXPECT_NEAR(m.stretch_linf, a, kTight);
  EXPECT_NEAR(m.inverse_stretch_l2, std::sqrt((1.0 / (a * a) + 1.0 / (b * b)) / 2.0), kTight);
  EXPECT_NEAR(m.inverse_stretch_linf, 1.0 / b, kTight);
  EXPECT_NEAR(m.area_distortion, std::log(a * b), kTight);
  EXPECT_NEAR(m.conformal_distortion, a / b, kTight);
  EXPECT_NEAR(m.symmetric_dirichlet, a * a + b * b + 1.0 / (a * a) + 1.0 / (b * b), kTight);
  EXPECT_EQ(m.folds, 0);

  // Length energy by brute force over the grid's edges (rest = source edge length).
  double num = 0.0, den = 0.0;
  for (const auto eh : grid.mesh.edges()) {
    const int i = grid.mesh.from_vertex_handle(grid.mesh.halfedge_handle(eh, 0)).idx();
    const int j = grid.mesh.to_vertex_handle(grid.mesh.halfedge_handle(eh, 0)).idx();
    const double k = (x.col(j) - x.col(i)).norm();
    const double d = (y.col(j) - y.col(i)).norm();
    num += (d - k) * (d - k);
    den += k * k;
  }
  EXPECT_NEAR(m.length_energy, num / den, kTight);

  // Angle errors by hand: the triangles are right isoceles triangles (legs 1) of two kinds. Under
  // diag(a, b) the legs along x and y stay perpendicular after the map only when they are the two
  // axis directions, and the angles follow from the mapped edge vectors.
  const auto angle = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return std::acos(u.dot(v) / (u.norm() * v.norm()));
  };
  const Eigen::Vector2d ex(a, 0.0), ey(0.0, b), exy(a, b);
  // Triangle (0,0),(1,0),(1,1): corners 90 deg at (1,0), 45 at (0,0), 45 at (1,1); mapped corner
  // at (0,0) is between ex and exy, at (1,0) between -ex and ey, at (1,1) between -ey and -exy.
  const double deg = 180.0 / std::numbers::pi;
  const double e0 = std::abs(angle(ex, exy) - std::numbers::pi / 4) * deg;
  const double e1 = std::abs(angle(-ex, ey) - std::numbers::pi / 2) * deg;
  const double e2 = std::abs(angle(-ey, -exy) - std::numbers::pi / 4) * deg;
  EXPECT_NEAR(e1, 0.0, 1e-12);
  // Both triangle kinds of a square split along the same diagonal have the same three errors
  // {e0, e1, e2} by symmetry; so does the fan of a quad from its first corner (the same diagonal).
  EXPECT_NEAR(m.angle_error_mean_deg, (e0 + e1 + e2) / 3.0, 1e-9);
  EXPECT_NEAR(m.angle_error_max_deg, std::max(e0, e2), 1e-9);
}

TEST(MapMetrics, RestScaleDividesOutAUniformScale) {
  const ParticleGrid grid = make_grid(4, 3, 0.3);
  const Eigen::Matrix3Xd x = grid.source_positions();
  const double c = 2.5;
  const Eigen::Matrix3Xd y = c * x;
  MapMetricsOptions options;
  options.target_normals = constant_normals(grid.num_particles(), Eigen::Vector3d::UnitZ());
  options.rest_scale = c;
  expect_perfect(measure_map(grid, y, options));

  // With sigma = 1 the same map stretches by c everywhere: every |d| = c k, so the normalised
  // length energy is sum ((c - 1) k)^2 / sum k^2 = (c - 1)^2.
  options.rest_scale = 1.0;
  const MapMetrics m = measure_map(grid, y, options);
  EXPECT_NEAR(m.length_energy, (c - 1.0) * (c - 1.0), kTight);
  EXPECT_NEAR(m.stretch_l2, c, kTight);
  EXPECT_NEAR(m.area_distortion, std::log(c * c), kTight);
  EXPECT_NEAR(m.conformal_distortion, 1.0, 1e-7);
  EXPECT_NEAR(m.symmetric_dirichlet, 2.0 * c * c + 2.0 / (c * c), kTight);
  EXPECT_NEAR(m.angle_error_max_deg, 0.0, 1e-9);
}

// Brute force of the fold definition in the plane z = 0 seen along `up` (+1 or -1): a face is
// folded when a triangle of any of its triangulations has a non-positive signed area along `up`.
// For a triangle that is itself; for a quad the triangles omitting one corner each.
int brute_force_folds(const ParticleGrid& grid, const Eigen::Matrix3Xd& y, double up,
                      std::vector<char>* per_face = nullptr) {
  int count = 0;
  for (const auto fh : grid.mesh.faces()) {
    std::vector<int> c;
    for (const auto vh : grid.mesh.fv_range(fh)) {
      c.push_back(vh.idx());
    }
    const int n = static_cast<int>(c.size());
    bool folded = false;
    for (int omit = 0; omit < (n == 3 ? 1 : n); ++omit) {
      std::array<int, 3> t{};
      int m = 0;
      for (int k = 0; k < n && m < 3; ++k) {
        if (n == 3 || k != omit) {
          t[m++] = c[k];
        }
      }
      const Eigen::Vector3d a = y.col(t[0]), b = y.col(t[1]), d = y.col(t[2]);
      const double z = (b.x() - a.x()) * (d.y() - a.y()) - (b.y() - a.y()) * (d.x() - a.x());
      folded = folded || up * z <= 0.0;
    }
    count += folded ? 1 : 0;
    if (per_face != nullptr) {
      per_face->push_back(folded ? 1 : 0);
    }
  }
  return count;
}

TEST(MapMetrics, FoldIsDetectedAgainstTheSurfaceNormal) {
  const ParticleGrid grid = make_grid(4, 4);
  Eigen::Matrix3Xd y = grid.source_positions();
  // Push the interior particle (2, 2) (index 2 * 5 + 2) past its neighbour (3, 2): the faces
  // around it whose orientation changes are inverted in the plane.
  const int moved = 12;
  y.col(moved) = Eigen::Vector3d(3.6, 2.2, 0.0);
  MapMetricsOptions options;
  options.target_normals = constant_normals(grid.num_particles(), Eigen::Vector3d::UnitZ());
  const MapMetrics m = measure_map(grid, y, options);

  std::vector<char> expected_faces;
  const int expected = brute_force_folds(grid, y, 1.0, &expected_faces);
  EXPECT_GT(expected, 0);
  EXPECT_EQ(m.folds, expected);
  ASSERT_EQ(m.per_face.folded.size(), expected_faces.size());
  for (size_t f = 0; f < expected_faces.size(); ++f) {
    EXPECT_EQ(m.per_face.folded[f], expected_faces[f]) << "face " << f;
  }
  // Triangles show their face's fold; an inverted triangle has a negative sigma_min.
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    EXPECT_EQ(m.per_triangle.folded[t], expected_faces[m.triangle_face[t]]) << "triangle " << t;
  }
  EXPECT_LT(m.sigma_min, 0.0);

  // Seen from below (normals -z) every face has an inverted triangle except those whose every
  // triangle is inverted from above.
  options.target_normals = constant_normals(grid.num_particles(), -Eigen::Vector3d::UnitZ());
  EXPECT_EQ(measure_map(grid, y, options).folds, brute_force_folds(grid, y, -1.0));

  // Without normals the fold test is not made.
  EXPECT_EQ(measure_map(grid, y).folds, -1);
}

// One unit-square quad, corners (0,0), (1,0), (1,1), (0,1) counter-clockwise, so its first-corner
// fan is split along the diagonal 0-2.
ParticleGrid single_quad_grid() {
  ParticleGrid grid;
  std::vector<GridMesh::VertexHandle> v;
  for (const auto& [x, y] : {std::pair{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}}) {
    v.push_back(grid.mesh.add_vertex(GridMesh::Point(x, y, 0.0)));
  }
  grid.mesh.add_face(v[0], v[1], v[2], v[3]);
  grid.source_points.assign(4, SurfacePoint{});
  grid.is_boundary.assign(4, 0);
  grid.build_springs();
  return grid;
}

TEST(MapMetrics, QuadFoldedOnlyAlongItsOtherDiagonalIsFolded) {
  // Corner 0 moved to (0.7, 0.7), inside the triangle (1, 2, 3): the quad is not convex (reflex at
  // corner 0). The split along 0-2 (the fan the heatmap shows) has two positive triangles, the
  // split along 1-3 has the inverted triangle (1, 3, 0). By hand, from corner 1: source edges
  // (-1, 1), (-1, 0), target edges (-1, 1), (-0.3, 0.7), so J = T S^-1 = [[0.3, -0.7], [-0.7,
  // 0.3]], symmetric with eigenvalues 1 and -0.4: singular values 1 and 0.4, det -0.4 (inverted),
  // so the signed sigma_min of that triangle is -0.4. The fan's triangles: (0, 1, 2) has J = [[0.3,
  // 0], [-0.7, 1]] (det 0.3), (0, 2, 3) the mirror image; (1, 2, 3) is untouched (1, 1).
  const ParticleGrid grid = single_quad_grid();
  Eigen::Matrix3Xd y = grid.source_positions();
  y.col(0) = Eigen::Vector3d(0.7, 0.7, 0.0);
  MapMetricsOptions options;
  options.target_normals = constant_normals(4, Eigen::Vector3d::UnitZ());
  const MapMetrics m = measure_map(grid, y, options);
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.folds, 1);
  EXPECT_EQ(m.per_face.folded[0], 1);
  EXPECT_EQ(m.degenerate, 0);
  EXPECT_NEAR(m.sigma_min, -0.4, kTight);
  EXPECT_NEAR(m.per_face.sigma_min[0], -0.4, kTight);
  // The same test below the metrics (particles/face_folds.h, the naive map's offset choice uses
  // it): the moved quad is inverted, the unmoved one is not, and seen from below (normals -z) it
  // is.
  EXPECT_EQ(inverted_faces(grid, y, options.target_normals), 1);
  EXPECT_EQ(inverted_faces(grid, grid.source_positions(), options.target_normals), 0);
  EXPECT_EQ(inverted_faces(grid, grid.source_positions(), -options.target_normals), 1);
  // Both fan triangles are positive: s1 s2 = det = 0.3, s1^2 + s2^2 = |J|_F^2 = 1.58.
  const double s2 = 0.5 * (std::sqrt(1.58 + 0.6) - std::sqrt(1.58 - 0.6));
  for (int t = 0; t < 2; ++t) {
    EXPECT_NEAR(m.per_triangle.s2[t], s2, kTight);
    EXPECT_NEAR(m.per_triangle.s1[t] * m.per_triangle.s2[t], 0.3, kTight);
    EXPECT_EQ(m.per_triangle.folded[t], 1);  // shown as its face
  }

  // The mirror case, corner 1 moved inside (0, 2, 3) to (0.3, 0.7): the fan's triangle (0, 1, 2)
  // is the inverted one; the face is folded either way.
  y = grid.source_positions();
  y.col(1) = Eigen::Vector3d(0.3, 0.7, 0.0);
  EXPECT_EQ(measure_map(grid, y, options).folds, 1);
  // A convex quad (a parallelogram) is not folded.
  y = grid.source_positions();
  y.col(2) = Eigen::Vector3d(1.5, 1.0, 0.0);
  y.col(3) = Eigen::Vector3d(0.5, 1.0, 0.0);
  EXPECT_EQ(measure_map(grid, y, options).folds, 0);
}

TEST(MapMetrics, SigmaMinOfAnAffineMapIsItsSmallerSingularValueOverSigma) {
  // x -> R diag(a, b) x with a = 2, b = 0.75 on a grid of quads and triangles: every triangle of
  // every triangulation has singular values a and b; divided by sigma = 0.5 the worst is b / sigma.
  const double a = 2.0, b = 0.75, sigma = 0.5;
  const ParticleGrid grid = make_grid(4, 3);
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(-1.1, Eigen::Vector3d(0.4, -0.1, 1.0).normalized()).toRotationMatrix();
  const Eigen::Matrix3Xd y =
      transformed(grid.source_positions(), r * Eigen::Vector3d(a, b, 1.0).asDiagonal(),
                  Eigen::Vector3d(-2.0, 0.5, 4.0));
  MapMetricsOptions options;
  options.rest_scale = sigma;
  options.target_normals = constant_normals(grid.num_particles(), r * Eigen::Vector3d::UnitZ());
  const MapMetrics m = measure_map(grid, y, options);
  EXPECT_EQ(m.folds, 0);
  EXPECT_NEAR(m.sigma_min, b / sigma, kTight);
  for (const double v : m.per_face.sigma_min) {
    EXPECT_NEAR(v, b / sigma, kTight);
  }
  // A mirror image (diag(a, -b)) inverts every triangle: sigma_min = -b / sigma, every face folded.
  const Eigen::Matrix3Xd mirrored =
      transformed(grid.source_positions(), r * Eigen::Vector3d(a, -b, 1.0).asDiagonal(),
                  Eigen::Vector3d::Zero());
  const MapMetrics w = measure_map(grid, mirrored, options);
  EXPECT_EQ(w.folds, static_cast<int>(grid.mesh.n_faces()));
  EXPECT_NEAR(w.sigma_min, -b / sigma, kTight);
}

TEST(MapMetrics, DegenerateTargetIsAFoldAndLeftOutOfTheMeans) {
  const ParticleGrid grid = make_grid(3, 3);
  Eigen::Matrix3Xd y = grid.source_positions();
  // Collapse the whole map onto the x axis: every triangle degenerates, so every face folds.
  y.row(1).setZero();
  MapMetricsOptions options;
  options.target_normals = constant_normals(grid.num_particles(), Eigen::Vector3d::UnitZ());
  const MapMetrics m = measure_map(grid, y, options);
  EXPECT_EQ(m.degenerate, static_cast<int>(grid.mesh.n_faces()));
  EXPECT_EQ(m.folds, m.degenerate);
  EXPECT_NEAR(m.sigma_min, 0.0, kTight);
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    EXPECT_TRUE(std::isinf(m.per_triangle.symmetric_dirichlet[t]));
    EXPECT_NEAR(m.per_triangle.s2[t], 0.0, kTight);
    // The x extent of every triangle's legs is kept: s1 = 1 for a projection onto an axis of a
    // right isoceles triangle with legs along x and y.
    EXPECT_NEAR(m.per_triangle.s1[t], 1.0, kTight);
  }
}

TEST(MapMetrics, OutsideParticlesAreExcludedAndCounted) {
  const ParticleGrid grid = make_grid(4, 4);
  Eigen::Matrix3Xd y = grid.source_positions();
  const int n = grid.num_particles();
  MapMetricsOptions options;
  options.outside.assign(n, 0);
  options.outside[6] = 1;
  // The outside particle's position is garbage: it must not count anywhere.
  y.col(6) = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  options.target_normals = constant_normals(n, Eigen::Vector3d::UnitZ());
  const MapMetrics m = measure_map(grid, y, options);
  int touching = 0, springs = 0;
  for (const auto& tri : m.triangles) {
    touching += (tri.array() == 6).any() ? 1 : 0;
  }
  for (const auto& s : grid.springs) {
    springs += (s.i == 6 || s.j == 6) ? 1 : 0;
  }
  EXPECT_EQ(m.outside, 1);
  EXPECT_EQ(m.outside_triangles, touching);
  EXPECT_EQ(m.measured_triangles, static_cast<int>(m.triangles.size()) - touching);
  EXPECT_EQ(m.measured_springs, static_cast<int>(grid.springs.size()) - springs);
  EXPECT_NEAR(m.symmetric_dirichlet, 4.0, kTight);
  EXPECT_NEAR(m.length_energy, 0.0, kTight);
}

TEST(MapMetrics, TrianglesAreTheFirstCornerFan) {
  const ParticleGrid grid = make_grid(2, 2);
  const auto tris = grid_triangles(grid);
  // Face 2 is the quad (0,1),(1,1),(1,2),(0,2) = particles 3, 4, 7, 6: fan from 3.
  ASSERT_EQ(tris.size(), 8u);
  EXPECT_EQ(tris[4], Eigen::Vector3i(3, 4, 7));
  EXPECT_EQ(tris[5], Eigen::Vector3i(3, 7, 6));
}

TEST(MapMetrics, ParallelSumsMatchTheTrianglesAndDoNotDependOnTheThreadCount) {
  // 90 x 60 squares: about 10,700 triangles, several of the reductions' chunks, on a curved
  // source under a smooth non-affine map with one face folded by hand.
  const ParticleGrid grid = make_grid(90, 60, 0.4);
  Eigen::Matrix3Xd y = grid.source_positions();
  for (int p = 0; p < y.cols(); ++p) {
    const Eigen::Vector3d x = y.col(p);
    y.col(p) = Eigen::Vector3d(x.x() + 0.1 * std::sin(x.y()), 1.1 * x.y(), x.z() + 0.05 * x.x());
  }
  const int middle = 30 * 91 + 45;  // a vertex inside: moved across its neighbour
  y.col(middle) = y.col(middle + 2);
  MapMetricsOptions options;
  options.target_normals = constant_normals(grid.num_particles(), Eigen::Vector3d::UnitZ());
  MapMetrics one, many;
  tbb::task_arena(1).execute([&] { one = measure_map(grid, y, options); });
  tbb::task_arena(4).execute([&] { many = measure_map(grid, y, options); });
  for (const auto& [a, b] : {std::pair{one.stretch_l2, many.stretch_l2},
                             std::pair{one.area_distortion, many.area_distortion},
                             std::pair{one.symmetric_dirichlet, many.symmetric_dirichlet},
                             std::pair{one.angle_error_mean_deg, many.angle_error_mean_deg},
                             std::pair{one.angle_error_max_deg, many.angle_error_max_deg},
                             std::pair{one.sigma_min, many.sigma_min}}) {
    EXPECT_EQ(a, b);
  }
  EXPECT_EQ(one.folds, many.folds);
  EXPECT_GT(one.folds, 0);
  // The aggregates against sums taken here, triangle by triangle, from the per-triangle values.
  const TriangleValues& tv = one.per_triangle;
  double area = 0.0, regular = 0.0, sd = 0.0, worst_angle = 0.0;
  int measured = 0;
  for (std::size_t t = 0; t < tv.s1.size(); ++t) {
    ++measured;
    area += tv.source_area[t];
    worst_angle = std::max(worst_angle, tv.angle_error_deg[t]);
    if (std::isfinite(tv.symmetric_dirichlet[t])) {
      regular += tv.source_area[t];
      sd += tv.source_area[t] * tv.symmetric_dirichlet[t];
    }
  }
  EXPECT_EQ(one.measured_triangles, measured);
  EXPECT_EQ(one.angle_error_max_deg, worst_angle);
  EXPECT_NEAR(one.symmetric_dirichlet, sd / regular, 1e-12 * (sd / regular));
  double worst_sigma = std::numeric_limits<double>::infinity();
  for (const double v : one.per_face.sigma_min) {
    worst_sigma = std::min(worst_sigma, v);
  }
  EXPECT_EQ(one.sigma_min, worst_sigma);
  EXPECT_LT(one.sigma_min, 0.0);  // the folded face's, negative
}

TEST(MapMetrics, RejectsInconsistentInput) {
  const ParticleGrid grid = make_grid(2, 2);
  const Eigen::Matrix3Xd x = grid.source_positions();
  EXPECT_THROW(measure_map(grid, Eigen::Matrix3Xd::Zero(3, 2)), InvalidInputError);
  MapMetricsOptions options;
  options.rest_scale = 0.0;
  EXPECT_THROW(measure_map(grid, x, options), InvalidInputError);
  options = {};
  options.outside.assign(3, 0);
  EXPECT_THROW(measure_map(grid, x, options), InvalidInputError);
  Eigen::Matrix3Xd bad = x;
  bad(0, 4) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(measure_map(grid, bad), InvalidInputError);
}

TEST(MapMetrics, MetricNamesRoundTrip) {
  for (const TriangleMetric metric : all_triangle_metrics()) {
    EXPECT_EQ(parse_triangle_metric(to_string(metric)), metric);
  }
  EXPECT_THROW(parse_triangle_metric("stretch"), InvalidInputError);
  EXPECT_EQ(perfect_value(TriangleMetric::SymmetricDirichlet), 4.0);
}

}  // namespace
}  // namespace elastic
