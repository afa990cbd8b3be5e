// Evaluation of the limit surface (limit_surface.h): the patch map finds the (sub-)patch containing
// (u, v), and the patch is evaluated by its kind (detail/limit_surface_impl.h): our own bicubic
// B-spline and Gregory bases, OpenSubdiv's basis for the rest. Derivatives are returned with
// respect to the ptex parameters (u, v) of the ptex face, whatever the patch's depth.
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>

#include <Eigen/Core>
#include <string>

#include "elastic/core/error.h"
#include "elastic/surface/detail/limit_surface_impl.h"
#include "elastic/surface/limit_surface.h"

namespace elastic {
namespace {

namespace Far = OpenSubdiv::Far;
using limit_surface_detail::PatchKind;
using limit_surface_detail::PatchRecord;

// Stores the accumulated parameter derivatives scaled to ptex units: first derivatives by k1,
// second derivatives by k2 (the chain-rule factors of each patch kind's local parameterisation).
inline void store_derivatives(SurfaceDerivatives& out, const double du[3], const double dv[3],
                              const double duu[3], const double duv[3], const double dvv[3],
                              double k1, double k2) {
  out.du = {k1 * du[0], k1 * du[1], k1 * du[2]};
  out.dv = {k1 * dv[0], k1 * dv[1], k1 * dv[2]};
  out.duu = {k2 * duu[0], k2 * duu[1], k2 * duu[2]};
  out.duv = {k2 * duv[0], k2 * duv[1], k2 * duv[2]};
  out.dvv = {k2 * dvv[0], k2 * dvv[1], k2 * dvv[2]};
}

/// Uniform cubic B-spline basis and its first and second derivatives at t in [0,1].
inline void bspline_basis(double t, double b[4], double d[4], double dd[4]) {
  const double s = 1.0 - t;
  const double t2 = t * t;
  b[0] = s * s * s / 6.0;
  b[1] = (3.0 * t2 * t - 6.0 * t2 + 4.0) / 6.0;
  b[2] = (-3.0 * t2 * t + 3.0 * t2 + 3.0 * t + 1.0) / 6.0;
  b[3] = t2 * t / 6.0;
  if (d) {
    d[0] = -0.5 * s * s;
    d[1] = 1.5 * t2 - 2.0 * t;
    d[2] = -1.5 * t2 + t + 0.5;
    d[3] = 0.5 * t2;
  }
  if (dd) {
    dd[0] = s;
    dd[1] = 3.0 * t - 2.0;
    dd[2] = 1.0 - 3.0 * t;
    dd[3] = t;
  }
}

/// Cubic Bernstein polynomials and their first and second derivatives at t in [0,1].
inline void bernstein3(double t, double b[4], double d[4], double dd[4]) {
  const double s = 1.0 - t;
  b[0] = s * s * s;
  b[1] = 3.0 * t * s * s;
  b[2] = 3.0 * t * t * s;
  b[3] = t * t * t;
  d[0] = -3.0 * s * s;
  d[1] = 3.0 * s * s - 6.0 * t * s;
  d[2] = 6.0 * t * s - 3.0 * t * t;
  d[3] = 3.0 * t * t;
  dd[0] = 6.0 * s;
  dd[1] = 6.0 * t - 12.0 * s;
  dd[2] = 6.0 * s - 12.0 * t;
  dd[3] = 6.0 * t;
}

/// A value and its first and second partial derivatives in (s, t).
struct Jet {
  double f = 0, fs = 0, ft = 0, fss = 0, fst = 0, ftt = 0;
};

/// The rational blend G = N / D of a Gregory patch, with N and D affine in (s, t), and its
/// derivatives: G_s = (N_s - G D_s) / D, G_ss = -2 G_s D_s / D, G_st = -(G_s D_t + G_t D_s) / D,
/// G_tt = -2 G_t D_t / D. D vanishes only at a patch corner, where the blended Bezier weight
/// vanishes to second order; `fallback` is the value OpenSubdiv uses there.
inline Jet rational(double n, double ns, double nt, double d, double ds, double dt,
                    double fallback) {
  Jet g;
  if (!(d > 0.0)) {
    g.f = fallback;
    return g;
  }
  g.f = n / d;
  g.fs = (ns - g.f * ds) / d;
  g.ft = (nt - g.f * dt) / d;
  g.fss = -2.0 * g.fs * ds / d;
  g.ftt = -2.0 * g.ft * dt / d;
  g.fst = -(g.fs * dt + g.ft * ds) / d;
  return g;
}
inline Jet one_minus(const Jet& g) {
  return {1.0 - g.f, -g.fs, -g.ft, -g.fss, -g.fst, -g.ftt};
}
/// Product rule for the Jet of a * b.
inline Jet product(const Jet& a, const Jet& b) {
  return {a.f * b.f,
          a.fs * b.f + a.f * b.fs,
          a.ft * b.f + a.f * b.ft,
          a.fss * b.f + 2.0 * a.fs * b.fs + a.f * b.fss,
          a.fst * b.f + a.fs * b.ft + a.ft * b.fs + a.f * b.fst,
          a.ftt * b.f + 2.0 * a.ft * b.ft + a.f * b.ftt};
}

/// Basis of the cubic Gregory quad in OpenSubdiv's point order: the 12 boundary points are Bezier
/// points (column in s, row in t), the 8 interior points come in pairs blending one Bezier interior
/// point, face point i+ with G_i and i- with 1 - G_i (G_0 = s/(s+t), G_1 = t/(1-s+t),
/// G_2 = (1-s)/(2-s-t), G_3 = (1-t)/(1+s-t) at the corners (0,0), (1,0), (1,1), (0,1)).
void gregory_quad_basis(double s, double t, Jet w[20]) {
  double bs[4], ds[4], dds[4], bt[4], dt[4], ddt[4];
  bernstein3(s, bs, ds, dds);
  bernstein3(t, bt, dt, ddt);
  auto tensor = [&](int col, int row) {
    return Jet{bs[col] * bt[row],  ds[col] * bt[row], bs[col] * dt[row],
               dds[col] * bt[row], ds[col] * dt[row], bs[col] * ddt[row]};
  };
  static constexpr int kBoundary[12][3] = {{0, 0, 0},  {1, 1, 0},  {7, 2, 0},  {5, 3, 0},
                                           {2, 0, 1},  {6, 3, 1},  {16, 0, 2}, {12, 3, 2},
                                           {15, 0, 3}, {17, 1, 3}, {11, 2, 3}, {10, 3, 3}};
  for (const auto& b : kBoundary) {
    w[b[0]] = tensor(b[1], b[2]);
  }
  const Jet g[4] = {rational(s, 1, 0, s + t, 1, 1, 0.0), rational(t, 0, 1, 1.0 - s + t, -1, 1, 0.0),
                    rational(1.0 - s, -1, 0, 2.0 - s - t, -1, -1, 0.0),
                    rational(1.0 - t, 0, -1, 1.0 + s - t, 1, -1, 0.0)};
  // (index of the + point, index of the - point, Bezier column, row) per corner.
  static constexpr int kInterior[4][4] = {
      {3, 4, 1, 1}, {8, 9, 2, 1}, {13, 14, 2, 2}, {18, 19, 1, 2}};
  for (int i = 0; i < 4; ++i) {
    const Jet b = tensor(kInterior[i][2], kInterior[i][3]);
    w[kInterior[i][0]] = product(b, g[i]);
    w[kInterior[i][1]] = product(b, one_minus(g[i]));
  }
}

/// Quartic Bezier triangle basis with derivatives, OpenSubdiv's point order: rows of increasing
/// power of t (row j holds 5 - j points), along a row increasing power of s; point (i, j) has the
/// weight 4!/(i! j! k!) s^i t^j w^k with w = 1 - s - t, k = 4 - i - j.
void bezier_triangle4(double s, double t, Jet b[15]) {
  const double w = 1.0 - s - t;
  double ps[5] = {1, s, s * s, s * s * s, s * s * s * s};
  double pt[5] = {1, t, t * t, t * t * t, t * t * t * t};
  double pw[5] = {1, w, w * w, w * w * w, w * w * w * w};
  auto pw_at = [&](const double* p, int e) { return e < 0 ? 0.0 : p[e]; };
  static constexpr double kFactorial[5] = {1, 1, 2, 6, 24};
  int index = 0;
  for (int j = 0; j <= 4; ++j) {
    for (int i = 0; i + j <= 4; ++i, ++index) {
      const int k = 4 - i - j;
      const double c = 24.0 / (kFactorial[i] * kFactorial[j] * kFactorial[k]);
      // Partial derivatives in the barycentric variables (u = s, v = t, w) of u^i v^j w^k ...
      const double di = i, dj = j, dk = k;
      const double f = ps[i] * pt[j] * pw[k];
      const double fu = di * pw_at(ps, i - 1) * pt[j] * pw[k];
      const double fv = dj * ps[i] * pw_at(pt, j - 1) * pw[k];
      const double fw = dk * ps[i] * pt[j] * pw_at(pw, k - 1);
      const double fuu = di * (di - 1) * pw_at(ps, i - 2) * pt[j] * pw[k];
      const double fvv = dj * (dj - 1) * ps[i] * pw_at(pt, j - 2) * pw[k];
      const double fww = dk * (dk - 1) * ps[i] * pt[j] * pw_at(pw, k - 2);
      const double fuv = di * dj * pw_at(ps, i - 1) * pw_at(pt, j - 1) * pw[k];
      const double fuw = di * dk * pw_at(ps, i - 1) * pt[j] * pw_at(pw, k - 1);
      const double fvw = dj * dk * ps[i] * pw_at(pt, j - 1) * pw_at(pw, k - 1);
      // ... and by the chain rule with dw/ds = dw/dt = -1.
      b[index] = {c * f,
                  c * (fu - fw),
                  c * (fv - fw),
                  c * (fuu - 2.0 * fuw + fww),
                  c * (fuv - fuw - fvw + fww),
                  c * (fvv - 2.0 * fvw + fww)};
    }
  }
}

/// Basis of the quartic Gregory triangle in OpenSubdiv's point order (5 points per corner, then the
/// 3 edge points); the Bezier interior points 6, 7, 10 become pairs blended with
/// G_0 = s/(s+t), G_1 = t/(1-s), G_2 = w/(1-t) and their complements.
void gregory_triangle_basis(double s, double t, Jet w[18]) {
  Jet b[15];
  bezier_triangle4(s, t, b);
  const Jet g0 = rational(s, 1, 0, s + t, 1, 1, 1.0);
  const Jet g1 = rational(t, 0, 1, 1.0 - s, -1, 0, 1.0);
  const Jet g2 = rational(1.0 - s - t, -1, -1, 1.0 - t, 0, -1, 1.0);
  w[0] = b[0];
  w[1] = b[1];
  w[2] = b[5];
  w[3] = product(b[6], g0);
  w[4] = product(b[6], one_minus(g0));
  w[5] = b[4];
  w[6] = b[8];
  w[7] = b[3];
  w[8] = product(b[7], g1);
  w[9] = product(b[7], one_minus(g1));
  w[10] = b[14];
  w[11] = b[12];
  w[12] = b[13];
  w[13] = product(b[10], g2);
  w[14] = product(b[10], one_minus(g2));
  w[15] = b[2];
  w[16] = b[11];
  w[17] = b[9];
}

// ---------------------------------------------------------------------------------------------
// One evaluation per patch kind. Each accumulates the position and (with kDerivatives) the
// derivatives in the patch's own parameters, then scales them to ptex units.

/// Tensor-product cubic B-spline: contract the 4x4 control net along s for each row, then the
/// three row sums along t. Derivatives by the chain rule with ds/du = dt/dv = scale.
template <bool kDerivatives>
void evaluate_bspline(const PatchRecord& rec, const Eigen::Vector2d& uv, const Eigen::Vector3d* cp,
                      SurfaceDerivatives& out) {
  const double s = uv.x() * rec.scale - rec.origin_u;
  const double t = uv.y() * rec.scale - rec.origin_v;
  double bs[4], ds[4], dds[4], bt[4], dt[4], ddt[4];
  bspline_basis(s, bs, kDerivatives ? ds : nullptr, kDerivatives ? dds : nullptr);
  bspline_basis(t, bt, kDerivatives ? dt : nullptr, kDerivatives ? ddt : nullptr);
  // Plain arrays: the control points are 16 consecutive xyz triples.
  const double* q = cp->data();
  double pos[3] = {0, 0, 0}, du[3] = {0, 0, 0}, dv[3] = {0, 0, 0};
  double duu[3] = {0, 0, 0}, duv[3] = {0, 0, 0}, dvv[3] = {0, 0, 0};
  for (int row = 0; row < 4; ++row) {
    const double* r = q + 12 * row;
    for (int c = 0; c < 3; ++c) {
      const double r0 = bs[0] * r[c] + bs[1] * r[3 + c] + bs[2] * r[6 + c] + bs[3] * r[9 + c];
      pos[c] += bt[row] * r0;
      if constexpr (kDerivatives) {
        const double r1 = ds[0] * r[c] + ds[1] * r[3 + c] + ds[2] * r[6 + c] + ds[3] * r[9 + c];
        const double r2 = dds[0] * r[c] + dds[1] * r[3 + c] + dds[2] * r[6 + c] + dds[3] * r[9 + c];
        du[c] += bt[row] * r1;
        dv[c] += dt[row] * r0;
        duu[c] += bt[row] * r2;
        duv[c] += dt[row] * r1;
        dvv[c] += ddt[row] * r0;
      }
    }
  }
  out.position = {pos[0], pos[1], pos[2]};
  if constexpr (kDerivatives) {
    const double k1 = rec.scale, k2 = rec.scale * rec.scale;
    store_derivatives(out, du, dv, duu, duv, dvv, k1, k2);
  }
}

/// The weighted sums of a patch's control points (`num_points` xyz triples at `q`) with the
/// weights' values and, with kDerivatives, their derivatives; then the derivatives scaled to ptex
/// units by k1 (first) and k2 (second), as store_derivatives.
template <bool kDerivatives>
void combine_control_points(const Jet* w, int num_points, const double* q, double k1, double k2,
                            SurfaceDerivatives& out) {
  double pos[3] = {0, 0, 0}, du[3] = {0, 0, 0}, dv[3] = {0, 0, 0};
  double duu[3] = {0, 0, 0}, duv[3] = {0, 0, 0}, dvv[3] = {0, 0, 0};
  for (int i = 0; i < num_points; ++i) {
    for (int c = 0; c < 3; ++c) {
      const double x = q[3 * i + c];
      pos[c] += w[i].f * x;
      if constexpr (kDerivatives) {
        du[c] += w[i].fs * x;
        dv[c] += w[i].ft * x;
        duu[c] += w[i].fss * x;
        duv[c] += w[i].fst * x;
        dvv[c] += w[i].ftt * x;
      }
    }
  }
  out.position = {pos[0], pos[1], pos[2]};
  if constexpr (kDerivatives) {
    store_derivatives(out, du, dv, duu, duv, dvv, k1, k2);
  }
}

/// Gregory quad or triangle with our own basis. Patch parameters (s, t) and the chain rule:
/// ds/du = dt/dv = +-scale (minus for a rotated triangle), so first derivatives take that factor
/// and second derivatives its square.
template <bool kDerivatives>
void evaluate_gregory(const PatchRecord& rec, const Eigen::Vector2d& uv, const Eigen::Vector3d* cp,
                      SurfaceDerivatives& out) {
  const double sign = rec.rotated_triangle ? -1.0 : 1.0;
  const double s = sign * (uv.x() * rec.scale - rec.origin_u);
  const double t = sign * (uv.y() * rec.scale - rec.origin_v);
  Jet w[20];
  if (rec.kind == PatchKind::Gregory) {
    gregory_quad_basis(s, t, w);
  } else {
    gregory_triangle_basis(s, t, w);
  }
  const double k1 = sign * rec.scale, k2 = rec.scale * rec.scale;
  combine_control_points<kDerivatives>(w, rec.num_points, cp->data(), k1, k2, out);
}

/// Everything else through OpenSubdiv's basis (at most 20 control points: Gregory basis).
template <bool kDerivatives>
void evaluate_opensubdiv(const Far::PatchTable& table, const Far::PatchTable::PatchHandle& handle,
                         const PatchRecord& rec, const Eigen::Vector2d& uv,
                         const Eigen::Vector3d* cp, SurfaceDerivatives& out) {
  constexpr int kMax = 20;
  double w[kMax], wu[kMax], wv[kMax], wuu[kMax], wuv[kMax], wvv[kMax];
  Jet jets[kMax];
  if constexpr (kDerivatives) {
    table.EvaluateBasis(handle, uv.x(), uv.y(), w, wu, wv, wuu, wuv, wvv);
    for (int i = 0; i < rec.num_points; ++i) {
      jets[i] = {w[i], wu[i], wv[i], wuu[i], wuv[i], wvv[i]};
    }
  } else {
    table.EvaluateBasis(handle, uv.x(), uv.y(), w);
    for (int i = 0; i < rec.num_points; ++i) {
      jets[i].f = w[i];
    }
  }
  // OpenSubdiv 3.5/3.6 scale the second-derivative weights of a rotated triangle patch by
  // -4^depth (the sign of the first-derivative chain rule applied once more); the chain rule for
  // s = c - 2^depth u gives +4^depth. Undo the sign here.
  const double k1 = rec.derivative_fix;
  const double k2 = rec.derivative_fix * rec.derivative_fix * (rec.rotated_triangle ? -1.0 : 1.0);
  combine_control_points<kDerivatives>(jets, rec.num_points, cp->data(), k1, k2, out);
}

}  // namespace

template <bool kDerivatives>
void LimitSurface::Impl::evaluate(const SurfacePoint& p, SurfaceDerivatives& out) const {
  check_point(p);
  const Eigen::Vector2d uv = domain.clamp(p.uv());
  const Far::PatchTable::PatchHandle* handle = patch_map->FindPatch(p.face, uv.x(), uv.y());
  if (!handle) {
    throw NumericalError(name, "no patch at ptex face " + std::to_string(p.face));
  }
  const PatchRecord& rec = patches[static_cast<size_t>(handle->patchIndex)];
  static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double),
                "control points are read as xyz triples");
  const Eigen::Vector3d* cp = patch_points.data() + rec.first_point;
  switch (rec.kind) {
    case PatchKind::BSpline:
      evaluate_bspline<kDerivatives>(rec, uv, cp, out);
      return;
    case PatchKind::Gregory:
    case PatchKind::GregoryTriangle:
      evaluate_gregory<kDerivatives>(rec, uv, cp, out);
      return;
    case PatchKind::OpenSubdiv:
      evaluate_opensubdiv<kDerivatives>(*patch_table, *handle, rec, uv, cp, out);
      return;
  }
}

Eigen::Vector3d LimitSurface::position(const SurfacePoint& p) const {
  SurfaceDerivatives d;
  impl_->evaluate<false>(p, d);
  return d.position;
}

SurfaceDerivatives LimitSurface::derivatives(const SurfacePoint& p) const {
  SurfaceDerivatives d;
  impl_->evaluate<true>(p, d);
  return d;
}

}  // namespace elastic
