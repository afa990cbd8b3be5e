#include "elastic/mapping/mapping.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "elastic/core/directed_edges.h"
#include "elastic/core/error.h"
#include "elastic/core/triangle_locator_2d.h"

namespace elastic {
namespace {

// Weights below -kRoundOff are "negative beyond round-off". A weight is a ratio of a distance to a
// triangle height; for a query exactly on an edge or at a corner it comes out as ~1e-15 of
// whichever sign, so 1e-10 separates "on the edge" from "across it" with a wide margin while still
// being far below anything a caller could measure (1e-10 of a grid spacing).
constexpr double kRoundOff = 1e-10;

// The walk from the disk map's guess crosses one or two triangles on a well-relaxed grid (the disk
// location is off by a fraction of a triangle); the bound only stops a pathological walk (a grid
// folded in 3D or in disk coordinates).
constexpr int kMaxWalkSteps = 64;

// neighbours[t][k]: the triangle across the edge of t opposite its corner k (the edge
// tri[k+1] -> tri[k+2]), or -1 on the grid's boundary. Triangles are consistently oriented, so the
// neighbour holds the same edge reversed.
std::vector<std::array<int, 3>> triangle_neighbours(const std::vector<Eigen::Vector3i>& triangles,
                                                    int num_particles) {
  const DirectedEdges edges(triangles, num_particles);
  std::vector<std::array<int, 3>> neighbours(triangles.size(), {-1, -1, -1});
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, triangles.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t t = r.begin(); t != r.end(); ++t) {
                        const Eigen::Vector3i& tri = triangles[t];
                        for (int k = 0; k < 3; ++k) {
                          // The neighbour across edge k (opposite corner k) holds it reversed; a
                          // duplicated edge gives its first triangle.
                          const int e = edges.find(tri[(k + 2) % 3], tri[(k + 1) % 3]);
                          if (e >= 0) {
                            neighbours[t][static_cast<std::size_t>(k)] = edges.triangle(e);
                          }
                        }
                      }
                    });
  return neighbours;
}

// Barycentric coordinates of the orthogonal projection of x onto the plane of the triangle
// (a, b, c): the least-squares solution of min |b1 e1 + b2 e2 - (x - a)| with e1 = b - a,
// e2 = c - a, from its 2x2 normal equations. False for a (numerically) degenerate triangle.
bool plane_weights(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& x, Eigen::Vector3d& w) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, d = x - a;
  const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
  const double det = g11 * g22 - g12 * g12;  // |e1 x e2|^2
  // Relative to g11 g22 this is sin^2 of the triangle's angle at a: 1e-24 means an angle of 1e-12.
  if (!(det > 1e-24 * g11 * g22)) {
    return false;
  }
  const double r1 = e1.dot(d), r2 = e2.dot(d);
  const double b1 = (g22 * r1 - g12 * r2) / det, b2 = (g11 * r2 - g12 * r1) / det;
  w = Eigen::Vector3d(1.0 - b1 - b2, b1, b2);
  return true;
}

// The point of the triangle nearest to the point with plane weights w (which may be outside it),
// as weights: unchanged when inside; otherwise the nearest point of the three edges. Because the
// point is already in the triangle's plane, this is also the triangle's closest point to the 3D
// query, and on an edge shared with a neighbour both triangles clamp to the same point.
Eigen::Vector3d clamp_to_triangle(const std::array<Eigen::Vector3d, 3>& corners,
                                  const Eigen::Vector3d& w) {
  if (w.minCoeff() >= 0.0) {
    return w;
  }
  const Eigen::Vector3d p = w[0] * corners[0] + w[1] * corners[1] + w[2] * corners[2];
  Eigen::Vector3d best = Eigen::Vector3d::Zero();
  double best_distance = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const Eigen::Vector3d edge = corners[static_cast<size_t>(j)] - corners[static_cast<size_t>(i)];
    const double length2 = edge.squaredNorm();
    const double s =
        length2 > 0.0
            ? std::clamp((p - corners[static_cast<size_t>(i)]).dot(edge) / length2, 0.0, 1.0)
            : 0.0;
    const double distance = (corners[static_cast<size_t>(i)] + s * edge - p).squaredNorm();
    if (distance < best_distance) {
      best_distance = distance;
      best = Eigen::Vector3d::Zero();
      best[i] = 1.0 - s;
      best[j] = s;
    }
  }
  return best;
}

}  // namespace

struct Mapping::Impl {
  const SurfaceProjector* source = nullptr;
  const SurfaceProjector* target = nullptr;
  const RegionDiskMap* source_disk = nullptr;
  const RegionDiskMap* target_disk = nullptr;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<std::array<int, 3>> neighbours;  // see triangle_neighbours()
  std::vector<SurfacePoint> source_points;
  std::vector<SurfacePoint> target_points;
  Eigen::Matrix3Xd source_positions;
  Eigen::Matrix3Xd target_positions;
  TriangleLocator2D source_locator;  // grid triangles in source-disk coordinates
  TriangleLocator2D target_locator;  // grid triangles in target-disk coordinates

  // Where a query lies in the grid: triangle and 3D affine weights, or triangle -1 (outside).
  struct Found {
    int triangle = -1;
    Eigen::Vector3d weights = Eigen::Vector3d::Zero();
  };

  std::array<Eigen::Vector3d, 3> corners(const Eigen::Matrix3Xd& positions, int t) const {
    const Eigen::Vector3i& tri = triangles[static_cast<size_t>(t)];
    return {positions.col(tri[0]), positions.col(tri[1]), positions.col(tri[2])};
  }

  // Locates the query (3D position x, disk coordinates `disk`) among the grid triangles laid out
  // by `positions` (the query side's particles): the disk locator's triangle (or, when the disk
  // point is in no grid triangle, its nearest one) is the first guess; then a walk in 3D from
  // triangle to triangle across the edge opposite the most negative plane weight, until the
  // weights are all >= -kRoundOff. See the file comment of mapping.h for the outcomes.
  Found locate(const TriangleLocator2D& locator, const Eigen::Matrix3Xd& positions,
               const Eigen::Vector2d& disk, const Eigen::Vector3d& x) const {
    TriangleLocator2D::Hit guess = locator.locate(disk, 1e-9);
    const bool disk_inside = guess.found();
    if (!disk_inside) {
      guess = locator.nearest(disk);
    }
    if (!guess.found()) {
      return {};
    }

    int t = guess.triangle;
    Eigen::Vector3d w;
    {
      const auto c = corners(positions, t);
      if (!plane_weights(c[0], c[1], c[2], x, w)) {
        // A grid triangle degenerate in 3D has no plane to project on: keep the disk's answer
        // there (inside only if the disk map put the query in it).
        return disk_inside ? Found{t, guess.barycentric} : Found{};
      }
    }
    std::array<int, kMaxWalkSteps> visited{};
    int num_visited = 0;
    int best = t;  // the visited triangle whose weights are the least negative
    Eigen::Vector3d best_weights = w;
    bool met_boundary = false;  // a weight was negative opposite an edge of the grid's boundary
    while (true) {
      visited[static_cast<size_t>(num_visited++)] = t;
      if (w.minCoeff() > best_weights.minCoeff()) {
        best = t;
        best_weights = w;
      }
      if (w.minCoeff() >= -kRoundOff) {
        return {t, w};
      }

      // Cross the edge opposite the most negative weight; if that edge is on the grid's boundary
      // (or leads back to a visited triangle), the next most negative one, which lets the walk
      // turn around a concave stretch of the boundary.
      std::array<int, 3> order{0, 1, 2};
      std::sort(order.begin(), order.end(), [&w](int i, int j) { return w[i] < w[j]; });
      int next = -1;
      Eigen::Vector3d next_weights;
      for (const int k : order) {
        if (w[k] >= -kRoundOff) {
          break;
        }
        const int n = neighbours[static_cast<size_t>(t)][static_cast<size_t>(k)];
        if (n < 0) {
          met_boundary = true;
          continue;
        }
        if (std::find(visited.begin(), visited.begin() + num_visited, n) !=
            visited.begin() + num_visited) {
          continue;
        }
        const auto c = corners(positions, n);
        if (!plane_weights(c[0], c[1], c[2], x, next_weights)) {
          continue;
        }
        next = n;
        break;
      }
      if (next < 0 || num_visited == kMaxWalkSteps) {
        break;
      }
      t = next;
      w = next_weights;
    }
    // No triangle holds the query's projection. Beyond the grid's boundary in 3D: outside if the
    // disk maps agree; if they put it inside the grid (the two disagree by the disk maps'
    // non-affinity, a sliver along the boundary), clamped. Otherwise the walk cycled between
    // triangles whose planes leave a gap (a query above an edge where the grid bends) or ran out
    // of steps: clamped too. Clamping is onto the least-outside triangle visited; across an edge
    // shared by two triangles both clamp to the same point of it, so this is continuous.
    if (met_boundary && !disk_inside) {
      return {};
    }
    return {best, clamp_to_triangle(corners(positions, best), best_weights)};
  }

  // Barycentric combination of particle positions, put on `surface` by the magnet warm-started from
  // the triangle's particle with the largest weight.
  Location land(const SurfaceProjector& projector, const Eigen::Matrix3Xd& positions,
                const std::vector<SurfacePoint>& points, const Found& found) const {
    const Eigen::Vector3i& tri = triangles[static_cast<size_t>(found.triangle)];
    const Eigen::Vector3d& w = found.weights;
    const Eigen::Vector3d x =
        w[0] * positions.col(tri[0]) + w[1] * positions.col(tri[1]) + w[2] * positions.col(tri[2]);
    int heaviest = 0;
    w.maxCoeff(&heaviest);
    const ClosestPoint cp = projector.closest(x, points[static_cast<size_t>(tri[heaviest])]);
    Location out;
    out.inside = true;
    out.point = cp.point;
    out.position = cp.position;
    out.triangle = found.triangle;
    out.barycentric = w;
    return out;
  }
};

Mapping::Mapping(const ParticleGrid& grid, const SurfaceProjector& source,
                 const RegionDiskMap& source_disk, const SurfaceProjector& target,
                 const RegionDiskMap& target_disk, const std::vector<SurfacePoint>& target_points) {
  const int n = grid.num_particles();
  if (static_cast<int>(target_points.size()) != n) {
    throw InvalidInputError("mapping", "target points do not match the particle count");
  }
  auto impl = std::make_shared<Impl>();
  impl->source = &source;
  impl->target = &target;
  impl->source_disk = &source_disk;
  impl->target_disk = &target_disk;
  impl->triangles = grid_triangles(grid);
  impl->neighbours = triangle_neighbours(impl->triangles, n);
  impl->source_points = grid.source_points;
  impl->target_points = target_points;
  impl->source_positions.resize(3, n);
  impl->target_positions.resize(3, n);
  std::vector<Eigen::Vector2d> source_uv(static_cast<size_t>(n)), target_uv(static_cast<size_t>(n));
  // Each particle on its own, in parallel (0.19 s of a 100k-particle map on one thread). The
  // first particle outside a region (by index, whatever the thread count) is the one reported.
  std::atomic<int> outside_source{n}, outside_target{n};
  const auto lower = [](std::atomic<int>& first, int i) {
    int seen = first.load();
    while (i < seen && !first.compare_exchange_weak(seen, i)) {
    }
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 256), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) {
      const auto u = static_cast<size_t>(i);
      impl->source_positions.col(i) = source.surface().position(grid.source_points[u]);
      impl->target_positions.col(i) = target.surface().position(target_points[u]);
      if (!source_disk.to_disk(grid.source_points[u], source_uv[u])) {
        lower(outside_source, i);
      }
      if (!target_disk.to_disk(target_points[u], target_uv[u])) {
        lower(outside_target, i);
      }
    }
  });
  if (outside_source < n && outside_source <= outside_target) {
    throw NumericalError("mapping", "particle " + std::to_string(outside_source.load()) +
                                        " is outside the source region");
  }
  if (outside_target < n) {
    throw NumericalError("mapping", "particle " + std::to_string(outside_target.load()) +
                                        " is outside the target region");
  }
  tbb::parallel_invoke(
      [&] { impl->source_locator = TriangleLocator2D(std::move(source_uv), impl->triangles); },
      [&] { impl->target_locator = TriangleLocator2D(std::move(target_uv), impl->triangles); });
  impl_ = std::move(impl);
}

Mapping::Location Mapping::forward(const SurfacePoint& source_point) const {
  Eigen::Vector2d disk;
  if (!impl_ || !impl_->source_disk->to_disk(source_point, disk)) {
    return {};
  }
  const Impl::Found found = impl_->locate(impl_->source_locator, impl_->source_positions, disk,
                                          impl_->source->surface().position(source_point));
  if (found.triangle < 0) {
    return {};
  }
  return impl_->land(*impl_->target, impl_->target_positions, impl_->target_points, found);
}

Mapping::Location Mapping::inverse(const SurfacePoint& target_point) const {
  Eigen::Vector2d disk;
  if (!impl_ || !impl_->target_disk->to_disk(target_point, disk)) {
    return {};
  }
  const Impl::Found found = impl_->locate(impl_->target_locator, impl_->target_positions, disk,
                                          impl_->target->surface().position(target_point));
  if (found.triangle < 0) {
    return {};
  }
  return impl_->land(*impl_->source, impl_->source_positions, impl_->source_points, found);
}

const std::vector<Eigen::Vector3i>& Mapping::triangles() const {
  static const std::vector<Eigen::Vector3i> none;
  return impl_ ? impl_->triangles : none;
}

}  // namespace elastic
