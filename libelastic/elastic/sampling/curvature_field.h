#pragma once
/// \file
/// The curvature measure that drives adaptive sampling (§4.3), r = sqrt((k1^2 + k2^2) / 2),
/// averaged over a neighbourhood of the particle scale.
///
/// Particles spaced h apart cannot follow curvature that changes over less than h; the paper's
/// pointwise r lets them try. On a smooth surface (a cap, a torus) r varies over the surface's own
/// scale and the average is r itself to O(h^2 r''). On a scan, the limit surface of a noisy control
/// mesh has curvature that changes sign and size from one control vertex to the next: the pointwise
/// r is noise at the particle scale, eq. 8's fixed point on the weights does not contract, and
/// spacings spread over two orders of magnitude (nefertiti-lowres.obj at 2,000 particles: 0.09 to
/// 15 around a median of 1.1, not converged after 300 sweeps).
///
/// The field is a kernel average over the region's tessellation vertices, weighted by their areas
/// (a third of the adjacent triangles'):
///
///     rbar(x) = sum_v A_v r_v K(|x - x_v|) / sum_v A_v K(|x - x_v|),
///     K(d) = (1 - d^2 / R^2)^3 for d < R = 3 s, else 0.
///
/// K is as wide as a Gaussian of standard deviation s (its mean squared radius over a plane is
/// R^2 / 5 = 1.8 s^2 against the Gaussian's 2 s^2) but vanishes with its first two derivatives at
/// R, so rbar is twice differentiable in x: a truncated Gaussian jumps by 1% of its peak where a
/// vertex enters the support, which kept the Newton steps from settling below 1e-5 of a spacing.
/// A constant r stays exactly constant (a sphere or a plane is unchanged), and the weights no
/// longer jump when a particle moves by a fraction of h.
/// Distances are straight-line, in space: on a region whose two sheets come within 3 s of each
/// other (a fold thinner than the particle spacing) the sheets share their curvature, which the
/// particles could not tell apart either. s is never below the tessellation's mean edge length,
/// so at least a ring of vertices falls inside the kernel. Where r is the same at every vertex (to
/// 1e-9 relative; a plane) the field is that constant and no query searches.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "elastic/regions/region.h"

namespace elastic {

class CurvatureField {
 public:
  /// Evaluates r at every vertex of `region` (in parallel) and indexes them. `radius` is s, in the
  /// surface's units (raised to the mean edge length of the region's tessellation; the kernel
  /// reaches 3 s); radius <= 0 gives the pointwise r of the paper.
  CurvatureField(const Region& region, double radius);

  /// r averaged around position x, whose surface point is q (q serves the pointwise field and
  /// the rare query with no vertex within 3 s, where it is r at q).
  double at(const Eigen::Vector3d& x, const SurfacePoint& q) const;

  /// The kernel's s actually used (0 for the pointwise field).
  double radius() const { return radius_; }

  /// The paper's pointwise r at q.
  static double pointwise(const LimitSurface& surface, const SurfacePoint& q);

 private:
  std::uint64_t cell_key(long ix, long iy, long iz) const;

  const LimitSurface& surface_;
  double radius_ = 0.0;
  double cell_ = 1.0;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  std::vector<double> px_, py_, pz_;       // vertex positions by coordinate, sorted by cell
  std::vector<double> weighted_r_, area_;  // A_v r_v and A_v, sorted by cell
  // The occupied cells, sorted, and where each one's vertices start (one past the last: nv). A
  // binary search over this short list stays in cache; one over every vertex's key (a few hundred
  // thousand on a scan's region) missed it at each step and was most of the field's cost.
  std::vector<std::uint64_t> cell_keys_;
  std::vector<int> cell_start_;
  std::optional<double> constant_;  // r where it is the same at every vertex
};

}  // namespace elastic
