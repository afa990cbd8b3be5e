#pragma once
/// \file
/// Baseline maps for comparison with ElasticPaint (issue 5): the multi-stage approach the paper
/// argues against (Biermann et al. 2002, "Cut-and-paste editing of multiresolution surfaces").
/// Both regions are flattened independently with CGAL's Surface_mesh_parameterization, the two
/// flattenings are aligned by the least-squares similarity that best matches the boundary
/// correspondence, and the particles are carried source -> source plane -> target plane -> target.
///
/// - Lscm: least-squares conformal map (Lévy et al. 2002), free boundary, two boundary vertices
///   pinned at the correspondence parameters s = 0 and s = 0.5.
/// - Arap: as-rigid-as-possible (Liu et al. 2008, local/global), free boundary, CGAL's mean-value
///   initialisation; CGAL post-processes flipped results.
/// - Dcm: discrete conformal map (Desbrun et al. 2002; cotangent weights) with the boundary fixed
///   on the unit circle at angle 2 pi s (a fixed convex border, as the method needs).
///
/// Every flattening is scaled to its region's 3D area, so `alignment_rms` is in surface units and
/// `alignment_scale` is about the ratio of the target's to the source's size.
///
/// The boundary correspondence is the normalised arc length s from each region's anchor (the one
/// ElasticPaint uses, see SurfaceCurve). Boundary particles are placed exactly on the target curve
/// at their s; interior particles go through the planar composition. A particle whose aligned
/// planar position falls outside the target flattening is flagged `outside` (never guessed): its
/// position is then the target boundary point nearest in the plane, and its SurfacePoint is left
/// invalid. See docs/baselines.md for the details and caveats.

#include <Eigen/Core>
#include <string_view>
#include <vector>

#include "elastic/particles/particle_grid.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/region.h"
#include "elastic/surface/surface_point.h"

namespace elastic {

enum class BaselineKind { Lscm, Arap, Dcm };

/// "lscm", "arap", "dcm".
std::string_view to_string(BaselineKind kind);
/// Parses "lscm", "arap" or "dcm" (case-sensitive).
/// \throws InvalidInputError naming `input` for any other text.
BaselineKind parse_baseline_kind(std::string_view text, std::string_view input = "baseline");

struct BaselineOptions {
  BaselineKind kind = BaselineKind::Lscm;  ///< which flattening
  int arap_iterations = 50;                ///< CGAL ARAP iterations (local/global alternations)
  /// CGAL ARAP's lambda (Liu et al.'s hybrid model): 0 is as-similar-as-possible (the same as
  /// LSCM); larger values favour rigid cells. CGAL's default, 1000, is ARAP for practical purposes.
  double arap_lambda = 1000.0;
  /// ARAP stops when one iteration changes the energy by less than this fraction (CGAL's
  /// tolerance; <= 0 always runs arap_iterations).
  double arap_tolerance = 1e-6;
  /// Largest region (vertices) given to ARAP. When CGAL 5.5's ARAP leaves flipped triangles it runs
  /// MVC_post_processor_3, whose matrix assembly inserts entries one by one into a compressed
  /// sparse matrix (quadratic): a 182,000-vertex region ran for over 20 minutes there. Larger
  /// regions are refused (NumericalError: the method cannot run on this valid input) instead of
  /// hanging; coarsen the projector's tessellation or raise this.
  int arap_max_vertices = 50000;
  /// Turn of the boundary correspondence on the target (MapResult::boundary_offset): source
  /// parameter s corresponds to target parameter s + target_offset, as in ElasticPaint's map.
  double target_offset = 0.0;
  /// Common correspondence parameters s = i / n sampled on both boundaries to fit the alignment.
  int alignment_samples = 2048;
  /// Barycentric tolerance of point location in the flattenings (relative to a triangle: 1e-9 is
  /// far above round-off and far below any triangle's size).
  double locate_tolerance = 1e-9;
};

struct BaselineResult {
  BaselineKind kind = BaselineKind::Lscm;
  Eigen::Matrix3Xd
      positions;  ///< 3 x #P target positions of the grid's particles (on the target surface)
  std::vector<SurfacePoint> points;  ///< #P target surface points (invalid for outside particles)
  std::vector<char> outside;         ///< #P 1 where the composition fell outside the target region
  int num_outside = 0;
  double seconds = 0.0;  ///< both flattenings + alignment + composition
  // the alignment's similarity (scale, rotation angle, translation) and its boundary RMS residual
  double alignment_scale = 1.0, alignment_rotation = 0.0, alignment_rms = 0.0;
  Eigen::Vector2d alignment_translation = Eigen::Vector2d::Zero();  ///< target = s R source + t
  /// Triangles with non-positive signed area in each flattening (0 when the flattening is
  /// bijective; LSCM and ARAP with a free boundary give no such guarantee).
  int source_flipped_triangles = 0, target_flipped_triangles = 0;
};

/// Maps the grid's particles from the source region to the target region by flattening both regions
/// with CGAL (kind), aligning the two flattenings by the least-squares similarity (no reflection)
/// that best matches the boundary correspondence (grid.boundary_parameter: the normalised arc
/// length from the anchors), and composing source -> plane -> plane -> target. Boundary particles
/// are placed exactly at their arc-length positions on the target curve (the same positions
/// ElasticPaint uses) so that every method shares the boundary correspondence.
/// \throws InvalidInputError naming the grid or a region when it is empty, has no boundary, is not
///         a disk, or a particle's source point is not in the source region; NumericalError naming
///         a region when its flattening fails (CGAL's error, or above ARAP's vertex limit). When
///         both flattenings fail, the source region's error is the one thrown.
BaselineResult map_baseline(const ParticleGrid& grid, const SurfaceProjector& source,
                            const Region& source_region, const SurfaceProjector& target,
                            const Region& target_region, const BaselineOptions& options = {});

}  // namespace elastic
