#include "elastic/baselines/baseline_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <chrono>
#include <cmath>
#include <complex>
#include <exception>
#include <limits>
#include <map>
#include <string>

#include "elastic/baselines/cgal_flattening.h"
#include "elastic/core/error.h"
#include "elastic/core/triangle_locator_2d.h"

namespace elastic {

std::string_view to_string(BaselineKind kind) {
  switch (kind) {
    case BaselineKind::Lscm:
      return "lscm";
    case BaselineKind::Arap:
      return "arap";
    case BaselineKind::Dcm:
      return "dcm";
  }
  return "unknown";
}

BaselineKind parse_baseline_kind(std::string_view text, std::string_view input) {
  for (BaselineKind kind : {BaselineKind::Lscm, BaselineKind::Arap, BaselineKind::Dcm}) {
    if (text == to_string(kind)) {
      return kind;
    }
  }
  throw InvalidInputError(std::string(input), "unknown baseline '" + std::string(text) +
                                                  "' (expected lscm, arap or dcm)");
}

namespace {

using Complex = std::complex<double>;

// Squared distance from p to the 3D triangle (a, b, c) and the barycentrics of the closest point
// (Ericson, Real-Time Collision Detection, 5.1.5: Voronoi regions of vertices, edges and face).
double closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b, const Eigen::Vector3d& c, Eigen::Vector3d& w) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    w = {1, 0, 0};
    return ap.squaredNorm();
  }
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    w = {0, 1, 0};
    return bp.squaredNorm();
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    w = {1 - v, v, 0};
    return (a + v * ab - p).squaredNorm();
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    w = {0, 0, 1};
    return cp.squaredNorm();
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double v = d2 / (d2 - d6);
    w = {1 - v, 0, v};
    return (a + v * ac - p).squaredNorm();
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    w = {0, 1 - v, v};
    return (b + v * (c - b) - p).squaredNorm();
  }
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0.0)) {  // degenerate triangle: distance to a corner
    w = {1, 0, 0};
    return ap.squaredNorm();
  }
  const double v = vb / denom, u = vc / denom;
  w = {1 - v - u, v, u};
  return (a + v * ab + u * ac - p).squaredNorm();
}

// Where a SurfacePoint of a region lies among the region's triangles: per ptex face, a planar
// locator over the (u, v) corners of the region triangles inside that face (triangle_uv).
class RegionPointLocator {
 public:
  explicit RegionPointLocator(const Region& region) : region_(&region) {
    const int num_faces = region.surface->num_faces();
    std::vector<std::vector<int>> face_triangles(static_cast<size_t>(num_faces));
    for (int t = 0; t < region.num_triangles(); ++t) {
      const int f = region.triangle_face[static_cast<size_t>(t)];
      if (f >= 0 && f < num_faces) {
        face_triangles[static_cast<size_t>(f)].push_back(t);
      }
    }
    locators_.resize(static_cast<size_t>(num_faces));
    triangles_ = std::move(face_triangles);
    for (size_t f = 0; f < triangles_.size(); ++f) {
      if (triangles_[f].empty()) {
        continue;
      }
      std::vector<Eigen::Vector2d> corners;
      std::vector<Eigen::Vector3i> local;
      for (int t : triangles_[f]) {
        const auto& uv = region.triangle_uv[static_cast<size_t>(t)];
        const int base = static_cast<int>(corners.size());
        corners.insert(corners.end(), uv.begin(), uv.end());
        local.emplace_back(base, base + 1, base + 2);
      }
      locators_[f] = TriangleLocator2D(std::move(corners), std::move(local));
    }
  }

  /// The region triangle holding p and p's barycentrics there. A point written in a ptex face that
  /// holds no region triangle containing it (a point on a ptex edge written in the neighbouring
  /// face) falls back to the region triangle nearest to `position` in 3D, accepted within a
  /// twentieth of that triangle's size (the tessellation's chord error is far smaller).
  bool locate(const SurfacePoint& p, const Eigen::Vector3d& position, double tolerance, int& t,
              Eigen::Vector3d& w) const {
    if (p.face >= 0 && static_cast<size_t>(p.face) < locators_.size() &&
        locators_[static_cast<size_t>(p.face)].num_triangles() > 0) {
      const TriangleLocator2D::Hit hit =
          locators_[static_cast<size_t>(p.face)].locate(p.uv(), tolerance);
      if (hit.found()) {
        t = triangles_[static_cast<size_t>(p.face)][static_cast<size_t>(hit.triangle)];
        w = hit.barycentric.cwiseMax(0.0) / hit.barycentric.cwiseMax(0.0).sum();
        return true;
      }
    }
    const Region& region = *region_;
    double best = std::numeric_limits<double>::infinity();
    t = -1;
    for (int k = 0; k < region.num_triangles(); ++k) {
      const Eigen::Vector3i& tri = region.triangles[static_cast<size_t>(k)];
      Eigen::Vector3d wk = Eigen::Vector3d::Zero();
      const double d2 = closest_on_triangle(position, region.positions[static_cast<size_t>(tri[0])],
                                            region.positions[static_cast<size_t>(tri[1])],
                                            region.positions[static_cast<size_t>(tri[2])], wk);
      if (d2 < best) {
        best = d2;
        t = k;
        w = wk;
      }
    }
    if (t < 0) {
      return false;
    }
    const Eigen::Vector3i& tri = region.triangles[static_cast<size_t>(t)];
    const double size = (region.positions[static_cast<size_t>(tri[1])] -
                         region.positions[static_cast<size_t>(tri[0])])
                            .norm() +
                        (region.positions[static_cast<size_t>(tri[2])] -
                         region.positions[static_cast<size_t>(tri[0])])
                            .norm();
    return best <= (0.05 * size) * (0.05 * size);
  }

 private:
  const Region* region_;
  std::vector<TriangleLocator2D> locators_;
  std::vector<std::vector<int>> triangles_;  // ptex face -> region triangles (locator order)
};

// The boundary of a region with its correspondence parametrisation: the point at parameter s on
// the 3D curve (exactly on the limit surface, through the triangle holding the boundary edge), and
// the same point in a flattening (linear along the flattened boundary edge).
class BoundaryParametrisation {
 public:
  // `offset` turns the correspondence: parameter s means the curve point at s + offset from the
  // region's anchor (RegionDiskMap::set_offset, BaselineOptions::target_offset).
  BoundaryParametrisation(const Region& region, const std::string& name, double offset = 0.0)
      : region_(&region), curve_(region.boundary_curve()), offset_(offset) {
    cumulative_ = curve_.arc_lengths();
    total_ = curve_.length();
    if (!(total_ > 0.0)) {
      throw InvalidInputError(name, "region boundary has zero length");
    }
    std::map<std::pair<int, int>, std::pair<int, int>>
        edge_triangle;  // (a, b) -> (triangle, corner of a)
    for (int t = 0; t < region.num_triangles(); ++t) {
      const Eigen::Vector3i& tri = region.triangles[static_cast<size_t>(t)];
      for (int k = 0; k < 3; ++k) {
        edge_triangle[{tri[k], tri[(k + 1) % 3]}] = {t, k};
      }
    }
    const size_t n = region.boundary.size();
    edge_triangle_.resize(n);
    edge_corner_.resize(n);
    for (size_t k = 0; k < n; ++k) {
      // The boundary runs counter-clockwise like the triangles, so edge k -> k+1 is a triangle's
      // own.
      const auto it = edge_triangle.find({region.boundary[k], region.boundary[(k + 1) % n]});
      if (it == edge_triangle.end()) {
        throw InvalidInputError(name, "boundary edge is not an edge of a region triangle");
      }
      edge_triangle_[k] = it->second.first;
      edge_corner_[k] = it->second.second;
    }
  }

  SurfaceCurve::Location locate(double s) const {
    const double turned = s + offset_;
    return curve_.locate(turned - std::floor(turned), cumulative_, total_);
  }

  /// The surface point at parameter s (on the boundary edge of its triangle).
  SurfacePoint point(double s) const {
    const SurfaceCurve::Location at = locate(s);
    const size_t k = static_cast<size_t>(at.segment);
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    w[edge_corner_[k]] = 1.0 - at.t;
    w[(edge_corner_[k] + 1) % 3] = at.t;
    return region_->point_in_triangle(edge_triangle_[k], w[1], w[2]);
  }

  /// The flattened boundary point at parameter s.
  Eigen::Vector2d planar(double s, const std::vector<Eigen::Vector2d>& uv) const {
    const SurfaceCurve::Location at = locate(s);
    const size_t n = region_->boundary.size();
    const size_t k = static_cast<size_t>(at.segment);
    return (1.0 - at.t) * uv[static_cast<size_t>(region_->boundary[k])] +
           at.t * uv[static_cast<size_t>(region_->boundary[(k + 1) % n])];
  }

 private:
  const Region* region_;
  SurfaceCurve curve_;
  double offset_ = 0.0;
  std::vector<double> cumulative_;
  double total_ = 0.0;
  std::vector<int> edge_triangle_;
  std::vector<int> edge_corner_;
};

void check_region(const Region& region, const SurfaceProjector& projector,
                  const std::string& name) {
  if (region.surface == nullptr || region.triangles.empty()) {
    throw InvalidInputError(name, "region is empty (no triangles)");
  }
  if (region.boundary.size() < 3) {
    throw InvalidInputError(name, "region has no boundary loop");
  }
  if (region.surface != &projector.surface()) {
    throw InvalidInputError(name, "region does not lie on the projector's surface");
  }
  if (region.triangle_face.size() != region.triangles.size() ||
      region.triangle_uv.size() != region.triangles.size() ||
      region.points.size() != region.positions.size()) {
    throw InvalidInputError(name, "region arrays have inconsistent sizes");
  }
}

void check_grid(const ParticleGrid& grid) {
  const int n = grid.num_particles();
  if (n == 0) {
    throw InvalidInputError("grid", "particle grid is empty");
  }
  if (grid.source_points.size() != static_cast<size_t>(n) ||
      grid.is_boundary.size() != static_cast<size_t>(n) ||
      grid.boundary_parameter.size() != grid.boundary_loop.size()) {
    throw InvalidInputError("grid", "particle arrays have inconsistent sizes");
  }
  if (grid.boundary_loop.empty()) {
    throw InvalidInputError("grid", "particle grid has no boundary");
  }
}

// Both flattenings, side by side (they are independent). Each task keeps its own exception, so
// that when both fail the error is always the source's.
std::pair<CgalFlattening, CgalFlattening> flatten_both(const Region& source_region,
                                                       const Region& target_region,
                                                       const BaselineOptions& options) {
  const CgalFlatteningOptions flattening{.arap_iterations = options.arap_iterations,
                                         .arap_lambda = options.arap_lambda,
                                         .arap_tolerance = options.arap_tolerance,
                                         .arap_max_vertices = options.arap_max_vertices,
                                         .name = "source region"};
  CgalFlatteningOptions target_flattening = flattening;
  target_flattening.name = "target region";
  CgalFlattening from, to;
  std::exception_ptr source_error, target_error;
  tbb::parallel_invoke(
      [&] {
        try {
          from = flatten_region_cgal(source_region, options.kind, flattening);
        } catch (...) {
          source_error = std::current_exception();
        }
      },
      [&] {
        try {
          to = flatten_region_cgal(target_region, options.kind, target_flattening);
        } catch (...) {
          target_error = std::current_exception();
        }
      });
  if (source_error) {
    std::rethrow_exception(source_error);
  }
  if (target_error) {
    std::rethrow_exception(target_error);
  }
  return {std::move(from), std::move(to)};
}

// The similarity z -> a z + b (complex a: rotation and scale, never a reflection) minimising
// sum_j |a p_j + b - q_j|^2 over boundary samples at common parameters s_j = j / N (Umeyama 1991
// in complex form: b matches the centroids, a = <p', q'> / |p'|^2 on the centred samples).
struct Similarity {
  Complex a = 1.0, b = 0.0;
  double rms = 0.0;  // of the samples' residuals
};

Similarity align_boundaries(const BoundaryParametrisation& source_boundary,
                            const std::vector<Eigen::Vector2d>& source_uv,
                            const BoundaryParametrisation& target_boundary,
                            const std::vector<Eigen::Vector2d>& target_uv, int samples) {
  std::vector<Complex> p(static_cast<size_t>(samples)), q(static_cast<size_t>(samples));
  Complex p_mean = 0.0, q_mean = 0.0;
  for (int j = 0; j < samples; ++j) {
    const double s = static_cast<double>(j) / samples;
    const Eigen::Vector2d ps = source_boundary.planar(s, source_uv);
    const Eigen::Vector2d qs = target_boundary.planar(s, target_uv);
    p[static_cast<size_t>(j)] = {ps.x(), ps.y()};
    q[static_cast<size_t>(j)] = {qs.x(), qs.y()};
    p_mean += p[static_cast<size_t>(j)];
    q_mean += q[static_cast<size_t>(j)];
  }
  p_mean /= static_cast<double>(samples);
  q_mean /= static_cast<double>(samples);
  Complex cross = 0.0;
  double norm2 = 0.0;
  for (int j = 0; j < samples; ++j) {
    const Complex pc = p[static_cast<size_t>(j)] - p_mean;
    cross += std::conj(pc) * (q[static_cast<size_t>(j)] - q_mean);
    norm2 += std::norm(pc);
  }
  if (!(norm2 > 0.0)) {
    throw NumericalError("source region", "flattened boundary collapsed to a point");
  }
  Similarity out;
  out.a = cross / norm2;
  out.b = q_mean - out.a * p_mean;
  if (!(std::abs(out.a) > 0.0)) {
    throw NumericalError("target region",
                         "flattened boundaries are uncorrelated (zero alignment scale)");
  }
  double residual2 = 0.0;
  for (int j = 0; j < samples; ++j) {
    residual2 += std::norm(out.a * p[static_cast<size_t>(j)] + out.b - q[static_cast<size_t>(j)]);
  }
  out.rms = std::sqrt(residual2 / samples);
  return out;
}

// Per particle: its parameter on the boundary curve, or -1 for interior particles.
std::vector<double> boundary_parameters(const ParticleGrid& grid) {
  const int n = grid.num_particles();
  std::vector<double> parameter(static_cast<size_t>(n), -1.0);
  for (size_t k = 0; k < grid.boundary_loop.size(); ++k) {
    const int i = grid.boundary_loop[k];
    if (i < 0 || i >= n) {
      throw InvalidInputError("grid", "boundary particle index out of range");
    }
    parameter[static_cast<size_t>(i)] = grid.boundary_parameter[k];
  }
  return parameter;
}

// The composition target^-1 o similarity o source of step 3 (see the header), written into
// result's positions, points and outside flags.
class Composition {
 public:
  Composition(const ParticleGrid& grid, const Region& source_region, const Region& target_region,
              const LimitSurface& target_surface, const CgalFlattening& from,
              const CgalFlattening& to, const BoundaryParametrisation& target_boundary,
              const Similarity& similarity, const BaselineOptions& options)
      : grid_(grid),
        source_region_(source_region),
        target_region_(target_region),
        target_surface_(target_surface),
        from_(from),
        target_boundary_(target_boundary),
        similarity_(similarity),
        options_(options),
        source_locator_(source_region),
        target_locator_(to.uv, target_region.triangles) {}

  void run(BaselineResult& result) const {
    const int n = grid_.num_particles();
    const std::vector<double> parameter = boundary_parameters(grid_);
    result.positions.resize(3, n);
    result.points.assign(static_cast<size_t>(n), SurfacePoint{});
    result.outside.assign(static_cast<size_t>(n), 0);
    std::vector<char> unlocated(static_cast<size_t>(n), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, n, 64), [&](const tbb::blocked_range<int>& r) {
      for (int i = r.begin(); i != r.end(); ++i) {
        const auto ii = static_cast<size_t>(i);
        if (parameter[ii] >= 0.0) {  // boundary particles: exactly at their parameter
          const SurfacePoint point = target_boundary_.point(parameter[ii]);
          result.points[ii] = point;
          result.positions.col(i) = target_surface_.position(point);
        } else if (!place_interior(i, result)) {
          unlocated[ii] = 1;
        }
      }
    });
    for (int i = 0; i < n; ++i) {
      if (unlocated[static_cast<size_t>(i)]) {
        throw InvalidInputError("grid", "particle " + std::to_string(i) +
                                            "'s source point is not in the source region");
      }
      result.num_outside += result.outside[static_cast<size_t>(i)];
    }
  }

 private:
  // False when the particle's source point is not in the source region.
  bool place_interior(int i, BaselineResult& result) const {
    const auto ii = static_cast<size_t>(i);
    const auto& x = grid_.mesh.point(GridMesh::VertexHandle(i));
    int t = -1;
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    if (!source_locator_.locate(grid_.source_points[ii], Eigen::Vector3d(x[0], x[1], x[2]),
                                options_.locate_tolerance, t, w)) {
      return false;
    }
    const Eigen::Vector3i& tri = source_region_.triangles[static_cast<size_t>(t)];
    const Eigen::Vector2d plane = w[0] * from_.uv[static_cast<size_t>(tri[0])] +
                                  w[1] * from_.uv[static_cast<size_t>(tri[1])] +
                                  w[2] * from_.uv[static_cast<size_t>(tri[2])];
    const Complex z = similarity_.a * Complex(plane.x(), plane.y()) + similarity_.b;
    const Eigen::Vector2d aligned(z.real(), z.imag());
    const TriangleLocator2D::Hit hit = target_locator_.locate(aligned, options_.locate_tolerance);
    if (hit.found()) {
      const Eigen::Vector3d c = hit.barycentric.cwiseMax(0.0) / hit.barycentric.cwiseMax(0.0).sum();
      const SurfacePoint point = target_region_.point_in_triangle(hit.triangle, c[1], c[2]);
      result.points[ii] = point;
      result.positions.col(i) = target_surface_.position(point);
    } else {
      // Outside the target flattening: flagged, its SurfacePoint left unset; its position is the
      // nearest point of the target flattening (on its boundary), so it stays on the surface.
      result.outside[ii] = 1;
      const TriangleLocator2D::Hit nearest = target_locator_.nearest(aligned);
      const SurfacePoint point = target_region_.point_in_triangle(
          nearest.triangle, nearest.barycentric[1], nearest.barycentric[2]);
      result.positions.col(i) = target_surface_.position(point);
    }
    return true;
  }

  const ParticleGrid& grid_;
  const Region& source_region_;
  const Region& target_region_;
  const LimitSurface& target_surface_;
  const CgalFlattening& from_;
  const BoundaryParametrisation& target_boundary_;
  const Similarity& similarity_;
  const BaselineOptions& options_;
  const RegionPointLocator source_locator_;
  const TriangleLocator2D target_locator_;
};

}  // namespace

BaselineResult map_baseline(const ParticleGrid& grid, const SurfaceProjector& source,
                            const Region& source_region, const SurfaceProjector& target,
                            const Region& target_region, const BaselineOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  check_grid(grid);
  check_region(source_region, source, "source region");
  check_region(target_region, target, "target region");
  if (options.alignment_samples < 3) {
    throw InvalidInputError("baseline options", "alignment_samples must be at least 3");
  }

  BaselineResult result;
  result.kind = options.kind;
  // 1. Both flattenings.
  const auto [from, to] = flatten_both(source_region, target_region, options);
  result.source_flipped_triangles = from.flipped_triangles;
  result.target_flipped_triangles = to.flipped_triangles;

  // 2. Alignment of the flattened boundaries.
  const BoundaryParametrisation source_boundary(source_region, "source region");
  const BoundaryParametrisation target_boundary(target_region, "target region",
                                                options.target_offset);
  const Similarity similarity =
      align_boundaries(source_boundary, from.uv, target_boundary, to.uv, options.alignment_samples);
  result.alignment_scale = std::abs(similarity.a);
  result.alignment_rotation = std::arg(similarity.a);
  result.alignment_translation = {similarity.b.real(), similarity.b.imag()};
  result.alignment_rms = similarity.rms;

  // 3. Composition.
  Composition(grid, source_region, target_region, target.surface(), from, to, target_boundary,
              similarity, options)
      .run(result);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace elastic
