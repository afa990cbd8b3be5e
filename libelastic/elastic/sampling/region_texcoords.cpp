#include "elastic/sampling/region_texcoords.h"

namespace elastic {

RegionTexcoords::RegionTexcoords(const Region& region) : region_(region) {
  if (region.texcoords.empty()) {
    return;
  }
  for (int t = 0; t < region.num_triangles(); ++t) {
    const int f = region.triangle_face[t];
    if (f >= static_cast<int>(by_face_.size())) {
      by_face_.resize(f + 1);
    }
    by_face_[f].push_back(t);
  }
}

bool RegionTexcoords::at(const SurfacePoint& p, Eigen::Vector2d& uv) const {
  if (p.face < 0 || p.face >= static_cast<int>(by_face_.size())) {
    return false;
  }
  int best = -1;
  Eigen::Vector3d best_w = Eigen::Vector3d::Zero();
  for (const int t : by_face_[p.face]) {
    const auto& c = region_.triangle_uv[t];
    const Eigen::Vector2d e1 = c[1] - c[0], e2 = c[2] - c[0], d = p.uv() - c[0];
    const double det = e1.x() * e2.y() - e1.y() * e2.x();
    if (det == 0.0) {
      continue;
    }
    // Barycentric coordinates of d in the triangle's (u, v) by Cramer's rule.
    const double b1 = (d.x() * e2.y() - d.y() * e2.x()) / det;
    const double b2 = (e1.x() * d.y() - e1.y() * d.x()) / det;
    const Eigen::Vector3d w(1.0 - b1 - b2, b1, b2);
    if (best < 0 || w.minCoeff() > best_w.minCoeff()) {
      best = t;
      best_w = w;
    }
  }
  if (best < 0 || best_w.minCoeff() < -1e-3) {
    return false;
  }
  const Eigen::Vector3i& tri = region_.triangles[best];
  uv = best_w[0] * region_.texcoords[tri[0]] + best_w[1] * region_.texcoords[tri[1]] +
       best_w[2] * region_.texcoords[tri[2]];
  return true;
}

}  // namespace elastic
