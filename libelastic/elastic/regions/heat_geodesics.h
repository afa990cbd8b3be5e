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
/// Paths are not traced here: integral curves of grad u wind near the source (see
/// exact_geodesics.h, which the `points:` sides use); the distance bounds the last band their
/// search falls back to (polygon_sides.h).

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "elastic/regions/cut_mesh.h"

namespace elastic::regions_detail {

class HeatGeodesics {
 public:
  /// Builds the cotangent Laplacian and the mass; the heat operator is factored on first use.
  HeatGeodesics(const std::vector<Eigen::Vector3d>& positions,
                const std::vector<Eigen::Vector3i>& triangles, std::string name);

  /// Heat u after one step from a point source.
  /// \throws NumericalError when the factorisation of the heat operator fails.
  Eigen::VectorXd heat(const MeshLocation& source) const;
  /// Approximate geodesic distance from the source to every vertex. Each call factors the Poisson
  /// operator pinned at the source's corner.
  Eigen::VectorXd distance(const MeshLocation& source) const;
  /// The same distance (to round-off) with the Poisson operator factored on the first call only,
  /// for many sources on one mesh: two more back-substitutions per call instead of a factorisation.
  Eigen::VectorXd distance_reusing(const MeshLocation& source) const;

  double mean_edge_length() const { return h_; }

 private:
  Eigen::Vector3d gradient(int t, const Eigen::VectorXd& f) const;
  Eigen::VectorXd divergence(const Eigen::VectorXd& u) const;
  Eigen::SparseMatrix<double> pinned_laplacian(int pin) const;
  void factor_heat() const;
  void factor_poisson() const;
  int pin_of(const MeshLocation& source) const;
  /// phi shifted to vanish at the source and by the heat step's offset (distance()).
  Eigen::VectorXd shifted_to_source(Eigen::VectorXd phi, const MeshLocation& source) const;

  const std::vector<Eigen::Vector3d>& x_;
  const std::vector<Eigen::Vector3i>& tri_;
  std::string name_;
  double h_ = 0.0;
  Eigen::SparseMatrix<double> laplacian_;  // cotangent, positive semi-definite, every diagonal
  Eigen::VectorXd mass_;                   // lumped (barycentric) mass per vertex
  mutable std::once_flag heat_factored_;
  mutable std::unique_ptr<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>> heat_solver_;
  mutable std::once_flag poisson_factored_;
  mutable std::unique_ptr<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>> poisson_solver_;
  mutable Eigen::VectorXd poisson_w0_;  // A^-1 e_0 (distance_reusing)
};

/// Heat-method distance from `source` that is exact (up to the method's own error) at every vertex
/// whose geodesic distance is at most `reach`, computed on the part of the mesh near the source
/// only: the triangles with a corner within Euclidean distance 2 `reach` of the source point,
/// connected to the source's triangle through them. A shortest path of length <= reach never leaves
/// the Euclidean ball of radius reach around its start, so every such path lies in that part, with
/// a margin of `reach` between it and the part's cut edges (where the heat method's boundary
/// condition differs from the whole mesh's). Every other vertex is at geodesic distance > reach and
/// gets `far` (> reach). Where the part would hold more than 70% of the triangles, the whole mesh
/// is used. The cost follows the disk, not the mesh: a 60 mm disk on the 70,000-face bust factored
/// a heat operator of the whole tessellation (57 s of a paste's loading).
Eigen::VectorXd local_geodesic_distance(const std::vector<Eigen::Vector3d>& positions,
                                        const std::vector<Eigen::Vector3i>& triangles,
                                        const MeshLocation& source, double reach, double far,
                                        const std::string& name);

/// local_geodesic_distance for many sources near each other (a disk dragged in small steps): the
/// part of the mesh within 2 kRoom `reach` of the first source, and its heat method with both
/// factorisations (HeatGeodesics::distance_reusing), are kept and reused while a later source's
/// ball of 2 `reach` lies inside that part's ball and its reach is at least 1 / kMaxRoom of the
/// kept one; otherwise they are built again around the new source. The distance differs from
/// local_geodesic_distance's within the heat method's own error (the part is larger, and its
/// boundary condition further away). A part that would be most of the mesh is not kept. Not
/// thread-safe.
class LocalHeatCache {
 public:
  static constexpr double kRoom = 1.25;
  static constexpr double kMaxRoom = 2.0;

  LocalHeatCache();
  ~LocalHeatCache();
  LocalHeatCache(const LocalHeatCache&) = delete;
  LocalHeatCache& operator=(const LocalHeatCache&) = delete;

  /// As local_geodesic_distance. The kept part is checked against the mesh at every call (its
  /// vertices' positions and its triangles), so a changed mesh rebuilds it.
  Eigen::VectorXd distance(const std::vector<Eigen::Vector3d>& positions,
                           const std::vector<Eigen::Vector3i>& triangles,
                           const MeshLocation& source, double reach, double far,
                           const std::string& name);
  /// How many parts were built (and their heat operators factored) so far.
  long builds() const { return builds_; }

 private:
  struct Held;
  std::unique_ptr<Held> held_;
  long builds_ = 0;
};

}  // namespace elastic::regions_detail
