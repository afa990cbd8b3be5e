#pragma once
/// \file
/// `ParticleGrid`: the particles and springs of the paper (§4.1, Figs. 1-2) on a source region.
///
/// The grid is an OpenMesh polygon mesh: particles are vertices, *normal springs* are edges,
/// *angular springs* are face corners. Interior particles form a regular quad grid; boundary
/// particles lie on the region's boundary curve and are joined to the outside of the quad grid by a
/// band of triangles (no degenerate or inverted faces). Faces are counter-clockwise seen from the
/// source normal side.
///
/// Rest values are recorded on the source after sampling (§4.2):
/// - normal spring (i, j): rest length k_ij = |s_j - s_i| (Euclidean source distance, eq. 13);
/// - angular spring at corner i of a face, between i and the *virtual point* m = (x_a + x_b) / 2,
///   the midpoint of i's two neighbours a, b in that face: rest length |s_i - m_source| (Fig. 1).
///
/// Flat arrays (`springs`, `angular_springs`) are derived from the mesh by `build_springs()` for
/// the solvers' inner loops; they stay valid as long as the mesh's connectivity does not change.

#include <Eigen/Core>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"
#include "elastic/surface/surface_point.h"

namespace elastic {

struct GridTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
};
using GridMesh = OpenMesh::PolyMesh_ArrayKernelT<GridTraits>;

/// A normal spring between particles i and j with rest length k_ij (eq. 13).
struct Spring {
  int i = -1;
  int j = -1;
  double rest = 0.0;
};

/// An angular spring at corner `i` of a face whose neighbours of i are `a` and `b` (virtual point
/// (x_a + x_b) / 2). `rest` is the source distance from i to the virtual point.
struct AngularSpring {
  int i = -1;
  int a = -1;
  int b = -1;
  double rest = 0.0;
};

struct ParticleGrid {
  /// Connectivity and source positions (mesh.point(vh) is the particle's source position).
  GridMesh mesh;
  /// #P source surface point of each particle (particle index = OpenMesh vertex index).
  std::vector<SurfacePoint> source_points;
  /// #P source texture coordinates, when the source mesh has UVs; empty otherwise.
  std::vector<Eigen::Vector2d> source_uv;
  /// #P 1 for particles on the boundary curve, 0 inside.
  std::vector<char> is_boundary;
  /// Boundary particles in counter-clockwise order along the curve.
  std::vector<int> boundary_loop;
  /// For each entry of boundary_loop, its correspondence parameter s in [0,1) on the source curve
  /// (normalised arc length from the anchor, see SurfaceCurve).
  std::vector<double> boundary_parameter;

  std::vector<Spring> springs;                 ///< one per mesh edge
  std::vector<AngularSpring> angular_springs;  ///< one per face corner

  int num_particles() const { return static_cast<int>(mesh.n_vertices()); }
  /// Source positions as a 3 x #P matrix.
  Eigen::Matrix3Xd source_positions() const;
  /// (Re)computes `springs` and `angular_springs` from the mesh connectivity and the current source
  /// positions (rest values = current source distances).
  void build_springs();
};

/// The grid's faces split into triangles, fanned from each face's first corner (faces are convex in
/// the grid's layout: quads of the regular grid and triangles of the boundary band, so any fan is
/// valid). The one split every user of grid triangles shares: Mapping's queries, the metrics and
/// heatmaps, the multilevel start. `faces`, when given, receives each triangle's face index.
std::vector<Eigen::Vector3i> grid_triangles(const ParticleGrid& grid,
                                            std::vector<int>* faces = nullptr);

/// The grid's faces with the given 3 x #P particle positions (e.g. source, naive or relaxed target
/// positions) as a PolygonMesh for writing; per-vertex texture coordinates are the particles'
/// source UVs when they carry them, so a written grid shows where every particle came from in the
/// source texture.
PolygonMesh to_polygon_mesh(const ParticleGrid& grid, const Eigen::Matrix3Xd& positions);

}  // namespace elastic
