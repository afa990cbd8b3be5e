#pragma once
/// \file
/// Internal to regions/: geodesic distance and shortest paths on a triangle mesh with the heat
/// method (Crane, Weischedel, Wardetzky, "Geodesics in Heat", ACM TOG 32(5), 2013).
///
/// 1. Heat flow for a short time t = h^2 (h the mean edge length), one backward Euler step:
///    (M + t L) u = delta_source, with M the lumped (barycentric) mass matrix and L the cotangent
///    Laplacian (positive semi-definite). The source is a point of a triangle: delta is spread over
///    the triangle's corners by barycentric weight.
/// 2. X = -grad u / |grad u| per triangle: unit vectors pointing away from the source (Varadhan:
///    the heat kernel's level sets approach geodesic circles as t -> 0).
/// 3. L phi = -div X, solved with phi pinned to 0 at the corner of the source triangle nearest the
///    source (the pin absorbs the boundary flux of an open mesh, where the Neumann problem is
///    inconsistent); phi is then shifted to vanish at the source.
///
/// Accuracy: phi converges to the smooth surface's geodesic distance as h -> 0; the error is O(h)
/// away from the source, larger within a few edges of it (the heat step smooths the distance cone's
/// tip).
///
/// Shortest paths are traced *upstream* of the heat gradient: from a start point, move across each
/// triangle along grad u of the heat released at the end point, until the triangle holding the end
/// point is reached. The integral curves of grad u are the geodesics through the source in the
/// limit t -> 0; the path is a polyline whose vertices lie on mesh edges.

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <memory>
#include <string>
#include <vector>

#include "elastic/regions/cut_mesh.h"

namespace elastic::regions_detail {

/// One node of a traced path: a point and the triangle in which the path runs from it to the next
/// node.
struct PathNode {
  MeshLocation location;      ///< the point (location.triangle contains it)
  int segment_triangle = -1;  ///< triangle holding this node and the next one
};

class HeatGeodesics {
 public:
  /// Builds and factors the heat operator. \throws NumericalError when the factorisation fails.
  HeatGeodesics(const std::vector<Eigen::Vector3d>& positions,
                const std::vector<Eigen::Vector3i>& triangles, std::string name);

  /// Heat u after one step from a point source.
  Eigen::VectorXd heat(const MeshLocation& source) const;
  /// Approximate geodesic distance from the source to every vertex.
  Eigen::VectorXd distance(const MeshLocation& source) const;
  /// The path from `from` to `to` (nodes from `from` up to, not including, `to`).
  /// \throws NumericalError when the trace gets stuck.
  std::vector<PathNode> trace_path(const MeshLocation& from, const MeshLocation& to) const;

  double mean_edge_length() const { return h_; }

 private:
  Eigen::Vector3d gradient(int t, const Eigen::VectorXd& f) const;
  /// Triangles containing the location (one for an interior point, two on an edge, a fan at a
  /// vertex).
  std::vector<int> triangles_at(const MeshLocation& p) const;
  /// Expresses p in triangle t (p must lie on t's closure).
  Eigen::Vector3d bary_in(const MeshLocation& p, int t) const;

  const std::vector<Eigen::Vector3d>& x_;
  const std::vector<Eigen::Vector3i>& tri_;
  std::string name_;
  double h_ = 0.0;
  Eigen::SparseMatrix<double> laplacian_;
  std::vector<std::vector<int>> vertex_triangles_;
  std::unique_ptr<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>> heat_solver_;
};

}  // namespace elastic::regions_detail
