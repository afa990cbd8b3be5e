#pragma once
// The case the warm-start and multilevel-start tests share: a plane disk (radius 0.6) onto disks of
// the unit sphere, and the name of a boundary mode for parameterised tests.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "elastic/mapping/map_regions.h"
#include "elastic/regions/region_spec.h"
#include "elastic/shapes/procedural_shapes.h"

namespace elastic::test {

struct DiskOntoSphere {
  LimitSurface plane_surface{make_plane({.resolution = 12})};
  LimitSurface sphere_surface{make_sphere({.resolution = 24})};
  SurfaceProjector source{plane_surface}, target{sphere_surface};
  Region from = make_region(source, parse_region_spec("disk:0,0,0,0.6"));

  /// A disk of the sphere around a direction `tilt` radians from +z towards +x.
  Region sphere_disk(double tilt, double radius) const {
    return make_region(
        target, parse_region_spec("disk:" + std::to_string(std::sin(tilt)) + ",0," +
                                  std::to_string(std::cos(tilt)) + "," + std::to_string(radius)));
  }
  static MapOptions options(BoundaryMode boundary, long particles = 600) {
    MapOptions o;
    o.sampling.layout.particles = particles;
    o.relaxation.boundary = boundary;
    return o;
  }
};

inline std::string boundary_name(const ::testing::TestParamInfo<BoundaryMode>& param) {
  return param.param == BoundaryMode::Fixed ? "Fixed" : "Slide";
}

}  // namespace elastic::test
