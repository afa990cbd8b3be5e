#include "elastic/metrics/map_metrics.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "elastic/core/error.h"
#include "elastic/particles/face_folds.h"

namespace elastic {

namespace {

struct MetricName {
  TriangleMetric metric;
  std::string_view name;
  double perfect;
};
constexpr std::array<MetricName, 7> kMetricNames{{
    {TriangleMetric::AngleError, "angle_error_deg", 0.0},
    {TriangleMetric::StretchL2, "stretch_l2", 1.0},
    {TriangleMetric::StretchLinf, "stretch_linf", 1.0},
    {TriangleMetric::InverseStretchL2, "inverse_stretch_l2", 1.0},
    {TriangleMetric::AreaDistortion, "area_distortion", 0.0},
    {TriangleMetric::ConformalDistortion, "conformal_distortion", 1.0},
    {TriangleMetric::SymmetricDirichlet, "symmetric_dirichlet", 4.0},
}};

const MetricName& lookup(TriangleMetric metric) {
  for (const auto& entry : kMetricNames) {
    if (entry.metric == metric) {
      return entry;
    }
  }
  return kMetricNames[0];
}

// The corner angle at a between the edges to b and c, in [0, pi]. atan2 of the cross and dot
// products keeps full relative accuracy for angles near 0 and pi, where acos of a cosine does not.
double corner_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d e = b - a;
  const Eigen::Vector3d f = c - a;
  return std::atan2(e.cross(f).norm(), e.dot(f));
}

bool all_finite(const Eigen::Matrix3Xd& m) {
  return m.allFinite();
}

// The affine map between one source and one target triangle, divided by sigma.
struct TrianglePair {
  double source_area = 0.0;
  double target_area = 0.0;
  double sum_sq = 0.0;  // s1^2 + s2^2
  double prod = 0.0;    // s1 s2
  double s1 = 0.0;
  double s2 = 0.0;
  Eigen::Vector3d target_normal = Eigen::Vector3d::Zero();  // (q1 - q0) x (q2 - q0)
};

// Singular values without a target frame: with S the source edges in an orthonormal frame of the
// source plane and G_s = S^T S, G_t = T^T T the Gram matrices of the source and target edge vectors
// (frame-independent dot products of 3D edges), J^T J = S^-T G_t S^-1, hence
//   s1^2 + s2^2 = trace(J^T J) = trace(G_s^-1 G_t),   s1 s2 = |det J| = A_t / A_s.
// This also holds for a degenerate target (A_t = 0), where a target frame would not exist.
// Returns false when the source triangle has zero area.
bool analyse_pair(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                  const Eigen::Vector3d& q0, const Eigen::Vector3d& q1, const Eigen::Vector3d& q2,
                  double sigma, TrianglePair& out) {
  const Eigen::Vector3d e = p1 - p0, f = p2 - p0, eq = q1 - q0, fq = q2 - q0;
  const Eigen::Vector3d source_normal = e.cross(f);
  out.target_normal = eq.cross(fq);
  out.source_area = 0.5 * source_normal.norm();
  out.target_area = 0.5 * out.target_normal.norm();
  if (!(out.source_area > 0.0)) {
    return false;
  }
  Eigen::Matrix2d gs, gt;
  gs << e.dot(e), e.dot(f), e.dot(f), f.dot(f);
  gt << eq.dot(eq), eq.dot(fq), eq.dot(fq), fq.dot(fq);
  // det G_s = |e x f|^2 = (2 A_s)^2 exactly in real arithmetic; use the cross product form, which
  // has no cancellation for thin triangles.
  const double det_gs = source_normal.squaredNorm();
  Eigen::Matrix2d gs_inv;
  gs_inv << gs(1, 1), -gs(0, 1), -gs(1, 0), gs(0, 0);
  gs_inv /= det_gs;
  out.sum_sq = (gs_inv * gt).trace() / (sigma * sigma);
  out.prod = out.target_area / out.source_area / (sigma * sigma);
  // s1, s2 from their sum of squares and product: (s1 +- s2)^2 = sum_sq +- 2 prod. The smaller one
  // as prod / s1 keeps its relative accuracy when s2 << s1.
  const double plus = std::sqrt(std::max(out.sum_sq + 2.0 * out.prod, 0.0));
  const double minus = std::sqrt(std::max(out.sum_sq - 2.0 * out.prod, 0.0));
  out.s1 = 0.5 * (plus + minus);
  out.s2 = out.s1 > 0.0 ? out.prod / out.s1 : 0.0;
  return true;
}

}  // namespace

std::string_view to_string(TriangleMetric metric) {
  return lookup(metric).name;
}

TriangleMetric parse_triangle_metric(std::string_view text, std::string_view input) {
  std::string known;
  for (const auto& entry : kMetricNames) {
    if (entry.name == text) {
      return entry.metric;
    }
    known += (known.empty() ? "" : ", ") + std::string(entry.name);
  }
  throw InvalidInputError(std::string(input), "unknown metric '" + std::string(text) +
                                                  "' (expected one of " + known + ")");
}

double perfect_value(TriangleMetric metric) {
  return lookup(metric).perfect;
}

const std::vector<TriangleMetric>& all_triangle_metrics() {
  static const std::vector<TriangleMetric> all = [] {
    std::vector<TriangleMetric> out;
    out.reserve(std::size(kMetricNames));
    for (const auto& entry : kMetricNames) {
      out.push_back(entry.metric);
    }
    return out;
  }();
  return all;
}

const std::vector<double>& TriangleValues::values(TriangleMetric metric) const {
  switch (metric) {
    case TriangleMetric::AngleError:
      return angle_error_deg;
    case TriangleMetric::StretchL2:
      return stretch_l2;
    case TriangleMetric::StretchLinf:
      return s1;
    case TriangleMetric::InverseStretchL2:
      return inverse_stretch_l2;
    case TriangleMetric::AreaDistortion:
      return area_distortion;
    case TriangleMetric::ConformalDistortion:
      return conformal_distortion;
    case TriangleMetric::SymmetricDirichlet:
      return symmetric_dirichlet;
  }
  return s1;
}

namespace {

// Faces or triangles per task of the parallel loops below: fixed, so that the deterministic
// reductions split the same way on any number of threads.
constexpr int kGrain = 4096;

// The inputs' sizes and values; returns the particles left out (the outside mask).
std::vector<char> check_measure_inputs(const ParticleGrid& grid,
                                       const Eigen::Matrix3Xd& target_positions,
                                       const MapMetricsOptions& options, const std::string& name) {
  const int n = grid.num_particles();
  if (target_positions.cols() != n) {
    throw InvalidInputError(name, "target positions have " +
                                      std::to_string(target_positions.cols()) + " columns for " +
                                      std::to_string(n) + " particles");
  }
  if (!options.outside.empty() && static_cast<int>(options.outside.size()) != n) {
    throw InvalidInputError(name, "the outside mask has " + std::to_string(options.outside.size()) +
                                      " entries for " + std::to_string(n) + " particles");
  }
  const bool have_normals = options.target_normals.cols() > 0;
  if (have_normals && options.target_normals.cols() != n) {
    throw InvalidInputError(name, "target normals have " +
                                      std::to_string(options.target_normals.cols()) +
                                      " columns for " + std::to_string(n) + " particles");
  }
  const double sigma = options.rest_scale;
  if (!std::isfinite(sigma) || sigma <= 0.0) {
    throw InvalidInputError(name, "rest scale must be finite and positive");
  }
  if (grid.mesh.n_faces() == 0) {
    throw InvalidInputError(name, "the particle grid has no faces");
  }
  if (grid.springs.empty()) {
    throw InvalidInputError(name, "the particle grid has no springs built");
  }
  const auto is_outside = [&](int p) { return !options.outside.empty() && options.outside[p]; };
  std::vector<char> skip(n, 0);
  for (int p = 0; p < n; ++p) {
    skip[p] = is_outside(p) ? 1 : 0;
  }
  // Outside particles may carry anything (NaN, zeros): only the placed ones must be finite.
  for (int p = 0; p < n; ++p) {
    if (!skip[p] && !target_positions.col(p).allFinite()) {
      throw InvalidInputError(
          name, "target position of particle " + std::to_string(p) + " is not finite");
    }
  }
  return skip;
}

// Length energy (eq. 13, normalised by the energy of collapsing every spring to a point).
void measure_length_energy(const ParticleGrid& grid, const Eigen::Matrix3Xd& target_positions,
                           const std::vector<char>& skip, double sigma, const std::string& name,
                           MapMetrics& out) {
  const int n = grid.num_particles();
  double num = 0.0, den = 0.0;
  for (const Spring& s : grid.springs) {
    if (s.i < 0 || s.i >= n || s.j < 0 || s.j >= n) {
      throw InvalidInputError(name, "a spring index is out of range");
    }
    if (skip[s.i] || skip[s.j]) {
      continue;
    }
    const double rest = sigma * s.rest;
    const double len = (target_positions.col(s.j) - target_positions.col(s.i)).norm();
    num += (len - rest) * (len - rest);
    den += rest * rest;
    ++out.measured_springs;
  }
  out.length_energy = den > 0.0 ? num / den : 0.0;
}

// The fold test and sigma_min, per grid face over every triangulation of the face
// (docs/metrics.md, "Folds"): one split alone can hide an inverted corner. A quad whose corner 0
// has moved inside the triangle (1, 2, 3) has two positive triangles along the diagonal 0-2 but
// an inverted triangle (1, 3, 0) along the other one. Returns the number of folded faces.
int judge_faces(const ParticleGrid& grid, const Eigen::Matrix3Xd& source,
                const Eigen::Matrix3Xd& target_positions, const std::vector<char>& skip,
                const MapMetricsOptions& options, const std::string& name, MapMetrics& out) {
  const bool have_normals = options.target_normals.cols() > 0;
  const double sigma = options.rest_scale;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  FaceValues& fv = out.per_face;
  // Faces are judged independently (each writes its own entries); the counts and the minimum
  // are exact in any order, so the result does not depend on the thread count.
  struct Judged {
    int folds = 0, degenerate = 0, judged = 0;
    double worst_sigma = std::numeric_limits<double>::infinity();
  };
  const auto judge = [&](const tbb::blocked_range<int>& range, Judged sum) {
    std::vector<int> corners;
    for (int f = range.begin(); f != range.end(); ++f) {
      corners.clear();
      for (const auto vh : grid.mesh.fv_range(GridMesh::FaceHandle(f))) {
        corners.push_back(vh.idx());
      }
      bool excluded = false;
      for (const int c : corners) {
        excluded = excluded || skip[c] != 0;
      }
      if (excluded) {
        fv.excluded[f] = 1;
        continue;
      }
      bool folded = false, degenerate = false;
      double sigma_min = inf;
      for (const Eigen::Vector3i& local : face_triangulations(static_cast<int>(corners.size()))) {
        const int a = corners[local[0]], b = corners[local[1]], c = corners[local[2]];
        TrianglePair pair;
        if (!analyse_pair(source.col(a), source.col(b), source.col(c), target_positions.col(a),
                          target_positions.col(b), target_positions.col(c), sigma, pair)) {
          throw InvalidInputError(
              name, "grid face " + std::to_string(f) + " has a zero-area triangle on the source");
        }
        const bool flat = !(pair.prod >= options.degenerate_area_ratio);
        bool inverted = false;
        if (have_normals) {
          // Inverted when the target triangle's normal points against the surface: compare with
          // the sum of the three corners' unit normals (robust to one corner normal being off).
          inverted =
              triangle_inverted(target_positions.col(a), target_positions.col(b),
                                target_positions.col(c), options.target_normals.col(a),
                                options.target_normals.col(b), options.target_normals.col(c));
        }
        degenerate = degenerate || flat;
        folded = folded || flat || inverted;
        // The signed smallest singular value: negative for an inverted triangle (det J < 0).
        sigma_min = std::min(sigma_min, inverted ? -pair.s2 : pair.s2);
      }
      fv.folded[f] = folded ? 1 : 0;
      fv.sigma_min[f] = sigma_min;
      sum.folds += folded ? 1 : 0;
      sum.degenerate += degenerate ? 1 : 0;
      sum.worst_sigma = std::min(sum.worst_sigma, sigma_min);
      ++sum.judged;
    }
    return sum;
  };
  const Judged judged = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<int>(0, static_cast<int>(grid.mesh.n_faces()), kGrain), Judged{}, judge,
      [](Judged a, const Judged& b) {
        a.folds += b.folds;
        a.degenerate += b.degenerate;
        a.judged += b.judged;
        a.worst_sigma = std::min(a.worst_sigma, b.worst_sigma);
        return a;
      });
  out.degenerate += judged.degenerate;
  const int folds = judged.folds;
  const int judged_faces = judged.judged;
  const double worst_sigma = judged.worst_sigma;
  out.sigma_min = judged_faces > 0 ? worst_sigma : nan;
  return folds;
}

// The sums of the per-triangle values that the map's aggregates are (weighted) means of.
struct TriangleSums {
  double w_sum = 0.0, w_stretch = 0.0, w_area = 0.0, w_conf = 0.0, w_sd = 0.0;
  double w_inv_sum = 0.0, w_inv_stretch = 0.0;
  double w_regular = 0.0;  // source area of the non-degenerate triangles
  double max_s1 = 0.0, max_inv = 0.0;
  double angle_sum = 0.0;
  long angle_count = 0;
  double angle_max = 0.0;
  int measured = 0;
  int excluded = 0;

  // The sums of two ranges of triangles, the left one first.
  static TriangleSums combine(TriangleSums a, const TriangleSums& b) {
    a.w_sum += b.w_sum;
    a.w_stretch += b.w_stretch;
    a.w_area += b.w_area;
    a.w_conf += b.w_conf;
    a.w_sd += b.w_sd;
    a.w_inv_sum += b.w_inv_sum;
    a.w_inv_stretch += b.w_inv_stretch;
    a.w_regular += b.w_regular;
    a.max_s1 = std::max(a.max_s1, b.max_s1);
    a.max_inv = std::max(a.max_inv, b.max_inv);
    a.angle_sum += b.angle_sum;
    a.angle_count += b.angle_count;
    a.angle_max = std::max(a.angle_max, b.angle_max);
    a.measured += b.measured;
    a.excluded += b.excluded;
    return a;
  }
};

// The values of grid triangle t (not excluded) into out.per_triangle, and its share of the sums.
void measure_triangle(int t, const Eigen::Matrix3Xd& source,
                      const Eigen::Matrix3Xd& target_positions, const MapMetricsOptions& options,
                      const std::string& name, MapMetrics& out, TriangleSums& sums) {
  constexpr double kDeg = 180.0 / std::numbers::pi;
  const double inf = std::numeric_limits<double>::infinity();
  TriangleValues& tv = out.per_triangle;
  const Eigen::Vector3i& tri = out.triangles[t];
  TrianglePair pair;
  if (!analyse_pair(source.col(tri[0]), source.col(tri[1]), source.col(tri[2]),
                    target_positions.col(tri[0]), target_positions.col(tri[1]),
                    target_positions.col(tri[2]), options.rest_scale, pair)) {
    throw InvalidInputError(name,
                            "grid triangle " + std::to_string(t) + " has zero area on the source");
  }
  const double sum_sq = pair.sum_sq;  // s1^2 + s2^2
  const double prod = pair.prod;      // s1 s2
  const double s1 = pair.s1;
  const double s2 = pair.s2;
  const double source_area = pair.source_area;
  const double target_area = pair.target_area;

  tv.s1[t] = s1;
  tv.s2[t] = s2;
  tv.source_area[t] = source_area;
  tv.target_area[t] = target_area;
  tv.stretch_l2[t] = std::sqrt(0.5 * sum_sq);

  // A triangle shows its face's fold (either triangulation); its own values need an inverse.
  const bool degenerate = !(prod >= options.degenerate_area_ratio);
  tv.folded[t] = out.per_face.folded[out.triangle_face[t]];

  // Corner angles (unsigned, in each triangle's own plane).
  double worst = 0.0;
  for (int k = 0; k < 3; ++k) {
    const int a = tri[k], b = tri[(k + 1) % 3], c = tri[(k + 2) % 3];
    const double src = corner_angle(source.col(a), source.col(b), source.col(c));
    const double tgt =
        corner_angle(target_positions.col(a), target_positions.col(b), target_positions.col(c));
    const double diff = std::abs(tgt - src) * kDeg;
    worst = std::max(worst, diff);
    sums.angle_sum += diff;
    ++sums.angle_count;
  }
  tv.angle_error_deg[t] = worst;
  sums.angle_max = std::max(sums.angle_max, worst);

  ++sums.measured;
  const double w = source_area;
  sums.w_sum += w;
  sums.w_stretch += w * 0.5 * sum_sq;
  sums.max_s1 = std::max(sums.max_s1, s1);
  if (degenerate) {
    tv.inverse_stretch_l2[t] = inf;
    tv.area_distortion[t] = inf;
    tv.conformal_distortion[t] = inf;
    tv.symmetric_dirichlet[t] = inf;
    return;
  }
  // 1/s1^2 + 1/s2^2 = (s1^2 + s2^2) / (s1 s2)^2.
  const double inv_sum_sq = sum_sq / (prod * prod);
  tv.inverse_stretch_l2[t] = std::sqrt(0.5 * inv_sum_sq);
  tv.area_distortion[t] = std::abs(std::log(prod));
  tv.conformal_distortion[t] = s1 / s2;
  tv.symmetric_dirichlet[t] = sum_sq + inv_sum_sq;
  sums.w_regular += w;
  sums.w_area += w * tv.area_distortion[t];
  sums.w_conf += w * tv.conformal_distortion[t];
  sums.w_sd += w * tv.symmetric_dirichlet[t];
  // The inverse map's domain is the target triangle: weight by its area.
  sums.w_inv_sum += target_area;
  sums.w_inv_stretch += target_area * 0.5 * inv_sum_sq;
  sums.max_inv = std::max(sums.max_inv, 1.0 / s2);
}

// The map's aggregates from the sums.
void aggregate(const TriangleSums& sums, MapMetrics& out) {
  if (sums.w_sum > 0.0) {
    out.stretch_l2 = std::sqrt(sums.w_stretch / sums.w_sum);
    out.stretch_linf = sums.max_s1;
  }
  // Degenerate triangles have no finite value in these means: they are left out (and counted in
  // `folds` and `degenerate`).
  if (sums.w_regular > 0.0) {
    out.inverse_stretch_linf = sums.max_inv;
    out.area_distortion = sums.w_area / sums.w_regular;
    out.conformal_distortion = sums.w_conf / sums.w_regular;
    out.symmetric_dirichlet = sums.w_sd / sums.w_regular;
  }
  if (sums.w_inv_sum > 0.0) {
    out.inverse_stretch_l2 = std::sqrt(sums.w_inv_stretch / sums.w_inv_sum);
  }
  if (sums.angle_count > 0) {
    out.angle_error_mean_deg = sums.angle_sum / static_cast<double>(sums.angle_count);
  }
}

}  // namespace

MapMetrics measure_map(const ParticleGrid& grid, const Eigen::Matrix3Xd& target_positions,
                       const MapMetricsOptions& options) {
  const int n = grid.num_particles();
  const std::string name = "map metrics";
  const std::vector<char> skip = check_measure_inputs(grid, target_positions, options, name);
  const Eigen::Matrix3Xd source = grid.source_positions();
  if (!all_finite(source)) {
    throw InvalidInputError(name, "a source position is not finite");
  }

  MapMetrics out;
  for (int p = 0; p < n; ++p) {
    out.outside += skip[p] ? 1 : 0;
  }
  measure_length_energy(grid, target_positions, skip, options.rest_scale, name, out);

  out.triangles = grid_triangles(grid, &out.triangle_face);
  const int nt = static_cast<int>(out.triangles.size());
  const int nf = static_cast<int>(grid.mesh.n_faces());
  TriangleValues& tv = out.per_triangle;
  FaceValues& fv = out.per_face;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (auto* v : {&tv.s1, &tv.s2, &tv.source_area, &tv.target_area, &tv.angle_error_deg,
                  &tv.stretch_l2, &tv.inverse_stretch_l2, &tv.area_distortion,
                  &tv.conformal_distortion, &tv.symmetric_dirichlet}) {
    v->assign(nt, nan);
  }
  tv.folded.assign(nt, 0);
  tv.excluded.assign(nt, 0);
  fv.folded.assign(nf, 0);
  fv.excluded.assign(nf, 0);
  fv.sigma_min.assign(nf, nan);

  const int folds = judge_faces(grid, source, target_positions, skip, options, name, out);
  // Each triangle writes its own entries; the sums are reduced over a split of the triangles that
  // depends only on their number (parallel_deterministic_reduce), so not on the thread count.
  const TriangleSums sums = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<int>(0, nt, kGrain), TriangleSums{},
      [&](const tbb::blocked_range<int>& range, TriangleSums part) {
        for (int t = range.begin(); t != range.end(); ++t) {
          const Eigen::Vector3i& tri = out.triangles[t];
          if (skip[tri[0]] || skip[tri[1]] || skip[tri[2]]) {
            tv.excluded[t] = 1;
            ++part.excluded;
            continue;
          }
          measure_triangle(t, source, target_positions, options, name, out, part);
        }
        return part;
      },
      TriangleSums::combine);
  out.outside_triangles += sums.excluded;
  out.measured_triangles += sums.measured;
  out.angle_error_max_deg = std::max(out.angle_error_max_deg, sums.angle_max);
  aggregate(sums, out);
  out.folds = options.target_normals.cols() > 0 ? folds : -1;
  return out;
}

Eigen::Matrix3Xd surface_normals(const LimitSurface& surface,
                                 const std::vector<SurfacePoint>& points,
                                 const std::vector<char>& skip) {
  const int n = static_cast<int>(points.size());
  Eigen::Matrix3Xd normals = Eigen::Matrix3Xd::Zero(3, n);
  tbb::parallel_for(tbb::blocked_range<int>(0, n, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int p = r.begin(); p != r.end(); ++p) {
      if ((!skip.empty() && skip[p]) || !points[p].valid()) {
        continue;
      }
      normals.col(p) = surface.curvature(points[p]).normal;
    }
  });
  return normals;
}

MapMetrics measure_on_target(const ParticleGrid& grid, const LimitSurface& target,
                             double rest_scale, const Eigen::Matrix3Xd& positions,
                             const std::vector<SurfacePoint>& points, std::vector<char> outside) {
  MapMetricsOptions options;
  options.rest_scale = rest_scale;
  // A particle without a valid target surface point has no normal and no defined place: it is
  // treated as outside (the baselines flag theirs; the others have none in practice).
  outside.resize(points.size(), 0);
  for (std::size_t p = 0; p < points.size(); ++p) {
    if (!points[p].valid()) {
      outside[p] = 1;
    }
  }
  options.target_normals = surface_normals(target, points, outside);
  options.outside = std::move(outside);
  return measure_map(grid, positions, options);
}

}  // namespace elastic
