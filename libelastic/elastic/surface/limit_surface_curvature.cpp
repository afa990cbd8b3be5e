// Curvature of the limit surface (limit_surface.h): the shape operator from the first and second
// fundamental forms of the evaluated derivatives.
#include <Eigen/Geometry>
#include <cmath>

#include "elastic/surface/detail/limit_surface_impl.h"
#include "elastic/surface/limit_surface.h"
#include "elastic/surface/ptex_domain.h"

namespace elastic {

// Differential geometry from the first and second fundamental forms. In the orthonormal tangent
// frame e1 = du/|du|, e2 = n x e1 the parameter Jacobian is upper triangular, B = [a b; 0 c]
// (columns: du and dv in that frame), and the shape operator is the symmetric S = B^-T II B^-1 with
// II = -[duu.n duv.n; duv.n dvv.n] (the header's sign: convex away from the normal is positive).
SurfaceCurvature LimitSurface::curvature(const SurfaceDerivatives& d) {
  SurfaceCurvature out;
  const Eigen::Vector3d cross = d.du.cross(d.dv);
  const double a = d.du.norm();
  const double area = cross.norm();
  if (!(a > 0.0) || !(area > 0.0) || !std::isfinite(area)) {
    // Degenerate parametrisation: no tangent plane from these derivatives. Report a flat point with
    // whatever direction is available (curvature(SurfacePoint) avoids this by nudging the point).
    if (area > 0.0) {
      out.normal = cross / area;
    }
    out.dir1 = out.normal.unitOrthogonal();
    out.dir2 = out.normal.cross(out.dir1);
    return out;
  }
  out.normal = cross / area;
  const Eigen::Vector3d e1 = d.du / a;
  const Eigen::Vector3d e2 = out.normal.cross(e1);
  const double b = d.dv.dot(e1);
  const double c = area / a;  // = dv . e2 > 0
  const double L = -d.duu.dot(out.normal), M = -d.duv.dot(out.normal), N = -d.dvv.dot(out.normal);
  // S = B^-T II B^-1 with B^-1 = [1/a, -b/(a c); 0, 1/c].
  const double i00 = 1.0 / a, i01 = -b / (a * c), i11 = 1.0 / c;
  // II * B^-1
  const double t00 = L * i00, t01 = L * i01 + M * i11;
  const double t10 = M * i00, t11 = M * i01 + N * i11;
  // B^-T * (II B^-1); B^-T = [i00 0; i01 i11]
  const double s00 = i00 * t00;
  const double s01 = i00 * t01;
  const double s11 = i01 * t01 + i11 * t11;
  (void)t10;  // s10 = i01 * t00 + i11 * t10 equals s01 by symmetry
  const double mean = 0.5 * (s00 + s11);
  const double half_diff = 0.5 * (s00 - s11);
  const double radius = std::hypot(half_diff, s01);
  out.k1 = mean + radius;
  out.k2 = mean - radius;
  out.mean = mean;
  out.gaussian = out.k1 * out.k2;
  // Eigenvector of k1 at angle theta with tan(2 theta) = 2 s01 / (s00 - s11); at an umbilic any
  // direction is principal and atan2(0, 0) = 0 picks e1.
  const double theta = 0.5 * std::atan2(2.0 * s01, s00 - s11);
  out.dir1 = std::cos(theta) * e1 + std::sin(theta) * e2;
  out.dir2 = out.normal.cross(out.dir1);
  return out;
}

SurfaceCurvature LimitSurface::curvature(const SurfacePoint& p) const {
  SurfaceDerivatives d = derivatives(p);
  const double scale = d.du.norm() * d.dv.norm();
  if (!(d.du.cross(d.dv).norm() > 1e-10 * scale) || !(scale > 0.0)) {
    // At some extraordinary corners the parametrisation is singular (du x dv = 0 while the surface
    // is smooth). Evaluate a tiny step towards the face centre instead (the one nudge,
    // kSingularNudge of ptex_domain.h): the curvature is continuous, so this changes it by O(1e-6)
    // relative.
    d = derivatives(impl_->domain.towards_centre(p, kSingularNudge));
  }
  return curvature(d);
}

// n = N / |N| with N = du x dv: dN/du = duu x dv + du x duv, dN/dv = duv x dv + du x dvv, and the
// unit normal's derivative is the part of dN/|N| orthogonal to n. For delta = du alpha + dv beta,
// (alpha, beta) = I^-1 (du . delta, dv . delta) with I the first fundamental form, so
// v . dn = (v . n_u, v . n_v) I^-1 (du . delta, dv . delta) = w . delta with
// w = [du dv] I^-1 (v . n_u, v . n_v) (I symmetric).
Eigen::Vector3d LimitSurface::normal_variation_adjoint(const SurfaceDerivatives& d,
                                                       const Eigen::Vector3d& v) {
  const Eigen::Vector3d cross = d.du.cross(d.dv);
  const double area = cross.norm();
  if (!(area > 0.0) || !std::isfinite(area)) {
    return Eigen::Vector3d::Zero();
  }
  const Eigen::Vector3d n = cross / area;
  const Eigen::Vector3d cross_u = d.duu.cross(d.dv) + d.du.cross(d.duv);
  const Eigen::Vector3d cross_v = d.duv.cross(d.dv) + d.du.cross(d.dvv);
  const Eigen::Vector3d n_u = (cross_u - n * n.dot(cross_u)) / area;
  const Eigen::Vector3d n_v = (cross_v - n * n.dot(cross_v)) / area;
  const double E = d.du.squaredNorm(), F = d.du.dot(d.dv), G = d.dv.squaredNorm();
  const double det = area * area;  // E G - F^2 (Lagrange's identity, without its cancellation)
  const double r0 = v.dot(n_u), r1 = v.dot(n_v);
  const double y0 = (G * r0 - F * r1) / det;
  const double y1 = (E * r1 - F * r0) / det;
  return y0 * d.du + y1 * d.dv;
}

}  // namespace elastic
