#pragma once
// For the benchmarks: a mesh file read, repaired as the tools do, and its limit surface and
// closest-point projector, each built once.

#include <memory>
#include <string>

#include "elastic/mesh/mesh_io.h"
#include "elastic/mesh/mesh_validation.h"
#include "elastic/projection/closest_point.h"
#include "elastic/surface/limit_surface.h"

namespace elastic::bench {

struct LoadedSurface {
  PolygonMesh mesh;
  std::unique_ptr<LimitSurface> surface;
  std::unique_ptr<SurfaceProjector> projector;
  explicit LoadedSurface(const std::string& path) : mesh(read_mesh(path).mesh) {
    sanitize_mesh(mesh, path);
    surface = std::make_unique<LimitSurface>(mesh);
    projector = std::make_unique<SurfaceProjector>(*surface);
  }
};

}  // namespace elastic::bench
