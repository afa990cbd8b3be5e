#pragma once
/// \file
/// The inside of `LimitSurface` (limit_surface.h), shared by its .cpp files and private to
/// surface/ (not installed):
///
// clang-format off
///   limit_surface.cpp             construction: validation, the OpenSubdiv refiner, ptex numbering,
///                                 the small queries (faces, vertices, centres)
///   limit_surface_patches.cpp     the patch table and each patch's control points, gathered
///   limit_surface_evaluation.cpp  evaluation: B-spline, Gregory and OpenSubdiv bases, position and
///                                 derivatives in ptex units
///   limit_surface_curvature.cpp   the shape operator: normal, principal curvatures and directions
///   limit_surface_walk.cpp        ptex adjacency, walking across ptex edges, the boundary test
// clang-format on

#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/topologyRefiner.h>

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_validation.h"
#include "elastic/surface/limit_surface.h"
#include "elastic/surface/ptex_domain.h"

namespace elastic {
namespace limit_surface_detail {

/// One stretch of a ptex edge and what lies across it: the neighbouring ptex face and the affine
/// map from this face's (u, v) to the neighbour's. A Catmull-Clark quad next to an n-gon has two
/// stretches per edge (the n-gon's edge is split between two sub-faces at its midpoint).
struct EdgeLink {
  /// The stretch ends at this edge parameter (it starts where the previous ends).
  double t_end = 1.0;
  int face = -1;  ///< neighbouring ptex face, -1 on the surface boundary
  Eigen::Matrix2d linear = Eigen::Matrix2d::Identity();  ///< uv' = linear * uv + offset
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
};

/// The stretches of a ptex face's edges (at most two per edge, `count` of them).
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
  /// the exact derivatives of the rational blend. OpenSubdiv's EvaluateBasis returns, for these,
  /// the derivatives of the Bezier patch frozen at (s, t) (the approximation of Loop et al. used by
  /// its shaders), which are not the derivatives of the evaluated position and would defeat Newton
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

}  // namespace limit_surface_detail

struct LimitSurface::Impl {
  using EdgeLink = limit_surface_detail::EdgeLink;
  using PtexAdjacency = limit_surface_detail::PtexAdjacency;
  using PatchRecord = limit_surface_detail::PatchRecord;

  PolygonMesh mesh;
  std::string name;
  int smooth_isolation_level = 0;  ///< the secondary isolation level used
  SubdivisionScheme scheme = SubdivisionScheme::CatmullClark;
  bool triangle = false;
  PtexDomain domain{false};  ///< the ptex faces' parameter domain (triangle for Loop)

  std::unique_ptr<OpenSubdiv::Far::TopologyRefiner> refiner;
  std::unique_ptr<OpenSubdiv::Far::PatchTable> patch_table;
  std::unique_ptr<OpenSubdiv::Far::PatchMap> patch_map;

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

  // Construction, in this order (limit_surface.cpp, limit_surface_patches.cpp,
  // limit_surface_walk.cpp).
  /// What the limit surface demands of its control mesh (manifold policy of mesh/).
  static ManifoldRequirements requirements();
  void validate_topology(const LimitSurfaceOptions& options);
  void validate_creases() const;
  void build_refiner(const LimitSurfaceOptions& options);
  void check_refiner_manifold() const;
  void build_ptex_numbering();
  void build_patches(int isolation, int smooth_isolation);
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

  /// Position and, with kDerivatives, derivatives in ptex units (limit_surface_evaluation.cpp).
  template <bool kDerivatives>
  void evaluate(const SurfacePoint& p, SurfaceDerivatives& out) const;
};

}  // namespace elastic
