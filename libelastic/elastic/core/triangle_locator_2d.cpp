#include "elastic/core/triangle_locator_2d.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace elastic {

TriangleLocator2D::TriangleLocator2D(std::vector<Eigen::Vector2d> vertices,
                                     std::vector<Eigen::Vector3i> triangles,
                                     double cells_per_triangle)
    : vertices_(std::move(vertices)), triangles_(std::move(triangles)) {
  if (triangles_.empty()) {
    return;
  }
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const Eigen::Vector3i& t : triangles_) {
    for (int k = 0; k < 3; ++k) {
      lo = lo.cwiseMin(vertices_[t[k]]);
      hi = hi.cwiseMax(vertices_[t[k]]);
    }
  }
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(1e-300);
  // Square cells, about cells_per_triangle * #T of them over the bounding box.
  const double cells = std::max(1.0, cells_per_triangle * static_cast<double>(triangles_.size()));
  cell_size_ = std::sqrt(extent.x() * extent.y() / cells);
  if (!(cell_size_ > 0.0)) {
    cell_size_ = std::max(extent.x(), extent.y());
  }
  nx_ = std::clamp(static_cast<int>(std::ceil(extent.x() / cell_size_)), 1, 1 << 14);
  ny_ = std::clamp(static_cast<int>(std::ceil(extent.y() / cell_size_)), 1, 1 << 14);
  cell_size_ = std::max(extent.x() / nx_, extent.y() / ny_);
  origin_ = lo;

  // Two passes (count, fill) into CSR arrays.
  std::vector<int> counts(static_cast<size_t>(nx_) * ny_ + 1, 0);
  auto for_each_cell = [&](int t, auto&& f) {
    const Eigen::Vector3i& tri = triangles_[t];
    const Eigen::Vector2d a = vertices_[tri[0]], b = vertices_[tri[1]], c = vertices_[tri[2]];
    int x0, y0, x1, y1;
    cell_range(a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c), x0, y0, x1, y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        f(y * nx_ + x);
      }
    }
  };
  for (int t = 0; t < num_triangles(); ++t) {
    for_each_cell(t, [&](int c) { ++counts[c + 1]; });
  }
  for (size_t c = 1; c < counts.size(); ++c) {
    counts[c] += counts[c - 1];
  }
  cell_start_ = counts;
  cell_items_.resize(counts.back());
  for (int t = 0; t < num_triangles(); ++t) {
    for_each_cell(t, [&](int c) { cell_items_[counts[c]++] = t; });
  }
}

void TriangleLocator2D::cell_range(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int& x0,
                                   int& y0, int& x1, int& y1) const {
  auto cell = [&](double v, double o, int n) {
    return std::clamp(static_cast<int>(std::floor((v - o) / cell_size_)), 0, n - 1);
  };
  x0 = cell(lo.x(), origin_.x(), nx_);
  x1 = cell(hi.x(), origin_.x(), nx_);
  y0 = cell(lo.y(), origin_.y(), ny_);
  y1 = cell(hi.y(), origin_.y(), ny_);
}

Eigen::Vector3d TriangleLocator2D::barycentric(int t, const Eigen::Vector2d& p) const {
  const Eigen::Vector3i& tri = triangles_[t];
  const Eigen::Vector2d a = vertices_[tri[0]], b = vertices_[tri[1]], c = vertices_[tri[2]];
  const Eigen::Vector2d e1 = b - a, e2 = c - a, d = p - a;
  const double det = e1.x() * e2.y() - e1.y() * e2.x();
  if (det == 0.0 || !std::isfinite(det)) {
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  const double b1 = (d.x() * e2.y() - d.y() * e2.x()) / det;
  const double b2 = (e1.x() * d.y() - e1.y() * d.x()) / det;
  return {1.0 - b1 - b2, b1, b2};
}

TriangleLocator2D::Hit TriangleLocator2D::locate(const Eigen::Vector2d& p, double tolerance) const {
  Hit best;
  if (triangles_.empty() || !p.allFinite()) {
    return best;
  }
  const Eigen::Vector2d slack = Eigen::Vector2d::Constant(tolerance * cell_size_);
  int x0, y0, x1, y1;
  cell_range(p - slack, p + slack, x0, y0, x1, y1);
  // Among the candidates, prefer the triangle in which p is deepest (largest smallest barycentric),
  // so that points on shared edges get a deterministic answer.
  double best_min = -std::numeric_limits<double>::infinity();
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const int c = y * nx_ + x;
      for (int k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
        const int t = cell_items_[k];
        const Eigen::Vector3d w = barycentric(t, p);
        if (!w.allFinite()) {
          continue;
        }
        const double m = w.minCoeff();
        if (m < -tolerance) {
          continue;
        }
        if (best.triangle < 0 || m > best_min || (m == best_min && t < best.triangle)) {
          best_min = m;
          best.triangle = t;
          best.barycentric = w;
        }
      }
    }
  }
  return best;
}

namespace {
// Closest point of segment [a,b] to p, as the parameter along it.
double segment_parameter(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                         const Eigen::Vector2d& p) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  return len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
}
}  // namespace

TriangleLocator2D::Hit TriangleLocator2D::nearest(const Eigen::Vector2d& p) const {
  Hit inside = locate(p);
  if (inside.found() || triangles_.empty()) {
    return inside;
  }
  // Search rings of cells outward until a candidate is found and the ring is farther than the best.
  Hit best;
  double best_d2 = std::numeric_limits<double>::infinity();
  const int cx =
      std::clamp(static_cast<int>(std::floor((p.x() - origin_.x()) / cell_size_)), 0, nx_ - 1);
  const int cy =
      std::clamp(static_cast<int>(std::floor((p.y() - origin_.y()) / cell_size_)), 0, ny_ - 1);
  const Eigen::Vector2d clamped(std::clamp(p.x(), origin_.x(), origin_.x() + nx_ * cell_size_),
                                std::clamp(p.y(), origin_.y(), origin_.y() + ny_ * cell_size_));
  const double outside = (p - clamped).norm();
  for (int ring = 0; ring < std::max(nx_, ny_); ++ring) {
    // Every cell of this ring is at least this far from p (a conservative lower bound).
    const double ring_distance = std::max(outside, (ring - 1) * cell_size_);
    if (best.found() && ring_distance * ring_distance > best_d2) {
      break;
    }
    for (int y = cy - ring; y <= cy + ring; ++y) {
      for (int x = cx - ring; x <= cx + ring; ++x) {
        if (std::max(std::abs(x - cx), std::abs(y - cy)) != ring) {
          continue;
        }
        if (x < 0 || y < 0 || x >= nx_ || y >= ny_) {
          continue;
        }
        const int c = y * nx_ + x;
        for (int k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
          const int t = cell_items_[k];
          const Eigen::Vector3i& tri = triangles_[t];
          for (int e = 0; e < 3; ++e) {
            const Eigen::Vector2d& a = vertices_[tri[e]];
            const Eigen::Vector2d& b = vertices_[tri[(e + 1) % 3]];
            const double s = segment_parameter(a, b, p);
            const double d2 = (a + s * (b - a) - p).squaredNorm();
            if (d2 < best_d2 || (d2 == best_d2 && t < best.triangle)) {
              best_d2 = d2;
              best.triangle = t;
              best.barycentric.setZero();
              best.barycentric[e] = 1.0 - s;
              best.barycentric[(e + 1) % 3] = s;
            }
          }
        }
      }
    }
  }
  return best;
}

}  // namespace elastic
