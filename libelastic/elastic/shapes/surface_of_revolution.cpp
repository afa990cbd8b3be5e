// Surfaces of revolution (detail/shape_building.h): a profile swept around the z axis, its rings
// laid out for nearly square quads or equilateral triangles, the bands between rings stitched, a
// quad disk or polygon at a pole.
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

#include "elastic/shapes/detail/shape_building.h"

namespace elastic::shapes_detail {
namespace {

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

}  // namespace

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

}  // namespace elastic::shapes_detail
