// LimitSurface: derivatives against finite differences, exact reproduction of affine and planar
// configurations, boundary interpolation, curvature of spheres and tori against the analytic
// values, ptex conventions, and input validation.
#include "elastic/surface/limit_surface.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"
#include "support.h"
#include "surface/surface_test_meshes.h"

namespace elastic {
namespace {

using test::cube;
using test::quad_grid;
using test::triangle_grid;

/// True when (u, v) is at least `margin` (in units of the finest patch size 2^-level) away from the
/// dyadic lines where adaptive patches meet (and, for triangles, the diagonals u + v = k 2^-level).
/// Finite differences must not straddle two patches: the limit surface is only C1 (G1 at Gregory
/// end caps) across them, so a straddling difference quotient would not converge to the second
/// derivative.
bool away_from_patch_seams(double u, double v, bool triangle, int level, double margin) {
  const double scale = std::ldexp(1.0, level);
  auto far_from_grid = [&](double x) {
    const double f = x * scale - std::floor(x * scale);
    return f > margin && f < 1.0 - margin;
  };
  if (!far_from_grid(u) || !far_from_grid(v)) {
    return false;
  }
  return !triangle || (far_from_grid(u + v) && u + v < 1.0 - margin / scale);
}

/// Random parameter points inside every ptex face, plus points close to every ptex corner (where
/// the extraordinary-vertex patches are), all away from patch seams.
std::vector<SurfacePoint> sample_points(const LimitSurface& s, int per_face, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<SurfacePoint> out;
  const bool tri = s.triangular_domain();
  for (int f = 0; f < s.num_faces(); ++f) {
    int added = 0;
    while (added < per_face) {
      const double u = uni(rng), v = uni(rng);
      if (tri && u + v > 1.0) {
        continue;
      }
      if (!away_from_patch_seams(u, v, tri, 6, 0.05)) {
        continue;
      }
      out.push_back({f, u, v});
      ++added;
    }
    // Near each corner, inside the finest (depth-6) patches: offsets of 0.3 and 0.6 patch widths.
    const double a = 0.3 / 64.0, b = 0.6 / 64.0;
    if (tri) {
      out.push_back({f, a, b});
      out.push_back({f, 1.0 - a - b - 0.5 / 64.0, a});
      out.push_back({f, b, 1.0 - a - b - 0.5 / 64.0});
    } else {
      out.push_back({f, a, b});
      out.push_back({f, 1.0 - a, b});
      out.push_back({f, 1.0 - b, 1.0 - a});
      out.push_back({f, a, 1.0 - b});
    }
  }
  return out;
}

/// Checks first derivatives against central differences of positions, second derivatives against
/// central differences of first derivatives, step h = 1e-6 in ptex units.
/// Tolerances: the truncation error is h^2/6 |P'''|; near an extraordinary vertex the depth-6
/// patches are 1/64 wide so |P'''| can reach ~64^2 |P'|, i.e. 1e-12 * 4096 / 6 ~ 1e-9 relative;
/// round-off is eps |P| / h ~ 1e-10 |P|. 1e-7 relative to the local derivative size leaves a wide
/// margin while still catching any missing factor (2, -1) or wrong basis (errors of order 1).
void expect_derivatives_match_differences(const LimitSurface& s,
                                          const std::vector<SurfacePoint>& pts) {
  const double h = 1e-6;
  const double position_scale = [&] {
    double m = 1.0;
    for (const auto& p : s.control_mesh().positions) {
      m = std::max(m, p.norm());
    }
    return m;
  }();
  int checked = 0;
  for (const SurfacePoint& p : pts) {
    const SurfaceDerivatives d = s.derivatives(p);
    const SurfacePoint pu0{p.face, p.u - h, p.v}, pu1{p.face, p.u + h, p.v};
    const SurfacePoint pv0{p.face, p.u, p.v - h}, pv1{p.face, p.u, p.v + h};
    const Eigen::Vector3d fd_u = (s.position(pu1) - s.position(pu0)) / (2 * h);
    const Eigen::Vector3d fd_v = (s.position(pv1) - s.position(pv0)) / (2 * h);
    const SurfaceDerivatives du0 = s.derivatives(pu0), du1 = s.derivatives(pu1);
    const SurfaceDerivatives dv0 = s.derivatives(pv0), dv1 = s.derivatives(pv1);
    const Eigen::Vector3d fd_uu = (du1.du - du0.du) / (2 * h);
    const Eigen::Vector3d fd_uv = (dv1.du - dv0.du) / (2 * h);
    const Eigen::Vector3d fd_vu = (du1.dv - du0.dv) / (2 * h);
    const Eigen::Vector3d fd_vv = (dv1.dv - dv0.dv) / (2 * h);
    const double s1 = std::max(d.du.norm(), d.dv.norm());
    const double s2 = std::max({d.duu.norm(), d.duv.norm(), d.dvv.norm(), s1});
    const double tol1 = 1e-7 * s1 + 1e-9 * position_scale;
    const double tol2 = 1e-6 * s2;
    const std::string where = "ptex face " + std::to_string(p.face) + " (" + std::to_string(p.u) +
                              ", " + std::to_string(p.v) + ")";
    EXPECT_LT((d.du - fd_u).norm(), tol1) << where;
    EXPECT_LT((d.dv - fd_v).norm(), tol1) << where;
    EXPECT_LT((d.duu - fd_uu).norm(), tol2) << where;
    EXPECT_LT((d.duv - fd_uv).norm(), tol2) << where;
    EXPECT_LT((d.duv - fd_vu).norm(), tol2) << where;
    EXPECT_LT((d.dvv - fd_vv).norm(), tol2) << where;
    EXPECT_LT((d.position - s.position(p)).norm(), 1e-14 * position_scale) << where;
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

TEST(LimitSurface, DerivativesMatchFiniteDifferencesOnCube) {
  const LimitSurface s(cube(), {.name = "cube"});
  EXPECT_EQ(s.scheme(), SubdivisionScheme::CatmullClark);
  EXPECT_EQ(s.num_faces(), 6);
  expect_derivatives_match_differences(s, sample_points(s, 12, 1));
}

TEST(LimitSurface, DerivativesMatchFiniteDifferencesOnCurvedQuadGridWithBoundary) {
  PolygonMesh mesh = quad_grid(5, 4, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, true);
  test::jitter(mesh, 0.3, 7);
  const LimitSurface s(mesh, {.name = "grid"});
  expect_derivatives_match_differences(s, sample_points(s, 6, 2));
}

TEST(LimitSurface, DerivativesMatchFiniteDifferencesOnLoopMeshes) {
  const LimitSurface sphere(test::icosphere(1, 1.0), {.name = "icosphere"});
  EXPECT_EQ(sphere.scheme(), SubdivisionScheme::Loop);
  EXPECT_TRUE(sphere.triangular_domain());
  expect_derivatives_match_differences(sphere, sample_points(sphere, 4, 3));

  PolygonMesh grid = triangle_grid(4, 4, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  test::jitter(grid, 0.3, 8);
  const LimitSurface open(grid, {.name = "triangle grid"});
  expect_derivatives_match_differences(open, sample_points(open, 4, 4));
}

TEST(LimitSurface, DerivativesMatchFiniteDifferencesOnMixedMesh) {
  // Pentagon and triangles under Catmull-Clark: n-gon sub-faces (non-quad roots).
  const LimitSurface s(test::mixed_solid(), {.name = "mixed"});
  EXPECT_EQ(s.scheme(), SubdivisionScheme::CatmullClark);
  EXPECT_EQ(s.num_faces(), 5 + 5 + 15);  // pentagon: 5 sub-faces, quads: 1 each, triangles: 3 each
  expect_derivatives_match_differences(s, sample_points(s, 6, 5));
}

TEST(LimitSurface, CatmullClarkOnTrianglesWhenForced) {
  const LimitSurface s(test::icosphere(0, 1.0), {.scheme = SubdivisionScheme::CatmullClark});
  EXPECT_EQ(s.scheme(), SubdivisionScheme::CatmullClark);
  EXPECT_FALSE(s.triangular_domain());
  EXPECT_EQ(s.num_faces(), 60);
  expect_derivatives_match_differences(s, sample_points(s, 2, 6));
}

// --- Ptex conventions -------------------------------------------------------------------------

TEST(LimitSurface, PtexCornersFollowTheControlFaceOrder) {
  // On a flat affine grid the limit is the affine map itself, so a ptex corner's limit position is
  // exactly its control vertex (the boundary rule keeps corners and straight edges in place).
  const PolygonMesh mesh = quad_grid(3, 3, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, true);
  const LimitSurface s(mesh);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto fv = mesh.face(f);
    const double corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d x = s.position({s.first_ptex_face(f), corners[c][0], corners[c][1]});
      EXPECT_LT((x - mesh.positions[static_cast<size_t>(fv[static_cast<size_t>(c)])]).norm(),
                1e-12);
    }
    // du x dv points along the control face normal (+z).
    const SurfaceDerivatives d = s.derivatives(s.face_center(s.first_ptex_face(f)));
    EXPECT_GT(d.du.cross(d.dv).z(), 0.0);
  }
}

TEST(LimitSurface, NgonSubFacesFollowTheDocumentedConvention) {
  // Sub-face i: (0,0) at corner i, (1,0) at the midpoint of edge (i, i+1), (1,1) at the centre,
  // (0,1) at the midpoint of edge (i-1, i). Shared points must coincide between sub-faces, and the
  // corner must be the limit point of vertex i (vertex_point gives another face's representation).
  const PolygonMesh mesh = test::mixed_solid();
  const LimitSurface s(mesh);
  const int first = s.first_ptex_face(0);  // the pentagon
  for (int i = 0; i < 5; ++i) {
    const int a = first + i, b = first + (i + 1) % 5;
    EXPECT_EQ(s.control_face(a), 0);
    const Eigen::Vector3d mid_a = s.position({a, 1, 0}), mid_b = s.position({b, 0, 1});
    EXPECT_LT((mid_a - mid_b).norm(), 1e-12);
    EXPECT_LT((s.position({a, 1, 1}) - s.position({b, 1, 1})).norm(), 1e-12);
    const int vertex = mesh.face(0)[static_cast<size_t>(i)];
    EXPECT_LT((s.position({a, 0, 0}) - s.position(s.vertex_point(vertex))).norm(), 1e-12);
    // The sub-face corner lies closer to its own control vertex than to any other of the pentagon.
    const Eigen::Vector3d x = s.position({a, 0, 0});
    for (int j = 0; j < 5; ++j) {
      if (j == i) {
        continue;
      }
      EXPECT_LT(
          (x - mesh.positions[static_cast<size_t>(vertex)]).norm(),
          (x - mesh.positions[static_cast<size_t>(mesh.face(0)[static_cast<size_t>(j)])]).norm());
    }
  }
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int n = mesh.face_size(f);
    const int count = (f + 1 < mesh.num_faces() ? s.first_ptex_face(f + 1) : s.num_faces()) -
                      s.first_ptex_face(f);
    EXPECT_EQ(count, n == 4 ? 1 : n);
    for (int k = 0; k < count; ++k) {
      EXPECT_EQ(s.control_face(s.first_ptex_face(f) + k), f);
    }
  }
}

TEST(LimitSurface, VertexPointsAreLimitPositionsOfTheirVertex) {
  // Every face around a vertex must agree on the vertex's limit position.
  for (const PolygonMesh& mesh : {cube(), test::mixed_solid(), test::icosphere(1, 1.0)}) {
    const LimitSurface s(mesh);
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const auto fv = mesh.face(f);
      const int n = static_cast<int>(fv.size());
      for (int c = 0; c < n; ++c) {
        SurfacePoint p;
        if (s.triangular_domain()) {
          p = {s.first_ptex_face(f), c == 1 ? 1.0 : 0.0, c == 2 ? 1.0 : 0.0};
        } else if (n == 4) {
          p = {s.first_ptex_face(f), c == 1 || c == 2 ? 1.0 : 0.0, c >= 2 ? 1.0 : 0.0};
        } else {
          p = {s.first_ptex_face(f) + c, 0.0, 0.0};
        }
        const Eigen::Vector3d expected = s.position(s.vertex_point(fv[static_cast<size_t>(c)]));
        EXPECT_LT((s.position(p) - expected).norm(), 1e-12) << "face " << f << " corner " << c;
      }
    }
  }
}

// --- Exact reproduction ------------------------------------------------------------------------

TEST(LimitSurface, FlatBilinearGridReproducesTheAffineMap) {
  // B-splines reproduce affine functions, and so do the boundary rules (phantom points are linear
  // extrapolations): the limit of an affine grid is the affine map, derivatives a and b, no
  // curvature. Tolerance: round-off of sums of ~16 terms of size |origin| + 6 |a|.
  const Eigen::Vector3d origin(0.3, -1.2, 2.0), a(0.7, 0.2, -0.1), b(-0.15, 0.5, 0.4);
  const LimitSurface s(quad_grid(6, 5, origin, a, b), {.name = "affine"});
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (int f = 0; f < s.num_faces(); ++f) {
    const int i = f % 6, j = f / 6;
    for (int k = 0; k < 10; ++k) {
      const SurfacePoint p{f, uni(rng), uni(rng)};
      const SurfaceDerivatives d = s.derivatives(p);
      EXPECT_LT((d.position - (origin + (i + p.u) * a + (j + p.v) * b)).norm(), 1e-13);
      EXPECT_LT((d.du - a).norm(), 1e-12);
      EXPECT_LT((d.dv - b).norm(), 1e-12);
      EXPECT_LT(d.duu.norm() + d.duv.norm() + d.dvv.norm(), 1e-11);
    }
  }
}

TEST(LimitSurface, PlanarMeshesWithIrregularVerticesStayInThePlane) {
  // Subdivision is affine-invariant and every rule is an affine combination, so a planar control
  // mesh has a planar limit: z = 0, normal +z, zero curvature, also at extraordinary vertices and
  // in n-gons. Tolerances are round-off (coordinates ~2).
  for (const PolygonMesh& mesh :
       {test::flat_wheel(5, true), test::flat_wheel(5, false), test::flat_wheel(3, true),
        triangle_grid(3, 3, {0, 0, 0}, {1, 0, 0}, {0.4, 1, 0})}) {
    const LimitSurface s(mesh);
    for (const SurfacePoint& p : sample_points(s, 6, 12)) {
      const SurfaceDerivatives d = s.derivatives(p);
      EXPECT_LT(std::abs(d.position.z()), 1e-13);
      EXPECT_LT(std::abs(d.du.z()) + std::abs(d.dv.z()), 1e-10);
      EXPECT_LT(std::abs(d.duu.z()) + std::abs(d.duv.z()) + std::abs(d.dvv.z()), 1e-7);
      const SurfaceCurvature k = s.curvature(p);
      EXPECT_NEAR(k.normal.z(), 1.0, 1e-12);
      EXPECT_LT(std::abs(k.k1) + std::abs(k.k2), 1e-9);
    }
  }
}

TEST(LimitSurface, OpenGridBoundaryLimitLiesOnTheControlBoundaryLines) {
  // With VTX_BOUNDARY_EDGE_AND_CORNER the boundary limit curve is the cubic B-spline of the
  // boundary polygon alone, and corners are interpolated. Boundary vertices are placed on the four
  // sides of the square (unevenly spaced), interior vertices are jittered in 3D: the limit boundary
  // must lie on the sides (to round-off) and the corners must be the control corners.
  PolygonMesh mesh = quad_grid(5, 5, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(-0.3, 0.3);
  for (int j = 0; j <= 5; ++j) {
    for (int i = 0; i <= 5; ++i) {
      Eigen::Vector3d& p = mesh.positions[static_cast<size_t>(j) * 6 + static_cast<size_t>(i)];
      const bool bi = i == 0 || i == 5, bj = j == 0 || j == 5;
      if (!bi) {
        p.x() += uni(rng);
      }
      if (!bj) {
        p.y() += uni(rng);
      }
      if (!bi && !bj) {
        p.z() += uni(rng);
      }
    }
  }
  const LimitSurface s(mesh, {.name = "open grid"});
  int checked = 0, boundary_edges = 0;
  for (int f = 0; f < s.num_faces(); ++f) {
    for (const SurfacePoint& mid : {SurfacePoint{f, 0.5, 0}, SurfacePoint{f, 1, 0.5},
                                    SurfacePoint{f, 0.5, 1}, SurfacePoint{f, 0, 0.5}}) {
      boundary_edges += s.on_boundary(mid) ? 1 : 0;
    }
    for (int k = 0; k <= 20; ++k) {
      const double t = k / 20.0;
      for (const SurfacePoint& p : {SurfacePoint{f, t, 0}, SurfacePoint{f, 1, t},
                                    SurfacePoint{f, t, 1}, SurfacePoint{f, 0, t}}) {
        if (!s.on_boundary(p)) {
          continue;
        }
        ++checked;
        const Eigen::Vector3d x = s.position(p);
        const double side =
            std::min({std::abs(x.x()), std::abs(x.x() - 5), std::abs(x.y()), std::abs(x.y() - 5)});
        EXPECT_LT(side, 1e-13) << "face " << f;
        EXPECT_LT(std::abs(x.z()), 1e-13);
      }
    }
  }
  EXPECT_EQ(boundary_edges, 20);
  EXPECT_GE(checked, 20 * 21);
  EXPECT_LT((s.position(s.vertex_point(0)) - mesh.positions[0]).norm(), 1e-13);
  EXPECT_LT((s.position(s.vertex_point(35)) - mesh.positions[35]).norm(), 1e-13);
}

// --- Curvature -----------------------------------------------------------------------------------

TEST(LimitSurface, CurvatureOfAnalyticQuadraticPatch) {
  // Independent check of the fundamental-form algebra: a paraboloid-like height field
  // z = (x^2 * kx + y^2 * ky) / 2 sampled by the control points of a B-spline reproduces quadratics
  // only up to a constant offset, so instead feed the static curvature() exact derivatives of
  // P(u, v) = (u, v, (a u^2 + 2 b u v + c v^2) / 2) at the origin, where the shape operator is
  // -[a b; b c] in our sign convention (normal +z, surface bending towards +z for a > 0).
  SurfaceDerivatives d;
  d.du = {1, 0, 0};
  d.dv = {0, 1, 0};
  const double a = 0.8, b = 0.3, c = -0.5;
  d.duu = {0, 0, a};
  d.duv = {0, 0, b};
  d.dvv = {0, 0, c};
  const SurfaceCurvature k = LimitSurface::curvature(d);
  const double mean = -(a + c) / 2, radius = std::hypot((a - c) / 2, b);
  EXPECT_NEAR(k.k1, mean + radius, 1e-14);
  EXPECT_NEAR(k.k2, mean - radius, 1e-14);
  EXPECT_NEAR(k.mean, mean, 1e-14);
  EXPECT_NEAR(k.gaussian, a * c - b * b, 1e-14);
  // dir1 is an eigenvector of -[a b; b c] with eigenvalue k1.
  Eigen::Matrix2d shape;
  shape << -a, -b, -b, -c;
  const Eigen::Vector2d e(k.dir1.x(), k.dir1.y());
  EXPECT_LT((shape * e - k.k1 * e).norm(), 1e-14);
  EXPECT_NEAR(k.dir1.cross(k.dir2).dot(k.normal), 1.0, 1e-14);
  // Skewed parametrisation of the same surface: P(s, t) = P(s + 0.5 t, 2 t). Same curvatures.
  SurfaceDerivatives skew;
  skew.du = d.du;
  skew.dv = 0.5 * d.du + 2.0 * d.dv;
  skew.duu = d.duu;
  skew.duv = 0.5 * d.duu + 2.0 * d.duv;
  skew.dvv = 0.25 * d.duu + 2.0 * d.duv + 4.0 * d.dvv;
  const SurfaceCurvature ks = LimitSurface::curvature(skew);
  EXPECT_NEAR(ks.k1, k.k1, 1e-13);
  EXPECT_NEAR(ks.k2, k.k2, 1e-13);
  EXPECT_LT((ks.dir1 - k.dir1).norm() * (ks.dir1 + k.dir1).norm(), 1e-12);  // same up to sign
}

void expect_sphere_curvature(const LimitSurface& s, double tolerance) {
  const double band = std::sin(60.0 * std::numbers::pi / 180.0);
  int checked = 0;
  for (const SurfacePoint& p : sample_points(s, 2, 21)) {
    const SurfaceDerivatives d = s.derivatives(p);
    const double r = d.position.norm();
    if (std::abs(d.position.z()) > band * r) {
      continue;  // polar caps: see the test's comment
    }
    const SurfaceCurvature k = s.curvature(d);
    EXPECT_NEAR(k.k1 * r, 1.0, tolerance) << "face " << p.face << " (" << p.u << ", " << p.v << ")";
    EXPECT_NEAR(k.k2 * r, 1.0, tolerance) << "face " << p.face << " (" << p.u << ", " << p.v << ")";
    EXPECT_GT(k.normal.dot(d.position / r), 0.999);  // outward and radial
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

TEST(LimitSurface, SphereCurvatureIsOneOverRadius) {
  // The limit of a spherical control mesh is close to, not exactly, a sphere. On a smooth 64 x 32
  // latitude-longitude net (h = 2 pi / 64) the error of k r is O(h^2): measured 0.36% (quads) and
  // 0.47% (triangles, Loop) between latitudes -60 and 60 degrees, and it shrinks 4x when h halves;
  // 1% is the bound asked for. Near the valence-64 poles the error grows without bound (curvature
  // of Catmull-Clark and Loop surfaces diverges at high-valence extraordinary vertices), and near
  // the corners of cube- or icosahedron-based spheres it stays at 10-30% however fine the mesh:
  // both are properties of subdivision surfaces, not of the evaluation, so those regions are not
  // tested here.
  expect_sphere_curvature(LimitSurface(test::uv_sphere(64, 32, 2.0, false), {.name = "uv sphere"}),
                          0.01);
  expect_sphere_curvature(
      LimitSurface(test::uv_sphere(64, 32, 2.0, true), {.name = "uv sphere tri"}), 0.01);
}

TEST(LimitSurface, TorusCurvatureMatchesTheAnalyticTorus) {
  // Torus of major radius R around z: at a point at distance rho from the axis and tube radius r
  // (both measured on the limit surface, since the limit of the control torus is slightly thinner),
  // with outward normals: k1 = 1/r (around the tube), k2 = cos(v) / rho = (rho - R) / (r rho).
  // The limit is not exactly a torus; the error is O(h^2): with 64 x 32 control points measured
  // max errors are 0.94% (k1 r) and 0.17% (k2 r), falling to 0.24% / 0.04% at 128 x 64. Bounds
  // 1.5% and 0.3% keep a margin over the measurement.
  const double R = 1.0, r0 = 0.35;
  const LimitSurface s(test::torus(64, 32, R, r0), {.name = "torus"});
  for (const SurfacePoint& p : sample_points(s, 1, 31)) {
    const SurfaceDerivatives d = s.derivatives(p);
    const SurfaceCurvature k = s.curvature(d);
    const double rho = std::hypot(d.position.x(), d.position.y());
    const double r = std::hypot(rho - R, d.position.z());
    EXPECT_NEAR(k.k1 * r, 1.0, 0.015);
    EXPECT_NEAR(k.k2 * r, (rho - R) / rho, 0.003);
    // dir1 runs around the tube: orthogonal to the azimuthal direction (measured < 1e-4).
    const Eigen::Vector3d azimuth =
        Eigen::Vector3d(-d.position.y(), d.position.x(), 0).normalized();
    EXPECT_LT(std::abs(k.dir1.dot(azimuth)), 1e-3);
    EXPECT_NEAR(k.dir1.cross(k.dir2).dot(k.normal), 1.0, 1e-12);
  }
}

TEST(LimitSurface, NormalVariationAdjointOnAnAnalyticSphere) {
  // P(theta, phi) = r (sin t cos p, sin t sin p, cos t): P_t x P_p points outwards and dn(delta) =
  // delta / r, so the adjoint of any v is its tangential part over r.
  const double r = 1.7, t = 0.9, ph = 0.4;
  const Eigen::Vector3d radial(std::sin(t) * std::cos(ph), std::sin(t) * std::sin(ph), std::cos(t));
  SurfaceDerivatives d;
  d.position = r * radial;
  d.du = r * Eigen::Vector3d(std::cos(t) * std::cos(ph), std::cos(t) * std::sin(ph), -std::sin(t));
  d.dv = r * Eigen::Vector3d(-std::sin(t) * std::sin(ph), std::sin(t) * std::cos(ph), 0.0);
  d.duu = -d.position;
  d.duv = r * Eigen::Vector3d(-std::cos(t) * std::sin(ph), std::cos(t) * std::cos(ph), 0.0);
  d.dvv = r * Eigen::Vector3d(-std::sin(t) * std::cos(ph), -std::sin(t) * std::sin(ph), 0.0);
  const Eigen::Vector3d v(0.3, -1.1, 0.7);
  const Eigen::Vector3d expected = (v - radial * radial.dot(v)) / r;
  EXPECT_LT((LimitSurface::normal_variation_adjoint(d, v) - expected).norm(), 1e-14);
  // Degenerate derivatives: no tangent plane, no variation.
  SurfaceDerivatives flat = d;
  flat.dv = flat.du;
  EXPECT_TRUE(LimitSurface::normal_variation_adjoint(flat, v).isZero(0.0));
}

TEST(LimitSurface, NormalVariationAdjointMatchesFiniteDifferencesOfTheNormal) {
  // On the torus (every vertex regular: the limit is C2, its normal C1 everywhere) the identity
  // v . dn(delta) = w . delta is checked against central differences of the unit normal along
  // parameter directions (alpha, beta), delta = du alpha + dv beta.
  const LimitSurface s(test::torus(32, 16, 1.0, 0.35), {.name = "torus"});
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss;
  const double h = 1e-5;
  int checked = 0;
  for (const SurfacePoint& p : sample_points(s, 1, 7)) {
    // sample_points keeps every point at least 7.8e-4 ptex units off patch seams and face edges:
    // the differences below (at most a few h) stay inside one patch.
    const SurfaceDerivatives d = s.derivatives(p);
    const Eigen::Vector3d v(gauss(rng), gauss(rng), gauss(rng));
    const double alpha = gauss(rng), beta = gauss(rng);
    auto normal = [&](double step) {
      return s.curvature(SurfacePoint{p.face, p.u + step * alpha, p.v + step * beta}).normal;
    };
    const double fd = v.dot(normal(h) - normal(-h)) / (2 * h);
    const double exact =
        LimitSurface::normal_variation_adjoint(d, v).dot(alpha * d.du + beta * d.dv);
    EXPECT_NEAR(exact, fd, 1e-6 * (1.0 + std::abs(fd)))
        << "face " << p.face << " (" << p.u << ", " << p.v << ")";
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

TEST(LimitSurface, CurvatureAtExtraordinaryCornersIsFinite) {
  for (const PolygonMesh& mesh : {cube(), test::mixed_solid(), test::icosphere(0, 1.0)}) {
    const LimitSurface s(mesh);
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      const SurfaceCurvature k = s.curvature(s.vertex_point(v));
      EXPECT_TRUE(std::isfinite(k.k1) && std::isfinite(k.k2));
      EXPECT_NEAR(k.normal.norm(), 1.0, 1e-12);
    }
    for (int f = 0; f < s.num_faces(); ++f) {
      const SurfaceCurvature k =
          s.curvature(SurfacePoint{f, 1.0, s.triangular_domain() ? 0.0 : 1.0});
      EXPECT_TRUE(std::isfinite(k.k1) && std::isfinite(k.k2));
    }
  }
}

// --- Shared test meshes -------------------------------------------------------------------------

void expect_limit_consistent(const LimitSurface& s) {
  // Spot checks that work on any mesh: derivatives against differences, vertex points agree.
  expect_derivatives_match_differences(s, sample_points(s, 1, 41));
}

TEST(LimitSurface, SharedCube) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "osd_catmark_cube.obj");
  const PolygonMesh mesh = read_mesh(path).mesh;
  const LimitSurface s(mesh, {.name = path.string()});
  EXPECT_EQ(s.num_faces(), 6);
  expect_limit_consistent(s);
  // Cube symmetry: the limit of every face centre is at the same distance from the cube's centre.
  // The file's coordinates are rounded to 6 decimals (1.414214 for sqrt 2), so the cube is
  // symmetric to ~1e-6 only.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : mesh.positions) {
    centre += p / mesh.num_vertices();
  }
  const double r0 = (s.position(s.face_center(0)) - centre).norm();
  for (int f = 1; f < 6; ++f) {
    EXPECT_NEAR((s.position(s.face_center(f)) - centre).norm(), r0, 2e-6);
  }
}

TEST(LimitSurface, SharedPawnWithCreases) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "osd_catmark_pawn.obj");
  const PolygonMesh mesh = read_mesh(path).mesh;
  ASSERT_FALSE(mesh.creases.empty()) << "the pawn's `t crease` tags were not read";
  const LimitSurface creased(mesh, {.name = path.string()});
  const LimitSurface smooth(mesh, {.use_creases = false, .name = path.string()});
  expect_limit_consistent(creased);
  // Creases pull the limit towards the control mesh: somewhere the two limits differ, by a visible
  // fraction of the pawn's size (measured ~1e-3 of a ~2.6 unit tall model).
  double max_difference = 0.0;
  for (int f = 0; f < creased.num_faces(); ++f) {
    max_difference = std::max(
        max_difference,
        (creased.position(creased.face_center(f)) - smooth.position(smooth.face_center(f))).norm());
  }
  EXPECT_GT(max_difference, 1e-4);
}

TEST(LimitSurface, SharedSpotControlMesh) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "spot_control_mesh.obj");
  const PolygonMesh mesh = read_mesh(path).mesh;
  const LimitSurface s(mesh, {.name = path.string()});
  EXPECT_EQ(s.scheme(), SubdivisionScheme::CatmullClark);
  EXPECT_EQ(s.num_faces(), 160 + 4 * 3 + 16 * 5);
  expect_limit_consistent(s);
}

TEST(LimitSurface, SmoothIsolationDepthDefaultsByMeshSize) {
  // Up to kDenseMeshFaces control faces the smooth extraordinary vertices get the full depth; a
  // larger mesh gets 2; an explicit value wins, and one outside 1..isolation_level is refused.
  const LimitSurface small(quad_grid(100, 100, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}), {});
  EXPECT_EQ(small.smooth_isolation_level(), 6);
  const LimitSurface dense(quad_grid(161, 160, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}), {});
  ASSERT_GT(dense.num_faces(), kDenseMeshFaces);
  EXPECT_EQ(dense.smooth_isolation_level(), 2);
  const LimitSurface chosen(quad_grid(161, 160, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}),
                            {.smooth_isolation_level = 5});
  EXPECT_EQ(chosen.smooth_isolation_level(), 5);
  const PolygonMesh grid = quad_grid(4, 4, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  for (const int bad : {0, -2, 7}) {
    EXPECT_THROW(LimitSurface(grid, {.smooth_isolation_level = bad}), InvalidInputError) << bad;
  }
  EXPECT_THROW(LimitSurface(grid, {.isolation_level = 3, .smooth_isolation_level = 4}),
               InvalidInputError);
}

TEST(LimitSurface, ShallowSmoothIsolationKeepsLoopsLimitPoints) {
  // An independent answer at the extraordinary vertices themselves, where the shallow depth leaves
  // the largest Gregory end caps: the Gregory corners interpolate the limit point, which for Loop
  // is (1 - n chi) x + chi sum of the ring, chi = 1 / (3 / (8 beta) + n), beta = (5/8 - (3/8 +
  // cos(2 pi / n) / 4)^2) / n (Loop 1987). An icosphere has valence-5 and valence-6 vertices.
  const PolygonMesh mesh = test::icosphere(2, 1.0);
  std::vector<std::vector<int>> ring(static_cast<size_t>(mesh.num_vertices()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto fv = mesh.face(f);
    for (size_t c = 0; c < 3; ++c) {
      std::vector<int>& r = ring[static_cast<size_t>(fv[c])];
      const int next = fv[(c + 1) % 3];
      if (std::find(r.begin(), r.end(), next) == r.end()) {
        r.push_back(next);
      }
    }
  }
  for (const int depth : {2, 6}) {
    const LimitSurface s(mesh, {.smooth_isolation_level = depth});
    ASSERT_EQ(s.smooth_isolation_level(), depth);
    int extraordinary = 0;
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      const std::vector<int>& r = ring[static_cast<size_t>(v)];
      const double n = static_cast<double>(r.size());
      const double a = 3.0 / 8.0 + 0.25 * std::cos(2.0 * std::numbers::pi / n);
      const double beta = (5.0 / 8.0 - a * a) / n;
      const double chi = 1.0 / (3.0 / (8.0 * beta) + n);
      Eigen::Vector3d expected = (1.0 - n * chi) * mesh.positions[static_cast<size_t>(v)];
      for (const int j : r) {
        expected += chi * mesh.positions[static_cast<size_t>(j)];
      }
      extraordinary += r.size() != 6 ? 1 : 0;
      EXPECT_LT((s.position(s.vertex_point(v)) - expected).norm(), 1e-12)
          << "depth " << depth << " vertex " << v << " valence " << r.size();
    }
    EXPECT_EQ(extraordinary, 12);
  }
}

TEST(LimitSurface, ShallowSmoothIsolationStaysCloseToTheDeepLimit) {
  // The documented price of depth 2 on a real mesh (LimitSurfaceOptions::smooth_isolation_level):
  // positions within 1e-3 of the bounding box's diagonal of depth 6 at random points, and the
  // option takes effect (the surfaces differ near extraordinary vertices).
  ELASTIC_REQUIRE_SHARED_MESH(path, "bob_tri.obj");
  const PolygonMesh mesh = read_mesh(path).mesh;
  const LimitSurface deep(mesh, {.smooth_isolation_level = 6});
  const LimitSurface shallow(mesh, {.smooth_isolation_level = 2});
  EXPECT_EQ(deep.smooth_isolation_level(), 6);
  Eigen::Vector3d lo = mesh.positions.front(), hi = lo;
  for (const Eigen::Vector3d& p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double diagonal = (hi - lo).norm();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double largest = 0.0;
  for (int i = 0; i < 20000; ++i) {
    SurfacePoint q;
    q.face = static_cast<int>(rng() % static_cast<unsigned>(deep.num_faces()));
    q.u = unit(rng);
    q.v = unit(rng);
    if (q.u + q.v > 1.0) {  // Loop: the ptex triangle u + v <= 1
      q.u = 1.0 - q.u;
      q.v = 1.0 - q.v;
    }
    largest = std::max(largest, (deep.position(q) - shallow.position(q)).norm());
  }
  EXPECT_LT(largest, 1e-3 * diagonal);
  EXPECT_GT(largest, 1e-7 * diagonal);
}

TEST(LimitSurface, SharedNonManifoldMeshIsRejected) {
  // 9 non-manifold edges, a non-manifold vertex, faces with repeated vertices (README of the shared
  // meshes): OpenSubdiv would accept it, the LimitSurface must not.
  ELASTIC_REQUIRE_SHARED_MESH(path, "osd_catmark_nonman_edges.obj");
  const PolygonMesh mesh = read_mesh(path).mesh;
  try {
    const LimitSurface s(mesh, {.name = path.string()});
    ADD_FAILURE() << "accepted a non-manifold mesh";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(e.input(), path.string());
  }
}

// --- Errors
// ----------------------------------------------------------------------------------------

template <class F>
void expect_invalid(F&& make, const std::string& needle) {
  try {
    make();
    ADD_FAILURE() << "expected InvalidInputError mentioning '" << needle << "'";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(e.input(), "bad-mesh");
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(LimitSurface, RejectsBadInput) {
  const LimitSurfaceOptions named{.name = "bad-mesh"};
  expect_invalid([&] { LimitSurface s(PolygonMesh{}, named); }, "empty");
  // Three quads on one edge.
  PolygonMesh fin = quad_grid(1, 1, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  fin.positions.emplace_back(0, 0, 1);
  fin.positions.emplace_back(1, 0, 1);
  fin.positions.emplace_back(0, 0, -1);
  fin.positions.emplace_back(1, 0, -1);
  fin.add_face({1, 0, 4, 5});
  fin.add_face({0, 1, 7, 6});
  expect_invalid([&] { LimitSurface s(fin, named); }, "non-manifold");
  // Two faces traversing an edge in the same direction.
  PolygonMesh flipped = quad_grid(2, 1, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  std::reverse(flipped.face_vertices.begin() + 4, flipped.face_vertices.end());
  expect_invalid([&] { LimitSurface s(flipped, named); }, "orientation");
  // Two fans touching at one vertex (bow tie).
  PolygonMesh bowtie;
  bowtie.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
  bowtie.add_face({0, 1, 2});
  bowtie.add_face({0, 3, 4});
  expect_invalid([&] { LimitSurface s(bowtie, named); }, "non-manifold");
  LimitSurfaceOptions loop = named;
  loop.scheme = SubdivisionScheme::Loop;
  expect_invalid([&] { LimitSurface s(cube(), loop); }, "Loop");
  for (int level : {0, 11}) {
    LimitSurfaceOptions o = named;
    o.isolation_level = level;
    expect_invalid([&] { LimitSurface s(cube(), o); }, "isolation_level");
  }
  PolygonMesh out_of_range = cube();
  out_of_range.face_vertices[3] = 42;
  expect_invalid([&] { LimitSurface s(out_of_range, named); }, "vertex 42");
  PolygonMesh nan_mesh = cube();
  nan_mesh.positions[2].x() = std::nan("");
  expect_invalid([&] { LimitSurface s(nan_mesh, named); }, "non-finite");
  PolygonMesh bad_crease = cube();
  bad_crease.creases.push_back({0, 7, 2.0});  // a diagonal, not an edge
  expect_invalid([&] { LimitSurface s(bad_crease, named); }, "crease");

  const LimitSurface s(cube(), named);
  expect_invalid([&] { (void)s.position({6, 0.5, 0.5}); }, "ptex face 6");
  expect_invalid([&] { (void)s.position({-1, 0.5, 0.5}); }, "ptex face -1");
  expect_invalid([&] { (void)s.vertex_point(8); }, "vertex 8");
}

TEST(LimitSurface, DomainQueries) {
  const LimitSurface quads(cube());
  EXPECT_TRUE(quads.in_domain({0, 1.0, 1.0}));
  EXPECT_FALSE(quads.in_domain({0, 1.0 + 1e-9, 0.5}));
  EXPECT_TRUE(quads.in_domain({0, 1.0 + 1e-9, 0.5}, 1e-8));
  EXPECT_FALSE(quads.in_domain({6, 0.5, 0.5}));
  EXPECT_FALSE(quads.in_domain({0, std::nan(""), 0.5}));
  EXPECT_FALSE(quads.on_boundary({0, 0.0, 0.5}));  // closed: no boundary anywhere
  const LimitSurface tris(test::icosphere(0, 1.0));
  EXPECT_TRUE(tris.in_domain({0, 0.5, 0.5}));
  EXPECT_FALSE(tris.in_domain({0, 0.6, 0.5}));
  EXPECT_EQ(tris.face_center(3), (SurfacePoint{3, 1.0 / 3.0, 1.0 / 3.0}));
  EXPECT_EQ(quads.face_center(3), (SurfacePoint{3, 0.5, 0.5}));
}

TEST(LimitSurface, MovesAndKeepsAnIndependentCopyOfTheMesh) {
  PolygonMesh mesh = cube();
  LimitSurface a(mesh);
  const Eigen::Vector3d x = a.position({2, 0.3, 0.4});
  mesh.positions[0] *= 5.0;  // the surface copied the mesh
  LimitSurface b(std::move(a));
  EXPECT_EQ(b.position({2, 0.3, 0.4}), x);
  EXPECT_EQ(b.control_mesh().positions[0], cube().positions[0]);
}

}  // namespace
}  // namespace elastic
