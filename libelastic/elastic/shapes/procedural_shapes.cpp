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

namespace elastic {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
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

// ---------------------------------------------------------------------------------------------------
// Profiles of surfaces of revolution.
//
// A profile is a plane curve t in [0,1] -> (r, z), r >= 0 the distance from the z axis. Sweeping it
// around z gives the surface point (r cos(theta), r sin(theta), z). Faces are first built with the
// corner order (ring i, angle j), (i, j+1), (i+1, j+1), (i+1, j): their normal is
// d/dtheta x d/dt = phi_hat x (r' r_hat + z' z_hat) = z' r_hat - r' z_hat, i.e. the profile's
// tangent (r', z') turned clockwise. A profile traversed with the solid on its left (bottom to top
// on the outside, outward from a bottom pole) therefore yields outward normals; `flip` reverses
// every face for a profile traversed the other way.

struct Profile {
  std::function<Eigen::Vector2d(double)> at;  ///< t in [0,1] -> (r, z); r(t) >= 0
  bool pole_at_start = false;                 ///< r(0) == 0: the surface closes at (0, z(0))
  bool closed = false;                        ///< at(0) == at(1): a closed curve (torus)
  bool flip = false;                          ///< reverse the faces (see above)
};

// A smooth curve through control points (r, z): cubic Hermite segments whose tangent directions are
// the bisectors of the adjacent chords and whose tangent lengths are the segment's chord length.
// This is tangent-continuous (G1), and scaling each segment's tangents by its own chord keeps the
// curve close to the control polygon where the points are unevenly spaced (no loops or overshoot,
// unlike uniform Catmull-Rom). When the first point is on the axis (a pole) its tangent is
// horizontal, so that the swept surface is smooth (tangent plane z = const) at the pole.
class HermiteProfile {
 public:
  explicit HermiteProfile(std::vector<Eigen::Vector2d> points) : points_(std::move(points)) {
    const size_t n = points_.size();
    tangents_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      Eigen::Vector2d d = Eigen::Vector2d::Zero();
      if (i > 0) {
        d += (points_[i] - points_[i - 1]).normalized();
      }
      if (i + 1 < n) {
        d += (points_[i + 1] - points_[i]).normalized();
      }
      tangents_[i] = d.normalized();
    }
    if (points_.front().x() == 0.0) {
      tangents_.front() = Eigen::Vector2d(1.0, 0.0);
    }
  }

  Eigen::Vector2d operator()(double t) const {
    const int segments = static_cast<int>(points_.size()) - 1;
    const double x = std::clamp(t, 0.0, 1.0) * segments;
    const int i = std::min(static_cast<int>(x), segments - 1);
    const double u = x - i;
    const double length = (points_[i + 1] - points_[i]).norm();
    const double u2 = u * u;
    const double u3 = u2 * u;
    const double h00 = 2 * u3 - 3 * u2 + 1;
    const double h10 = u3 - 2 * u2 + u;
    const double h01 = -2 * u3 + 3 * u2;
    const double h11 = u3 - u2;
    Eigen::Vector2d p = h00 * points_[i] + h10 * length * tangents_[i] + h01 * points_[i + 1] +
                        h11 * length * tangents_[i + 1];
    p.x() = std::max(p.x(), 0.0);  // the pole stays exactly on the axis
    return p;
  }

 private:
  std::vector<Eigen::Vector2d> points_;
  std::vector<Eigen::Vector2d> tangents_;
};

// Where the rings of a swept profile go.
//
// Around the axis every ring has `n` segments, so the circumferential edge at radius r is 2 pi r /
// n. Along the profile we aim for the same length (times sqrt(3)/2 for triangles, the height of an
// equilateral triangle), i.e. nearly square quads / equilateral triangles everywhere: a conformal
// spacing, h(s) = c 2 pi r(s) / n. Three limits keep it sensible:
//  - Near a pole the conformal spacing would need infinitely many rings. From the pole until the
//    radius first reaches half the largest radius, r counts as that `pole_radius`: the region
//    around the pole is meshed uniformly (quad disk, or rings with fewer vertices for triangles).
//  - Elsewhere radii below a quarter of the largest (`thin_radius`, the goblet's stem) count as
//    that, trading faces up to ~2:1 for far fewer rings.
//  - The profile turns by at most min(45 deg, 4 x 2 pi / n) per step (h <= turn / curvature), so
//    that tight bends (the goblet's foot edge) get a few rings instead of being cut across.
//
// The profile is sampled densely, 1 / h(s) integrated to tau(s) = int ds / h(s), and ring i is put
// where tau = i * tau_total / m with m = round(tau_total).
struct RingLayout {
  std::vector<double> t;         ///< profile parameter of each ring (m + 1 rings open, m closed)
  std::vector<double> s;         ///< arc length from the profile's start
  double pole_radius = 0.0;      ///< radius standing in for smaller ones in the pole region
  double pole_region_end = 0.0;  ///< arc length where the pole region ends (0 without a pole)
  // Dense table for arc length -> parameter.
  std::vector<double> dense_t;
  std::vector<double> dense_s;

  double t_at_arc_length(double arc) const {
    auto it = std::lower_bound(dense_s.begin(), dense_s.end(), arc);
    if (it == dense_s.begin()) {
      return dense_t.front();
    }
    if (it == dense_s.end()) {
      return dense_t.back();
    }
    const size_t k = static_cast<size_t>(it - dense_s.begin());
    const double w = (arc - dense_s[k - 1]) / (dense_s[k] - dense_s[k - 1]);
    return dense_t[k - 1] + w * (dense_t[k] - dense_t[k - 1]);
  }
};

RingLayout layout_rings(const Profile& profile, int n, double step_factor, int min_rings,
                        bool even_count) {
  const int dense = std::max(4096, 16 * n);
  std::vector<Eigen::Vector2d> p(static_cast<size_t>(dense) + 1);
  std::vector<double> dense_t(p.size());
  for (int k = 0; k <= dense; ++k) {
    dense_t[k] = static_cast<double>(k) / dense;
    p[k] = profile.at(dense_t[k]);
  }
  RingLayout layout;
  layout.dense_t = std::move(dense_t);
  double max_radius = 0.0;
  for (const Eigen::Vector2d& q : p) {
    max_radius = std::max(max_radius, q.x());
  }
  layout.pole_radius = 0.5 * max_radius;
  const double thin_radius = 0.25 * max_radius;
  const double max_turn = std::min(0.25 * kPi, 4.0 * kTwoPi / n);
  size_t pole_region_samples = 0;  // samples [0, pole_region_samples) are in the pole region
  if (profile.pole_at_start) {
    while (pole_region_samples < p.size() && p[pole_region_samples].x() < layout.pole_radius) {
      ++pole_region_samples;
    }
  }

  // Discrete curvature at each sample: turning angle between the adjacent chords over their mean
  // length.
  const size_t count = p.size();
  std::vector<double> step(count);
  const double angular_step = kTwoPi / n;
  for (size_t k = 0; k < count; ++k) {
    // Neighbours of sample k; at the ends of an open profile use the nearest interior sample's.
    size_t mid = k;
    if (!profile.closed) {
      mid = std::clamp<size_t>(k, 1, count - 2);
    }
    const size_t prev = mid == 0 ? count - 2 : mid - 1;  // closed: p[count - 1] == p[0]
    const size_t next = mid + 1 == count ? 1 : mid + 1;
    const Eigen::Vector2d a = p[mid] - p[prev];
    const Eigen::Vector2d b = p[next] - p[mid];
    const double turn = std::atan2(std::abs(a.x() * b.y() - a.y() * b.x()), a.dot(b));
    const double curvature = turn / (0.5 * (a.norm() + b.norm()));
    double length = std::max(p[k].x(), k < pole_region_samples ? layout.pole_radius : thin_radius);
    if (curvature > 0.0) {
      length = std::min(length, max_turn / (angular_step * curvature));
    }
    step[k] = step_factor * angular_step * length;
  }

  layout.dense_s.assign(count, 0.0);
  std::vector<double> tau(count, 0.0);
  for (size_t k = 1; k < count; ++k) {
    const double ds = (p[k] - p[k - 1]).norm();
    layout.dense_s[k] = layout.dense_s[k - 1] + ds;
    tau[k] = tau[k - 1] + ds / (0.5 * (step[k] + step[k - 1]));
  }
  if (pole_region_samples > 0) {
    layout.pole_region_end = layout.dense_s[pole_region_samples - 1];
  }

  const double total = tau[count - 1];
  int m = std::max(min_rings, static_cast<int>(std::lround(total)));
  if (even_count && m % 2 != 0) {
    ++m;
  }
  const int rings = profile.closed ? m : m + 1;
  layout.t.resize(static_cast<size_t>(rings));
  layout.s.resize(static_cast<size_t>(rings));
  size_t k = 1;
  for (int i = 0; i < rings; ++i) {
    const double target = total * i / m;
    while (k + 1 < count && tau[k] < target) {
      ++k;
    }
    const double w = std::clamp((target - tau[k - 1]) / (tau[k] - tau[k - 1]), 0.0, 1.0);
    layout.t[i] = layout.dense_t[k - 1] + w * (layout.dense_t[k] - layout.dense_t[k - 1]);
    layout.s[i] = layout.dense_s[k - 1] + w * (layout.dense_s[k] - layout.dense_s[k - 1]);
  }
  layout.t.front() = 0.0;
  layout.s.front() = 0.0;
  if (!profile.closed) {
    layout.t.back() = 1.0;
    layout.s.back() = layout.dense_s.back();
  }
  return layout;
}

Eigen::Vector3d swept_point(const Eigen::Vector2d& rz, double theta) {
  return {rz.x() * std::cos(theta), rz.x() * std::sin(theta), rz.y()};
}

// A ring of vertices at one profile position: vertex j (0 <= j < count) is at angle offset + 2 pi j
// / count.
struct Ring {
  int first = 0;
  int count = 0;
  double offset = 0.0;
  int vertex(long j) const { return first + static_cast<int>(((j % count) + count) % count); }
};

Ring add_ring(PolygonMesh& mesh, const Eigen::Vector2d& rz, int count, double offset) {
  Ring ring{mesh.num_vertices(), count, offset};
  for (int j = 0; j < count; ++j) {
    mesh.positions.push_back(swept_point(rz, offset + kTwoPi * j / count));
  }
  return ring;
}

double min_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  auto angle = [](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    return std::atan2(u.cross(v).norm(), u.dot(v));
  };
  const double alpha = angle(b - a, c - a);
  const double beta = angle(c - b, a - b);
  return std::min({alpha, beta, kPi - alpha - beta});
}

// Triangulates the band between ring a (earlier on the profile) and ring b. A triangulation of the
// band is a monotone walk once around both rings, each step advancing one ring by one vertex and
// making one triangle (a + b triangles, a valid strip whatever the choices). The walk is chosen by
// dynamic programming over the states (vertices done on a, vertices done on b), as in optimal
// contour stitching (Fuchs, Kedem and Uselton 1977), maximising the sum of log(smallest angle) over
// the band's triangles, which keeps slivers out where a greedy choice can be trapped (coarse rings
// whose vertices line up). States are restricted to those whose two vertices are at most two steps
// apart in angle; the plain angular sweep stays in that corridor, so a walk always exists, and the
// work is linear in the ring sizes. Between equal rings offset by half a step the best walk is the
// regular zig-zag (valence 6 everywhere). Corner order follows the default convention (a forward in
// angle, then b).
void stitch_triangles(PolygonMesh& mesh, const Ring& a, const Ring& b) {
  if (a.count == 1) {  // fan around a pole
    for (int j = 0; j < b.count; ++j) {
      mesh.add_face({a.first, b.vertex(j + 1), b.vertex(j)});
    }
    return;
  }
  const double da = kTwoPi / a.count;
  const double db = kTwoPi / b.count;
  // Start the walk at a's vertex 0 and b's vertex nearest to it in angle.
  const long b0 = std::lround((a.offset - b.offset) / db);
  const double beta0 = b.offset + db * static_cast<double>(b0);
  auto pa = [&](int i) { return mesh.positions[static_cast<size_t>(a.vertex(i))]; };
  auto pb = [&](int i) { return mesh.positions[static_cast<size_t>(b.vertex(b0 + i))]; };
  auto score = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
    return std::log(std::max(min_angle(p, q, r), 1e-12));
  };

  // Corridor: for each ia, the ib with |angle_a(ia) - angle_b(ib)| <= max(da, db).
  const double width = 2.0 * std::max(da, db);
  const int p = a.count;
  const int q = b.count;
  std::vector<int> lo(static_cast<size_t>(p) + 1);
  std::vector<int> hi(static_cast<size_t>(p) + 1);
  for (int ia = 0; ia <= p; ++ia) {
    const double alpha = a.offset + da * ia - beta0;
    // The walk starts at (0, 0) and ends at (p, q).
    lo[ia] = ia == 0 ? 0 : std::clamp(static_cast<int>(std::ceil((alpha - width) / db)), 0, q);
    hi[ia] = ia == p ? q : std::clamp(static_cast<int>(std::floor((alpha + width) / db)), 0, q);
  }
  constexpr double kUnreachable = -std::numeric_limits<double>::infinity();
  // best[ia][ib - lo[ia]]: best score of a walk from (0, 0); from_a: its last step advanced a.
  std::vector<std::vector<double>> best(static_cast<size_t>(p) + 1);
  std::vector<std::vector<char>> from_a(static_cast<size_t>(p) + 1);
  auto at = [&](int ia, int ib) {
    return (ia < 0 || ib < lo[ia] || ib > hi[ia]) ? kUnreachable : best[ia][ib - lo[ia]];
  };
  for (int ia = 0; ia <= p; ++ia) {
    const size_t width_ia = static_cast<size_t>(std::max(0, hi[ia] - lo[ia] + 1));
    best[ia].assign(width_ia, kUnreachable);
    from_a[ia].assign(width_ia, 0);
    for (int ib = lo[ia]; ib <= hi[ia]; ++ib) {
      double value = (ia == 0 && ib == 0) ? 0.0 : kUnreachable;
      char came_from_a = 0;
      if (const double prev = at(ia - 1, ib); prev > kUnreachable) {
        value = prev + score(pa(ia - 1), pa(ia), pb(ib));
        came_from_a = 1;
      }
      if (const double prev = ib > lo[ia] ? best[ia][ib - 1 - lo[ia]] : kUnreachable;
          prev > kUnreachable) {
        const double candidate = prev + score(pa(ia), pb(ib), pb(ib - 1));
        if (candidate > value) {
          value = candidate;
          came_from_a = 0;
        }
      }
      best[ia][ib - lo[ia]] = value;
      from_a[ia][ib - lo[ia]] = came_from_a;
    }
  }
  // Walk back from (p, q), then emit the triangles in walk order.
  std::vector<char> steps;
  for (int ia = p, ib = q; ia > 0 || ib > 0;) {
    const char step = from_a[ia][ib - lo[ia]];
    steps.push_back(step);
    if (step) {
      --ia;
    } else {
      --ib;
    }
  }
  int ia = 0;
  int ib = 0;
  for (auto it = steps.rbegin(); it != steps.rend(); ++it) {
    if (*it) {
      mesh.add_face({a.vertex(ia), a.vertex(ia + 1), b.vertex(b0 + ib)});
      ++ia;
    } else {
      mesh.add_face({a.vertex(ia), b.vertex(b0 + ib + 1), b.vertex(b0 + ib)});
      ++ib;
    }
  }
}

void stitch_quads(PolygonMesh& mesh, const Ring& a, const Ring& b) {
  for (int j = 0; j < a.count; ++j) {
    mesh.add_face({a.vertex(j), a.vertex(j + 1), b.vertex(j + 1), b.vertex(j)});
  }
}

// Quad version of a pole: a rectangular grid of a x b quads (2(a + b) = n) whose boundary is ring q
// of the profile, so every ring keeps n vertices and no quad is degenerate. Grid point (i, j) gets
// normalised coordinates u = 2i/a - 1, v = 2j/b - 1; its distance level is rho = max(|u|, |v|) (a
// concentric-squares map: the grid's nested squares become the disk's nested circles) and its angle
// is where the ray from the centre through it meets the grid's boundary, measured as perimeter
// position p in [0, n) counter-clockwise from corner (0, 0) and mapped to 2 pi p / n. Boundary grid
// vertices thus land exactly on ring q's vertices; interior ones are placed on the surface at arc
// length rho * s_q from the pole. The four grid corners become valence-3 vertices, the only
// extraordinary ones.
void add_quad_disk(PolygonMesh& mesh, const Profile& profile, const RingLayout& layout,
                   const Ring& rim, int q, int n) {
  const int a = n / 4;
  const int b = n / 2 - a;
  auto perimeter = [&](double x, double y) {  // (x, y) on the boundary of [0,a] x [0,b], grid units
    const double u = 2.0 * x / a - 1.0;
    const double v = 2.0 * y / b - 1.0;
    if (-v >= std::abs(u)) {
      return x;  // bottom side, y = 0
    }
    if (u >= std::abs(v)) {
      return a + y;  // right side, x = a
    }
    if (v >= std::abs(u)) {
      return a + b + (a - x);  // top side, y = b
    }
    return 2.0 * a + b + (b - y);  // left side, x = 0
  };
  std::vector<int> index(static_cast<size_t>((a + 1) * (b + 1)));
  auto id = [&](int i, int j) -> int& { return index[static_cast<size_t>(j * (a + 1) + i)]; };
  for (int j = 0; j <= b; ++j) {
    for (int i = 0; i <= a; ++i) {
      const double u = 2.0 * i / a - 1.0;
      const double v = 2.0 * j / b - 1.0;
      const double rho = std::max(std::abs(u), std::abs(v));
      if (i == 0 || j == 0 || i == a || j == b) {
        id(i, j) = rim.vertex(std::lround(perimeter(i, j)));
        continue;
      }
      double theta = 0.0;
      if (rho > 0.0) {
        // Boundary point on the ray through (u, v), back in grid units.
        const double x = 0.5 * a * (1.0 + u / rho);
        const double y = 0.5 * b * (1.0 + v / rho);
        theta = rim.offset + kTwoPi * perimeter(x, y) / n;
      }
      const Eigen::Vector2d rz = profile.at(layout.t_at_arc_length(rho * layout.s[q]));
      id(i, j) = mesh.num_vertices();
      mesh.positions.push_back(swept_point(rz, theta));
    }
  }
  // (i,j), (i,j+1), (i+1,j+1), (i+1,j) runs clockwise in the (u, v) square, which the map sends
  // orientation-preservingly to increasing angle: the default convention for a pole at the start.
  for (int j = 0; j < b; ++j) {
    for (int i = 0; i < a; ++i) {
      mesh.add_face({id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)});
    }
  }
}

PolygonMesh sweep(const Profile& profile, const ShapeOptions& options) {
  const int n = options.resolution;
  const bool tris = options.faces == ShapeFaces::Triangles;
  // Quads at a pole: the disk replaces rings 1..q-1; odd n cannot bound an all-quad disk (a quad
  // mesh has an even number of boundary edges), so then the pole is one n-gon spanning ring 1.
  const int disk_ring =
      (!tris && profile.pole_at_start)
          ? (n % 2 == 0 ? std::max(1, static_cast<int>(std::lround((n / 2 - n / 4) / 2.0))) : 1)
          : 0;
  // At least one band besides the pole's (else the coarsest cap would be one flat face).
  const int min_rings = profile.closed ? (tris ? 4 : 3) : profile.pole_at_start ? disk_ring + 1 : 1;
  const RingLayout layout = layout_rings(profile, n, tris ? std::sqrt(3.0) / 2.0 : 1.0, min_rings,
                                         profile.closed && tris);

  PolygonMesh mesh;
  const int ring_count = static_cast<int>(layout.t.size());
  std::vector<Ring> rings(static_cast<size_t>(ring_count));
  for (int i = 0; i < ring_count; ++i) {
    const Eigen::Vector2d rz = profile.at(layout.t[i]);
    if (i == 0 && profile.pole_at_start) {
      rings[0] = {mesh.num_vertices(), 1, 0.0};
      if (tris) {
        mesh.positions.push_back({0.0, 0.0, rz.y()});
      }
      continue;
    }
    if (!tris) {
      if (i >= disk_ring) {
        rings[i] = add_ring(mesh, rz, n, 0.0);
      }
      continue;
    }
    // Triangles: in the pole region the rings have fewer vertices (about n r / pole_radius, so that
    // edges around are as long as the rings' spacing there), then n; every other ring is turned by
    // half its step.
    int count = n;
    if (layout.s[i] < layout.pole_region_end) {
      count = std::clamp(static_cast<int>(std::lround(n * rz.x() / layout.pole_radius)), 3, n);
    }
    rings[i] = add_ring(mesh, rz, count, (i % 2 != 0) ? kPi / count : 0.0);
  }

  const int bands = profile.closed ? ring_count : ring_count - 1;
  for (int i = 0; i < bands; ++i) {
    const Ring& a = rings[i];
    const Ring& b = rings[(i + 1) % ring_count];
    if (tris) {
      stitch_triangles(mesh, a, b);
    } else if (i >= disk_ring) {
      stitch_quads(mesh, a, b);
    }
  }
  if (disk_ring > 0) {
    const Ring& rim = rings[disk_ring];
    if (n % 2 == 0) {
      add_quad_disk(mesh, profile, layout, rim, disk_ring, n);
    } else {
      std::vector<int> polygon(
          static_cast<size_t>(n));  // decreasing angle: normal -z at a start pole
      for (int j = 0; j < n; ++j) {
        polygon[j] = rim.vertex(n - 1 - j);
      }
      mesh.add_face(polygon);
    }
  }
  if (profile.flip) {
    reverse_faces(mesh);
  }
  apply_scale(mesh, options.scale);
  return mesh;
}

// ---------------------------------------------------------------------------------------------------
// Sphere

// Quads: each cube face is an N x N grid with the equal-angle map x = tan(pi/4 * xi), xi in [-1,
// 1], before projecting onto the sphere, which makes the quads far more uniform than an evenly
// spaced grid (area ratio about 1.4 instead of 5). Vertices are keyed by their integer lattice
// point on the cube's surface, so the cube's edges and corners are shared exactly.
PolygonMesh cube_sphere(int N) {
  PolygonMesh mesh;
  std::unordered_map<std::int64_t, int> lattice;
  const std::int64_t side = N + 1;
  auto coordinate = [N](int i) { return std::tan(0.25 * kPi * (2.0 * i / N - 1.0)); };
  auto vertex = [&](const std::array<int, 3>& c) {
    const std::int64_t key = (c[0] * side + c[1]) * side + c[2];
    auto [it, inserted] = lattice.try_emplace(key, mesh.num_vertices());
    if (inserted) {
      mesh.positions.push_back(
          Eigen::Vector3d(coordinate(c[0]), coordinate(c[1]), coordinate(c[2])).normalized());
    }
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int b = (axis + 1) % 3;
    const int c = (axis + 2) % 3;
    for (int sign : {-1, 1}) {
      auto corner = [&](int i, int j) {
        std::array<int, 3> lattice_point{};
        lattice_point[axis] = sign > 0 ? N : 0;
        lattice_point[b] = i;
        lattice_point[c] = j;
        return vertex(lattice_point);
      };
      for (int i = 0; i < N; ++i) {
        for (int j = 0; j < N; ++j) {
          // e_b x e_c = +e_axis: counter-clockwise seen from outside on the + face.
          const int v00 = corner(i, j), v10 = corner(i + 1, j), v11 = corner(i + 1, j + 1),
                    v01 = corner(i, j + 1);
          if (sign > 0) {
            mesh.add_face({v00, v10, v11, v01});
          } else {
            mesh.add_face({v00, v01, v11, v10});
          }
        }
      }
    }
  }
  return mesh;
}

// Triangles: an icosahedron whose faces are split into k^2 triangles (frequency k, barycentric
// grid), then projected. Every vertex has valence 6 except the 12 icosahedron vertices (valence 5).
PolygonMesh icosphere(int k) {
  const double phi = 0.5 * (1.0 + std::sqrt(5.0));
  std::vector<Eigen::Vector3d> corners;
  for (double s1 : {-1.0, 1.0}) {
    for (double s2 : {-1.0, 1.0}) {
      corners.emplace_back(0.0, s1, s2 * phi);
      corners.emplace_back(s1, s2 * phi, 0.0);
      corners.emplace_back(s2 * phi, 0.0, s1);
    }
  }
  // Edges join corners at distance 2 (the edge length of this icosahedron); faces are mutually
  // joined triples, oriented so that their normal points away from the centre.
  auto adjacent = [&](size_t i, size_t j) {
    return std::abs((corners[i] - corners[j]).norm() - 2.0) < 1e-9;
  };
  std::vector<std::array<int, 3>> faces;
  for (size_t i = 0; i < 12; ++i) {
    for (size_t j = i + 1; j < 12; ++j) {
      for (size_t l = j + 1; l < 12; ++l) {
        if (!adjacent(i, j) || !adjacent(j, l) || !adjacent(i, l)) {
          continue;
        }
        std::array<int, 3> f{static_cast<int>(i), static_cast<int>(j), static_cast<int>(l)};
        const Eigen::Vector3d normal = (corners[j] - corners[i]).cross(corners[l] - corners[i]);
        if (normal.dot(corners[i] + corners[j] + corners[l]) < 0.0) {
          std::swap(f[1], f[2]);
        }
        faces.push_back(f);
      }
    }
  }

  PolygonMesh mesh;
  for (const Eigen::Vector3d& c : corners) {
    mesh.positions.push_back(c.normalized());
  }
  // Interior vertices of each edge, ordered from its lower to its higher corner index.
  std::unordered_map<int, int> edge_first;              // key lo * 12 + hi
  auto edge_vertex = [&](int u, int w, int weight_w) {  // point (k - weight_w) u + weight_w w
    if (u > w) {
      std::swap(u, w);
      weight_w = k - weight_w;
    }
    auto [it, inserted] = edge_first.try_emplace(u * 12 + w, mesh.num_vertices());
    if (inserted) {
      for (int t = 1; t < k; ++t) {
        mesh.positions.push_back(((k - t) * corners[u] + t * corners[w]).normalized());
      }
    }
    return it->second + weight_w - 1;
  };
  for (const std::array<int, 3>& f : faces) {
    const int A = f[0], B = f[1], C = f[2];
    // Grid point with weights (k - i - j, i, j) on corners (A, B, C).
    std::vector<int> grid(static_cast<size_t>((k + 1) * (k + 1)), -1);
    auto point = [&](int i, int j) -> int {
      int& slot = grid[static_cast<size_t>(i * (k + 1) + j)];
      if (slot >= 0) {
        return slot;
      }
      const int wa = k - i - j;
      if (i == 0 && j == 0) {
        return slot = A;
      }
      if (wa == 0 && j == 0) {
        return slot = B;
      }
      if (wa == 0 && i == 0) {
        return slot = C;
      }
      if (j == 0) {
        return slot = edge_vertex(A, B, i);
      }
      if (i == 0) {
        return slot = edge_vertex(A, C, j);
      }
      if (wa == 0) {
        return slot = edge_vertex(B, C, j);
      }
      slot = mesh.num_vertices();
      mesh.positions.push_back((wa * corners[A] + i * corners[B] + j * corners[C]).normalized());
      return slot;
    };
    for (int i = 0; i < k; ++i) {
      for (int j = 0; i + j < k; ++j) {
        mesh.add_face({point(i, j), point(i + 1, j), point(i, j + 1)});
        if (i + j + 2 <= k) {
          mesh.add_face({point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)});
        }
      }
    }
  }
  return mesh;
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
