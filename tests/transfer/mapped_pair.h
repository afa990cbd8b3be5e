#pragma once
// A mapped pair of regions for the transfer tests, with everything the map references kept alive
// together (projectors reference surfaces; regions and the mapping reference projectors) and the
// map's differential.

#include <memory>

#include "elastic/mapping/map_regions.h"
#include "elastic/regions/region_spec.h"
#include "elastic/transfer/tangent_frames.h"

namespace elastic::test {

struct Mapped {
  std::unique_ptr<LimitSurface> source_surface, target_surface;
  std::unique_ptr<SurfaceProjector> source, target;
  Region from, to;
  MapResult result;
  std::unique_ptr<MapDifferential> differential;
};

/// Maps `source_spec` on the source mesh's limit surface onto `target_spec` on the target's.
inline std::unique_ptr<Mapped> map_pair(const PolygonMesh& source_mesh,
                                        const PolygonMesh& target_mesh,
                                        const RegionSpec& source_spec,
                                        const RegionSpec& target_spec, int particles = 400) {
  auto m = std::make_unique<Mapped>();
  m->source_surface = std::make_unique<LimitSurface>(source_mesh);
  m->target_surface = std::make_unique<LimitSurface>(target_mesh);
  m->source = std::make_unique<SurfaceProjector>(*m->source_surface);
  m->target = std::make_unique<SurfaceProjector>(*m->target_surface);
  m->from = make_region(*m->source, source_spec);
  m->to = make_region(*m->target, target_spec);
  MapOptions options;
  options.sampling.layout.particles = particles;
  m->result = map_regions(*m->source, m->from, *m->target, m->to, options);
  m->differential =
      std::make_unique<MapDifferential>(*m->source_surface, *m->target_surface, m->result);
  return m;
}

}  // namespace elastic::test
