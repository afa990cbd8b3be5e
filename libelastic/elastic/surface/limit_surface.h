#pragma once
/// \file
/// `LimitSurface`: the smooth surface d(u,v) of the paper, here the subdivision limit surface of an
/// arbitrary manifold control mesh, evaluated exactly (not by refinement) with OpenSubdiv's patch
/// tables in double precision.
///
/// - Scheme: Loop for an all-triangle mesh, Catmull-Clark for quad and mixed meshes (overridable).
/// - Boundaries are interpolated (OpenSubdiv VTX_BOUNDARY_EDGE_AND_CORNER): the limit surface ends
///   on the control mesh's boundary curve, and valence-2 boundary corners are sharp.
/// - Extraordinary vertices are handled by adaptive isolation with Gregory end caps (Gregory
///   triangles for Loop): within `isolation_level` rings of refinement the surface is the exact
///   limit, in the last ring around an extraordinary vertex it is OpenSubdiv's G1 Gregory
///   approximation.
/// - Creases and corners from the mesh's `creases`/`corners` are applied (when `use_creases`).
///
/// Evaluation: regular patches are bicubic B-splines (Catmull-Clark) or quartic box splines (Loop);
/// first and second derivatives are the exact derivatives of the evaluated position everywhere,
/// including the rational Gregory patches (whose derivatives OpenSubdiv only approximates), so they
/// agree with finite differences and can drive Newton iterations. Derivatives are with respect to
/// the ptex parameters (u, v) of surface_point.h, also on n-gon sub-faces and rotated Loop
/// sub-patches. Cost (Release, one core): ~45 ns for a position, ~80 ns with first and second
/// derivatives, ~150 ns for curvature on a regular patch; no allocation per call.
///
/// Accuracy of curvature as a property of subdivision surfaces, not of this evaluation: on a smooth
/// control net the limit's curvature approaches that of the surface the net samples at O(h^2), but
/// near an extraordinary vertex it does not converge under refinement (it stays off by 10-30%
/// around valence 3 and 5 and grows without bound at high valence).
///
/// Points are given as `SurfacePoint` (ptex face, u, v): see surface_point.h for the convention.
/// Parameters slightly outside a face's domain are clamped into it for evaluation; a face index out
/// of range or a non-finite (u, v) throws InvalidInputError.
///
/// Ownership and threads: a LimitSurface copies what it needs from the control mesh and owns its
/// OpenSubdiv tables. It can be moved, not copied. All const member functions are thread-safe.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"
#include "elastic/surface/ptex_domain.h"
#include "elastic/surface/surface_point.h"

namespace elastic {

enum class SubdivisionScheme {
  Automatic,    ///< Loop when every face is a triangle, Catmull-Clark otherwise
  Loop,         ///< Loop (triangle meshes only)
  CatmullClark  ///< Catmull-Clark (any polygon mesh)
};

/// Control meshes with more faces are refined less deeply around smooth extraordinary vertices by
/// default (LimitSurfaceOptions::smooth_isolation_level).
inline constexpr int kDenseMeshFaces = 25000;

struct LimitSurfaceOptions {
  /// Subdivision scheme; Automatic picks Loop for all-triangle meshes and Catmull-Clark otherwise.
  SubdivisionScheme scheme = SubdivisionScheme::Automatic;
  /// Depth of adaptive refinement around extraordinary vertices and creases (OpenSubdiv isolation
  /// level). Higher is more accurate near extraordinary vertices and costs memory; 1..10.
  int isolation_level = 6;
  /// Depth of refinement around *smooth* extraordinary vertices (OpenSubdiv's secondary level),
  /// 1..isolation_level; creases and corners keep isolation_level. -1 (default): isolation_level
  /// on meshes of up to kDenseMeshFaces control faces, 2 on larger ones. A dense scan is mostly
  /// extraordinary vertices (nefertiti-lowres.obj: 62% of 35,002), and at depth 6 its 70,000
  /// faces became 2.2 million patches: 13-15 s and 3.2 GB to build, against 3.5-4 s and 0.8 GB at
  /// depth 2. The price is the Gregory end caps' G1 approximation over a larger neighbourhood of
  /// each extraordinary vertex: against depth 6, positions move by at most 3.2e-4 of the bounding
  /// box's diagonal (mean 1.5e-6) and normals by at most 0.09 rad on nefertiti-lowres.obj, 2.4e-4
  /// and 0.006 rad on bob_tri.obj (200,000 random points each).
  int smooth_isolation_level = -1;
  /// Apply the mesh's crease and corner sharpness tags.
  bool use_creases = true;
  /// Name of the surface for error messages (usually the file it came from).
  std::string name = "surface";
};

/// Position and first and second derivatives with respect to the ptex parameters (u, v).
struct SurfaceDerivatives {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d du = Eigen::Vector3d::Zero();
  Eigen::Vector3d dv = Eigen::Vector3d::Zero();
  Eigen::Vector3d duu = Eigen::Vector3d::Zero();
  Eigen::Vector3d duv = Eigen::Vector3d::Zero();
  Eigen::Vector3d dvv = Eigen::Vector3d::Zero();
};

/// Differential geometry at a point.
/// Sign convention: normal curvature k(t) = -<d2P(t,t), normal> / |dP(t)|^2, so a convex surface
/// bends away from its normal with positive curvature: a sphere with outward normals has k1 = k2 =
/// +1/r, a cylinder of radius r with outward normals has k1 = 1/r, k2 = 0. Principal directions are
/// unit 3D tangent vectors, k1 >= k2, and (dir1, dir2, normal) is right-handed.
struct SurfaceCurvature {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit normal, du x dv normalised
  double k1 = 0.0;                                    ///< larger principal curvature
  double k2 = 0.0;                                    ///< smaller principal curvature
  Eigen::Vector3d dir1 = Eigen::Vector3d::UnitX();    ///< principal direction of k1 (unit, tangent)
  Eigen::Vector3d dir2 = Eigen::Vector3d::UnitY();    ///< principal direction of k2 (unit, tangent)
  double mean = 0.0;                                  ///< (k1 + k2) / 2
  double gaussian = 0.0;                              ///< k1 * k2
};

class LimitSurface {
 public:
  /// Builds the limit surface of `mesh`.
  /// \throws InvalidInputError naming `options.name` when the mesh is not a valid manifold
  ///         polygon mesh, worded by manifold_problem() (run validate_mesh first for a full
  ///         report): no faces, a face with fewer than 3 corners or a repeated or out-of-range
  ///         vertex, a non-finite coordinate, an edge used by more than two faces or twice in the
  ///         same direction, a vertex whose faces form more than one fan; or a crease that is not
  ///         an edge, or when Loop is forced on a non-triangle mesh, or isolation_level is outside
  ///         1..10. Zero-area faces, several components and unreferenced vertices are accepted.
  explicit LimitSurface(const PolygonMesh& mesh, const LimitSurfaceOptions& options = {});
  ~LimitSurface();
  LimitSurface(LimitSurface&&) noexcept;
  LimitSurface& operator=(LimitSurface&&) noexcept;
  LimitSurface(const LimitSurface&) = delete;
  LimitSurface& operator=(const LimitSurface&) = delete;

  /// The scheme actually used (never Automatic).
  SubdivisionScheme scheme() const;
  /// True for Loop, where ptex faces are triangles in (u, v).
  bool triangular_domain() const { return scheme() == SubdivisionScheme::Loop; }
  /// The parameter domain of every ptex face (ptex_domain.h): the unit triangle for Loop, the
  /// unit square for Catmull-Clark.
  PtexDomain domain() const { return PtexDomain(triangular_domain()); }
  const std::string& name() const;

  /// Number of ptex faces; valid SurfacePoint::face values are 0 .. num_faces()-1.
  int num_faces() const;
  /// The isolation depth used around smooth extraordinary vertices (see
  /// LimitSurfaceOptions::smooth_isolation_level).
  int smooth_isolation_level() const;
  /// The control-mesh face a ptex face belongs to.
  int control_face(int ptex_face) const;
  /// The first ptex face of a control face (an n-gon under Catmull-Clark has n consecutive ones).
  int first_ptex_face(int control_face) const;
  /// The control mesh as it was given (positions, faces, attributes).
  const PolygonMesh& control_mesh() const;

  /// True when (u, v) lies in the face's parameter domain (square or triangle), within `tolerance`.
  bool in_domain(const SurfacePoint& p, double tolerance = 0.0) const;

  /// Limit position d(u, v).
  Eigen::Vector3d position(const SurfacePoint& p) const;
  /// Limit position and first and second derivatives.
  SurfaceDerivatives derivatives(const SurfacePoint& p) const;
  /// Unit normal, principal curvatures and directions, mean and Gaussian curvature.
  /// Where du x dv vanishes (a singular parametrisation at some extraordinary corners), the point
  /// is nudged kSingularNudge (1e-6 ptex units, ptex_domain.h) towards the face centre and
  /// evaluated there.
  SurfaceCurvature curvature(const SurfacePoint& p) const;
  /// Curvature from already evaluated derivatives (saves an evaluation): the shape operator from
  /// the first and second fundamental forms, expressed in the orthonormal tangent frame (du/|du|, n
  /// x du). With degenerate derivatives (du x dv = 0) it reports zero curvature.
  static SurfaceCurvature curvature(const SurfaceDerivatives& d);
  /// The unit normal's variation pulled back to the point: a tangent displacement delta of the
  /// point turns n = du x dv / |du x dv| by dn(delta) = n_u alpha + n_v beta (delta = du alpha +
  /// dv beta; the Weingarten map, minus the shape operator of SurfaceCurvature); returns the
  /// tangent vector w with v . dn(delta) = w . delta for every tangent delta. It turns a derivative
  /// with respect to the normal at a point into one with respect to the point's position (the
  /// fast solver's barrier, particles/spring_energy.h). On a sphere of radius r with outward
  /// normals, w is v's tangential part over r. Zero with degenerate derivatives (du x dv = 0).
  static Eigen::Vector3d normal_variation_adjoint(const SurfaceDerivatives& d,
                                                  const Eigen::Vector3d& v);

  /// Moves from `from` by `delta` in parameter space, continuing into neighbouring ptex faces when
  /// the straight path leaves the face (the remaining step is re-expressed in the neighbour's
  /// parameters). Stops on the surface boundary (the result lies on the boundary edge). Never
  /// returns a point outside a face's domain. `crossed` (optional) receives the number of ptex
  /// edges crossed. Re-expression unfolds the two faces into one plane: a similarity for
  /// Catmull-Clark (a rotation by a multiple of 90 degrees; scale 2 from an n-gon's sub-face into a
  /// quad, 1/2 back), for Loop the affine map that makes the two triangles a parallelogram. The
  /// adjacency is built once from the control topology. A path through a vertex continues into the
  /// face across the edge it meets first (on a regular vertex: the diagonal face); walks are
  /// reversible with the re-expressed step.
  SurfacePoint walk(const SurfacePoint& from, const Eigen::Vector2d& delta,
                    int* crossed = nullptr) const;

  /// True when p lies on the surface boundary (a ptex edge with no neighbour), within `tolerance`
  /// in (u,v).
  bool on_boundary(const SurfacePoint& p, double tolerance = 1e-12) const;

  /// Representative SurfacePoint at a control vertex's limit position (in the first face that uses
  /// the vertex; \throws InvalidInputError for a vertex in no face), and at the centre of a ptex
  /// face (PtexDomain::centre(): (0.5, 0.5), or (1/3, 1/3) for Loop).
  SurfacePoint vertex_point(int control_vertex) const;
  SurfacePoint face_center(int ptex_face) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace elastic
