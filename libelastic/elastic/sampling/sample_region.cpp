#include "elastic/sampling/sample_region.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "elastic/core/error.h"

namespace elastic {

SamplingStatistics measure_sampling(const ParticleGrid& grid, const LimitSurface& surface) {
  SamplingStatistics st;
  const GridMesh& mesh = grid.mesh;
  const int np = grid.num_particles();
  st.particles = np;
  for (int p = 0; p < np; ++p) {
    (grid.is_boundary[p] ? st.boundary_particles : st.interior_particles)++;
  }
  st.normal_springs = static_cast<int>(mesh.n_edges());
  for (const auto f : mesh.faces()) {
    const int n = static_cast<int>(mesh.valence(f));
    st.angular_springs += n;
    if (n == 4) {
      ++st.quads;
    }
    if (n == 3) {
      ++st.triangles;
    }
  }
  const Eigen::Matrix3Xd x = grid.source_positions();
  std::vector<Eigen::Vector3d> normal(np);
  std::vector<double> r(np);
  for (int p = 0; p < np; ++p) {
    const SurfaceCurvature c = surface.curvature(grid.source_points[p]);
    normal[p] = c.normal;
    r[p] = std::sqrt(0.5 * (c.k1 * c.k1 + c.k2 * c.k2));
  }
  std::vector<double> spacing(np, 0.0);
  for (const auto v : mesh.vertices()) {
    double sum = 0.0;
    int n = 0;
    for (const auto w : mesh.vv_range(v)) {
      sum += (x.col(w.idx()) - x.col(v.idx())).norm();
      ++n;
    }
    spacing[v.idx()] = n > 0 ? sum / n : 0.0;
  }
  if (np > 0) {
    std::vector<double> sorted = spacing;
    std::sort(sorted.begin(), sorted.end());
    st.spacing_min = sorted.front();
    st.spacing_max = sorted.back();
    st.spacing_median = sorted[sorted.size() / 2];
  }
  // Density ratio between the high- and low-curvature quarters of the interior particles.
  std::vector<int> interior;
  for (int p = 0; p < np; ++p) {
    if (!grid.is_boundary[p] && spacing[p] > 0.0) {
      interior.push_back(p);
    }
  }
  if (interior.size() >= 8) {
    std::stable_sort(interior.begin(), interior.end(), [&](int a, int b) { return r[a] < r[b]; });
    const size_t q = interior.size() / 4;
    double low = 0.0, high = 0.0;
    for (size_t k = 0; k < q; ++k) {
      low += 1.0 / (spacing[interior[k]] * spacing[interior[k]]);
      const int p = interior[interior.size() - 1 - k];
      high += 1.0 / (spacing[p] * spacing[p]);
    }
    st.density_ratio = high / low;
  }
  for (const auto f : mesh.faces()) {
    std::vector<int> v;
    for (const auto vh : mesh.fv_range(f)) {
      v.push_back(vh.idx());
    }
    const int n = static_cast<int>(v.size());
    bool inverted = false;
    for (int c = 0; c < n; ++c) {
      const Eigen::Vector3d e1 = x.col(v[(c + 1) % n]) - x.col(v[c]);
      const Eigen::Vector3d e2 = x.col(v[(c + n - 1) % n]) - x.col(v[c]);
      const double scale = e1.norm() * e2.norm();
      const double sine = scale > 0.0 ? e1.cross(e2).dot(normal[v[c]]) / scale : 0.0;
      st.min_corner_sine = std::min(st.min_corner_sine, sine);
      if (sine <= 0.0) {
        inverted = true;
      }
    }
    if (inverted) {
      ++st.inverted_faces;
    }
  }
  return st;
}

SampleRegionResult sample_region(const Region& region, const SurfaceProjector& projector,
                                 const SampleRegionOptions& options) {
  if (region.surface != &projector.surface()) {
    throw InvalidInputError(options.layout.name,
                            "the region does not lie on the projector's surface");
  }
  SampleRegionResult result;
  result.layout = layout_particle_grid(region, options.layout);
  if (options.adaptive) {
    AdaptiveSamplingOptions sampling = options.sampling;
    sampling.name = options.layout.name;
    result.sampling = adaptive_sampling(std::move(result.layout.grid), region, projector, sampling);
    result.grid = std::move(result.sampling.grid);
    result.sampling.grid = ParticleGrid{};
    result.layout.grid = ParticleGrid{};
  } else {
    result.grid = std::move(result.layout.grid);
    result.layout.grid = ParticleGrid{};
  }
  result.statistics = measure_sampling(result.grid, projector.surface());
  return result;
}

}  // namespace elastic
