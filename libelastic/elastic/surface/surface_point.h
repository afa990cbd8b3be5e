#pragma once
/// \file
/// `SurfacePoint`: the one type for "a point on a surface" that crosses every module boundary
/// (projection, regions, sampling, particles, mapping, transfer).
///
/// A surface point is a location on the *limit surface* of a control mesh (see limit_surface.h),
/// given as a ptex face and parameters (u, v) inside it. Ptex faces follow OpenSubdiv's
/// `Far::PtexIndices`:
///
/// - Catmull-Clark: a quad control face is one ptex face. An n-gon (n != 4) is split into n ptex
///   sub-faces, numbered consecutively from the control face's first ptex index; sub-face i is the
///   quad (corner i, midpoint of edge (i, i+1), face centre, midpoint of edge (i-1, i)). (u, v) lie
///   in the unit square [0,1]^2: a quad's corners 0, 1, 2, 3 are at (0,0), (1,0), (1,1), (0,1); a
///   sub-face's corner vertex is at (0,0), the next edge midpoint at (1,0), the centre at (1,1).
/// - Loop: every control triangle is one ptex face; (u, v) lie in the triangle u >= 0, v >= 0,
///   u + v <= 1 with the triangle's corners 0, 1, 2 at (0,0), (1,0), (0,1).
///
/// Corners are those of the control face in its stored (counter-clockwise) order, so dP/du x dP/dv
/// points to the side the control mesh's normals point to. Points on a shared edge have one
/// representation per adjacent ptex face; all of them denote the same 3D point.

#include <Eigen/Core>

namespace elastic {

struct SurfacePoint {
  int face = -1;   ///< ptex face index, -1 when the point is not set
  double u = 0.0;  ///< first parameter inside the ptex face
  double v = 0.0;  ///< second parameter inside the ptex face

  bool valid() const { return face >= 0; }
  Eigen::Vector2d uv() const { return {u, v}; }
  friend bool operator==(const SurfacePoint&, const SurfacePoint&) = default;
};

}  // namespace elastic
