#pragma once
/// \file
/// Laying out the particle grid of §4.1 on a source region, before adaptive sampling.
///
/// 1. The region is flattened (flatten_region, conformal by default so grid cells stay square-ish
/// on the
///    surface), oriented so its boundary runs counter-clockwise, scaled so its planar area equals
///    the region's 3D area, and centred at its area centroid. Lengths in this plane approximate
///    surface lengths (exactly for a developable region flattened isometrically).
/// 2. For a spacing h, M = round(L / h) *boundary particles* are placed at equal arc length on the
/// 3D
///    boundary curve (length L), s_k = k / M from the anchor (SurfaceCurve::locate): exact to
///    round-off.
/// 3. Lattice and band in the plane (planar_grid.h, for any simple polygon): points of the
///    axis-aligned square lattice of step h (origin at the centroid) at least `clearance * h`
///    inside the boundary particles' polygon; the cells with four such corners, cleaned to one
///    simple, hole-free patch, are the quads, strictly inside the polygon.
/// 4. The band between the quads' outline and the boundary polygon is triangulated by constrained
///    Delaunay (annulus_triangulation.h): no degenerate or inverted triangles, and quads plus band
///    tile the polygon. Guarantee: no band triangle has all three corners on the boundary. Where
///    one would (at a sharp turn of the boundary: a rectangle's corner, a star's tip), free
///    particles are added (planar_grid.h), so every face of the grid has a corner that can move.
/// 5. h is found by a secant/bisection search on the *actual* count (lattice vertices of the quads
///    plus M) so that it is within `count_tolerance` of the request; if the band's free particles
///    then push the count past `max_count_error`, the search is repeated for N minus them.
/// 6. Every particle is mapped to the surface through the flattening: 2D point location in the
/// flattened
///    region triangles, barycentric coordinates, Region::point_in_triangle. Interior particles sit
///    at the limit position of that SurfacePoint; boundary particles on the boundary chord (see
///    boundary_sampler.h).
///
/// The grid's faces are counter-clockwise seen from the normal side (the region's orientation).
/// Rest values of the springs are set by ParticleGrid::build_springs() on the laid-out positions.

#include <string>
#include <vector>

#include "elastic/particles/particle_grid.h"
#include "elastic/regions/region.h"
#include "elastic/regions/region_flattening.h"

namespace elastic {

struct GridLayoutOptions {
  /// Requested number of particles N (interior + boundary). 16 .. 5,000,000.
  long particles = 1000;
  /// Stop the spacing search once |count - N| <= count_tolerance * N (the contract is 5%).
  double count_tolerance = 0.01;
  /// Largest accepted relative count error of the lattice and boundary particles; the layout throws
  /// NumericalError beyond it. The band's free points come on top: past this error the search is
  /// repeated once for N minus them (at a few dozen particles the result may stay beyond it).
  double max_count_error = 0.05;
  /// Minimum distance of a kept lattice point from the boundary polygon, in units of h. Must exceed
  /// 1/sqrt(2) (see the file comment); larger values make the boundary band wider.
  double clearance = 0.75;
  /// Flattening used for the layout; Conformal falls back to Disk when it folds, BoundaryFirst to
  /// Conformal where it does not apply or folds. BoundaryFirst factorises a real system of half
  /// the size (whole hemisphere.off at 5,775 particles: the map 0.74 -> 0.58 s) but keeps the
  /// boundary's lengths, which leaves all the scale change inside: on large curved regions of a
  /// scan the grid's spacings spread far more (a nefertiti-lowres.obj disk of radius 98.7: 0.70 to
  /// 9.0 around 2.6, against 1.4 to 5.5), and maps from there came out worse (length energy up to
  /// 3x), so Conformal stays the default (docs/results/speed.md).
  FlatteningMethod flattening = FlatteningMethod::Conformal;
  /// Spacing search steps (each counts the lattice once).
  int max_search_steps = 40;
  /// Name of the region in error messages (e.g. "--region").
  std::string name = "region";
};

struct GridLayoutResult {
  ParticleGrid grid;
  double spacing = 0.0;        ///< lattice step h (surface length units, see the file comment)
  int interior_particles = 0;  ///< particles of the quad grid
  int boundary_particles = 0;  ///< M, on the boundary curve
  int quads = 0;               ///< grid faces that are lattice cells
  int band_triangles = 0;      ///< triangles joining the grid outline to the boundary particles
  /// Free particles added inside the band where a triangle would have had every corner on the
  /// boundary (counted in interior_particles; numbered after the lattice points).
  int band_points = 0;
  double count_error = 0.0;  ///< (particles - N) / N
  int search_steps = 0;      ///< lattice counts done by the spacing search
  FlatteningMethod flattening = FlatteningMethod::Conformal;  ///< the flattening actually used
  /// #P position of each particle in the scaled flattened plane.
  std::vector<Eigen::Vector2d> flat_positions;
  /// #P 1 for interior particles whose four lattice cells are all quads of the grid ("regular":
  /// exactly four normal springs and four angular springs), 0 otherwise.
  std::vector<char> is_regular;
};

/// Lays out about options.particles particles on `region` (see the file comment).
/// \throws InvalidInputError naming options.name for an absurd count (outside 16 .. 5,000,000), an
/// empty
///         region, or a region too small or too thin for the count (fewer than 4 interior
///         particles); NumericalError when the flattening folds or the lattice and boundary count
///         cannot be met within max_count_error.
GridLayoutResult layout_particle_grid(const Region& region, const GridLayoutOptions& options = {});

}  // namespace elastic
