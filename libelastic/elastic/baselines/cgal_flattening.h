#pragma once
/// \file
/// Flattening a Region into the plane with CGAL's Surface_mesh_parameterization (CGAL 5.5), for
/// the baselines (baseline_map.h). CGAL stays inside cgal_flattening.cpp; this header is plain.
///
/// Borders, per method (each region's boundary correspondence parameter s is the normalised arc
/// length from its anchor, SurfaceCurve):
/// - Lscm: `LSCM_parameterizer_3` with `Two_vertices_parameterizer_3` pinning the boundary vertices
///   nearest s = 0 and s = 0.5 (free boundary; the pins fix the similarity, not the shape).
/// - Arap: `ARAP_parameterizer_3` (free boundary; CGAL initialises with mean-value coordinates on a
///   circle, pins one vertex, and runs MVC_post_processor_3 when the result has flips).
/// - Dcm: `Discrete_conformal_map_parameterizer_3` with the boundary fixed on the unit circle at
///   angle 2 pi s (our own border parameterizer, so that s = 0 lies at angle 0 on every region).
///
/// The result is scaled so that the flattened area equals the region's 3D area (lengths are then
/// comparable to surface lengths) and reflected if CGAL returned it clockwise, so that the
/// flattening's orientation agrees with the region's (counter-clockwise seen from the normal side).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "elastic/baselines/baseline_map.h"
#include "elastic/regions/region.h"

namespace elastic {

struct CgalFlatteningOptions {
  int arap_iterations = 50;     ///< ARAP local/global iterations (upper bound)
  double arap_lambda = 1000.0;  ///< ARAP's lambda: 0 is ASAP (= LSCM); larger is more rigid
  /// ARAP stops when the relative energy change of one iteration falls below this (CGAL's
  /// tolerance; <= 0 runs all iterations).
  double arap_tolerance = 1e-6;
  /// Regions with more vertices are refused by ARAP (see BaselineOptions::arap_max_vertices).
  int arap_max_vertices = 50000;
  std::string name = "region";  ///< names the region in error messages
};

struct CgalFlattening {
  std::vector<Eigen::Vector2d> uv;  ///< #V planar position of each region vertex
  int flipped_triangles = 0;        ///< triangles with non-positive signed area
  double scale = 1.0;               ///< factor applied to CGAL's output to match the 3D area
  /// Wall time of CGAL's parameterize call alone (mesh building and checks excluded), seconds.
  double seconds_parameterize = 0.0;
};

/// Flattens `region` with the CGAL parameterizer of `kind`.
/// \throws InvalidInputError naming options.name when the region is empty or is not a manifold
///         topological disk with one boundary loop. NumericalError naming it when CGAL reports a
///         failure (its message is included), the result has zero area, or (ARAP) the region has
///         more than arap_max_vertices vertices.
CgalFlattening flatten_region_cgal(const Region& region, BaselineKind kind,
                                   const CgalFlatteningOptions& options = {});

}  // namespace elastic
