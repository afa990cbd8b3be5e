#pragma once
/// \file
/// `SurfaceCurve`: a closed curve on a limit surface, the boundary of a region (§4.1 of the paper).
///
/// The curve is a closed polyline whose vertices lie exactly on the limit surface (each has its
/// SurfacePoint); between vertices it is the straight chord. It is dense (vertices come from the
/// cut of the surface's dense tessellation), so the chords stay within the tessellation's tolerance
/// of the surface. Arc length is measured along the chords; it is the parameter of the boundary
/// correspondence: a source boundary particle at normalised arc length s maps to the target curve's
/// point at the same s (§4.1).
///
/// Orientation: counter-clockwise seen from the side the surface normal points to, i.e. the region
/// lies to the left of the direction of travel when the normal points up. The correspondence
/// parameter s starts at the anchor, `anchor` (a normalised arc length measured from vertex 0), and
/// runs in the curve's direction.

#include <Eigen/Core>
#include <vector>

#include "elastic/surface/surface_point.h"

namespace elastic {

struct SurfaceCurve {
  std::vector<SurfacePoint> points;  ///< #N vertices on the limit surface (not repeated at the end)
  std::vector<Eigen::Vector3d> positions;  ///< #N their limit positions
  double anchor = 0.0;  ///< where s = 0 lies, as normalised arc length from vertex 0, in [0,1)

  int size() const { return static_cast<int>(positions.size()); }
  /// Total length of the closed polyline (including the closing chord N-1 -> 0).
  double length() const;
  /// Cumulative arc length at each vertex: #N values, first 0, increasing.
  std::vector<double> arc_lengths() const;

  /// The point at correspondence parameter s in [0,1) (wrapped modulo 1), i.e. at normalised arc
  /// length anchor + s from vertex 0: the chord segment it falls on and the fraction along it.
  /// position = (1 - t) positions[segment] + t positions[(segment + 1) % N].
  struct Location {
    int segment = 0;
    double t = 0.0;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
  };
  Location locate(double s) const;
  /// The same, with `cumulative` = arc_lengths() and `total` = length() computed once by the
  /// caller: O(log N) per call instead of O(N), for callers that locate many points on one curve.
  Location locate(double s, const std::vector<double>& cumulative, double total) const;

  /// Normalised arc length from vertex 0 of the polyline point nearest to x (to set `anchor`).
  double nearest_arc_parameter(const Eigen::Vector3d& x) const;
};

}  // namespace elastic
