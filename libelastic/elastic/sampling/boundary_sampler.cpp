#include "elastic/sampling/boundary_sampler.h"

#include <cmath>
#include <string>
#include <utility>

#include "elastic/core/error.h"

namespace elastic {

BoundarySampler::BoundarySampler(const Region& region, const std::string& name)
    : region_(&region), curve_(region.boundary_curve()) {
  length_ = curve_.length();
  cumulative_ = curve_.arc_lengths();
  if (!(length_ > 0.0) || !std::isfinite(length_)) {
    throw InvalidInputError(name, "the boundary curve has zero length");
  }
  const std::vector<BoundaryChord> chords = region.boundary_chords();
  const int n = static_cast<int>(region.boundary.size());
  chord_triangle_.resize(n);
  for (int k = 0; k < n; ++k) {
    const BoundaryChord& chord = chords[k];
    if (chord.triangle < 0) {
      throw InvalidInputError(name, "boundary chord " + std::to_string(k) +
                                        " is not an edge of the region's triangles");
    }
    chord_triangle_[k] = Eigen::Vector3i(chord.triangle, chord.corner_from, chord.corner_to);
  }
}

BoundarySampler::Sample BoundarySampler::at(double s) const {
  Sample out;
  out.s = s - std::floor(s);
  if (out.s >= 1.0) {
    out.s = 0.0;
  }
  const SurfaceCurve::Location loc = curve_.locate(out.s, cumulative_, length_);
  const int n = curve_.size();
  out.segment = loc.segment;
  out.t = loc.t;
  out.position = loc.position;
  const Eigen::Vector3d chord =
      curve_.positions[(loc.segment + 1) % n] - curve_.positions[loc.segment];
  const double chord_length = chord.norm();
  if (chord_length > 0.0) {
    out.tangent = chord / chord_length;
  }
  const Eigen::Vector3i& owner = chord_triangle_[loc.segment];
  out.triangle = owner[0];
  out.barycentric.setZero();
  out.barycentric[owner[1]] = 1.0 - loc.t;
  out.barycentric[owner[2]] = loc.t;
  out.point = region_->point_in_triangle(out.triangle, out.barycentric[1], out.barycentric[2]);
  return out;
}

}  // namespace elastic
