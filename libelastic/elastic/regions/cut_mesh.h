#pragma once
/// \file
/// Internal to regions/: `CutMesh`, a mutable copy of a limit tessellation in which closed curves
/// are embedded exactly (split edges and triangles until the curve is a chain of mesh edges) before
/// a side of the curve is extracted as a Region.
///
/// Every triangle keeps the ptex face it lies in and its corners' (u, v) in that face, and
/// remembers the tessellation triangle it was cut from (`origin`). New vertices get (u, v) by
/// linear interpolation in the split triangle's face, so they lie exactly on the limit surface, and
/// their positions are evaluated there. Inside one ptex face the (u, v) of all triangles form a
/// planar, conforming, counter-clockwise triangulation of the face's domain: straight segments in
/// (u, v) can be walked across it. An optional second chart, `tex` (texture coordinates per corner,
/// linear per triangle), is interpolated the same way for curves drawn in texture space.

#include <Eigen/Core>
#include <array>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "elastic/regions/region.h"
#include "elastic/surface/limit_surface.h"
#include "elastic/surface/limit_tessellation.h"

namespace elastic::regions_detail {

/// A point of a triangle mesh as weights on a triangle's corners.
struct MeshLocation {
  int triangle = -1;
  Eigen::Vector3d bary = Eigen::Vector3d(1.0, 0.0, 0.0);
};

/// The 3D point of a location on the mesh with these positions and triangles.
inline Eigen::Vector3d position_of(const std::vector<Eigen::Vector3d>& positions,
                                   const std::vector<Eigen::Vector3i>& triangles,
                                   const MeshLocation& p) {
  const Eigen::Vector3i& c = triangles[static_cast<size_t>(p.triangle)];
  return p.bary[0] * positions[static_cast<size_t>(c[0])] +
         p.bary[1] * positions[static_cast<size_t>(c[1])] +
         p.bary[2] * positions[static_cast<size_t>(c[2])];
}

/// The corners' (u, v) of every tessellation triangle in its own ptex face. A vertex welded on a
/// ptex edge carries the (u, v) of one adjacent face only; for the other faces its coordinates are
/// found among the face's boundary grid nodes (the tessellation is a uniform grid per face) as the
/// node whose limit position coincides with the vertex.
std::vector<std::array<Eigen::Vector2d, 3>> tessellation_corner_uv(const LimitSurface& surface,
                                                                   const LimitTessellation& tess);
/// The same for the tessellation triangles `which` only, in that order.
std::vector<std::array<Eigen::Vector2d, 3>> tessellation_corner_uv(const LimitSurface& surface,
                                                                   const LimitTessellation& tess,
                                                                   const std::vector<int>& which);

/// (u, v) of barycentric coordinates in a triangle with corner (u, v) `uv`.
inline Eigen::Vector2d interpolate(const std::array<Eigen::Vector2d, 3>& uv,
                                   const Eigen::Vector3d& b) {
  return b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2];
}
/// Barycentric coordinates of p in the planar triangle (a, b, c); zeros for a degenerate triangle.
Eigen::Vector3d barycentric_2d(const std::array<Eigen::Vector2d, 3>& tri, const Eigen::Vector2d& p);

/// The triangle among `candidates` that holds the (u, v) point `p` most deeply: the largest
/// smallest barycentric coordinate, so that a point on an edge, or outside by round-off, still
/// finds one. Degenerate triangles are skipped; `corner_uv(i)` gives candidate i's corners. The
/// coordinates are returned as computed (callers clamp them to the triangle); triangle -1 when no
/// candidate is usable.
template <typename CornerUv>
MeshLocation deepest_triangle(const std::vector<int>& candidates, const CornerUv& corner_uv,
                              const Eigen::Vector2d& p) {
  MeshLocation best;
  double best_min = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < candidates.size(); ++i) {
    const Eigen::Vector3d b = barycentric_2d(corner_uv(i), p);
    if (!b.isZero() && b.minCoeff() > best_min) {
      best_min = b.minCoeff();
      best = MeshLocation{candidates[i], b};
    }
  }
  return best;
}

enum class Chart { Ptex, Texture };

class CutMesh {
 public:
  CutMesh(const LimitSurface& surface, const LimitTessellation& tess,
          std::vector<std::array<Eigen::Vector2d, 3>> corner_uv, std::string name);

  const LimitSurface& surface() const { return *surface_; }
  int num_vertices() const { return static_cast<int>(positions.size()); }
  int num_triangles() const { return static_cast<int>(triangles.size()); }

  /// Fills `tex` from the control mesh's texture coordinates (regions/texture_coordinates.h).
  void enable_texture_chart();

  /// Splits edge (a, b) at (1 - t) a + t b (both adjacent triangles); returns the new vertex.
  int split_edge(int a, int b, double t);
  /// Splits triangle tri at barycentric coordinates `bary` into three; returns the new vertex.
  int split_triangle(int tri, const Eigen::Vector3d& bary);
  /// Makes the point at `bary` of triangle `tri` a vertex: an existing vertex when the point is one
  /// (or within `snap` in barycentric terms of a vertex not on a curve), an edge split when it is
  /// on an edge (or within `snap` of an edge that is not a curve edge), otherwise a triangle split.
  int insert_in_triangle(int tri, Eigen::Vector3d bary, double snap);
  /// Inserts a point given by (u, v) in the face of tessellation triangle `origin_triangle`:
  /// located among the triangles cut from it.
  int insert_point(int origin_triangle, const Eigen::Vector2d& uv, double snap);

  /// Coordinates of vertex v in `chart` as seen from triangle t (v must be a corner of t).
  Eigen::Vector2d chart_coordinate(Chart chart, int t, int v) const;
  /// Embeds the straight segment (in `chart`) from vertex a (chart coordinate ca) to vertex b (cb)
  /// as a chain of curve edges, splitting the edges it crosses. With `face` >= 0 only triangles of
  /// that ptex face are walked. \throws InvalidInputError "crosses itself" when the segment meets
  /// the curve.
  void walk(int a, Eigen::Vector2d ca, int b, Chart chart, int face, double snap);

  /// Triangles that contain both a and b.
  std::vector<int> edge_triangles(int a, int b) const;
  bool is_curve_edge(int a, int b) const {
    return curve_edges.count({std::min(a, b), std::max(a, b)}) > 0;
  }
  void add_curve_edge(int a, int b) { curve_edges.insert({std::min(a, b), std::max(a, b)}); }
  [[noreturn]] void throw_crossing() const;

  /// Connected sets of triangles, neighbours across edges that are not curve edges (or, when `keep`
  /// is given, only among triangles with keep[t]).
  std::vector<std::vector<int>> components(const std::vector<char>* keep = nullptr) const;

  std::vector<Eigen::Vector3d> positions;
  std::vector<SurfacePoint> points;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<int> face;
  std::vector<std::array<Eigen::Vector2d, 3>> uv;
  std::vector<std::array<Eigen::Vector2d, 3>> tex;  ///< empty unless enable_texture_chart()
  std::vector<int> origin;  ///< tessellation triangle each triangle came from
  /// The corners' (u, v) of every tessellation triangle as it was before any cut: barycentric
  /// coordinates in a tessellation triangle (MeshLocation of the tessellation) interpolate these,
  /// not `uv`, whose entry for that index is one of the pieces once the triangle is split.
  std::vector<std::array<Eigen::Vector2d, 3>> origin_uv;
  std::vector<std::vector<int>> vertex_triangles;
  std::vector<std::vector<int>> children;  ///< per tessellation triangle, the triangles cut from it
  std::vector<char> on_curve;              ///< per vertex
  std::set<std::pair<int, int>> curve_edges;

 private:
  int corner(int t, int v) const;
  int add_vertex(const SurfacePoint& p);
  int add_triangle(const Eigen::Vector3i& tri, int parent);

  const LimitSurface* surface_;
  std::string name_;
};

/// Topology of a set of triangles: boundary loops (each oriented like the triangles, i.e. with the
/// triangles on the left) and whether it is a disk (one boundary loop without a repeated vertex,
/// Euler characteristic V - E + F = 1).
struct PatchTopology {
  std::vector<std::vector<int>> loops;  ///< vertex indices of the cut mesh
  int euler = 0;
  bool pinched = false;  ///< a boundary vertex with more than one outgoing boundary edge
  double area = 0.0;
  bool is_disk() const { return loops.size() == 1 && !pinched && euler == 1; }
};
PatchTopology patch_topology(const CutMesh& mesh, const std::vector<int>& triangles);

/// Copies the triangles into a Region (boundary = the patch's single loop, counter-clockwise).
Region make_region_from_patch(const CutMesh& mesh, const std::vector<int>& triangles,
                              const PatchTopology& topology);

}  // namespace elastic::regions_detail
