#pragma once
/// \file
/// Triangulating the band between two nested simple polygons in the plane (an annulus), without
/// adding points: the constrained Delaunay triangulation of both polygons' vertices with every
/// polygon edge a constraint, restricted to the faces between the two polygons. Used by the grid
/// layout to join the quad grid's outline to the boundary particles (§4.1: boundary particles "are
/// connected to the outside of the grid"). Delaunay maximises the smallest angle among
/// triangulations of the same points and constraints, and no triangle can be degenerate (zero area)
/// or inverted.
///
/// The implementation (CGAL's 2D constrained Delaunay triangulation with exact predicates) is
/// confined to annulus_triangulation.cpp.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace elastic {

struct AnnulusTriangulationOptions {
  /// Name used in error messages.
  std::string name = "annulus";
  /// What the loops are, for error messages.
  std::string outer_label = "the outer loop";
  std::string inner_label = "the inner loop";
  /// Extra points (indices into the caller's point array) strictly inside the band, inserted as
  /// free vertices of the triangulation (no constraint edges). The grid layout adds them where a
  /// triangle would otherwise have all three corners on the outer loop.
  std::vector<int> steiner;
};

struct AnnulusTriangulation {
  /// Triangles as indices into the caller's point array, counter-clockwise (positive signed area).
  std::vector<Eigen::Vector3i> triangles;
};

/// Triangulates the region between `outer` and `inner`, both counter-clockwise loops of indices
/// into `points` (not repeated at the end), `inner` strictly inside `outer`, with the optional
/// free points `options.steiner` in between. \throws
/// InvalidInputError naming options.name when a loop has fewer than 3 vertices, two used points
///         coincide, the outer loop crosses itself, or the inner loop crosses itself or the outer
///         loop (the band would need new points); the message says which.
AnnulusTriangulation triangulate_annulus(const std::vector<Eigen::Vector2d>& points,
                                         const std::vector<int>& outer,
                                         const std::vector<int>& inner,
                                         const AnnulusTriangulationOptions& options = {});

}  // namespace elastic
