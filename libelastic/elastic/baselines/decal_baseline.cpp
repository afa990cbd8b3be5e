#include "elastic/baselines/decal_baseline.h"

#include <chrono>

namespace elastic {

DecalBaselineResult exponential_map_decal(const LimitSurface& target, const DecalGeometry& geometry,
                                          const DecalBaselineOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  // A step of 0 lets exponential_map take |v| / 32; the fraction asked for is passed as the step
  // of the farthest particle, and no step is longer than a quarter of any particle's distance.
  const double farthest = geometry.placement.scale * geometry.source_radius;
  std::vector<double> reached;
  const InitialMap placed = exponential_map_placement(
      target, geometry, {.step = options.step_fraction * farthest}, &reached);
  DecalBaselineResult result;
  result.positions = placed.positions;
  result.points = placed.points;
  for (const double r : reached) {
    result.stopped += r < 1.0 ? 1 : 0;
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace elastic
