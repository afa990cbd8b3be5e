#pragma once
/// \file
/// `Region`: a disk-shaped part of a limit surface bounded by one closed curve (§4.1), cut out of
/// the surface's dense tessellation *along the curve* (the boundary is the curve, not a staircase
/// of edges).
///
/// The region is a triangle mesh: vertices lie exactly on the limit surface and know their
/// SurfacePoint; each triangle lies inside one ptex face and knows its corners' (u, v) in that
/// face, so any point of a triangle maps to a SurfacePoint by barycentric interpolation of (u, v).
/// The boundary loop runs counter-clockwise seen from the normal side (interior on the left), and
/// its vertices are the boundary curve's vertices, in order: `boundary_curve()` returns them as a
/// SurfaceCurve.
///
/// A Region does not own its surface: `surface` must outlive it.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "elastic/regions/surface_curve.h"
#include "elastic/surface/limit_surface.h"

namespace elastic {

/// The region triangle that holds one boundary chord boundary[k] -> boundary[k + 1].
struct BoundaryChord {
  int triangle = -1;    ///< region triangle, -1 when no triangle has the chord as an edge
  int corner_from = 0;  ///< corner (0..2) of `triangle` at boundary[k]
  int corner_to = 0;    ///< corner (0..2) of `triangle` at boundary[k + 1]
};

struct Region {
  const LimitSurface* surface = nullptr;  ///< the surface the region lies on (not owned)

  std::vector<Eigen::Vector3d> positions;  ///< #V limit positions
  std::vector<SurfacePoint> points;        ///< #V surface points
  std::vector<Eigen::Vector3i> triangles;  ///< #T counter-clockwise vertex triples
  std::vector<int> triangle_face;          ///< #T ptex face containing each triangle
  std::vector<std::array<Eigen::Vector2d, 3>> triangle_uv;  ///< #T corners' (u,v) in triangle_face
  /// #V texture coordinates interpolated from the control mesh's UVs; empty when it has none.
  std::vector<Eigen::Vector2d> texcoords;

  std::vector<int> boundary;  ///< vertex indices of the boundary loop, counter-clockwise
  double anchor = 0.0;        ///< correspondence start on the boundary (see SurfaceCurve::anchor)
  /// True when `anchor` was given by the user (RegionSpec::anchor), false when chosen
  /// automatically; the mapping may turn an automatic correspondence (choose_boundary_offset).
  bool anchor_given = false;

  int num_vertices() const { return static_cast<int>(positions.size()); }
  int num_triangles() const { return static_cast<int>(triangles.size()); }
  /// The boundary as a SurfaceCurve (with `anchor`).
  SurfaceCurve boundary_curve() const;
  /// For each boundary chord k (boundary[k] -> boundary[k + 1], cyclic), the triangle holding it
  /// as its own counter-clockwise edge (the last such triangle), or else one holding it reversed
  /// (the first); `triangle` is -1 when neither exists. O(#T) with only the chords keyed.
  std::vector<BoundaryChord> boundary_chords() const;
  /// Sum of triangle areas.
  double area() const;
  /// The SurfacePoint at barycentric coordinates (b1, b2) of triangle t (b0 = 1 - b1 - b2).
  SurfacePoint point_in_triangle(int t, double b1, double b2) const;
};

}  // namespace elastic
