#pragma once
/// \file
/// Internal to regions/: exact shortest paths on a triangle mesh (the polyhedral geodesics of
/// Mitchell, Mount and Papadimitriou, SIAM J. Comput. 16(4), 1987, as implemented by CGAL's
/// Surface_mesh_shortest_path after Xin and Wang, ACM TOG 28(4), 2009).
///
/// Used for the sides of a `points:` polygon. A polyhedral shortest path is straight inside every
/// triangle it crosses and unfolds to a straight line across each edge; two shortest paths that
/// share an end point meet only there (unless one contains the other), so the sides of a simple
/// polygon never touch each other near its corners, however sharp. The heat method's traced paths
/// (integral curves of the heat gradient, heat_geodesics.h) do not have that property: within a few
/// edges of the heat source the traced gradient field points at the source triangle's corners, not
/// at the point, and an incoming side can wind into the outgoing one at a sharp tip or a reflex
/// notch of a star.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "elastic/regions/cut_mesh.h"

namespace elastic::regions_detail {

/// One node of a path: a point and the triangle in which the path runs from it to the next node.
struct PathNode {
  MeshLocation location;      ///< the point (location.triangle contains it)
  int segment_triangle = -1;  ///< triangle holding this node and the next one
};

/// Triangles within the ellipse d_from + d_to <= (1 + slack) d + margin around the shortest path
/// from a to b, with d_from and d_to (approximate) distance fields from both ends at the vertices
/// and d the distance between the ends: every point of a path at most `slack` longer than the
/// shortest, plus `margin` for the error of the fields.
std::vector<char> geodesic_band(const std::vector<Eigen::Vector3i>& triangles,
                                const Eigen::VectorXd& d_from, const Eigen::VectorXd& d_to,
                                double slack, double margin);

/// A shortest path: its nodes and its length.
struct GeodesicPath {
  std::vector<PathNode> nodes;  ///< from `from` up to, not including, `to`
  double length = 0.0;          ///< along the surface (CGAL's, between the ends moved kInside)
};

class ExactGeodesics {
 public:
  /// Keeps the mesh (by reference: it must outlive this object).
  ExactGeodesics(const std::vector<Eigen::Vector3d>& positions,
                 const std::vector<Eigen::Vector3i>& triangles, std::string name);
  ~ExactGeodesics();
  ExactGeodesics(const ExactGeodesics&) = delete;
  ExactGeodesics& operator=(const ExactGeodesics&) = delete;

  /// The shortest path from `from` to `to` among the triangles with band[t] set: nodes from `from`
  /// up to, not including, `to`, each with a triangle that holds it and the next node, and its
  /// length. CGAL's
  /// sequence tree grows over every triangle it is given (about a minute and a gigabyte on a
  /// 30,000-triangle plane), so the caller restricts the search to a band around the path
  /// (`geodesic_band`); both end points' triangles must be in it. \throws InvalidInputError when
  /// the band is not an oriented 2-manifold, NumericalError when `to` is unreachable from `from`
  /// inside it.
  GeodesicPath path(const MeshLocation& from, const MeshLocation& to,
                    const std::vector<char>& band);
  /// The same with the band as its triangles' indices in increasing order (a small band of a large
  /// tessellation costs its own size, not the tessellation's).
  GeodesicPath path(const MeshLocation& from, const MeshLocation& to, const std::vector<int>& band);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace elastic::regions_detail
