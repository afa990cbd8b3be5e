#pragma once
/// \file
/// Distortion metrics of a map between a particle grid's source positions and any placement of
/// its particles on the target (ElasticPaint's relaxed positions, the naive map, a baseline), so
/// that every method is measured on the same grid by the same code. Formulas with references:
/// docs/metrics.md.
///
/// The map is piecewise linear on the grid's triangles: every face is split into a fan of
/// triangles from its first corner, exactly as `Mapping::triangles()` splits it (the regular quads
/// along the diagonal from their first corner; band triangles stay as they are). Each triangle is
/// measured between its *own* source plane and its *own* target plane: with orthonormal 2D frames
/// in the two planes (first axis along the edge 0->1, second axis completing a right-handed frame
/// with the triangle's normal), the edge matrices S = [p1 - p0, p2 - p0] (source) and
/// T = [q1 - q0, q2 - q0] (target) in those frames give the 2x2 Jacobian J = T S^-1 of the affine
/// map between the two triangles. Its singular values s1 >= s2 >= 0 are the principal stretches.
/// Both frames follow the triangles' own orientation, so det J > 0 always: inversion is detected
/// separately, against the target surface normal (`folds`).
///
/// Folds, the one definition (docs/metrics.md): a triangle is inverted when its target normal
/// (q1 - q0) x (q2 - q0) has a non-positive dot product with the sum of the unit surface normals
/// at its corners, or degenerate. A grid *face* is folded when a triangle of *either*
/// triangulation of it is inverted or degenerate (a quad: the four triangles of its two diagonal
/// splits; a triangle: itself), since the fan alone hides a quad whose first or third corner has
/// moved inside. `folds` counts folded faces; `sigma_min` is the smallest signed singular value of
/// J / sigma over the same triangles (negative on an inverted one).
///
/// Scale: the Jacobian is divided by the rest scale sigma (the uniform scale the map is meant to
/// have, `MapMetricsOptions::rest_scale`, e.g. MapResult::rest_scale), so a map that is exactly
/// the similarity of scale sigma has s1 = s2 = 1. Use sigma = 1 to measure absolute lengths.
///
/// Aggregates are weighted by source triangle areas (the forward map's domain) unless said
/// otherwise; the inverse stretch (target -> source) is weighted by target areas (its domain).
/// Triangles with a corner flagged `outside` are excluded from every aggregate and counted;
/// triangles whose target is degenerate (zero area: no Jacobian inverse) fold their face and are
/// excluded from the aggregates that divide by s2.

#include <Eigen/Core>
#include <string_view>
#include <vector>

#include "elastic/particles/particle_grid.h"
#include "elastic/surface/limit_surface.h"

namespace elastic {

/// A per-triangle quantity that a heatmap can show. Names as in the reports.
enum class TriangleMetric {
  AngleError,           ///< "angle_error_deg": largest corner angle difference of the triangle
  StretchL2,            ///< "stretch_l2": sqrt((s1^2 + s2^2) / 2), forward
  StretchLinf,          ///< "stretch_linf": s1, forward
  InverseStretchL2,     ///< "inverse_stretch_l2": sqrt((s1^-2 + s2^-2) / 2)
  AreaDistortion,       ///< "area_distortion": |log(s1 s2)|
  ConformalDistortion,  ///< "conformal_distortion": s1 / s2
  SymmetricDirichlet    ///< "symmetric_dirichlet": s1^2 + s2^2 + s1^-2 + s2^-2
};
/// The report name of the metric, e.g. "symmetric_dirichlet".
std::string_view to_string(TriangleMetric metric);
/// Parses a report name. \throws InvalidInputError naming `input` otherwise.
TriangleMetric parse_triangle_metric(std::string_view text,
                                     std::string_view input = "triangle metric");
/// The value of a perfect (isometric up to sigma) triangle: 0 for angle and area, 1 for stretches
/// and conformal distortion, 4 for the symmetric Dirichlet energy.
double perfect_value(TriangleMetric metric);
/// All of them, in declaration order.
const std::vector<TriangleMetric>& all_triangle_metrics();

struct MapMetricsOptions {
  /// sigma: rest lengths are sigma k_ij in the length energy, and Jacobians are divided by sigma.
  double rest_scale = 1.0;
  /// 3 x #P unit target surface normals at the particles for the fold test (surface_normals());
  /// when empty no fold test is made: `folds` = -1 and only degenerate triangles are flagged.
  Eigen::Matrix3Xd target_normals;
  /// #P flags (nonzero = the method could not place the particle inside the target region); empty
  /// means none. Springs and triangles touching a flagged particle are excluded and counted.
  std::vector<char> outside;
  /// A target triangle is degenerate when its area is below this fraction of its source area times
  /// sigma^2 (s1 s2 below it): its inverse Jacobian does not exist in floating point.
  double degenerate_area_ratio = 1e-12;
};

/// Per-triangle values, all of size #T (the triangles of `MapMetrics::triangles`).
struct TriangleValues {
  std::vector<double> s1;               ///< larger singular value of J / sigma
  std::vector<double> s2;               ///< smaller singular value of J / sigma (>= 0)
  std::vector<double> source_area;      ///< source triangle area (the weight)
  std::vector<double> target_area;      ///< target triangle area
  std::vector<char> folded;             ///< 1: the triangle's face is folded (FaceValues::folded)
  std::vector<char> excluded;           ///< 1: a corner is outside (no values: NaN)
  std::vector<double> angle_error_deg;  ///< max over the 3 corners of |target - source angle|
  std::vector<double> stretch_l2;       ///< sqrt((s1^2 + s2^2) / 2)
  std::vector<double> inverse_stretch_l2;    ///< sqrt((s1^-2 + s2^-2) / 2) (+inf if degenerate)
  std::vector<double> area_distortion;       ///< |log(s1 s2)| (+inf if degenerate)
  std::vector<double> conformal_distortion;  ///< s1 / s2 (+inf if degenerate)
  std::vector<double> symmetric_dirichlet;   ///< s1^2 + s2^2 + s1^-2 + s2^-2 (+inf if degenerate)
  /// The values of one metric (s1 for StretchLinf).
  const std::vector<double>& values(TriangleMetric metric) const;
};

/// Per grid face values, all of size #F (the grid's faces in index order).
struct FaceValues {
  /// 1: a triangle of either triangulation of the face is inverted w.r.t. the surface normal, or
  /// degenerate (the definition of a fold).
  std::vector<char> folded;
  /// The smallest signed singular value of J / sigma over the triangles of both triangulations:
  /// s2 of a well-oriented triangle, -s2 of an inverted one. NaN for an excluded face.
  std::vector<double> sigma_min;
  std::vector<char> excluded;  ///< 1: a corner is outside (not judged)
};

/// The aggregates that reports carry (docs/metrics.md has every formula).
struct MapMetrics {
  /// Eq. 13 normalised: sum (|d_ij| - sigma k_ij)^2 / sum (sigma k_ij)^2 over the normal springs
  /// (grid edges) whose ends are both placed. 0 is perfect.
  double length_energy = 0.0;
  /// Mean and max over the corners of measured triangles of |target angle - source angle|, degrees.
  double angle_error_mean_deg = 0.0;
  double angle_error_max_deg = 0.0;
  /// Sander et al. 2001, forward (source -> target): sqrt(sum A (s1^2 + s2^2) / 2 / sum A), A the
  /// source areas, and max s1. 1 is perfect.
  double stretch_l2 = 1.0;
  double stretch_linf = 1.0;
  /// The same for the inverse map (target -> source, singular values 1/s2 >= 1/s1), weighted by
  /// target areas; max 1/s2. Degenerate triangles are left out.
  double inverse_stretch_l2 = 1.0;
  double inverse_stretch_linf = 1.0;
  /// sum A |log(s1 s2)| / sum A. 0 is perfect.
  double area_distortion = 0.0;
  /// sum A s1/s2 / sum A. 1 is perfect.
  double conformal_distortion = 1.0;
  /// sum A (s1^2 + s2^2 + s1^-2 + s2^-2) / sum A. 4 is perfect.
  double symmetric_dirichlet = 4.0;
  /// Folded grid faces: faces with a triangle, in either of their triangulations, inverted
  /// relative to the target surface normal or degenerate (FaceValues::folded); -1 when no normals
  /// were given (not measured; only degenerate triangles are then flagged per face).
  int folds = 0;
  /// The worst triangle: the smallest signed singular value of J / sigma over both triangulations
  /// of every judged face (FaceValues::sigma_min); 1 for a similarity of scale sigma, <= 0 for a
  /// collapsed or inverted triangle. NaN when no face is judged.
  double sigma_min = 1.0;
  int degenerate = 0;          ///< faces with a degenerate target triangle (counted in `folds`)
  int outside = 0;             ///< particles flagged outside
  int outside_triangles = 0;   ///< triangles excluded because a corner is outside
  int measured_triangles = 0;  ///< triangles in the aggregates
  int measured_springs = 0;    ///< springs in length_energy

  /// The grid's triangles (particle index triples, counter-clockwise on the source).
  std::vector<Eigen::Vector3i> triangles;
  /// #T: the grid face each triangle comes from.
  std::vector<int> triangle_face;
  /// Per-triangle values for heatmaps.
  TriangleValues per_triangle;
  /// Per-face fold flags and sigma_min.
  FaceValues per_face;
};

/// Measures the map grid source positions -> `target_positions` (3 x #P).
/// \throws InvalidInputError when sizes disagree (naming them), the grid has no faces or no built
///         springs, rest_scale is not finite and positive, or a position is not finite.
MapMetrics measure_map(const ParticleGrid& grid, const Eigen::Matrix3Xd& target_positions,
                       const MapMetricsOptions& options = {});

/// Unit limit-surface normals at `points` (3 x #P) for `MapMetricsOptions::target_normals`; columns
/// of points flagged in `skip` (nonzero, may be empty) are left zero and not evaluated.
Eigen::Matrix3Xd surface_normals(const LimitSurface& surface,
                                 const std::vector<SurfacePoint>& points,
                                 const std::vector<char>& skip = {});

/// Measures a placement of `grid`'s particles on `target` the way every report does
/// (docs/metrics.md): measure_map with `rest_scale` and the target's limit-surface normals at
/// `points`; particles flagged in `outside` (may be empty) or without a valid surface point are
/// left out. \throws as measure_map.
MapMetrics measure_on_target(const ParticleGrid& grid, const LimitSurface& target,
                             double rest_scale, const Eigen::Matrix3Xd& positions,
                             const std::vector<SurfacePoint>& points,
                             std::vector<char> outside = {});

}  // namespace elastic
