#pragma once
/// \file
/// Point location in a planar triangle mesh: which triangle contains a 2D point, and its
/// barycentric coordinates there. A uniform bucket grid over the triangles' bounding boxes makes a
/// query O(1) on average for meshes of roughly uniform triangle size (the flattened regions and
/// particle grids it is used on).
///
/// Points outside every triangle (by more than the tolerance) are reported as not found, never
/// guessed; `nearest` gives the closest triangle instead when a caller wants to clamp.
///
/// The locator copies the vertex positions and triangles; it is immutable after construction and
/// its queries are thread-safe.

#include <Eigen/Core>
#include <vector>

namespace elastic {

class TriangleLocator2D {
 public:
  struct Hit {
    int triangle = -1;  ///< -1 when the point is in no triangle
    Eigen::Vector3d barycentric =
        Eigen::Vector3d::Zero();  ///< weights of the triangle's corners 0,1,2
    bool found() const { return triangle >= 0; }
  };

  TriangleLocator2D() = default;
  /// \param cells_per_triangle bucket-grid resolution: about this many cells per triangle overall.
  TriangleLocator2D(std::vector<Eigen::Vector2d> vertices, std::vector<Eigen::Vector3i> triangles,
                    double cells_per_triangle = 1.0);

  /// The triangle containing p (barycentrics all >= -tolerance), or not found.
  /// Degenerate (zero-area) triangles are never returned.
  Hit locate(const Eigen::Vector2d& p, double tolerance = 1e-12) const;
  /// The triangle whose closest point to p is nearest, with the barycentrics of that closest point
  /// (all in [0,1]); not found only for an empty locator.
  Hit nearest(const Eigen::Vector2d& p) const;

  int num_triangles() const { return static_cast<int>(triangles_.size()); }

 private:
  Eigen::Vector3d barycentric(int t, const Eigen::Vector2d& p) const;
  void cell_range(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int& x0, int& y0, int& x1,
                  int& y1) const;

  std::vector<Eigen::Vector2d> vertices_;
  std::vector<Eigen::Vector3i> triangles_;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  double cell_size_ = 1.0;
  int nx_ = 0;
  int ny_ = 0;
  std::vector<int>
      cell_start_;  // CSR: triangles overlapping cell c are cell_items_[cell_start_[c]..[c+1])
  std::vector<int> cell_items_;
};

}  // namespace elastic
