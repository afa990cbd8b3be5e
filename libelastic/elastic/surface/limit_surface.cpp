#include "elastic/surface/limit_surface.h"

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <mutex>
#include <string>
#include <utility>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_validation.h"

namespace elastic {
namespace {

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

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

// ---------------------------------------------------------------------------------------------
// OpenSubdiv reports topology problems through process-wide callbacks that print by default. The
// library never prints: the callbacks keep the last message of the calling thread, which the
// constructor turns into an InvalidInputError when the factory gives up.
thread_local std::string osd_last_message;

void osd_error_callback(Far::ErrorType /*type*/, const char* message) {
  osd_last_message = message ? message : "OpenSubdiv error";
}
void osd_warning_callback(const char* message) {
  osd_last_message = message ? message : "OpenSubdiv warning";
}
void install_osd_callbacks() {
  static std::once_flag once;
  std::call_once(once, [] {
    Far::SetErrorCallback(osd_error_callback);
    Far::SetWarningCallback(osd_warning_callback);
  });
}

/// Primvar type for OpenSubdiv's refiner and stencil tables, in double precision. The weights come
/// as float or double depending on the table, hence the templated AddWithWeight.
struct Point3 {
  double x = 0.0, y = 0.0, z = 0.0;
  void Clear(void* = nullptr) { x = y = z = 0.0; }
  template <class W>
  void AddWithWeight(const Point3& src, W weight) {
    const double w = static_cast<double>(weight);
    x += w * src.x;
    y += w * src.y;
    z += w * src.z;
  }
};

/// One stretch of a ptex edge and what lies across it: the neighbouring ptex face and the affine
/// map from this face's (u, v) to the neighbour's. A Catmull-Clark quad next to an n-gon has two
/// stretches per edge (the n-gon's edge is split between two sub-faces at its midpoint).
struct EdgeLink {
  double t_end =
      1.0;        ///< the stretch ends at this edge parameter (it starts where the previous ends)
  int face = -1;  ///< neighbouring ptex face, -1 on the surface boundary
  Eigen::Matrix2d linear = Eigen::Matrix2d::Identity();  ///< uv' = linear * uv + offset
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
};

struct PtexAdjacency {
  std::array<std::array<EdgeLink, 2>, 4> links;
  std::array<int, 4> count{0, 0, 0, 0};
  const EdgeLink& find(int edge, double t) const {
    const int n = count[static_cast<size_t>(edge)];
    const auto& row = links[static_cast<size_t>(edge)];
    for (int i = 0; i + 1 < n; ++i) {
      if (t <= row[static_cast<size_t>(i)].t_end) {
        return row[static_cast<size_t>(i)];
      }
    }
    return row[static_cast<size_t>(n - 1)];
  }
};

/// How a patch is evaluated.
enum class PatchKind : uint8_t {
  /// Regular bicubic B-spline: our own tensor-product code on 16 control points with the boundary
  /// phantom points already substituted.
  BSpline,
  /// Cubic Gregory quad (20 points) and quartic Gregory triangle (18 points): our own basis with
  /// the
  /// exact derivatives of the rational blend. OpenSubdiv's EvaluateBasis returns, for these, the
  /// derivatives of the Bezier patch frozen at (s, t) (the approximation of Loop et al. used by its
  /// shaders), which are not the derivatives of the evaluated position and would defeat Newton
  /// iterations and finite-difference checks.
  Gregory,
  GregoryTriangle,
  /// Anything else (Loop box splines): Far::PatchTable::EvaluateBasis, whose derivatives are exact.
  OpenSubdiv
};

/// What the evaluator needs about a patch of the patch table (indexed by PatchHandle::patchIndex).
struct PatchRecord {
  PatchKind kind = PatchKind::OpenSubdiv;
  /// Triangular patch parametrically rotated by 180 degrees inside its ptex triangle (Loop).
  bool rotated_triangle = false;
  /// d(patch parameter)/d(ptex parameter) = 2^(depth - [non-quad root]).
  double scale = 1.0;
  /// Patch origin: s = u * scale - origin_u (or origin_u - u * scale for a rotated triangle).
  double origin_u = 0.0;
  double origin_v = 0.0;
  /// Correction of OpenSubdiv's derivative scaling for PatchKind::OpenSubdiv (see evaluate()).
  double derivative_fix = 1.0;
  int first_point = 0;  ///< offset of the control points in Impl::patch_points
  int num_points = 0;
};

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

}  // namespace

// =============================================================================================
struct LimitSurface::Impl {
  PolygonMesh mesh;
  std::string name;
  SubdivisionScheme scheme = SubdivisionScheme::CatmullClark;
  bool triangle = false;
  PtexDomain domain{false};  ///< the ptex faces' parameter domain (triangle for Loop)

  std::unique_ptr<Far::TopologyRefiner> refiner;
  std::unique_ptr<Far::PatchTable> patch_table;
  std::unique_ptr<Far::PatchMap> patch_map;

  std::vector<PatchRecord> patches;           ///< per patch of the table
  std::vector<Eigen::Vector3d> patch_points;  ///< control points of every patch, gathered
  int max_patch_points = 0;

  std::vector<int> ptex_to_control;      ///< #ptex faces
  std::vector<int> control_to_ptex;      ///< #control faces + 1 (first ptex face of each)
  std::vector<PtexAdjacency> adjacency;  ///< #ptex faces
  std::vector<std::pair<int, int>> vertex_face_corner;  ///< #V: (control face, corner) or (-1,-1)

  [[noreturn]] void fail(const std::string& problem) const {
    throw InvalidInputError(name, problem);
  }

  /// What the limit surface demands of its control mesh (manifold policy of mesh/).
  static ManifoldRequirements requirements();
  void validate_topology(const LimitSurfaceOptions& options);
  void build_refiner(const LimitSurfaceOptions& options);
  void build_patches(int isolation_level);
  void build_adjacency();

  void check_point(const SurfacePoint& p) const {
    if (p.face < 0 || p.face >= static_cast<int>(ptex_to_control.size())) {
      fail("surface point on ptex face " + std::to_string(p.face) + ", valid faces are 0.." +
           std::to_string(ptex_to_control.size() - 1));
    }
    if (!std::isfinite(p.u) || !std::isfinite(p.v)) {
      fail("surface point with non-finite (u, v)");
    }
  }

  template <bool kDerivatives>
  void evaluate(const SurfacePoint& p, SurfaceDerivatives& out) const;
};

// ---------------------------------------------------------------------------------------------
// Input validation. OpenSubdiv accepts non-manifold topology silently (it tags it and makes it
// sharp), so the mesh must pass the manifold policy of mesh/ (manifold_problem, its wording too)
// first; what a limit surface can carry (zero-area faces, several components, unreferenced
// vertices) is accepted.
ManifoldRequirements LimitSurface::Impl::requirements() {
  ManifoldRequirements r;
  r.allow_several_components = true;
  r.allow_zero_area_faces = true;
  r.allow_unreferenced_vertices = true;
  r.validation.max_examples = 5;
  return r;
}

void LimitSurface::Impl::validate_topology(const LimitSurfaceOptions& options) {
  if (options.isolation_level < 1 || options.isolation_level > 10) {
    fail("isolation_level " + std::to_string(options.isolation_level) + " is out of range 1..10");
  }
  const int nv = mesh.num_vertices();
  const int nf = mesh.num_faces();
  if (nf > 0 &&
      (static_cast<int>(mesh.face_offsets.size()) != nf + 1 || mesh.face_offsets.front() != 0 ||
       mesh.face_offsets.back() != static_cast<int>(mesh.face_vertices.size()))) {
    fail("inconsistent face offsets");
  }
  const ManifoldRequirements required = requirements();
  const std::string problem =
      manifold_problem(mesh, validate_mesh(mesh, required.validation), required);
  if (!problem.empty()) {
    fail(problem);
  }
  if (!options.use_creases) {
    return;
  }
  // Undirected edges as sorted keys min * nv + max, to check that creases are edges.
  std::vector<int64_t> edges;
  edges.reserve(mesh.face_vertices.size());
  for (int f = 0; f < nf; ++f) {
    const auto fv = mesh.face(f);
    const size_t n = fv.size();
    for (size_t i = 0; i < n; ++i) {
      const int a = fv[i], b = fv[(i + 1) % n];
      edges.push_back(static_cast<int64_t>(std::min(a, b)) * nv + std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  for (const Crease& c : mesh.creases) {
    const int64_t key = static_cast<int64_t>(std::min(c.v0, c.v1)) * nv + std::max(c.v0, c.v1);
    const bool in_range = c.v0 >= 0 && c.v0 < nv && c.v1 >= 0 && c.v1 < nv;
    if (!in_range || !std::binary_search(edges.begin(), edges.end(), key)) {
      fail("crease (" + std::to_string(c.v0) + ", " + std::to_string(c.v1) +
           ") is not an edge of the mesh");
    }
    if (!std::isfinite(c.sharpness) || c.sharpness < 0.0) {
      fail("crease (" + std::to_string(c.v0) + ", " + std::to_string(c.v1) +
           ") has an invalid sharpness");
    }
  }
  for (const auto& [v, sharpness] : mesh.corners) {
    if (v < 0 || v >= nv) {
      fail("corner tag on vertex " + std::to_string(v) + ", which does not exist");
    }
    if (!std::isfinite(sharpness) || sharpness < 0.0) {
      fail("corner tag on vertex " + std::to_string(v) + " has an invalid sharpness");
    }
  }
}

void LimitSurface::Impl::build_refiner(const LimitSurfaceOptions& options) {
  const bool all_triangles = mesh.is_triangle_mesh();
  switch (options.scheme) {
    case SubdivisionScheme::Automatic:
      scheme = all_triangles ? SubdivisionScheme::Loop : SubdivisionScheme::CatmullClark;
      break;
    case SubdivisionScheme::Loop:
      if (!all_triangles) {
        fail("the Loop scheme needs a triangle mesh, and this mesh has other faces");
      }
      scheme = SubdivisionScheme::Loop;
      break;
    case SubdivisionScheme::CatmullClark:
      scheme = SubdivisionScheme::CatmullClark;
      break;
  }
  triangle = scheme == SubdivisionScheme::Loop;
  domain = PtexDomain(triangle);

  std::vector<int> verts_per_face(static_cast<size_t>(mesh.num_faces()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    verts_per_face[static_cast<size_t>(f)] = mesh.face_size(f);
  }

  std::vector<Far::Index> crease_pairs;
  std::vector<float> crease_weights;
  std::vector<Far::Index> corner_vertices;
  std::vector<float> corner_weights;
  if (options.use_creases) {
    for (const Crease& c : mesh.creases) {
      crease_pairs.push_back(c.v0);
      crease_pairs.push_back(c.v1);
      crease_weights.push_back(static_cast<float>(c.sharpness));
    }
    for (const auto& [v, sharpness] : mesh.corners) {
      corner_vertices.push_back(v);
      corner_weights.push_back(static_cast<float>(sharpness));
    }
  }

  Far::TopologyDescriptor desc;
  desc.numVertices = mesh.num_vertices();
  desc.numFaces = mesh.num_faces();
  desc.numVertsPerFace = verts_per_face.data();
  desc.vertIndicesPerFace = mesh.face_vertices.data();
  desc.numCreases = static_cast<int>(crease_weights.size());
  desc.creaseVertexIndexPairs = crease_pairs.data();
  desc.creaseWeights = crease_weights.data();
  desc.numCorners = static_cast<int>(corner_weights.size());
  desc.cornerVertexIndices = corner_vertices.data();
  desc.cornerWeights = corner_weights.data();

  Sdc::Options sdc;
  sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  sdc.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_ALL);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  const Sdc::SchemeType type = triangle ? Sdc::SCHEME_LOOP : Sdc::SCHEME_CATMARK;

  install_osd_callbacks();
  osd_last_message.clear();
  refiner.reset(Factory::Create(desc, Factory::Options(type, sdc)));
  if (!refiner) {
    fail("OpenSubdiv cannot build the topology" +
         (osd_last_message.empty() ? std::string() : ": " + osd_last_message));
  }
  // OpenSubdiv's own verdict on vertex manifoldness, a safety net behind the manifold policy
  // (which already rejects a vertex whose faces form more than one fan), in the policy's words.
  const Far::TopologyLevel& base = refiner->GetLevel(0);
  MeshValidation flagged;
  for (int v = 0; v < base.GetNumVertices(); ++v) {
    if (base.GetVertexFaces(v).size() > 0 && base.IsVertexNonManifold(v)) {
      if (flagged.non_manifold_vertices.count++ < requirements().validation.max_examples) {
        flagged.non_manifold_vertices.examples.push_back(v);
      }
    }
  }
  if (flagged.non_manifold_vertices.count > 0) {
    fail(manifold_problem(mesh, flagged, requirements()));
  }
}

void LimitSurface::Impl::build_patches(int isolation_level) {
  Far::PatchTableFactory::Options patch_options(static_cast<unsigned int>(isolation_level));
  patch_options.SetPatchPrecision<double>();
  // Gregory basis end caps around extraordinary vertices; for Loop the factory makes them Gregory
  // triangles. Smooth corners keep the legacy sharp patches (the factory default).
  patch_options.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
  patch_options.generateVaryingTables = false;
  patch_options.generateVaryingLocalPoints = false;

  refiner->RefineAdaptive(patch_options.GetRefineAdaptiveOptions());
  patch_table.reset(Far::PatchTableFactory::Create(*refiner, patch_options));
  if (!patch_table) {
    fail("OpenSubdiv could not build the patch table");
  }

  // Positions of every refined vertex (all levels), then the end caps' local points. Patch control
  // point indices address this concatenation.
  const int num_refined = refiner->GetNumVerticesTotal();
  const int num_local = patch_table->GetNumLocalPoints();
  std::vector<Point3> points(static_cast<size_t>(num_refined + num_local));
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d& x = mesh.positions[static_cast<size_t>(v)];
    points[static_cast<size_t>(v)] = {x.x(), x.y(), x.z()};
  }
  Far::PrimvarRefinerReal<double> primvar(*refiner);
  Point3* src = points.data();
  for (int level = 1; level <= refiner->GetMaxLevel(); ++level) {
    Point3* dst = src + refiner->GetLevel(level - 1).GetNumVertices();
    primvar.Interpolate(level, src, dst);
    src = dst;
  }
  if (num_local > 0) {
    // PatchTable::ComputeLocalPointValues asserts on double-precision tables: use the stencils.
    const auto* stencils = patch_table->GetLocalPointStencilTable<double>();
    if (!stencils) {
      fail("OpenSubdiv built no local point stencils");
    }
    stencils->UpdateValues(points.data(), points.data() + num_refined);
  }
  auto vec = [&](Far::Index i) {
    const Point3& q = points[static_cast<size_t>(i)];
    return Eigen::Vector3d(q.x, q.y, q.z);
  };

  // Gather each patch's control points so that evaluation reads one contiguous block. The block is
  // reserved at its exact size first: on meshes with many extraordinary vertices it holds tens of
  // millions of points, and growing it by doubling touched (and the kernel zeroed) about three
  // times its final size, which dominated loading.
  patches.assign(static_cast<size_t>(patch_table->GetNumPatchesTotal()), PatchRecord{});
  patch_points.clear();
  size_t total_points = 0;
  for (int array = 0; array < patch_table->GetNumPatchArrays(); ++array) {
    const Far::PatchDescriptor desc = patch_table->GetPatchArrayDescriptor(array);
    const size_t per_patch = desc.GetType() == Far::PatchDescriptor::REGULAR
                                 ? size_t{16}
                                 : static_cast<size_t>(desc.GetNumControlVertices());
    total_points += per_patch * static_cast<size_t>(patch_table->GetNumPatches(array));
  }
  patch_points.reserve(total_points);
  int patch_index = 0;
  for (int array = 0; array < patch_table->GetNumPatchArrays(); ++array) {
    const Far::PatchDescriptor desc = patch_table->GetPatchArrayDescriptor(array);
    for (int i = 0; i < patch_table->GetNumPatches(array); ++i, ++patch_index) {
      const Far::ConstIndexArray cvs = patch_table->GetPatchVertices(array, i);
      const Far::PatchParam param = patch_table->GetPatchParam(array, i);
      PatchRecord& rec = patches[static_cast<size_t>(patch_index)];
      const int depth = param.GetDepth();
      const bool non_quad = param.NonQuadRoot();
      rec.scale = std::ldexp(1.0, depth - (non_quad ? 1 : 0));
      rec.origin_u = param.GetU();
      rec.origin_v = param.GetV();
      switch (desc.GetType()) {
        case Far::PatchDescriptor::REGULAR:
          rec.kind = PatchKind::BSpline;
          break;
        case Far::PatchDescriptor::GREGORY_BASIS:
          rec.kind = PatchKind::Gregory;
          break;
        case Far::PatchDescriptor::GREGORY_TRIANGLE:
          rec.kind = PatchKind::GregoryTriangle;
          break;
        default:
          rec.kind = PatchKind::OpenSubdiv;
          break;
      }
      rec.rotated_triangle = triangle && param.IsTriangleRotated();
      if (rec.rotated_triangle) {
        // PatchParam::NormalizeTriangle: s = (2^depth - U) - u * 2^depth.
        rec.origin_u = std::ldexp(1.0, depth) - param.GetU();
        rec.origin_v = std::ldexp(1.0, depth) - param.GetV();
      }
      // OpenSubdiv scales derivatives by 2^depth, which is right for quads but twice the ptex
      // derivative under a non-quad root (whose sub-faces are already one level down).
      rec.derivative_fix = non_quad ? 0.5 : 1.0;
      rec.first_point = static_cast<int>(patch_points.size());
      rec.num_points = cvs.size();
      max_patch_points = std::max(max_patch_points, rec.num_points);
      if (rec.kind == PatchKind::BSpline) {
        std::array<Eigen::Vector3d, 16> p;
        for (int k = 0; k < 16; ++k) {
          p[static_cast<size_t>(k)] = cvs[k] >= 0 ? vec(cvs[k]) : Eigen::Vector3d::Zero();
        }
        // Substitute the phantom points beyond boundary edges by linear extrapolation (the rule
        // OpenSubdiv applies to the basis weights): row 0 / column 3 / row 3 / column 0 for
        // boundary bits 1 / 2 / 4 / 8. The substitutions commute, so corners come out right in any
        // order.
        auto at = [&](int row, int col) -> Eigen::Vector3d& {
          return p[static_cast<size_t>(4 * row + col)];
        };
        const int boundary = param.GetBoundary();
        for (int j = 0; j < 4; ++j) {
          if (boundary & 8) {
            at(j, 0) = 2.0 * at(j, 1) - at(j, 2);
          }
          if (boundary & 2) {
            at(j, 3) = 2.0 * at(j, 2) - at(j, 1);
          }
        }
        for (int j = 0; j < 4; ++j) {
          if (boundary & 1) {
            at(0, j) = 2.0 * at(1, j) - at(2, j);
          }
          if (boundary & 4) {
            at(3, j) = 2.0 * at(2, j) - at(1, j);
          }
        }
        patch_points.insert(patch_points.end(), p.begin(), p.end());
      } else {
        for (int k = 0; k < cvs.size(); ++k) {
          patch_points.push_back(cvs[k] >= 0 ? vec(cvs[k]) : Eigen::Vector3d::Zero());
        }
      }
    }
  }
  patch_map = std::make_unique<Far::PatchMap>(*patch_table);
}

// ---------------------------------------------------------------------------------------------
// Ptex adjacency. Every ptex edge covers a stretch of a control edge (a whole edge for quads and
// triangles, half of one for the sub-faces of an n-gon) or is a "spoke" between two sub-faces of
// the same n-gon. A control edge's parameter tau runs from the face's corner e (tau = 0) to corner
// e+1; a ptex edge's parameter t from its corner k to k+1, and tau = alpha + beta * t along it.
void LimitSurface::Impl::build_adjacency() {
  struct Piece {
    int ptex, edge;
    double alpha, beta;
  };
  // The ptex edges covering control edge e of face f, in order of increasing tau.
  auto pieces = [&](int f, int e) {
    std::array<Piece, 2> out{};
    int count = 0;
    const int first = control_to_ptex[static_cast<size_t>(f)];
    const int n = mesh.face_size(f);
    if (triangle || n == 4) {
      out[0] = {first, e, 0.0, 1.0};
      count = 1;
    } else {
      out[0] = {first + e, 0, 0.0, 0.5};            // sub-face e: corner e to the midpoint
      out[1] = {first + (e + 1) % n, 3, 0.5, 0.5};  // sub-face e+1: midpoint to corner e+1
      count = 2;
    }
    return std::make_pair(out, count);
  };

  // Opposite half-edge of every (face, local edge): sorted directed edges.
  const int nv = mesh.num_vertices();
  struct Half {
    int64_t key;  // a * nv + b for the directed edge a -> b
    int face, edge;
  };
  std::vector<Half> halves;
  halves.reserve(mesh.face_vertices.size());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto fv = mesh.face(f);
    const int n = static_cast<int>(fv.size());
    for (int i = 0; i < n; ++i) {
      halves.push_back({static_cast<int64_t>(fv[static_cast<size_t>(i)]) * nv +
                            fv[static_cast<size_t>((i + 1) % n)],
                        f, i});
    }
  }
  std::sort(halves.begin(), halves.end(),
            [](const Half& x, const Half& y) { return x.key < y.key; });
  auto opposite = [&](int f, int e) -> std::pair<int, int> {
    const auto fv = mesh.face(f);
    const int n = static_cast<int>(fv.size());
    const int64_t key = static_cast<int64_t>(fv[static_cast<size_t>((e + 1) % n)]) * nv +
                        fv[static_cast<size_t>(e)];
    const auto it = std::lower_bound(halves.begin(), halves.end(), key,
                                     [](const Half& h, int64_t k) { return h.key < k; });
    if (it == halves.end() || it->key != key) {
      return {-1, -1};
    }
    return {it->face, it->edge};
  };

  // The affine map taking ptex edge (this side) stretch [ta, tb] onto the neighbour's edge stretch
  // [ua, ub] (reversed direction), extended across the edge: a similarity for quads (it unfolds the
  // two squares into one plane, scaling by 2 between a quad and an n-gon's sub-face); for triangles
  // the map that unfolds the two triangles into a parallelogram (the neighbour's far corner is the
  // reflection of ours through the edge midpoint).
  auto make_link = [&](int k, double ta, double tb, int g, int m, double ua, double ub) {
    EdgeLink link;
    link.t_end = tb;
    link.face = g;
    const Eigen::Vector2d pa = domain.edge_point(k, ta), pb = domain.edge_point(k, tb);
    const Eigen::Vector2d qa = domain.edge_point(m, ua), qb = domain.edge_point(m, ub);
    if (!triangle) {
      // Complex-linear map z -> c z + d with c = (qb - qa) / (pb - pa).
      const std::complex<double> zp(pb.x() - pa.x(), pb.y() - pa.y());
      const std::complex<double> zq(qb.x() - qa.x(), qb.y() - qa.y());
      const std::complex<double> c = zq / zp;
      link.linear << c.real(), -c.imag(), c.imag(), c.real();
    } else {
      const Eigen::Vector2d pc = domain.corner((k + 2) % 3);
      const Eigen::Vector2d qd = domain.corner((m + 2) % 3);
      const Eigen::Vector2d qc = qa + qb - qd;  // both edges are whole edges here
      Eigen::Matrix2d from, to;
      from << pb - pa, pc - pa;
      to << qb - qa, qc - qa;
      link.linear = to * from.inverse();
    }
    link.offset = qa - link.linear * pa;
    return link;
  };

  const int num_ptex = static_cast<int>(ptex_to_control.size());
  adjacency.assign(static_cast<size_t>(num_ptex), PtexAdjacency{});
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int n = mesh.face_size(f);
    const int first = control_to_ptex[static_cast<size_t>(f)];
    for (int e = 0; e < n; ++e) {
      const auto [mine, mine_count] = pieces(f, e);
      const auto [g, ge] = opposite(f, e);
      for (int i = 0; i < mine_count; ++i) {
        const Piece& p = mine[static_cast<size_t>(i)];
        PtexAdjacency& adj = adjacency[static_cast<size_t>(p.ptex)];
        auto& row = adj.links[static_cast<size_t>(p.edge)];
        int& count = adj.count[static_cast<size_t>(p.edge)];
        if (g < 0) {
          row[0] = EdgeLink{};  // boundary: no neighbour along the whole ptex edge
          count = 1;
          continue;
        }
        const auto [theirs, theirs_count] = pieces(g, ge);
        for (int j = 0; j < theirs_count; ++j) {
          const Piece& q = theirs[static_cast<size_t>(j)];
          // Their stretch covers tau' in [q.alpha, q.alpha + q.beta], i.e. tau = 1 - tau'.
          const double lo = std::max(p.alpha, 1.0 - q.alpha - q.beta);
          const double hi = std::min(p.alpha + p.beta, 1.0 - q.alpha);
          if (hi - lo <= 1e-12) {
            continue;
          }
          const double ta = (lo - p.alpha) / p.beta, tb = (hi - p.alpha) / p.beta;
          const double ua = (1.0 - lo - q.alpha) / q.beta, ub = (1.0 - hi - q.alpha) / q.beta;
          row[static_cast<size_t>(count++)] = make_link(p.edge, ta, tb, q.ptex, q.edge, ua, ub);
        }
        // Stretches were produced in order of their tau' pieces, which is decreasing t: sort.
        std::sort(row.begin(), row.begin() + count,
                  [](const EdgeLink& a, const EdgeLink& b) { return a.t_end < b.t_end; });
      }
    }
    // Spokes inside an n-gon: sub-face i's edge 1 (edge midpoint to centre) is sub-face i+1's
    // edge 2.
    if (!triangle && n != 4) {
      for (int i = 0; i < n; ++i) {
        const int a = first + i, b = first + (i + 1) % n;
        adjacency[static_cast<size_t>(a)].links[1][0] = make_link(1, 0.0, 1.0, b, 2, 1.0, 0.0);
        adjacency[static_cast<size_t>(a)].count[1] = 1;
        adjacency[static_cast<size_t>(b)].links[2][0] = make_link(2, 0.0, 1.0, a, 1, 1.0, 0.0);
        adjacency[static_cast<size_t>(b)].count[2] = 1;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Evaluation. The patch map finds the (sub-)patch containing (u, v); the derivatives are returned
// with respect to the ptex parameters (u, v) of the ptex face, whatever the patch's depth.
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

  if (rec.kind == PatchKind::BSpline) {
    // Tensor-product cubic B-spline: contract the 4x4 control net along s for each row, then the
    // three row sums along t. Derivatives by the chain rule with ds/du = dt/dv = scale.
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
          const double r2 =
              dds[0] * r[c] + dds[1] * r[3 + c] + dds[2] * r[6 + c] + dds[3] * r[9 + c];
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
    return;
  }

  if (rec.kind == PatchKind::Gregory || rec.kind == PatchKind::GregoryTriangle) {
    // Patch parameters (s, t) and the chain rule: ds/du = dt/dv = +-scale (minus for a rotated
    // triangle), so first derivatives take that factor and second derivatives its square.
    const double sign = rec.rotated_triangle ? -1.0 : 1.0;
    const double s = sign * (uv.x() * rec.scale - rec.origin_u);
    const double t = sign * (uv.y() * rec.scale - rec.origin_v);
    Jet w[20];
    if (rec.kind == PatchKind::Gregory) {
      gregory_quad_basis(s, t, w);
    } else {
      gregory_triangle_basis(s, t, w);
    }
    const double* q = cp->data();
    double pos[3] = {0, 0, 0}, du[3] = {0, 0, 0}, dv[3] = {0, 0, 0};
    double duu[3] = {0, 0, 0}, duv[3] = {0, 0, 0}, dvv[3] = {0, 0, 0};
    for (int i = 0; i < rec.num_points; ++i) {
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
      const double k1 = sign * rec.scale, k2 = rec.scale * rec.scale;
      store_derivatives(out, du, dv, duu, duv, dvv, k1, k2);
    }
    return;
  }

  // Everything else through OpenSubdiv's basis (at most 20 control points: Gregory basis).
  constexpr int kMax = 20;
  double w[kMax], wu[kMax], wv[kMax], wuu[kMax], wuv[kMax], wvv[kMax];
  if constexpr (kDerivatives) {
    patch_table->EvaluateBasis(*handle, uv.x(), uv.y(), w, wu, wv, wuu, wuv, wvv);
  } else {
    patch_table->EvaluateBasis(*handle, uv.x(), uv.y(), w);
  }
  const double* q = cp->data();
  double pos[3] = {0, 0, 0}, du[3] = {0, 0, 0}, dv[3] = {0, 0, 0};
  double duu[3] = {0, 0, 0}, duv[3] = {0, 0, 0}, dvv[3] = {0, 0, 0};
  for (int i = 0; i < rec.num_points; ++i) {
    for (int c = 0; c < 3; ++c) {
      const double x = q[3 * i + c];
      pos[c] += w[i] * x;
      if constexpr (kDerivatives) {
        du[c] += wu[i] * x;
        dv[c] += wv[i] * x;
        duu[c] += wuu[i] * x;
        duv[c] += wuv[i] * x;
        dvv[c] += wvv[i] * x;
      }
    }
  }
  out.position = {pos[0], pos[1], pos[2]};
  if constexpr (kDerivatives) {
    // OpenSubdiv 3.5/3.6 scale the second-derivative weights of a rotated triangle patch by
    // -4^depth (the sign of the first-derivative chain rule applied once more); the chain rule for
    // s = c - 2^depth u gives +4^depth. Undo the sign here.
    const double k1 = rec.derivative_fix;
    const double k2 = rec.derivative_fix * rec.derivative_fix * (rec.rotated_triangle ? -1.0 : 1.0);
    store_derivatives(out, du, dv, duu, duv, dvv, k1, k2);
  }
}

// =============================================================================================
LimitSurface::LimitSurface(const PolygonMesh& mesh, const LimitSurfaceOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.mesh = mesh;
  m.name = options.name;
  m.validate_topology(options);
  m.build_refiner(options);

  // Ptex numbering from OpenSubdiv itself (before adaptive refinement changes nothing about it).
  const Far::PtexIndices ptex(*m.refiner);
  const int nf = mesh.num_faces();
  m.control_to_ptex.resize(static_cast<size_t>(nf) + 1);
  for (int f = 0; f < nf; ++f) {
    m.control_to_ptex[static_cast<size_t>(f)] = ptex.GetFaceId(f);
  }
  m.control_to_ptex[static_cast<size_t>(nf)] = ptex.GetNumFaces();
  m.ptex_to_control.resize(static_cast<size_t>(ptex.GetNumFaces()));
  for (int f = 0; f < nf; ++f) {
    for (int i = m.control_to_ptex[static_cast<size_t>(f)];
         i < m.control_to_ptex[static_cast<size_t>(f) + 1]; ++i) {
      m.ptex_to_control[static_cast<size_t>(i)] = f;
    }
  }

  m.vertex_face_corner.assign(static_cast<size_t>(mesh.num_vertices()), {-1, -1});
  for (int f = 0; f < nf; ++f) {
    const auto fv = mesh.face(f);
    for (int c = 0; c < static_cast<int>(fv.size()); ++c) {
      auto& slot = m.vertex_face_corner[static_cast<size_t>(fv[static_cast<size_t>(c)])];
      if (slot.first < 0) {
        slot = {f, c};
      }
    }
  }

  m.build_patches(options.isolation_level);
  if (m.patch_table->GetNumPtexFaces() != ptex.GetNumFaces()) {
    m.fail("OpenSubdiv's patch table and ptex indices disagree on the number of ptex faces");
  }
  m.build_adjacency();
}

LimitSurface::~LimitSurface() = default;
LimitSurface::LimitSurface(LimitSurface&&) noexcept = default;
LimitSurface& LimitSurface::operator=(LimitSurface&&) noexcept = default;

SubdivisionScheme LimitSurface::scheme() const {
  return impl_->scheme;
}
const std::string& LimitSurface::name() const {
  return impl_->name;
}
int LimitSurface::num_faces() const {
  return static_cast<int>(impl_->ptex_to_control.size());
}

int LimitSurface::control_face(int ptex_face) const {
  if (ptex_face < 0 || ptex_face >= num_faces()) {
    impl_->fail("ptex face " + std::to_string(ptex_face) + " does not exist");
  }
  return impl_->ptex_to_control[static_cast<size_t>(ptex_face)];
}

int LimitSurface::first_ptex_face(int control_face) const {
  if (control_face < 0 || control_face >= impl_->mesh.num_faces()) {
    impl_->fail("control face " + std::to_string(control_face) + " does not exist");
  }
  return impl_->control_to_ptex[static_cast<size_t>(control_face)];
}

const PolygonMesh& LimitSurface::control_mesh() const {
  return impl_->mesh;
}

bool LimitSurface::in_domain(const SurfacePoint& p, double tolerance) const {
  if (p.face < 0 || p.face >= num_faces()) {
    return false;
  }
  return impl_->domain.contains(p.uv(), tolerance);  // also rejects NaN
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

SurfacePoint LimitSurface::walk(const SurfacePoint& from, const Eigen::Vector2d& delta,
                                int* crossed) const {
  const Impl& m = *impl_;
  m.check_point(from);
  if (!delta.allFinite()) {
    m.fail("walk with a non-finite step");
  }
  const bool tri = m.triangle;
  int face = from.face;
  const PtexDomain& domain = m.domain;
  Eigen::Vector2d x = domain.clamp(from.uv());
  Eigen::Vector2d d = delta;
  int count = 0;
  int zero_steps = 0;  // consecutive crossings without progress (circling a vertex)
  constexpr int kMaxCrossings = 1 << 20;
  for (int iteration = 0; iteration < kMaxCrossings; ++iteration) {
    // Smallest s >= 0 at which x + s d leaves the domain, and through which edge.
    double s_exit = std::numeric_limits<double>::infinity();
    int edge = -1;
    auto consider = [&](double s, int k) {
      if (s < s_exit) {
        s_exit = std::max(s, 0.0);
        edge = k;
      }
    };
    if (d.y() < 0.0) {
      consider(-x.y() / d.y(), 0);  // v = 0
    }
    if (d.x() < 0.0) {
      consider(-x.x() / d.x(), tri ? 2 : 3);  // u = 0
    }
    if (tri) {
      const double g = d.x() + d.y();
      if (g > 0.0) {
        consider((1.0 - x.x() - x.y()) / g, 1);  // u + v = 1
      }
    } else {
      if (d.x() > 0.0) {
        consider((1.0 - x.x()) / d.x(), 1);  // u = 1
      }
      if (d.y() > 0.0) {
        consider((1.0 - x.y()) / d.y(), 2);  // v = 1
      }
    }
    if (edge < 0 || s_exit >= 1.0) {
      x = domain.clamp(x + d);
      break;
    }
    const Eigen::Vector2d q = x + s_exit * d;
    const double t = std::clamp(domain.edge_parameter(edge, q), 0.0, 1.0);
    const EdgeLink& link = m.adjacency[static_cast<size_t>(face)].find(edge, t);
    const Eigen::Vector2d on_edge = domain.edge_point(edge, t);
    if (link.face < 0 || zero_steps > 64) {
      x = on_edge;  // the boundary stops the walk (or we gave up circling a vertex)
      break;
    }
    zero_steps = s_exit == 0.0 ? zero_steps + 1 : 0;
    d = link.linear * ((1.0 - s_exit) * d);
    x = domain.clamp(link.linear * on_edge + link.offset);
    face = link.face;
    ++count;
  }
  if (crossed) {
    *crossed = count;
  }
  return {face, x.x(), x.y()};
}

bool LimitSurface::on_boundary(const SurfacePoint& p, double tolerance) const {
  if (!in_domain(p, tolerance)) {
    return false;
  }
  const Impl& m = *impl_;
  const Eigen::Vector2d x = p.uv();
  for (int k = 0; k < m.domain.num_corners(); ++k) {
    if (std::abs(m.domain.inside_distance(k, x)) > tolerance) {
      continue;
    }
    const double t = std::clamp(m.domain.edge_parameter(k, x), 0.0, 1.0);
    if (m.adjacency[static_cast<size_t>(p.face)].find(k, t).face < 0) {
      return true;
    }
  }
  return false;
}

SurfacePoint LimitSurface::vertex_point(int control_vertex) const {
  const Impl& m = *impl_;
  if (control_vertex < 0 || control_vertex >= m.mesh.num_vertices()) {
    m.fail("control vertex " + std::to_string(control_vertex) + " does not exist");
  }
  const auto [f, c] = m.vertex_face_corner[static_cast<size_t>(control_vertex)];
  if (f < 0) {
    m.fail("control vertex " + std::to_string(control_vertex) + " belongs to no face");
  }
  const int first = m.control_to_ptex[static_cast<size_t>(f)];
  if (m.triangle || m.mesh.face_size(f) == 4) {
    const Eigen::Vector2d uv = m.domain.corner(c);
    return {first, uv.x(), uv.y()};
  }
  return {first + c, 0.0, 0.0};  // an n-gon's sub-face c has the corner vertex at (0, 0)
}

SurfacePoint LimitSurface::face_center(int ptex_face) const {
  if (ptex_face < 0 || ptex_face >= num_faces()) {
    impl_->fail("ptex face " + std::to_string(ptex_face) + " does not exist");
  }
  const Eigen::Vector2d c = impl_->domain.centre();
  return {ptex_face, c.x(), c.y()};
}

}  // namespace elastic
