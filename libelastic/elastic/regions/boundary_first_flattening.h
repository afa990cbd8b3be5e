#pragma once
/// \file
/// Boundary first flattening (Sawhney and Crane 2017, "Boundary First Flattening", ACM TOG 37(1)):
/// a conformal flattening of a disk-shaped Region that keeps the boundary's lengths (the log scale
/// factor u vanishes on the boundary), built from three solves with one real matrix, the interior
/// block L_II of the cotangent Laplacian:
/// 1. the log scale factor that flattens the interior, L_II u_I = -Omega_I (Omega: angle defect
///    2 pi - sum of corner angles; the discrete Yamabe equation Delta u = K with u = 0 on the
///    boundary, L = -Delta positive semi-definite);
/// 2. the boundary's new geodesic curvature k~ = k + (L u)_B (k: pi - sum of corner angles at a
///    boundary vertex; Gauss-Bonnet makes the k~ sum to 2 pi), integrated into a polygon with the
///    3D edge lengths, then closed by the least change of the lengths weighted by 1/l (a 2 x 2
///    system);
/// 3. the interior by the harmonic extension of the polygon's x and y (the components of a
///    conformal map are harmonic, and the polygon is, up to discretisation, the boundary of one).
///
/// Against a least-squares conformal map of the same region (region_flattening.h), whose free
/// boundary couples u and v into one complex system that only a factorisation solves well (two
/// pins leave its conformal modes nearly free: AMG-preconditioned conjugate gradients took 381
/// iterations on the 28,900-vertex hemisphere), the matrix here is real and half the size, and its
/// factorisation costs about a quarter of the complex one. The choice of map is canonical, too:
/// conformal flattenings differ by the harmonic part of their log scale factor, and u = 0 on the
/// boundary leaves none, so u has the least Dirichlet energy among them (the cross term with a
/// harmonic h integrates to the boundary, where u vanishes); on a round cap it is the centred
/// stereographic projection, where two pins leave the Moebius motions of the disk to round-off.
///
/// A planar region comes out as itself (Omega = 0 and k~ = k, and the cotangent Laplacian
/// reproduces linear functions), up to a rigid motion.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "elastic/regions/region.h"

namespace elastic {

/// The flattening's vertex positions, rotated and translated so that vertex `first` is at the
/// origin and vertex `second` on the positive x axis (the two vertices of the least-squares
/// conformal map's pins, so that both lay a lattice out in the same direction). Lengths are the
/// region's own (no rescaling). Orientation: triangles come out counter-clockwise.
///
/// std::nullopt when the method does not apply: a triangle of zero area in 3D (a weld of two
/// copies of a vertex; the angle sums at those copies are undefined), no interior vertex, or a
/// factorisation that fails. The caller then uses another flattening.
std::optional<std::vector<Eigen::Vector2d>> boundary_first_flattening(const Region& region,
                                                                      int first, int second);

}  // namespace elastic
