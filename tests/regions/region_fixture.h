#pragma once
// Shared by the region tests: a control mesh with its limit surface and projector, and the plane.

#include <memory>

#include "elastic/mesh/polygon_mesh.h"
#include "elastic/projection/closest_point.h"
#include "elastic/shapes/procedural_shapes.h"
#include "elastic/surface/limit_surface.h"

namespace elastic {

/// A control mesh, its limit surface and a projector, kept together (the surface must outlive
/// users).
struct Fixture {
  std::unique_ptr<LimitSurface> surface;
  std::unique_ptr<SurfaceProjector> projector;
  explicit Fixture(const PolygonMesh& mesh, int tess_resolution = 8) {
    surface = std::make_unique<LimitSurface>(mesh);
    ProjectionOptions options;
    options.tessellation.resolution = tess_resolution;
    projector = std::make_unique<SurfaceProjector>(*surface, options);
  }
  /// The limit surface point nearest x (test inputs placed exactly on the surface).
  Eigen::Vector3d on_surface(const Eigen::Vector3d& x) const {
    return projector->closest(x).position;
  }
  double mean_edge() const {
    const LimitTessellation& t = projector->tessellation();
    double sum = 0.0;
    for (const auto& tri : t.triangles) {
      for (int k = 0; k < 3; ++k) {
        sum += (t.positions[static_cast<size_t>(tri[k])] -
                t.positions[static_cast<size_t>(tri[(k + 1) % 3])])
                   .norm();
      }
    }
    return sum / static_cast<double>(3 * t.triangles.size());
  }
};

inline PolygonMesh plane_mesh() {
  return make_plane({.faces = ShapeFaces::Quads, .resolution = 8});
}

}  // namespace elastic
