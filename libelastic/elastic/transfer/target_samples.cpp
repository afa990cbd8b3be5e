#include "elastic/transfer/target_samples.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <utility>

#include "elastic/core/error.h"
#include "elastic/projection/foot_point.h"
#include "elastic/surface/limit_surface.h"

namespace elastic {
namespace {

using EdgeKey = std::pair<int, int>;
EdgeKey key(int a, int b) {
  return {std::min(a, b), std::max(a, b)};
}

// Position of a boundary vertex along the region's boundary loop: lambda = k + t for the point at
// fraction t (in the ptex chart) of the loop's segment k (from boundary[k] to boundary[k+1]); -1
// for interior vertices. Midpoints of boundary edges are halfway in lambda, which is halfway in
// (u, v) along the segment, i.e. the same point the 1-to-4 split creates.
double midpoint_lambda(double a, double b, int loop_size) {
  // a -> b follows the loop (boundary edges of counter-clockwise triangles run along it); b may
  // have wrapped past the loop's start.
  if (b <= a) {
    b += loop_size;
  }
  const double m = 0.5 * (a + b);
  return m >= loop_size ? m - loop_size : m;
}

// For each directed boundary segment k (boundary[k] -> boundary[k+1]) of a region, the triangle
// holding it, so that a point at fraction t of the segment gets (u, v) in that triangle's face.
std::vector<int> boundary_segment_triangles(const Region& region) {
  const int n = static_cast<int>(region.boundary.size());
  std::map<EdgeKey, int> directed;  // (from, to) -> triangle
  for (int t = 0; t < region.num_triangles(); ++t) {
    const Eigen::Vector3i& tri = region.triangles[static_cast<size_t>(t)];
    for (int k = 0; k < 3; ++k) {
      directed[{tri[k], tri[(k + 1) % 3]}] = t;
    }
  }
  std::vector<int> out(static_cast<size_t>(n), -1);
  for (int k = 0; k < n; ++k) {
    const int a = region.boundary[static_cast<size_t>(k)];
    const int b = region.boundary[static_cast<size_t>((k + 1) % n)];
    const auto it = directed.find({a, b});
    if (it != directed.end()) {
      out[static_cast<size_t>(k)] = it->second;
    }
  }
  return out;
}

// The (u, v) of region vertex v as a corner of triangle t.
Eigen::Vector2d corner_uv(const Region& region, int t, int v) {
  const Eigen::Vector3i& tri = region.triangles[static_cast<size_t>(t)];
  for (int k = 0; k < 3; ++k) {
    if (tri[k] == v) {
      return region.triangle_uv[static_cast<size_t>(t)][static_cast<size_t>(k)];
    }
  }
  return region.points[static_cast<size_t>(v)].uv();
}

// The point of a region's boundary at correspondence parameter s, exactly on the limit surface:
// the curve's chord segment and fraction from SurfaceCurve::locate, put into (u, v) of the face of
// the triangle holding the segment (the curve is straight in (u, v) there).
struct CurveOnSurface {
  const Region* region = nullptr;
  SurfaceCurve curve;
  std::vector<double> cumulative;
  double total = 0.0;
  std::vector<int> segment_triangle;

  explicit CurveOnSurface(const Region& r)
      : region(&r),
        curve(r.boundary_curve()),
        cumulative(curve.arc_lengths()),
        total(curve.length()),
        segment_triangle(boundary_segment_triangles(r)) {}

  SurfacePoint at(double s) const {
    const SurfaceCurve::Location loc = curve.locate(s, cumulative, total);
    const int n = curve.size();
    const int a = region->boundary[static_cast<size_t>(loc.segment)];
    const int b = region->boundary[static_cast<size_t>((loc.segment + 1) % n)];
    const int t = segment_triangle[static_cast<size_t>(loc.segment)];
    if (t < 0) {
      return loc.t < 0.5 ? region->points[static_cast<size_t>(a)]
                         : region->points[static_cast<size_t>(b)];
    }
    const Eigen::Vector2d uv =
        (1.0 - loc.t) * corner_uv(*region, t, a) + loc.t * corner_uv(*region, t, b);
    return SurfacePoint{region->triangle_face[static_cast<size_t>(t)], uv.x(), uv.y()};
  }

  // Correspondence parameter of loop position lambda (segment + fraction along its chord).
  double parameter(double lambda) const {
    const int n = curve.size();
    int k = static_cast<int>(std::floor(lambda));
    k = std::clamp(k, 0, n - 1);
    const double f = lambda - k;
    const double len = (curve.positions[static_cast<size_t>((k + 1) % n)] -
                        curve.positions[static_cast<size_t>(k)])
                           .norm();
    double s = (cumulative[static_cast<size_t>(k)] + f * len) / total - curve.anchor;
    s -= std::floor(s);
    return s;
  }
};

// Mesh under refinement.
struct Work {
  std::vector<SurfacePoint> points;
  std::vector<double> lambda;  // loop position, -1 inside
  std::vector<Eigen::Vector3i> triangles;
  std::vector<int> face;
  std::vector<std::array<Eigen::Vector2d, 3>> uv;
  std::vector<int> parent;
};

// One 1-to-4 split of every triangle at its edge midpoints in (u, v). A midpoint shared by two
// triangles of different ptex faces is created once (from the first triangle that meets the edge);
// both (face, u, v) denote the same limit point.
void split_all(Work& w, int loop_size) {
  std::map<EdgeKey, int> edge_count;
  for (const Eigen::Vector3i& t : w.triangles) {
    for (int k = 0; k < 3; ++k) {
      ++edge_count[key(t[k], t[(k + 1) % 3])];
    }
  }
  std::map<EdgeKey, int> midpoint;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<int> face, parent;
  std::vector<std::array<Eigen::Vector2d, 3>> uv;
  triangles.reserve(w.triangles.size() * 4);
  face.reserve(w.triangles.size() * 4);
  parent.reserve(w.triangles.size() * 4);
  uv.reserve(w.triangles.size() * 4);
  for (size_t t = 0; t < w.triangles.size(); ++t) {
    const Eigen::Vector3i& c = w.triangles[t];
    const auto& cuv = w.uv[t];
    std::array<int, 3> m{};
    std::array<Eigen::Vector2d, 3> muv;
    for (int k = 0; k < 3; ++k) {
      const int a = c[k], b = c[(k + 1) % 3];
      muv[static_cast<size_t>(k)] =
          0.5 * (cuv[static_cast<size_t>(k)] + cuv[static_cast<size_t>((k + 1) % 3)]);
      const auto [it, fresh] = midpoint.try_emplace(key(a, b), static_cast<int>(w.points.size()));
      m[static_cast<size_t>(k)] = it->second;
      if (!fresh) {
        continue;
      }
      w.points.push_back(SurfacePoint{w.face[t], muv[static_cast<size_t>(k)].x(),
                                      muv[static_cast<size_t>(k)].y()});
      const double la = w.lambda[static_cast<size_t>(a)], lb = w.lambda[static_cast<size_t>(b)];
      const bool boundary_edge = edge_count[key(a, b)] == 1 && la >= 0.0 && lb >= 0.0;
      w.lambda.push_back(boundary_edge ? midpoint_lambda(la, lb, loop_size) : -1.0);
    }
    const auto add = [&](int a, int b, int d, const Eigen::Vector2d& ua, const Eigen::Vector2d& ub,
                         const Eigen::Vector2d& ud) {
      triangles.emplace_back(a, b, d);
      face.push_back(w.face[t]);
      parent.push_back(w.parent[t]);
      uv.push_back({ua, ub, ud});
    };
    // Corner k keeps the midpoints of its two edges: (c_k, m_k, m_{k-1}); the middle triangle is
    // (m_0, m_1, m_2). All four keep the parent's orientation.
    add(c[0], m[0], m[2], cuv[0], muv[0], muv[2]);
    add(c[1], m[1], m[0], cuv[1], muv[1], muv[0]);
    add(c[2], m[2], m[1], cuv[2], muv[2], muv[1]);
    add(m[0], m[1], m[2], muv[0], muv[1], muv[2]);
  }
  w.triangles = std::move(triangles);
  w.face = std::move(face);
  w.parent = std::move(parent);
  w.uv = std::move(uv);
}

double longest_edge(const std::vector<Eigen::Vector3d>& x, const Eigen::Vector3i& t) {
  return std::max({(x[static_cast<size_t>(t[1])] - x[static_cast<size_t>(t[0])]).norm(),
                   (x[static_cast<size_t>(t[2])] - x[static_cast<size_t>(t[1])]).norm(),
                   (x[static_cast<size_t>(t[0])] - x[static_cast<size_t>(t[2])]).norm()});
}

// Levels needed to bring `length` down to `limit` by halving.
int levels_for(double length, double limit) {
  if (!(limit > 0.0) || length <= limit) {
    return 0;
  }
  return static_cast<int>(std::ceil(std::log2(length / limit) - 1e-12));
}

}  // namespace

namespace {

// The refinement levels asked for: from the coarse triangles' 3D edges and (when asked) their
// images on the source, then more while below min_vertices, fewer when above max_vertices. Sets
// `limited` when the caps cut the levels asked for.
int refinement_levels(const Region& region, const Mapping& mapping,
                      const TargetSamplingOptions& options, bool& limited) {
  const int loop_size = static_cast<int>(region.boundary.size());
  int levels = 0;
  for (const Eigen::Vector3i& t : region.triangles) {
    levels = std::max(levels, levels_for(longest_edge(region.positions, t), options.max_edge));
  }
  if (options.max_source_edge > 0.0) {
    std::vector<Eigen::Vector3d> source(region.points.size(), Eigen::Vector3d::Zero());
    std::vector<char> has(region.points.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, region.points.size()),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t i = r.begin(); i != r.end(); ++i) {
                          const Mapping::Location loc = mapping.inverse(region.points[i]);
                          has[i] = loc.inside;
                          source[i] = loc.position;
                        }
                      });
    for (const Eigen::Vector3i& t : region.triangles) {
      if (!has[static_cast<size_t>(t[0])] || !has[static_cast<size_t>(t[1])] ||
          !has[static_cast<size_t>(t[2])]) {
        continue;
      }
      levels = std::max(levels, levels_for(longest_edge(source, t), options.max_source_edge));
    }
  }
  if (levels > options.max_levels) {
    levels = options.max_levels;
    limited = true;
  }
  // Vertex count after each level: V' = V + E, E' = 2E + 3T, T' = 4T (Euler on the disk).
  long v = static_cast<long>(region.points.size());
  long t = region.num_triangles();
  long e = (3 * t + loop_size) / 2;
  for (int l = 0;; ++l) {
    const bool wanted = l < levels || (v < options.min_vertices && l < options.max_levels);
    if (!wanted) {
      return l;
    }
    if (v + e > options.max_vertices) {
      limited = limited || l < levels;
      return l;
    }
    v += e;
    e = 2 * e + 3 * t;
    t *= 4;
  }
}

// The region as the first mesh under refinement: boundary vertices at their loop positions.
Work initial_work(const Region& region) {
  Work w;
  w.points = region.points;
  w.lambda.assign(region.points.size(), -1.0);
  for (int k = 0; k < static_cast<int>(region.boundary.size()); ++k) {
    w.lambda[static_cast<size_t>(region.boundary[static_cast<size_t>(k)])] = k;
  }
  w.triangles = region.triangles;
  w.face = region.triangle_face;
  w.uv = region.triangle_uv;
  w.parent.resize(region.triangles.size());
  std::iota(w.parent.begin(), w.parent.end(), 0);
  return w;
}

// The sampler's steps over the refined mesh (see sample_target).
class SourceLocator {
 public:
  SourceLocator(const Region& region, const Mapping& mapping, const TargetSamplingOptions& options,
                const Work& w, TargetSamples& out)
      : region_(region), mapping_(mapping), options_(options), w_(w), out_(out) {
    if (options.source_region != nullptr && region.boundary.size() >= 3 &&
        options.source_region->boundary.size() >= 3) {
      target_curve_.emplace(region);
      source_curve_.emplace(*options.source_region);
    }
    source_surface_ = options.source_region != nullptr ? options.source_region->surface : nullptr;
  }

  // Every vertex's limit position, normal and source location (boundary vertices by arc length
  // on the source curve when it is known, the others by the mapping's inverse).
  void evaluate_vertices() {
    const LimitSurface& surface = *region_.surface;
    const size_t nv = out_.points.size();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nv), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const SurfacePoint& p = out_.points[i];
        out_.positions[i] = surface.position(p);
        out_.normals[i] = surface.curvature(p).normal;
        if (out_.on_boundary[i] && source_curve_ && source_surface_ != nullptr) {
          // The boundary correspondence of §4.1: same normalised arc length from the anchors.
          Mapping::Location loc;
          loc.inside = true;
          loc.point = source_curve_->at(target_curve_->parameter(w_.lambda[i]));
          loc.position = source_surface_->position(loc.point);
          out_.sources[i] = loc;
        } else {
          out_.sources[i] = mapping_.inverse(p);
        }
      }
    });
    if (source_curve_) {
      for (size_t i = 0; i < nv; ++i) {
        out_.boundary_by_arc_length += out_.on_boundary[i] ? 1 : 0;
      }
    }
  }

  bool relinearise() const {
    return source_surface_ != nullptr && options_.source_particles.cols() > 0 &&
           options_.source_particles.cols() == options_.target_particles.cols();
  }

  // Interior vertices the grid does not cover: with particle positions, the grid triangle of an
  // adjacent covered vertex (the piecewise-linear map extended a little past the grid's edge, see
  // the header); otherwise the inverse of a point nudged towards an adjacent triangle's centroid.
  void resolve_uncovered() {
    const size_t nv = out_.points.size();
    std::vector<std::vector<int>> vertex_triangles(nv);
    for (size_t t = 0; t < w_.triangles.size(); ++t) {
      for (int k = 0; k < 3; ++k) {
        vertex_triangles[static_cast<size_t>(w_.triangles[t][k])].push_back(static_cast<int>(t));
      }
    }
    for (size_t i = 0; i < nv; ++i) {
      if (out_.sources[i].inside) {
        continue;
      }
      const bool found = (relinearise() && adopt_neighbour(i, vertex_triangles[i])) ||
                         nudged_inverse(i, vertex_triangles[i]);
      ++(found ? out_.nudged : out_.unresolved);
    }
  }

  // Piecewise-linear weights in 3D (see the header), then the foot point on the source surface.
  void relinearise_sources() {
    if (!relinearise()) {
      return;
    }
    const size_t nv = out_.points.size();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nv), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        relinearise_vertex(i);
      }
    });
  }

 private:
  // Vertex i takes the source location of an adjacent covered vertex that has a grid triangle.
  bool adopt_neighbour(size_t i, const std::vector<int>& triangles) {
    for (int t : triangles) {
      for (int k = 0; k < 3; ++k) {
        const Mapping::Location& other =
            out_.sources[static_cast<size_t>(w_.triangles[static_cast<size_t>(t)][k])];
        if (other.inside && other.triangle >= 0) {
          out_.sources[i] = other;
          return true;
        }
      }
    }
    return false;
  }

  // The inverse of vertex i moved 10%, 25%, then 50% of the way towards an adjacent triangle's
  // centroid, in that triangle's ptex face.
  bool nudged_inverse(size_t i, const std::vector<int>& triangles) {
    for (const double f : {0.1, 0.25, 0.5}) {
      for (int t : triangles) {
        const auto& uv = w_.uv[static_cast<size_t>(t)];
        const Eigen::Vector3i& tri = w_.triangles[static_cast<size_t>(t)];
        Eigen::Vector2d own = uv[0];
        for (int k = 0; k < 3; ++k) {
          if (static_cast<size_t>(tri[k]) == i) {
            own = uv[static_cast<size_t>(k)];
          }
        }
        const Eigen::Vector2d centroid = (uv[0] + uv[1] + uv[2]) / 3.0;
        const Eigen::Vector2d q = (1.0 - f) * own + f * centroid;
        const Mapping::Location loc =
            mapping_.inverse(SurfacePoint{w_.face[static_cast<size_t>(t)], q.x(), q.y()});
        if (loc.inside) {
          out_.sources[i] = loc;
          return true;
        }
      }
    }
    return false;
  }

  void relinearise_vertex(size_t i) {
    const auto& grid_triangles = mapping_.triangles();
    const Eigen::Matrix3Xd& sp = options_.source_particles;
    const Eigen::Matrix3Xd& tp = options_.target_particles;
    Mapping::Location& loc = out_.sources[i];
    if (!loc.inside || loc.triangle < 0 ||
        loc.triangle >= static_cast<int>(grid_triangles.size())) {
      return;
    }
    const Eigen::Vector3i& tri = grid_triangles[static_cast<size_t>(loc.triangle)];
    if (tri.maxCoeff() >= tp.cols()) {
      return;
    }
    const Eigen::Vector3d t0 = tp.col(tri[0]);
    const Eigen::Vector3d e1 = tp.col(tri[1]) - t0, e2 = tp.col(tri[2]) - t0;
    const Eigen::Vector3d d = out_.positions[i] - t0;
    // Normal equations of min |b1 e1 + b2 e2 - d|: the projection onto the triangle's plane.
    const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
    const double det = g11 * g22 - g12 * g12;
    if (!(det > 1e-24 * g11 * g22)) {
      return;  // degenerate particle triangle: keep the inverse
    }
    const double r1 = e1.dot(d), r2 = e2.dot(d);
    const double b1 = (g22 * r1 - g12 * r2) / det, b2 = (g11 * r2 - g12 * r1) / det;
    const Eigen::Vector3d weights(1.0 - b1 - b2, b1, b2);
    const Eigen::Vector3d y =
        weights[0] * sp.col(tri[0]) + weights[1] * sp.col(tri[1]) + weights[2] * sp.col(tri[2]);
    // The closest point to y from the inverse's answer (already within O(h^2) of it): the foot
    // point, to a miss of kFootMiss times the particle triangle's size (far below a texel), in at
    // most kFootSteps steps; where the parameterisation degenerates the point reached is kept.
    const FootPoint foot = foot_point(*source_surface_, y, loc.point,
                                      {.tolerance = kFootMiss * std::sqrt(std::max(g11, g22)),
                                       .max_steps = kFootSteps,
                                       .stop_at_boundary = false,
                                       .degenerate_ratio = 0.0});
    loc.point = foot.point;
    loc.position = foot.d.position;
    loc.barycentric = weights;
  }

  static constexpr double kFootMiss = 1e-12;
  static constexpr int kFootSteps = 6;

  const Region& region_;
  const Mapping& mapping_;
  const TargetSamplingOptions& options_;
  const Work& w_;
  TargetSamples& out_;
  std::optional<CurveOnSurface> target_curve_, source_curve_;
  const LimitSurface* source_surface_ = nullptr;
};

// The refined region's boundary loop: boundary vertices in loop order.
std::vector<int> boundary_loop(const std::vector<double>& lambda) {
  std::vector<std::pair<double, int>> loop;
  for (size_t i = 0; i < lambda.size(); ++i) {
    if (lambda[i] >= 0.0) {
      loop.emplace_back(lambda[i], static_cast<int>(i));
    }
  }
  std::sort(loop.begin(), loop.end());
  std::vector<int> out;
  out.reserve(loop.size());
  for (const auto& entry : loop) {
    out.push_back(entry.second);
  }
  return out;
}

// The longest target edge, and the longest source chord of a triangle whose corners all have a
// source.
void measure_edges(TargetSamples& out) {
  std::vector<Eigen::Vector3d> source_positions(out.sources.size());
  for (size_t i = 0; i < out.sources.size(); ++i) {
    source_positions[i] = out.sources[i].position;
  }
  for (const Eigen::Vector3i& t : out.triangles) {
    out.max_edge_length = std::max(out.max_edge_length, longest_edge(out.positions, t));
    if (out.sources[static_cast<size_t>(t[0])].inside &&
        out.sources[static_cast<size_t>(t[1])].inside &&
        out.sources[static_cast<size_t>(t[2])].inside) {
      out.max_source_edge_length =
          std::max(out.max_source_edge_length, longest_edge(source_positions, t));
    }
  }
}

void check_options(const Region& region, const TargetSamplingOptions& options) {
  const std::string& name = options.name;
  if (region.surface == nullptr || region.num_triangles() == 0) {
    throw InvalidInputError(name, "the target region is empty");
  }
  if (!(options.max_edge >= 0.0) || !(options.max_source_edge >= 0.0) ||
      !std::isfinite(options.max_edge) || !std::isfinite(options.max_source_edge)) {
    throw InvalidInputError(name, "max_edge and max_source_edge must be finite and >= 0");
  }
  if (options.max_levels < 0 || options.max_levels > 12) {
    throw InvalidInputError(
        name, "max_levels " + std::to_string(options.max_levels) + " is outside 0..12");
  }
}

}  // namespace

TargetSamples sample_target(const Region& region, const Mapping& mapping,
                            const TargetSamplingOptions& options) {
  check_options(region, options);
  TargetSamples out;
  out.levels = refinement_levels(region, mapping, options, out.limited);
  Work w = initial_work(region);
  for (int l = 0; l < out.levels; ++l) {
    split_all(w, static_cast<int>(region.boundary.size()));
  }

  const size_t nv = w.points.size();
  out.points = std::move(w.points);
  out.positions.resize(nv);
  out.normals.resize(nv);
  out.sources.resize(nv);
  out.on_boundary.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    out.on_boundary[i] = w.lambda[i] >= 0.0;
  }
  SourceLocator locator(region, mapping, options, w, out);
  locator.evaluate_vertices();
  locator.resolve_uncovered();
  locator.relinearise_sources();

  out.boundary = boundary_loop(w.lambda);
  out.triangles = std::move(w.triangles);
  out.triangle_face = std::move(w.face);
  out.triangle_uv = std::move(w.uv);
  out.triangle_parent = std::move(w.parent);
  measure_edges(out);
  return out;
}

double source_texel_length(const Region& region, int columns, int rows) {
  if (region.texcoords.size() != region.positions.size() || columns <= 0 || rows <= 0) {
    return 0.0;
  }
  double texture_area = 0.0;
  for (const Eigen::Vector3i& t : region.triangles) {
    const Eigen::Vector2d& a = region.texcoords[static_cast<size_t>(t[0])];
    const Eigen::Vector2d e1 = region.texcoords[static_cast<size_t>(t[1])] - a;
    const Eigen::Vector2d e2 = region.texcoords[static_cast<size_t>(t[2])] - a;
    texture_area += 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
  }
  const double texels = texture_area * static_cast<double>(columns) * static_cast<double>(rows);
  if (!(texels > 0.0)) {
    return 0.0;
  }
  return std::sqrt(region.area() / texels);
}

}  // namespace elastic
