#include "elastic/sampling/curvature_field.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace elastic {
namespace {

constexpr long kAxisCells = 1L << 20;  // cells per axis the 64-bit key can hold
constexpr double kSupport = 3.0;       // the kernel reaches kSupport * s
constexpr double kConstant = 1e-9;     // relative spread of r below which the field is constant

}  // namespace

double CurvatureField::pointwise(const LimitSurface& surface, const SurfacePoint& q) {
  const SurfaceCurvature c = surface.curvature(q);
  return std::sqrt(0.5 * (c.k1 * c.k1 + c.k2 * c.k2));
}

CurvatureField::CurvatureField(const Region& region, double radius) : surface_(*region.surface) {
  const int nv = region.num_vertices();
  if (!(radius > 0.0) || nv == 0) {
    return;
  }
  // Vertex areas (a third of each adjacent triangle) and the mean edge length.
  std::vector<double> area(nv, 0.0);
  double edges = 0.0;
  for (const Eigen::Vector3i& t : region.triangles) {
    const Eigen::Vector3d &a = region.positions[t[0]], &b = region.positions[t[1]],
                          &c = region.positions[t[2]];
    const double third = (b - a).cross(c - a).norm() / 6.0;
    for (int k = 0; k < 3; ++k) {
      area[t[k]] += third;
    }
    edges += (b - a).norm() + (c - b).norm() + (a - c).norm();
  }
  const double mean_edge =
      region.triangles.empty() ? 0.0 : edges / (3.0 * static_cast<double>(region.num_triangles()));
  radius_ = std::max(radius, mean_edge);

  Eigen::Vector3d lo = region.positions[0], hi = lo;
  for (const Eigen::Vector3d& p : region.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  cell_ = std::max(kSupport * radius_, (hi - lo).maxCoeff() / static_cast<double>(kAxisCells - 2));
  origin_ = lo;

  std::vector<double> r(nv);
  tbb::parallel_for(0, nv, [&](int v) { r[v] = pointwise(surface_, region.points[v]); });
  // A region of constant r (a plane: r = 0 to round-off) averages to that constant everywhere:
  // no index is needed and no query is made.
  const auto [r_min, r_max] = std::minmax_element(r.begin(), r.end());
  if (*r_max - *r_min <= kConstant * std::max(*r_max, 1.0 / (hi - lo).norm())) {
    constant_ = 0.5 * (*r_min + *r_max);
    return;
  }
  std::vector<std::uint64_t> key(nv);
  for (int v = 0; v < nv; ++v) {
    const Eigen::Vector3d c = (region.positions[v] - origin_) / cell_;
    key[v] = cell_key(static_cast<long>(std::floor(c.x())), static_cast<long>(std::floor(c.y())),
                      static_cast<long>(std::floor(c.z())));
  }
  std::vector<int> order(nv);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
  px_.resize(nv);
  py_.resize(nv);
  pz_.resize(nv);
  weighted_r_.resize(nv);
  area_.resize(nv);
  for (int k = 0; k < nv; ++k) {
    const int v = order[k];
    px_[k] = region.positions[v].x();
    py_[k] = region.positions[v].y();
    pz_[k] = region.positions[v].z();
    weighted_r_[k] = area[v] * r[v];
    area_[k] = area[v];
    if (k == 0 || key[v] != cell_keys_.back()) {
      cell_keys_.push_back(key[v]);
      cell_start_.push_back(k);
    }
  }
  cell_start_.push_back(nv);
}

std::uint64_t CurvatureField::cell_key(long ix, long iy, long iz) const {
  // Cells are offset by one so that the neighbours of the first cell stay non-negative.
  const auto axis = [](long i) {
    return static_cast<std::uint64_t>(std::clamp(i + 1, 0L, kAxisCells - 1));
  };
  return (axis(ix) << 42U) | (axis(iy) << 21U) | axis(iz);
}

double CurvatureField::at(const Eigen::Vector3d& x, const SurfacePoint& q) const {
  if (constant_) {
    return *constant_;
  }
  if (cell_keys_.empty()) {
    return pointwise(surface_, q);
  }
  const Eigen::Vector3d c = (x - origin_) / cell_;
  const long ix = static_cast<long>(std::floor(c.x())), iy = static_cast<long>(std::floor(c.y())),
             iz = static_cast<long>(std::floor(c.z()));
  const double reach2 = kSupport * kSupport * radius_ * radius_;
  double num = 0.0, den = 0.0;
  for (long dx = -1; dx <= 1; ++dx) {
    for (long dy = -1; dy <= 1; ++dy) {
      for (long dz = -1; dz <= 1; ++dz) {
        const std::uint64_t k = cell_key(ix + dx, iy + dy, iz + dz);
        const auto cell = std::lower_bound(cell_keys_.begin(), cell_keys_.end(), k);
        if (cell == cell_keys_.end() || *cell != k) {
          continue;
        }
        const auto index = static_cast<size_t>(cell - cell_keys_.begin());
        const auto first = static_cast<size_t>(cell_start_[index]);
        const auto last = static_cast<size_t>(cell_start_[index + 1]);
        for (size_t v = first; v < last; ++v) {
          const double ex = px_[v] - x.x(), ey = py_[v] - x.y(), ez = pz_[v] - x.z();
          const double d2 = ex * ex + ey * ey + ez * ez;
          if (d2 < reach2) {
            const double t = 1.0 - d2 / reach2;
            const double g = t * t * t;
            num += g * weighted_r_[v];
            den += g * area_[v];
          }
        }
      }
    }
  }
  return den > 0.0 ? num / den : pointwise(surface_, q);
}

}  // namespace elastic
