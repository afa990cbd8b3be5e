#pragma once
/// \file
/// The particle grid of §4.1 laid out in the plane, inside a simple polygon (the boundary particles
/// of a flattened region, grid_layout.h): a patch of square lattice cells strictly inside the
/// polygon, and a band of triangles between the patch's outline and the polygon. Purely planar, so
/// that its guarantees hold, and are tested, for any simple polygon: convex or not, 36 degree tips,
/// reflex notches (docs/sampling.md "Layout").
///
/// 1. `select_lattice_cells`: points of the square lattice of step h are kept when they lie inside
///    the polygon (scanline parity) and at least `clearance * h` from every polygon edge. A cell is
///    selected when its four corners are kept; the selection is cleaned to one edge-connected,
///    hole-free patch without pinch vertices (two cells touching only at a corner), so its outline
///    is one simple polygon. With clearance > 1/sqrt(2) no point of the polygon lies in a selected
///    cell (a polygon vertex inside a cell would be within h/sqrt(2) of a corner; an edge crossing
///    a cell without a vertex in it passes within h/2 of a corner), so every cell, and the outline,
///    is strictly inside the polygon; outline edges keep at least (clearance - 1/2) h from it.
/// 2. `build_planar_grid`: the band between outline and polygon is triangulated by constrained
///    Delaunay (annulus_triangulation.h): every band triangle is counter-clockwise with positive
///    area, and quads plus band triangles tile the polygon exactly. Then the band guarantee: no
///    triangle has all three corners on the polygon. Where one has (a sharp tip, a rectangle's
///    corner, a thin part of the band), a free point is added at its centroid and the band is
///    triangulated again with those points; after a few rounds any such triangle left is split at
///    its centroid into three (which always ends it). So every face of the grid has a corner that
///    can move while the boundary particles are held.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace elastic {

struct PlanarLatticeOptions {
  /// Minimum distance of a kept lattice point from the polygon, in units of h. Must exceed
  /// 1/sqrt(2) (see the file comment); larger values make the band wider.
  double clearance = 0.75;
};

/// The selected cells of the square lattice {offset + h (i, j)} inside a polygon.
struct PlanarLattice {
  double h = 0.0;
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();  ///< lattice origin
  int i0 = 0, j0 = 0;                                ///< lattice index of local point (0, 0)
  int nx = 0, ny = 0;       ///< lattice points per row / column (0 when none fits)
  std::vector<char> cells;  ///< (nx-1) x (ny-1), row-major, 1 when the cell is selected
  int points = 0;           ///< lattice points that are a corner of a selected cell

  Eigen::Vector2d point(int i, int j) const { return offset + h * Eigen::Vector2d(i0 + i, j0 + j); }
  bool cell(int a, int b) const {
    return a >= 0 && b >= 0 && a < nx - 1 && b < ny - 1 &&
           cells[static_cast<size_t>(b) * (nx - 1) + a];
  }
};

/// Selects the lattice cells for the counter-clockwise polygon `polygon` (vertices not repeated),
/// spacing h and lattice origin `offset` (step 1 of the file comment).
PlanarLattice select_lattice_cells(const std::vector<Eigen::Vector2d>& polygon, double h,
                                   const Eigen::Vector2d& offset,
                                   const PlanarLatticeOptions& options = {});

/// The planar grid: quads of the selected cells and the band triangles.
struct PlanarGrid {
  /// Points: the lattice points (cell corners, in row order), then the band's free points, then
  /// the polygon's vertices in their order (the boundary particles).
  std::vector<Eigen::Vector2d> points;
  int lattice_points = 0;
  int band_points = 0;      ///< free points added to the band (step 2)
  int boundary_points = 0;  ///< = polygon.size()
  /// Lattice cells, corners counter-clockwise (indices into points).
  std::vector<Eigen::Vector4i> quads;
  /// Band triangles, counter-clockwise (positive signed area).
  std::vector<Eigen::Vector3i> triangles;
  /// The quads' outline, counter-clockwise (indices of lattice points).
  std::vector<int> outline;
  /// Per point: 1 for lattice points whose four cells are all quads, else 0.
  std::vector<char> regular;
  int interior_points() const { return lattice_points + band_points; }
};

struct PlanarGridOptions {
  /// Name of the region in error messages (e.g. "--source-region").
  std::string name = "region";
  /// Rounds of Delaunay re-triangulation with the new free points before any band triangle still
  /// without a free corner is split at its centroid (step 2; one round suffices in practice).
  int delaunay_rounds = 4;
};

/// Builds quads, outline and band for `polygon` and the selection `lattice` made from it (step 2
/// of the file comment). \throws InvalidInputError naming options.name when the lattice has no
/// cell, or the polygon crosses itself or has coinciding vertices (a part of the region narrower
/// than the spacing); NumericalError if the outline is not one simple loop (an internal error).
PlanarGrid build_planar_grid(const std::vector<Eigen::Vector2d>& polygon,
                             const PlanarLattice& lattice, const PlanarGridOptions& options = {});

}  // namespace elastic
