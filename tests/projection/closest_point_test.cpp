// SurfaceProjector against answers it did not produce: a brute-force search (dense sampling of
// every ptex face, then a pattern search in the parameter domain), the first-order optimality
// conditions of the closest point (residual along the normal, or along the boundary's normal
// plane), points already on the surface, and agreement of its own forms (warm == cold, batched ==
// single).

#include "elastic/projection/closest_point.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
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

// ---------------------------------------------------------------------------------------------------
// Control meshes built here (small, so brute force stays cheap).

PolygonMesh cube_mesh() {  // Catmull-Clark: a rounded blob of diameter ~1.2
  PolygonMesh m;
  for (int i = 0; i < 8; ++i) {
    m.positions.emplace_back(i & 1 ? 1.0 : -1.0, i & 2 ? 1.0 : -1.0, i & 4 ? 1.0 : -1.0);
  }
  m.add_face({0, 2, 3, 1});
  m.add_face({4, 5, 7, 6});
  m.add_face({0, 1, 5, 4});
  m.add_face({2, 6, 7, 3});
  m.add_face({0, 4, 6, 2});
  m.add_face({1, 3, 7, 5});
  return m;
}

PolygonMesh octahedron_mesh() {  // Loop, every vertex of valence 4 (extraordinary)
  PolygonMesh m;
  for (int axis = 0; axis < 3; ++axis) {
    for (double s : {1.0, -1.0}) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      p[axis] = s;
      m.positions.push_back(p);
    }
  }
  for (int sx = 0; sx < 2; ++sx) {
    for (int sy = 0; sy < 2; ++sy) {
      for (int sz = 0; sz < 2; ++sz) {
        const int x = sx, y = 2 + sy, z = 4 + sz;
        if ((sx + sy + sz) % 2 == 0) {
          m.add_face({x, y, z});
        } else {
          m.add_face({x, z, y});
        }
      }
    }
  }
  return m;
}

// Faces are the triples of vertices at mutual distance 2, oriented outward.
PolygonMesh icosahedron_mesh() {
  PolygonMesh m;
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  for (double a : {-1.0, 1.0}) {
    for (double b : {-phi, phi}) {
      m.positions.emplace_back(0.0, a, b);
      m.positions.emplace_back(a, b, 0.0);
      m.positions.emplace_back(b, 0.0, a);
    }
  }
  auto edge = [&](int i, int j) {
    return std::abs(
               (m.positions[static_cast<size_t>(i)] - m.positions[static_cast<size_t>(j)]).norm() -
               2.0) < 1e-9;
  };
  for (int i = 0; i < 12; ++i) {
    for (int j = i + 1; j < 12; ++j) {
      for (int k = j + 1; k < 12; ++k) {
        if (!edge(i, j) || !edge(j, k) || !edge(i, k)) {
          continue;
        }
        const Eigen::Vector3d& a = m.positions[static_cast<size_t>(i)];
        const Eigen::Vector3d& b = m.positions[static_cast<size_t>(j)];
        const Eigen::Vector3d& c = m.positions[static_cast<size_t>(k)];
        if ((b - a).cross(c - a).dot(a + b + c) > 0.0) {
          m.add_face({i, j, k});
        } else {
          m.add_face({i, k, j});
        }
      }
    }
  }
  return m;
}

// Open 4x4 quad grid over [-1,1]^2 with a bump in the middle; one boundary loop with four sharp
// corners.
PolygonMesh bump_grid_mesh() {
  PolygonMesh m;
  constexpr int n = 4;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = -1.0 + 2.0 * i / n, y = -1.0 + 2.0 * j / n;
      m.positions.emplace_back(x, y, 0.6 * std::exp(-3.0 * (x * x + y * y)));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      m.add_face(
          {j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i});
    }
  }
  return m;
}

PolygonMesh torus_mesh() {  // major radius 1, minor 0.35, 8 x 6 quads
  PolygonMesh m;
  constexpr int nu = 8, nv = 6;
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const double t = 2.0 * std::numbers::pi * i / nu, p = 2.0 * std::numbers::pi * j / nv;
      m.positions.emplace_back((1.0 + 0.35 * std::cos(p)) * std::cos(t),
                               (1.0 + 0.35 * std::cos(p)) * std::sin(t), 0.35 * std::sin(p));
    }
  }
  auto id = [](int i, int j) { return ((i + nu) % nu) * nv + (j + nv) % nv; };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      m.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return m;
}

PolygonMesh pentagonal_prism_mesh() {  // Catmull-Clark, two pentagons (10 ptex sub-faces) + 5 quads
  PolygonMesh m;
  for (double z : {-0.5, 0.5}) {
    for (int i = 0; i < 5; ++i) {
      const double a = 2.0 * std::numbers::pi * i / 5;
      m.positions.emplace_back(std::cos(a), std::sin(a), z);
    }
  }
  m.add_face({4, 3, 2, 1, 0});
  m.add_face({5, 6, 7, 8, 9});
  for (int i = 0; i < 5; ++i) {
    m.add_face({i, (i + 1) % 5, 5 + (i + 1) % 5, 5 + i});
  }
  return m;
}

struct Shape {
  std::string name;
  PolygonMesh mesh;
};

std::vector<Shape> all_shapes() {
  return {{"cube", cube_mesh()},
          {"octahedron", octahedron_mesh()},
          {"icosahedron", icosahedron_mesh()},
          {"bump_grid", bump_grid_mesh()},
          {"torus", torus_mesh()},
          {"pentagonal_prism", pentagonal_prism_mesh()}};
}

LimitSurface make_surface(const Shape& shape) {
  LimitSurfaceOptions options;
  options.name = shape.name;
  return LimitSurface(shape.mesh, options);
}

// ---------------------------------------------------------------------------------------------------
// Helpers.

bool triangular(const LimitSurface& s) {
  return s.triangular_domain();
}

SurfacePoint clamp_to_domain(const LimitSurface& s, int face, double u, double v) {
  u = std::clamp(u, 0.0, 1.0);
  v = std::clamp(v, 0.0, 1.0);
  if (triangular(s) && u + v > 1.0) {
    const double excess = 0.5 * (u + v - 1.0);
    u = std::max(0.0, u - excess);
    v = std::max(0.0, v - excess);
    if (u + v > 1.0) {
      v = 1.0 - u;
    }
  }
  return {face, u, v};
}

SurfacePoint random_surface_point(const LimitSurface& s, std::mt19937& rng) {
  std::uniform_int_distribution<int> face(0, s.num_faces() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  SurfacePoint p{face(rng), unit(rng), unit(rng)};
  if (triangular(s) && p.u + p.v > 1.0) {
    p.u = 1.0 - p.u;
    p.v = 1.0 - p.v;
  }
  return p;
}

Eigen::Vector3d unit_normal(const LimitSurface& s, const SurfacePoint& p) {
  const SurfaceDerivatives d = s.derivatives(p);
  return d.du.cross(d.dv).normalized();
}

struct BruteResult {
  SurfacePoint point;
  Eigen::Vector3d position;
  double distance = std::numeric_limits<double>::infinity();
};

// Dense samples of every ptex face, then a pattern search (8 neighbours at spacing h, halving h
// when none improves, clamped to the face's domain) from the best few samples, down to h = 1e-11.
BruteResult brute_force(const LimitSurface& s, const Eigen::Vector3d& x, int samples = 10) {
  struct Sample {
    double d2;
    SurfacePoint p;
  };
  std::vector<Sample> all;
  for (int f = 0; f < s.num_faces(); ++f) {
    for (int i = 0; i <= samples; ++i) {
      for (int j = 0; j <= samples; ++j) {
        if (triangular(s) && i + j > samples) {
          continue;
        }
        const SurfacePoint p{f, static_cast<double>(i) / samples, static_cast<double>(j) / samples};
        all.push_back({(s.position(p) - x).squaredNorm(), p});
      }
    }
  }
  const size_t keep = std::min<size_t>(6, all.size());
  std::partial_sort(all.begin(), all.begin() + static_cast<long>(keep), all.end(),
                    [](const Sample& a, const Sample& b) { return a.d2 < b.d2; });
  BruteResult best;
  for (size_t k = 0; k < keep; ++k) {
    SurfacePoint p = all[k].p;
    double d2 = all[k].d2;
    double h = 1.0 / samples;
    while (h > 1e-11) {
      bool improved = false;
      for (int du = -1; du <= 1; ++du) {
        for (int dv = -1; dv <= 1; ++dv) {
          if (du == 0 && dv == 0) {
            continue;
          }
          const SurfacePoint q = clamp_to_domain(s, p.face, p.u + du * h, p.v + dv * h);
          const double e = (s.position(q) - x).squaredNorm();
          if (e < d2) {
            d2 = e;
            p = q;
            improved = true;
          }
        }
      }
      if (!improved) {
        h *= 0.5;
      }
    }
    if (std::sqrt(d2) < best.distance) {
      best.distance = std::sqrt(d2);
      best.point = p;
      best.position = s.position(p);
    }
  }
  return best;
}

// Points near the surface (off by up to `offset` along the normal) and points in a box around it.
std::vector<Eigen::Vector3d> query_points(const LimitSurface& s, std::mt19937& rng, int near_count,
                                          double offset, int box_count, double box_scale) {
  std::vector<Eigen::Vector3d> xs;
  std::uniform_real_distribution<double> off(-offset, offset), unit(-1.0, 1.0);
  for (int k = 0; k < near_count; ++k) {
    const SurfacePoint p = random_surface_point(s, rng);
    xs.push_back(s.position(p) + off(rng) * unit_normal(s, p));
  }
  for (int k = 0; k < box_count; ++k) {
    xs.emplace_back(box_scale * unit(rng), box_scale * unit(rng), box_scale * unit(rng));
  }
  return xs;
}

// ---------------------------------------------------------------------------------------------------

class ProjectorOnShape : public ::testing::TestWithParam<int> {};

// The projector finds the global minimum: its distance equals the brute-force distance. Tolerance:
// the pattern search stops at a parameter spacing of 1e-11; at a smooth minimum the distance error
// is quadratic in it, at a boundary minimum linear with slope |d_u| < 10, so 1e-9 covers both with
// room. Positions are compared for near points (a unique, well-separated minimum) to 1e-6: the
// pattern search's position error is ~h / sqrt(condition), well below that.
TEST_P(ProjectorOnShape, MatchesBruteForce) {
  const Shape shape = all_shapes()[static_cast<size_t>(GetParam())];
  const LimitSurface surface = make_surface(shape);
  const SurfaceProjector projector(surface);
  std::mt19937 rng(1234 + GetParam());
  const int near_count = surface.num_faces() > 30 ? 100 : 200;
  const std::vector<Eigen::Vector3d> xs =
      query_points(surface, rng, near_count, 0.1, near_count / 2, 2.0);
  int position_checks = 0;
  for (size_t k = 0; k < xs.size(); ++k) {
    const Eigen::Vector3d& x = xs[k];
    const ClosestPoint c = projector.closest(x);
    const BruteResult b = brute_force(surface, x);
    SCOPED_TRACE(shape.name + " query " + std::to_string(k));
    EXPECT_TRUE(c.converged);
    EXPECT_NEAR(c.distance, b.distance, 1e-9);
    EXPECT_NEAR((c.position - x).norm(), c.distance, 1e-14);
    EXPECT_LT((surface.position(c.point) - c.position).norm(), 1e-14);
    if (static_cast<int>(k) < near_count) {
      ++position_checks;
      EXPECT_LT((c.position - b.position).norm(), 1e-6);
    }
  }
  EXPECT_GT(position_checks, 0);
}

// Far points (10 and 100 surface sizes away): still the global minimum.
TEST_P(ProjectorOnShape, FarPointsMatchBruteForce) {
  const Shape shape = all_shapes()[static_cast<size_t>(GetParam())];
  const LimitSurface surface = make_surface(shape);
  const SurfaceProjector projector(surface);
  std::mt19937 rng(99 + GetParam());
  std::normal_distribution<double> gauss;
  for (double radius : {10.0, 100.0}) {
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector3d x =
          radius * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
      const ClosestPoint c = projector.closest(x);
      const BruteResult b = brute_force(surface, x);
      SCOPED_TRACE(shape.name + " radius " + std::to_string(radius));
      EXPECT_TRUE(c.converged);
      // Far away the distance is ~radius and its round-off ~radius * eps; the search's error stays
      // 1e-9.
      EXPECT_NEAR(c.distance, b.distance, 1e-9 * radius);
    }
  }
}

// First-order optimality: at an interior closest point the residual x - d is normal to the surface,
// so (x - d) . d_u = (x - d) . d_v = 0 and (x - d) is parallel to `normal`. Relative tolerance
// 1e-9: Newton stops at round-off (~1e-15 |x| / |x - d|, below 1e-11 for distances above 1e-3).
TEST_P(ProjectorOnShape, ResidualIsNormal) {
  const Shape shape = all_shapes()[static_cast<size_t>(GetParam())];
  const LimitSurface surface = make_surface(shape);
  const SurfaceProjector projector(surface);
  std::mt19937 rng(7 + GetParam());
  const std::vector<Eigen::Vector3d> xs = query_points(surface, rng, 150, 0.3, 50, 3.0);
  int checked = 0;
  for (const Eigen::Vector3d& x : xs) {
    const ClosestPoint c = projector.closest(x);
    ASSERT_TRUE(c.converged) << x.transpose() << " d " << c.distance << " p " << c.point.face << " "
                             << c.point.u << " " << c.point.v;
    if (c.on_boundary || c.distance < 1e-3) {
      continue;
    }
    ++checked;
    const SurfaceDerivatives d = surface.derivatives(c.point);
    const Eigen::Vector3d r = x - c.position;
    EXPECT_LT(std::abs(r.dot(d.du)) / (r.norm() * d.du.norm()), 1e-9);
    EXPECT_LT(std::abs(r.dot(d.dv)) / (r.norm() * d.dv.norm()), 1e-9);
    EXPECT_LT(r.normalized().cross(c.normal).norm(), 1e-9);
    EXPECT_NEAR(c.normal.norm(), 1.0, 1e-14);
    EXPECT_NEAR(c.normal.dot(d.du.cross(d.dv).normalized()), 1.0, 1e-12);  // orientation du x dv
  }
  EXPECT_GT(checked, 100);
}

// A point on the surface projects to itself. Tolerance 1e-12: positions are O(1), Newton stops when
// the gradient is at round-off, ~1e-15.
TEST_P(ProjectorOnShape, PointOnSurfaceProjectsToItself) {
  const Shape shape = all_shapes()[static_cast<size_t>(GetParam())];
  const LimitSurface surface = make_surface(shape);
  const SurfaceProjector projector(surface);
  std::mt19937 rng(42 + GetParam());
  for (int k = 0; k < 100; ++k) {
    const SurfacePoint p = random_surface_point(surface, rng);
    const Eigen::Vector3d x = surface.position(p);
    const ClosestPoint c = projector.closest(x);
    EXPECT_TRUE(c.converged);
    EXPECT_LT(c.distance, 1e-12);
    EXPECT_LT((c.position - x).norm(), 1e-12);
    const ClosestPoint w = projector.closest(x, p);
    EXPECT_LT(w.distance, 1e-12);
  }
}

// Warm start from the previous answer (a particle moving by 1e-3) gives the cold answer. Tolerance:
// both are Newton minima of the same function, equal to ~1e-15 / conditioning; 1e-10 in position.
TEST_P(ProjectorOnShape, WarmStartMatchesCold) {
  const Shape shape = all_shapes()[static_cast<size_t>(GetParam())];
  const LimitSurface surface = make_surface(shape);
  const SurfaceProjector projector(surface);
  std::mt19937 rng(5 + GetParam());
  std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
  const std::vector<Eigen::Vector3d> xs = query_points(surface, rng, 100, 0.05, 0, 0.0);
  for (const Eigen::Vector3d& x : xs) {
    const ClosestPoint first = projector.closest(x);
    const Eigen::Vector3d moved = x + Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
    const ClosestPoint cold = projector.closest(moved);
    const ClosestPoint warm = projector.closest(moved, first.point);
    EXPECT_TRUE(warm.converged);
    EXPECT_LT((warm.position - cold.position).norm(), 1e-10);
    EXPECT_NEAR(warm.distance, cold.distance, 1e-12);
    EXPECT_EQ(warm.on_boundary, cold.on_boundary);
  }
}

// The batched form gives exactly the single-query results, cold and warm.
TEST_P(ProjectorOnShape, BatchedEqualsSingle) {
  const Shape shape = all_shapes()[static_cast<size_t>(GetParam())];
  const LimitSurface surface = make_surface(shape);
  const SurfaceProjector projector(surface);
  std::mt19937 rng(11 + GetParam());
  const std::vector<Eigen::Vector3d> xs = query_points(surface, rng, 300, 0.2, 100, 2.0);
  std::vector<ClosestPoint> cold(xs.size()), warm(xs.size());
  projector.closest(xs, cold);
  std::vector<SurfacePoint> hints;
  hints.reserve(cold.size());
  for (const ClosestPoint& c : cold) {
    hints.push_back(c.point);
  }
  std::vector<Eigen::Vector3d> moved = xs;
  for (Eigen::Vector3d& x : moved) {
    x += Eigen::Vector3d(1e-4, -2e-4, 1e-4);
  }
  projector.closest(moved, warm, hints);
  for (size_t k = 0; k < xs.size(); ++k) {
    const ClosestPoint a = projector.closest(xs[k]);
    EXPECT_EQ(a.point, cold[k].point);
    EXPECT_EQ(a.distance, cold[k].distance);
    const ClosestPoint b = projector.closest(moved[k], hints[k]);
    EXPECT_EQ(b.point, warm[k].point);
    EXPECT_EQ(b.distance, warm[k].distance);
  }
}

INSTANTIATE_TEST_SUITE_P(Shapes, ProjectorOnShape, ::testing::Range(0, 6),
                         [](const auto& test_info) {
                           return all_shapes()[static_cast<size_t>(test_info.param)].name;
                         });

// ---------------------------------------------------------------------------------------------------

// Points beside an open surface project onto its boundary curve: on_boundary is set, the distance
// is the brute-force one, and the residual is orthogonal to the boundary tangent (first-order
// condition of the constrained minimum; 1e-9 relative as above).
TEST(Projector, OpenBoundary) {
  const Shape shape{"bump_grid", bump_grid_mesh()};
  const LimitSurface surface = make_surface(shape);
  const SurfaceProjector projector(surface);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> along(-0.8, 0.8), height(-0.5, 0.5), out(1.2, 2.0);
  int edge_checks = 0;
  for (int k = 0; k < 60; ++k) {
    // Beside one of the four sides, away from the corners.
    const int side = k % 4;
    const double a = along(rng), o = out(rng);
    const Eigen::Vector3d x = side == 0   ? Eigen::Vector3d(o, a, height(rng))
                              : side == 1 ? Eigen::Vector3d(-o, a, height(rng))
                              : side == 2 ? Eigen::Vector3d(a, o, height(rng))
                                          : Eigen::Vector3d(a, -o, height(rng));
    const ClosestPoint c = projector.closest(x);
    SCOPED_TRACE("query " + std::to_string(k));
    EXPECT_TRUE(c.converged);
    EXPECT_TRUE(c.on_boundary);
    EXPECT_TRUE(surface.on_boundary(c.point, 1e-9));
    EXPECT_NEAR(c.distance, brute_force(surface, x).distance, 1e-9);
    // The boundary edge the point is on gives the tangent: d_v on u = 0 or 1, d_u on v = 0 or 1.
    const SurfaceDerivatives d = surface.derivatives(c.point);
    const bool on_u_edge = c.point.u < 1e-9 || c.point.u > 1.0 - 1e-9;
    const bool on_v_edge = c.point.v < 1e-9 || c.point.v > 1.0 - 1e-9;
    if (on_u_edge == on_v_edge) {
      continue;  // a corner (not expected here, but no tangent there)
    }
    const Eigen::Vector3d t = on_u_edge ? d.dv : d.du;
    const Eigen::Vector3d r = x - c.position;
    EXPECT_LT(std::abs(r.dot(t)) / (r.norm() * t.norm()), 1e-9);
    ++edge_checks;
  }
  EXPECT_GT(edge_checks, 50);
}

// Beyond the grid's (sharp) corners the closest point is the corner itself.
TEST(Projector, OpenBoundaryCorner) {
  const Shape shape{"bump_grid", bump_grid_mesh()};
  const LimitSurface surface = make_surface(shape);
  const SurfaceProjector projector(surface);
  for (double sx : {-1.0, 1.0}) {
    for (double sy : {-1.0, 1.0}) {
      const Eigen::Vector3d x(1.5 * sx, 1.7 * sy, 0.2);
      const ClosestPoint c = projector.closest(x);
      EXPECT_TRUE(c.converged);
      EXPECT_TRUE(c.on_boundary);
      // The limit surface interpolates sharp boundary corners: the corner control vertex.
      EXPECT_LT((c.position - Eigen::Vector3d(sx, sy, 0.6 * std::exp(-6.0))).norm(), 1e-12);
    }
  }
}

// Along a symmetry axis through a control vertex the closest point is that vertex's limit point (it
// is the unique extreme point of the symmetric blob in that direction). Every vertex of the
// octahedron (valence 4) and icosahedron (valence 5) is extraordinary for Loop, where the ptex
// charts meet singularly and Newton may start at a face corner. Tolerance 1e-11 in position:
// measured errors are below 1e-13 (round-off of coordinates up to 50), with room to spare.
TEST(Projector, ExtraordinaryVertexOnAxis) {
  for (const Shape& shape :
       {Shape{"octahedron", octahedron_mesh()}, Shape{"icosahedron", icosahedron_mesh()}}) {
    const LimitSurface surface = make_surface(shape);
    const SurfaceProjector projector(surface);
    for (int v = 0; v < shape.mesh.num_vertices(); ++v) {
      const Eigen::Vector3d vertex = surface.position(surface.vertex_point(v));
      for (double scale : {1.2, 5.0, 50.0}) {
        const Eigen::Vector3d x = scale * shape.mesh.positions[static_cast<size_t>(v)];
        const ClosestPoint c = projector.closest(x);
        SCOPED_TRACE(shape.name + " vertex " + std::to_string(v) + " scale " +
                     std::to_string(scale));
        EXPECT_TRUE(c.converged);
        EXPECT_LT((c.position - vertex).norm(), 1e-11);
        EXPECT_NEAR(c.distance, (x - vertex).norm(), 1e-12 * scale);
        // Warm-started from its own answer: stays there.
        const ClosestPoint w = projector.closest(x, c.point);
        EXPECT_LT((w.position - vertex).norm(), 1e-11);
      }
    }
  }
}

TEST(Projector, NonFiniteQueryThrows) {
  const Shape shape{"cube", cube_mesh()};
  const LimitSurface surface = make_surface(shape);
  const SurfaceProjector projector(surface);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const SurfacePoint hint = surface.face_center(0);
  for (const Eigen::Vector3d& x :
       {Eigen::Vector3d(nan, 0, 0), Eigen::Vector3d(0, inf, 0), Eigen::Vector3d(0, 0, -inf)}) {
    EXPECT_THROW(projector.closest(x), InvalidInputError);
    EXPECT_THROW(projector.closest(x, hint), InvalidInputError);
    std::vector<Eigen::Vector3d> xs{Eigen::Vector3d(2, 0, 0), x};
    std::vector<ClosestPoint> out(2);
    EXPECT_THROW(projector.closest(xs, out), InvalidInputError);
  }
  try {
    projector.closest(Eigen::Vector3d(nan, 0, 0));
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(e.input(), "cube");
  }
}

TEST(Projector, BadArgumentsThrow) {
  const Shape shape{"octahedron", octahedron_mesh()};
  const LimitSurface surface = make_surface(shape);
  const SurfaceProjector projector(surface);
  const Eigen::Vector3d x(0.3, 0.2, 2.0);
  EXPECT_THROW(projector.closest(x, SurfacePoint{surface.num_faces(), 0.1, 0.1}),
               InvalidInputError);
  EXPECT_THROW(projector.closest(x, SurfacePoint{0, 0.8, 0.8}),
               InvalidInputError);  // outside the triangle
  std::vector<Eigen::Vector3d> xs(3, x);
  std::vector<ClosestPoint> out(2);
  EXPECT_THROW(projector.closest(xs, out), InvalidInputError);
  std::vector<ClosestPoint> out3(3);
  std::vector<SurfacePoint> hints(2, surface.face_center(0));
  EXPECT_THROW(projector.closest(xs, out3, hints), InvalidInputError);
  ProjectionOptions bad;
  bad.max_newton_iterations = 0;
  EXPECT_THROW(SurfaceProjector(surface, bad), InvalidInputError);
  // An unset hint means "no hint": the global query.
  EXPECT_EQ(projector.closest(x, SurfacePoint{}).point, projector.closest(x).point);
}

// A bad hint (far side of a convex blob) still yields the global answer, through Newton or the
// fallback.
TEST(Projector, FarHintStillGlobal) {
  const Shape shape{"cube", cube_mesh()};
  const LimitSurface surface = make_surface(shape);
  const SurfaceProjector projector(surface);
  std::mt19937 rng(17);
  for (int k = 0; k < 40; ++k) {
    const SurfacePoint p = random_surface_point(surface, rng);
    const Eigen::Vector3d x = surface.position(p) + 0.2 * unit_normal(surface, p);
    const ClosestPoint cold = projector.closest(x);
    const ClosestPoint warm =
        projector.closest(x, surface.face_center((p.face + 3) % surface.num_faces()));
    EXPECT_NEAR(warm.distance, cold.distance, 1e-12);
    EXPECT_LT((warm.position - cold.position).norm(), 1e-9);
  }
}

// Moving the projector keeps it working (it owns Embree handles).
TEST(Projector, Movable) {
  const Shape shape{"torus", torus_mesh()};
  const LimitSurface surface = make_surface(shape);
  SurfaceProjector a(surface);
  const Eigen::Vector3d x(1.4, 0.1, 0.05);
  const ClosestPoint before = a.closest(x);
  SurfaceProjector b(std::move(a));
  EXPECT_EQ(b.closest(x).point, before.point);
  SurfaceProjector c(surface,
                     ProjectionOptions{.tessellation = {.resolution = 2, .target_triangles = 0}});
  c = std::move(b);
  EXPECT_EQ(c.closest(x).point, before.point);
  EXPECT_EQ(&c.surface(), &surface);
}

// A real control mesh with extraordinary vertices and an open boundary (OpenSubdiv's pawn): the
// optimality conditions and the on-surface identity hold.
TEST(Projector, PawnOptimality) {
  ELASTIC_REQUIRE_SHARED_MESH(path, "osd_catmark_pawn.obj");
  const PolygonMesh mesh = read_mesh(path).mesh;
  LimitSurfaceOptions options;
  options.name = path.string();
  const LimitSurface surface(mesh, options);
  const SurfaceProjector projector(surface);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> off(-0.05, 0.05);
  int checked = 0;
  for (int k = 0; k < 200; ++k) {
    const SurfacePoint p = random_surface_point(surface, rng);
    const Eigen::Vector3d on = surface.position(p);
    EXPECT_LT(projector.closest(on).distance, 1e-11);  // coordinates up to ~3: a few eps * 3 * 100
    const Eigen::Vector3d x = on + off(rng) * unit_normal(surface, p);
    const ClosestPoint c = projector.closest(x);
    EXPECT_TRUE(c.converged);
    EXPECT_LE(c.distance, (x - on).norm() + 1e-12);  // never worse than the point we started from
    if (c.on_boundary || c.distance < 1e-3) {
      continue;
    }
    const SurfaceDerivatives d = surface.derivatives(c.point);
    const Eigen::Vector3d r = x - c.position;
    EXPECT_LT(std::abs(r.dot(d.du)) / (r.norm() * d.du.norm()), 1e-9);
    EXPECT_LT(std::abs(r.dot(d.dv)) / (r.norm() * d.dv.norm()), 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 150);
}

TEST(SurfaceProjector, DenseControlMeshesGetACoarserTessellationAndTheSameClosestPoints) {
  // A wavy 150 x 150 quad grid: 22,500 quads would make 720,000 triangles at resolution 4, above
  // kProjectorMaxTriangles (3 makes 405,000); a 100 x 100 grid (320,000) keeps 4.
  PolygonMesh wavy = test::quad_grid(150, 150, {0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0});
  for (Eigen::Vector3d& p : wavy.positions) {
    p.z() = 0.05 * std::sin(9.0 * p.x()) * std::cos(7.0 * p.y());
  }
  const LimitSurface dense(wavy);
  const SurfaceProjector coarse(dense);
  EXPECT_EQ(coarse.tessellation().resolution, 3);
  EXPECT_LE(static_cast<long>(coarse.tessellation().triangles.size()), kProjectorMaxTriangles);
  const LimitSurface small(test::quad_grid(100, 100, {0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}));
  EXPECT_EQ(SurfaceProjector(small).tessellation().resolution, 4);
  // The answer is the limit surface's closest point whatever the tessellation that seeds it.
  const SurfaceProjector fine(dense, ProjectionOptions{.tessellation = {.resolution = 4}});
  EXPECT_EQ(fine.tessellation().resolution, 4);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.1, 1.4), h(-0.08, 0.08);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d q(u(rng), u(rng), h(rng));
    const ClosestPoint a = coarse.closest(q), b = fine.closest(q);
    ASSERT_TRUE(a.converged && b.converged);
    EXPECT_NEAR((a.position - q).norm(), (b.position - q).norm(), 1e-9) << k;
    EXPECT_LT((a.position - b.position).norm(), 1e-6) << k;
  }
}

}  // namespace
}  // namespace elastic
