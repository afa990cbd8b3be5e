#include "elastic/mapping/initial_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>

#include "elastic/core/error.h"
#include "elastic/core/triangle_locator_2d.h"
#include "elastic/particles/face_folds.h"

namespace elastic {

struct RegionDiskMap::Locators {
  TriangleLocator2D disk;                        // region triangles in disk coordinates
  std::vector<std::vector<int>> face_triangles;  // ptex face -> region triangles inside it
  std::vector<double> boundary_arc;    // cumulative arc length at each boundary vertex, / total
  std::vector<int> boundary_triangle;  // region triangle holding boundary edge k -> k+1
  std::vector<Eigen::Vector2i> boundary_corners;  // that triangle's corner indices of the edge ends
};

namespace {

// Barycentric coordinates of p in the triangle (a, b, c); NaN for a degenerate triangle.
Eigen::Vector3d barycentric(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                            const Eigen::Vector2d& c, const Eigen::Vector2d& p) {
  const Eigen::Vector2d e1 = b - a, e2 = c - a, d = p - a;
  const double det = e1.x() * e2.y() - e1.y() * e2.x();
  if (det == 0.0) {
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  const double b1 = (d.x() * e2.y() - d.y() * e2.x()) / det;
  const double b2 = (e1.x() * d.y() - e1.y() * d.x()) / det;
  return {1.0 - b1 - b2, b1, b2};
}

// Squared distance from p to triangle (a, b, c) in 3D and the barycentrics of the closest point.
double closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b, const Eigen::Vector3d& c, Eigen::Vector3d& w) {
  // Project onto the plane, then clamp to the edges when outside (enough for a fallback search).
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d00 = ab.dot(ab), d01 = ab.dot(ac), d11 = ac.dot(ac);
  const double d20 = ap.dot(ab), d21 = ap.dot(ac);
  const double det = d00 * d11 - d01 * d01;
  if (det > 0.0) {
    const double v = (d11 * d20 - d01 * d21) / det;
    const double u = (d00 * d21 - d01 * d20) / det;
    if (v >= 0.0 && u >= 0.0 && u + v <= 1.0) {
      w = {1.0 - u - v, v, u};
      return (a + v * ab + u * ac - p).squaredNorm();
    }
  }
  double best = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d corners[3] = {a, b, c};
  for (int e = 0; e < 3; ++e) {
    const Eigen::Vector3d& s0 = corners[e];
    const Eigen::Vector3d& s1 = corners[(e + 1) % 3];
    const Eigen::Vector3d d = s1 - s0;
    const double len2 = d.squaredNorm();
    const double t = len2 > 0.0 ? std::clamp((p - s0).dot(d) / len2, 0.0, 1.0) : 0.0;
    const double dist = (s0 + t * d - p).squaredNorm();
    if (dist < best) {
      best = dist;
      w.setZero();
      w[e] = 1.0 - t;
      w[(e + 1) % 3] = t;
    }
  }
  return best;
}

}  // namespace

RegionDiskMap::RegionDiskMap(const Region& region) : region_(&region) {
  if (region.surface == nullptr || region.triangles.empty() || region.boundary.size() < 3) {
    throw InvalidInputError("region", "region is empty or has no boundary");
  }
  flattening_ = flatten_region(region, {.method = FlatteningMethod::Disk});
  auto locators = std::make_shared<Locators>();
  locators->disk = TriangleLocator2D(flattening_.uv, region.triangles);
  locators->face_triangles.resize(region.surface->num_faces());
  for (int t = 0; t < region.num_triangles(); ++t) {
    locators->face_triangles[region.triangle_face[t]].push_back(t);
  }

  // Boundary: arc lengths and, for each boundary edge, the triangle that holds it.
  const int n = static_cast<int>(region.boundary.size());
  const std::vector<BoundaryChord> chords = region.boundary_chords();
  locators->boundary_arc.resize(n + 1, 0.0);
  locators->boundary_triangle.resize(n);
  locators->boundary_corners.resize(n);
  for (int k = 0; k < n; ++k) {
    const int a = region.boundary[k], b = region.boundary[(k + 1) % n];
    locators->boundary_arc[k + 1] =
        locators->boundary_arc[k] + (region.positions[b] - region.positions[a]).norm();
    // The boundary runs counter-clockwise, like the triangles, so edge a->b is a triangle's own
    // edge.
    const BoundaryChord& chord = chords[k];
    if (chord.triangle < 0 || chord.corner_to != (chord.corner_from + 1) % 3) {
      throw InvalidInputError("region", "boundary edge is not an edge of a region triangle");
    }
    locators->boundary_triangle[k] = chord.triangle;
    locators->boundary_corners[k] = Eigen::Vector2i(chord.corner_from, chord.corner_to);
  }
  const double total = locators->boundary_arc[n];
  if (!(total > 0.0)) {
    throw InvalidInputError("region", "boundary has zero length");
  }
  for (double& a : locators->boundary_arc) {
    a /= total;
  }
  locators_ = std::move(locators);
}

bool RegionDiskMap::to_disk(const SurfacePoint& p, Eigen::Vector2d& disk) const {
  const Region& region = *region_;
  auto interpolate = [&](int t, const Eigen::Vector3d& w) {
    const Eigen::Vector3i& tri = region.triangles[t];
    disk = w[0] * flattening_.uv[tri[0]] + w[1] * flattening_.uv[tri[1]] +
           w[2] * flattening_.uv[tri[2]];
  };
  // In the point's own ptex face: the region triangle containing (u, v), deepest first.
  if (p.face >= 0 && p.face < static_cast<int>(locators_->face_triangles.size())) {
    int best = -1;
    double best_min = -1e-9;  // parameter-space slack for points on triangle edges
    Eigen::Vector3d best_w = Eigen::Vector3d::Zero();
    for (int t : locators_->face_triangles[p.face]) {
      const auto& uv = region.triangle_uv[t];
      const Eigen::Vector3d w = barycentric(uv[0], uv[1], uv[2], p.uv());
      if (!w.allFinite()) {
        continue;
      }
      if (w.minCoeff() > best_min) {
        best_min = w.minCoeff();
        best = t;
        best_w = w;
      }
    }
    if (best >= 0) {
      interpolate(best, best_w.cwiseMax(0.0) / best_w.cwiseMax(0.0).sum());
      disk = turn_.transpose() * disk;
      return true;
    }
  }
  // A point on a ptex edge may be written in the neighbouring face: fall back to the nearest region
  // triangle in 3D, accepted when the point is within round-off of it.
  const Eigen::Vector3d x = region.surface->position(p);
  double best_d2 = std::numeric_limits<double>::infinity();
  int best = -1;
  Eigen::Vector3d best_w = Eigen::Vector3d::Zero();
  for (int t = 0; t < region.num_triangles(); ++t) {
    const Eigen::Vector3i& tri = region.triangles[t];
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    const double d2 = closest_on_triangle(x, region.positions[tri[0]], region.positions[tri[1]],
                                          region.positions[tri[2]], w);
    if (d2 < best_d2) {
      best_d2 = d2;
      best = t;
      best_w = w;
    }
  }
  if (best < 0) {
    return false;
  }
  // Accept points within a small fraction of the triangle's size (chord error of the tessellation).
  const Eigen::Vector3i& tri = region.triangles[best];
  const double size = (region.positions[tri[1]] - region.positions[tri[0]]).norm() +
                      (region.positions[tri[2]] - region.positions[tri[0]]).norm();
  if (best_d2 > (0.05 * size) * (0.05 * size)) {
    return false;
  }
  interpolate(best, best_w);
  disk = turn_.transpose() * disk;
  return true;
}

bool RegionDiskMap::from_disk(const Eigen::Vector2d& disk, SurfacePoint& p,
                              double tolerance) const {
  if (!disk.allFinite() || disk.norm() > 1.0 + tolerance) {
    return false;
  }
  const Eigen::Vector2d flat = turn_ * disk;
  TriangleLocator2D::Hit hit = locators_->disk.locate(flat, 1e-12);
  if (!hit.found()) {
    hit = locators_->disk.nearest(flat);  // between the circle and its inscribed polygon
  }
  if (!hit.found()) {
    return false;
  }
  p = region_->point_in_triangle(hit.triangle, hit.barycentric[1], hit.barycentric[2]);
  return true;
}

SurfacePoint RegionDiskMap::boundary_point(double s) const {
  const Region& region = *region_;
  const std::vector<double>& arc = locators_->boundary_arc;
  const int n = static_cast<int>(region.boundary.size());
  double a = std::fmod(region.anchor + offset_ + s, 1.0);
  if (a < 0.0) {
    a += 1.0;
  }
  // Segment k with arc[k] <= a < arc[k+1].
  const int k = std::clamp(
      static_cast<int>(std::upper_bound(arc.begin(), arc.end(), a) - arc.begin()) - 1, 0, n - 1);
  const double span = arc[k + 1] - arc[k];
  const double t = span > 0.0 ? std::clamp((a - arc[k]) / span, 0.0, 1.0) : 0.0;
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  w[locators_->boundary_corners[k][0]] = 1.0 - t;
  w[locators_->boundary_corners[k][1]] = t;
  return region.point_in_triangle(locators_->boundary_triangle[k], w[1], w[2]);
}

void RegionDiskMap::set_offset(double offset) {
  offset_ = offset - std::floor(offset);
  const double angle = 2.0 * std::numbers::pi * offset_;
  turn_ << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
}

namespace {

// The half of the naive map (or of a transported map) that does not depend on the target: each
// interior particle's point on the source's (or the previous region's) disk, each boundary
// particle's correspondence parameter (-1 for interior ones).
struct SourceDiskPoints {
  std::vector<Eigen::Vector2d> disk;
  std::vector<double> parameter;
  std::vector<char> outside;  // 1: the source point is not in the source region (disk = 0)
};

// Each particle of `grid` on `disk`'s disk: interior particle i at its surface point points[i]
// (on `disk`'s region), boundary particle k (boundary_loop order) by its correspondence parameter
// parameters[k], taken modulo 1 (exact for parameters already in [0, 1)).
SourceDiskPoints disk_points(const ParticleGrid& grid, const std::vector<SurfacePoint>& points,
                             const std::vector<double>& parameters, const RegionDiskMap& disk) {
  const int n = grid.num_particles();
  SourceDiskPoints result;
  result.disk.assign(static_cast<std::size_t>(n), Eigen::Vector2d::Zero());
  result.parameter.assign(static_cast<std::size_t>(n), -1.0);
  result.outside.assign(static_cast<std::size_t>(n), 0);
  for (std::size_t k = 0; k < grid.boundary_loop.size(); ++k) {
    result.parameter[static_cast<std::size_t>(grid.boundary_loop[k])] =
        parameters[k] - std::floor(parameters[k]);
  }
  // Each particle on its own (the disk maps are immutable): the same result on any thread count.
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 512), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (result.parameter[k] < 0.0 && !disk.to_disk(points[k], result.disk[k])) {
        result.outside[k] = 1;
        result.disk[k].setZero();  // keep the particle inside the target region; counted outside
      }
    }
  });
  return result;
}

SourceDiskPoints source_disk_points(const ParticleGrid& grid, const RegionDiskMap& source) {
  return disk_points(grid, grid.source_points, grid.boundary_parameter, source);
}

// The other half: the disk points onto the target region.
InitialMap place_on_target(const SourceDiskPoints& from, const RegionDiskMap& target) {
  const auto n = static_cast<int>(from.disk.size());
  InitialMap result;
  result.positions.resize(3, n);
  result.points.resize(static_cast<std::size_t>(n));
  const LimitSurface& surface = *target.region().surface;
  std::vector<char> missed(static_cast<std::size_t>(n), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 512), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) {
      const auto k = static_cast<std::size_t>(i);
      SurfacePoint q;
      if (from.parameter[k] >= 0.0) {
        q = target.boundary_point(from.parameter[k]);
      } else if (!target.from_disk(from.disk[k], q)) {
        missed[k] = 1;
        target.from_disk(Eigen::Vector2d::Zero(), q);
      }
      result.points[k] = q;
      result.positions.col(i) = surface.position(q);
    }
  });
  for (std::size_t k = 0; k < missed.size(); ++k) {
    result.outside += from.outside[k] + missed[k];
  }
  return result;
}

}  // namespace

InitialMap naive_map(const ParticleGrid& grid, const RegionDiskMap& source,
                     const RegionDiskMap& target) {
  return place_on_target(source_disk_points(grid, source), target);
}

InitialMap transported_map(const ParticleGrid& grid, const std::vector<SurfacePoint>& points,
                           const std::vector<double>& boundary_parameters,
                           const RegionDiskMap& from, const RegionDiskMap& to) {
  const int n = grid.num_particles();
  if (points.size() != static_cast<std::size_t>(n) ||
      boundary_parameters.size() != grid.boundary_loop.size()) {
    throw InvalidInputError("transported map",
                            "the map's points or boundary parameters do not match the grid (" +
                                std::to_string(n) + " particles)");
  }
  // The same two halves as the naive map, with `from`'s disk in place of the source's.
  return place_on_target(disk_points(grid, points, boundary_parameters, from), to);
}

namespace {

// s(t) of the coarse boundary: the pairs (t_k, s_k) in loop order, t unwrapped to increase once
// around the loop from t_0 and s likewise (the slide keeps the order); linear in between and
// across the seam (t_last -> t_0 + 1, s_last -> s_0 + 1).
class BoundaryCorrespondence {
 public:
  BoundaryCorrespondence(const std::vector<double>& t, const std::vector<double>& s)
      : t_(t), s_(s) {
    for (std::size_t k = 1; k < t_.size(); ++k) {
      t_[k] += std::ceil(t_[k - 1] - t_[k]);  // the smallest t_k + n at or above t_{k-1}
      s_[k] += std::ceil(s_[k - 1] - s_[k]);
    }
  }

  double operator()(double t) const {
    const std::size_t m = t_.size();
    const double q = t - std::floor(t - t_[0]);  // in [t_0, t_0 + 1)
    const auto k =
        static_cast<std::size_t>(std::upper_bound(t_.begin(), t_.end(), q) - t_.begin()) - 1;
    const double t1 = k + 1 < m ? t_[k + 1] : t_[0] + 1.0;
    const double s1 = k + 1 < m ? s_[k + 1] : s_[0] + 1.0;
    const double w = t1 > t_[k] ? std::clamp((q - t_[k]) / (t1 - t_[k]), 0.0, 1.0) : 0.0;
    return s_[k] + w * (s1 - s_[k]);
  }

 private:
  std::vector<double> t_, s_;
};

}  // namespace

InitialMap prolonged_map(const ParticleGrid& grid, const ParticleGrid& coarse,
                         const std::vector<SurfacePoint>& coarse_points,
                         const std::vector<double>& coarse_parameters, const RegionDiskMap& source,
                         const RegionDiskMap& target, std::vector<double>& boundary_parameters) {
  const int nc = coarse.num_particles();
  if (coarse_points.size() != static_cast<std::size_t>(nc) ||
      coarse_parameters.size() != coarse.boundary_loop.size() || coarse.boundary_loop.size() < 3) {
    throw InvalidInputError("coarse start",
                            "the coarse map's points or boundary parameters do "
                            "not match its grid (" +
                                std::to_string(nc) + " particles)");
  }
  // Each coarse particle on both disks: from the source grid's points, and where it was relaxed.
  const SourceDiskPoints from = source_disk_points(coarse, source);
  const SourceDiskPoints to = disk_points(coarse, coarse_points, coarse_parameters, target);
  std::vector<Eigen::Vector2d> from_disk = from.disk, to_disk = to.disk;
  int outside = 0;
  for (int i = 0; i < nc; ++i) {
    const auto k = static_cast<std::size_t>(i);
    outside += from.outside[k] + to.outside[k];
    for (const auto* side : {&from, &to}) {
      if (side->parameter[k] >= 0.0) {
        const double angle = 2.0 * std::numbers::pi * side->parameter[k];
        (side == &from ? from_disk : to_disk)[k] = {std::cos(angle), std::sin(angle)};
      }
    }
  }
  const std::vector<Eigen::Vector3i> triangles = grid_triangles(coarse);
  const TriangleLocator2D locator(from_disk, triangles);

  const BoundaryCorrespondence s_of_t(coarse.boundary_parameter, coarse_parameters);
  boundary_parameters.clear();
  for (const double t : grid.boundary_parameter) {
    boundary_parameters.push_back(s_of_t(t));
  }

  // The grid's particles on the source disk, through the coarse map to the target disk.
  // (Boundary particles keep their parameter s(t): place_on_target puts them on the curve.)
  SourceDiskPoints fine = disk_points(grid, grid.source_points, boundary_parameters, source);
  const int n = grid.num_particles();
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 512), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (fine.parameter[k] >= 0.0 || fine.outside[k] != 0) {
        continue;
      }
      const Eigen::Vector2d& p = fine.disk[k];
      TriangleLocator2D::Hit hit = locator.locate(p, 1e-12);
      if (!hit.found()) {
        hit = locator.nearest(p);  // the sliver along the boundary: extrapolate that triangle's map
        const Eigen::Vector3i& c = triangles[static_cast<std::size_t>(hit.triangle)];
        const Eigen::Vector3d w = barycentric(from_disk[static_cast<std::size_t>(c[0])],
                                              from_disk[static_cast<std::size_t>(c[1])],
                                              from_disk[static_cast<std::size_t>(c[2])], p);
        if (w.allFinite()) {
          hit.barycentric = w;
        }
      }
      const Eigen::Vector3i& c = triangles[static_cast<std::size_t>(hit.triangle)];
      Eigen::Vector2d q = Eigen::Vector2d::Zero();
      for (int j = 0; j < 3; ++j) {
        q += hit.barycentric[j] * to_disk[static_cast<std::size_t>(c[j])];
      }
      // Extrapolation may leave the disk by round-off of the chord: back onto its inside.
      const double r2 = q.squaredNorm();
      constexpr double kInside = 1.0 - 1e-9;
      fine.disk[k] = r2 > kInside * kInside ? Eigen::Vector2d(q * (kInside / std::sqrt(r2))) : q;
    }
  });
  InitialMap result = place_on_target(fine, target);
  result.outside += outside;
  return result;
}

namespace {

// Faces of the naive map that fold against the target surface: the one fold definition
// (particles/face_folds.h), with the unit normals at the particles.
int naive_folds(const ParticleGrid& grid, const InitialMap& naive, const LimitSurface& surface) {
  const auto n = static_cast<Eigen::Index>(naive.points.size());
  Eigen::Matrix3Xd normals(3, n);
  tbb::parallel_for(
      tbb::blocked_range<Eigen::Index>(0, n, 512), [&](const tbb::blocked_range<Eigen::Index>& r) {
        for (Eigen::Index i = r.begin(); i != r.end(); ++i) {
          normals.col(i) = surface.curvature(naive.points[static_cast<std::size_t>(i)]).normal;
        }
      });
  return inverted_faces(grid, naive.positions, normals);
}

}  // namespace

BoundaryOffsetResult choose_boundary_offset(const ParticleGrid& grid, const RegionDiskMap& source,
                                            RegionDiskMap& target,
                                            const BoundaryOffsetOptions& options) {
  if (options.candidates < 1) {
    throw InvalidInputError("boundary offset", "needs at least one candidate");
  }
  const SpringSystem springs(grid, options.energy);
  BoundaryOffsetResult result;
  result.candidates = options.candidates;
  // The source half of the naive map does not turn with the offset: computed once.
  const SourceDiskPoints from = source_disk_points(grid, source);
  std::vector<double> energy(static_cast<std::size_t>(options.candidates));
  // The least-energy candidate's placement is kept: it is the one tested for folds first, and
  // usually the one returned.
  std::optional<InitialMap> lowest;
  int lowest_k = -1;
  for (int k = 0; k < options.candidates; ++k) {
    target.set_offset(static_cast<double>(k) / options.candidates);
    InitialMap naive = place_on_target(from, target);
    energy[static_cast<std::size_t>(k)] = naive.outside > 0
                                              ? std::numeric_limits<double>::infinity()
                                              : springs.evaluate(naive.positions).total();
    if (lowest_k < 0 ||
        energy[static_cast<std::size_t>(k)] < energy[static_cast<std::size_t>(lowest_k)]) {
      lowest = std::move(naive);
      lowest_k = k;
    }
  }
  result.energy_at_zero = energy[0];
  // By energy (ties keep the smaller offset: the region's own anchor first); the first whose naive
  // map folds no face wins, else the one with the fewest folds. A folded start is what the solver
  // handles worst (the barrier cannot cross a fold; untangling can fail), and usually only the
  // first candidate is tested.
  std::vector<int> order(energy.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return energy[static_cast<std::size_t>(a)] < energy[static_cast<std::size_t>(b)];
  });
  const LimitSurface& surface = *target.region().surface;
  int fewest = std::numeric_limits<int>::max();
  for (const int k : order) {
    if (!std::isfinite(energy[static_cast<std::size_t>(k)]) &&
        fewest < std::numeric_limits<int>::max()) {
      break;
    }
    target.set_offset(static_cast<double>(k) / options.candidates);
    InitialMap naive = k == lowest_k ? std::move(*lowest) : place_on_target(from, target);
    const int folds = naive_folds(grid, naive, surface);
    if (folds < fewest) {
      fewest = folds;
      result.offset = static_cast<double>(k) / options.candidates;
      result.energy = energy[static_cast<std::size_t>(k)];
      result.folds = folds;
      result.naive = std::move(naive);
    }
    if (folds == 0) {
      break;
    }
  }
  target.set_offset(result.offset);
  return result;
}

}  // namespace elastic
