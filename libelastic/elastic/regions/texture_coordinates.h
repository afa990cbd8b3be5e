#pragma once
/// \file
/// Texture (UV) coordinates of points on a limit surface, from the control mesh's per-corner UVs.
///
/// The UV of a SurfacePoint is the interpolation of its control face's corner UVs over the ptex
/// domain (surface_point.h gives the convention): linear over a Loop triangle ((1-u-v) c0 + u c1 +
/// v c2); bilinear over a Catmull-Clark quad (corners 0..3 at (0,0), (1,0), (1,1), (0,1)); bilinear
/// over an n-gon's sub-face i, whose corners carry c_i, the midpoint of edge (i, i+1), the centroid
/// of the face's UVs and the midpoint of edge (i-1, i). This is the texture layout the control
/// mesh's UVs describe, spread over the smooth surface; it is continuous inside a control face and
/// across control edges that are not UV seams.

#include <Eigen/Core>

#include "elastic/surface/limit_surface.h"

namespace elastic {

/// The texture coordinate of p. \throws InvalidInputError naming the surface when its control mesh
/// has no texture coordinates.
Eigen::Vector2d texture_coordinate(const LimitSurface& surface, const SurfacePoint& p);

}  // namespace elastic
