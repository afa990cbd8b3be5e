#pragma once
/// \file
/// Points on a region's boundary curve by their correspondence parameter s (§4.1): s in [0,1) is
/// the normalised arc length along the curve's chords, measured from the anchor in the curve's
/// (counter-clockwise) direction. Boundary particles are placed and slid with it.
///
/// A sample's 3D `position` lies exactly on the chord polyline (so arc lengths are exact to
/// round-off); its `point` is the SurfacePoint obtained by interpolating, in the ptex (u, v) of the
/// region triangle that owns the chord, between the chord's two end points. The two differ by at
/// most the region tessellation's distance to the limit surface.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "elastic/regions/region.h"
#include "elastic/regions/surface_curve.h"

namespace elastic {

class BoundarySampler {
 public:
  /// \throws InvalidInputError naming `name` when a boundary chord belongs to no region triangle or
  /// the
  ///         curve has zero length.
  explicit BoundarySampler(const Region& region, const std::string& name = "region");

  struct Sample {
    double s = 0.0;   ///< correspondence parameter, wrapped into [0,1)
    int segment = 0;  ///< chord index (curve vertex segment -> segment + 1)
    double t = 0.0;   ///< fraction along the chord
    Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< point on the chord polyline
    Eigen::Vector3d tangent = Eigen::Vector3d::UnitX();  ///< unit direction of the chord
    SurfacePoint point;                                  ///< surface point (see the file comment)
    int triangle = -1;                                   ///< region triangle owning the chord
    /// Barycentric coordinates of the sample in `triangle` (corners 0, 1, 2).
    Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
  };
  Sample at(double s) const;

  const SurfaceCurve& curve() const { return curve_; }
  double length() const { return length_; }

 private:
  const Region* region_;
  SurfaceCurve curve_;
  double length_ = 0.0;
  std::vector<double> cumulative_;  ///< curve_.arc_lengths(), for O(log N) locate
  /// Per chord k: owning triangle and the corner indices (0..2) of curve vertices k and k+1 in it.
  std::vector<Eigen::Vector3i> chord_triangle_;
};

}  // namespace elastic
