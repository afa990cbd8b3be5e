#include "elastic/mapping/mapping.h"

#include "elastic/core/error.h"
#include "elastic/core/triangle_locator_2d.h"

namespace elastic {

struct Mapping::Impl {
  const SurfaceProjector* source = nullptr;
  const SurfaceProjector* target = nullptr;
  const RegionDiskMap* source_disk = nullptr;
  const RegionDiskMap* target_disk = nullptr;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<SurfacePoint> source_points;
  std::vector<SurfacePoint> target_points;
  Eigen::Matrix3Xd source_positions;
  Eigen::Matrix3Xd target_positions;
  TriangleLocator2D source_locator;  // grid triangles in source-disk coordinates
  TriangleLocator2D target_locator;  // grid triangles in target-disk coordinates

  // Barycentric combination of particle positions, put on `surface` by the magnet warm-started from
  // the triangle's particle with the largest weight.
  static Location land(const SurfaceProjector& projector, const Eigen::Matrix3Xd& positions,
                       const std::vector<SurfacePoint>& points, const Eigen::Vector3i& tri,
                       const Eigen::Vector3d& w, int triangle) {
    Location out;
    const Eigen::Vector3d x =
        w[0] * positions.col(tri[0]) + w[1] * positions.col(tri[1]) + w[2] * positions.col(tri[2]);
    int heaviest = 0;
    w.maxCoeff(&heaviest);
    const ClosestPoint cp = projector.closest(x, points[tri[heaviest]]);
    out.inside = true;
    out.point = cp.point;
    out.position = cp.position;
    out.triangle = triangle;
    out.barycentric = w;
    return out;
  }
};

namespace {
// Splits every grid face into a fan of triangles from its first corner (faces are convex in the
// grid's layout: quads of the regular grid and triangles of the boundary band).
std::vector<Eigen::Vector3i> grid_triangles(const GridMesh& mesh) {
  std::vector<Eigen::Vector3i> triangles;
  triangles.reserve(mesh.n_faces() * 2);
  for (const auto fh : mesh.faces()) {
    std::vector<int> corners;
    for (const auto vh : mesh.fv_range(fh)) corners.push_back(vh.idx());
    for (size_t k = 1; k + 1 < corners.size(); ++k) {
      triangles.emplace_back(corners[0], corners[k], corners[k + 1]);
    }
  }
  return triangles;
}
}  // namespace

Mapping::Mapping(const ParticleGrid& grid, const SurfaceProjector& source,
                 const RegionDiskMap& source_disk, const SurfaceProjector& target,
                 const RegionDiskMap& target_disk, const std::vector<SurfacePoint>& target_points) {
  const int n = grid.num_particles();
  if (static_cast<int>(target_points.size()) != n) {
    throw InvalidInputError("mapping", "target points do not match the particle count");
  }
  auto impl = std::make_shared<Impl>();
  impl->source = &source;
  impl->target = &target;
  impl->source_disk = &source_disk;
  impl->target_disk = &target_disk;
  impl->triangles = grid_triangles(grid.mesh);
  impl->source_points = grid.source_points;
  impl->target_points = target_points;
  impl->source_positions.resize(3, n);
  impl->target_positions.resize(3, n);
  std::vector<Eigen::Vector2d> source_uv(n), target_uv(n);
  for (int i = 0; i < n; ++i) {
    impl->source_positions.col(i) = source.surface().position(grid.source_points[i]);
    impl->target_positions.col(i) = target.surface().position(target_points[i]);
    if (!source_disk.to_disk(grid.source_points[i], source_uv[i])) {
      throw NumericalError("mapping",
                           "particle " + std::to_string(i) + " is outside the source region");
    }
    if (!target_disk.to_disk(target_points[i], target_uv[i])) {
      throw NumericalError("mapping",
                           "particle " + std::to_string(i) + " is outside the target region");
    }
  }
  impl->source_locator = TriangleLocator2D(std::move(source_uv), impl->triangles);
  impl->target_locator = TriangleLocator2D(std::move(target_uv), impl->triangles);
  impl_ = std::move(impl);
}

Mapping::Location Mapping::forward(const SurfacePoint& source_point) const {
  Eigen::Vector2d disk;
  if (!impl_ || !impl_->source_disk->to_disk(source_point, disk)) return {};
  const auto hit = impl_->source_locator.locate(disk, 1e-9);
  if (!hit.found()) return {};
  return Impl::land(*impl_->target, impl_->target_positions, impl_->target_points,
                    impl_->triangles[hit.triangle], hit.barycentric, hit.triangle);
}

Mapping::Location Mapping::inverse(const SurfacePoint& target_point) const {
  Eigen::Vector2d disk;
  if (!impl_ || !impl_->target_disk->to_disk(target_point, disk)) return {};
  const auto hit = impl_->target_locator.locate(disk, 1e-9);
  if (!hit.found()) return {};
  return Impl::land(*impl_->source, impl_->source_positions, impl_->source_points,
                    impl_->triangles[hit.triangle], hit.barycentric, hit.triangle);
}

const std::vector<Eigen::Vector3i>& Mapping::triangles() const {
  static const std::vector<Eigen::Vector3i> none;
  return impl_ ? impl_->triangles : none;
}

}  // namespace elastic
