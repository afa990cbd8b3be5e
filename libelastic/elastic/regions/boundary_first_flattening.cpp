#include "elastic/regions/boundary_first_flattening.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cmath>
#include <numbers>

namespace elastic {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

/// Corner angles and cotangent weights of every triangle; false when a triangle has zero area.
struct Geometry {
  std::vector<double> angle_sum;  ///< #V sum of the corner angles at each vertex
  Triplets laplacian;             ///< L = -Delta, both triangles, with its diagonal
};

bool measure(const Region& region, Geometry& g) {
  const int nv = region.num_vertices();
  g.angle_sum.assign(static_cast<size_t>(nv), 0.0);
  g.laplacian.reserve(9 * region.triangles.size());
  for (const Eigen::Vector3i& t : region.triangles) {
    for (int k = 0; k < 3; ++k) {
      const int l = t[k], i = t[(k + 1) % 3], j = t[(k + 2) % 3];
      const Eigen::Vector3d a =
          region.positions[static_cast<size_t>(i)] - region.positions[static_cast<size_t>(l)];
      const Eigen::Vector3d b =
          region.positions[static_cast<size_t>(j)] - region.positions[static_cast<size_t>(l)];
      const double cross = a.cross(b).norm();
      if (!(cross > 0.0)) {
        return false;
      }
      const double dot = a.dot(b);
      g.angle_sum[static_cast<size_t>(l)] += std::atan2(cross, dot);
      // Edge (i, j) opposite corner l: weight cot(l) / 2 in L (Pinkall-Polthier).
      const double w = 0.5 * dot / cross;
      g.laplacian.emplace_back(i, j, -w);
      g.laplacian.emplace_back(j, i, -w);
      g.laplacian.emplace_back(i, i, w);
      g.laplacian.emplace_back(j, j, w);
    }
  }
  return true;
}

/// The boundary polygon with edge lengths `length` (edge k from boundary[k] to boundary[k + 1])
/// and turning angle `turn[k]` at boundary[k] (the first edge points along +x), closed by the
/// least change sum (l'_k - l_k)^2 / l_k that makes the edge vectors sum to zero: l' = l - N T^T
/// lambda with N = diag(l), T the 2 x m matrix of unit edge directions and (T N T^T) lambda = T l.
std::vector<Eigen::Vector2d> closed_polygon(const std::vector<double>& length,
                                            const std::vector<double>& turn) {
  const size_t m = length.size();
  std::vector<Eigen::Vector2d> direction(m);
  double phi = 0.0;
  for (size_t k = 0; k < m; ++k) {
    if (k > 0) {
      phi += turn[k];
    }
    direction[k] = Eigen::Vector2d(std::cos(phi), std::sin(phi));
  }
  Eigen::Matrix2d tnt = Eigen::Matrix2d::Zero();
  Eigen::Vector2d gap = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < m; ++k) {
    tnt += length[k] * direction[k] * direction[k].transpose();
    gap += length[k] * direction[k];
  }
  const Eigen::Vector2d lambda = tnt.ldlt().solve(gap);
  std::vector<Eigen::Vector2d> corner(m);
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < m; ++k) {
    corner[k] = at;
    const double l = length[k] * (1.0 - direction[k].dot(lambda));
    at += l * direction[k];
  }
  return corner;
}

}  // namespace

std::optional<std::vector<Eigen::Vector2d>> boundary_first_flattening(const Region& region,
                                                                      int first, int second) {
  const int nv = region.num_vertices();
  const auto nb = static_cast<int>(region.boundary.size());
  Geometry g;
  if (nb < 3 || !measure(region, g)) {
    return std::nullopt;
  }
  std::vector<int> interior(static_cast<size_t>(nv), 0);  // interior index, -1 on the boundary
  for (const int v : region.boundary) {
    interior[static_cast<size_t>(v)] = -1;
  }
  int ni = 0;
  for (int& index : interior) {
    if (index == 0) {
      index = ni++;
    } else {
      index = -1;
    }
  }
  if (ni == 0) {
    return std::nullopt;
  }
  // L_II and L_IB (boundary columns indexed by vertex) from the triplets.
  Triplets ii, ib;
  ii.reserve(g.laplacian.size());
  for (const auto& e : g.laplacian) {
    const int r = interior[static_cast<size_t>(e.row())];
    if (r < 0) {
      continue;
    }
    if (const int c = interior[static_cast<size_t>(e.col())]; c >= 0) {
      ii.emplace_back(r, c, e.value());
    } else {
      ib.emplace_back(r, e.col(), e.value());
    }
  }
  Eigen::SparseMatrix<double> lii(ni, ni), lib(ni, nv);
  lii.setFromTriplets(ii.begin(), ii.end());
  lib.setFromTriplets(ib.begin(), ib.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(lii);
  if (solver.info() != Eigen::Success) {
    return std::nullopt;
  }
  // 1. u on the interior (u = 0 on the boundary).
  Eigen::VectorXd omega(ni);
  for (int v = 0; v < nv; ++v) {
    if (const int r = interior[static_cast<size_t>(v)]; r >= 0) {
      omega[r] = 2.0 * std::numbers::pi - g.angle_sum[static_cast<size_t>(v)];
    }
  }
  const Eigen::VectorXd u = solver.solve(-omega);
  if (solver.info() != Eigen::Success || !u.allFinite()) {
    return std::nullopt;
  }
  // 2. k~_b = k_b + (L u)_b = k_b + sum over interior i of L_ib u_i (L symmetric).
  const Eigen::VectorXd lu = lib.transpose() * u;  // indexed by vertex
  std::vector<double> length(static_cast<size_t>(nb)), turn(static_cast<size_t>(nb));
  for (int k = 0; k < nb; ++k) {
    const int v = region.boundary[static_cast<size_t>(k)];
    const int w = region.boundary[static_cast<size_t>((k + 1) % nb)];
    length[static_cast<size_t>(k)] =
        (region.positions[static_cast<size_t>(w)] - region.positions[static_cast<size_t>(v)])
            .norm();
    turn[static_cast<size_t>(k)] = std::numbers::pi - g.angle_sum[static_cast<size_t>(v)] + lu[v];
  }
  const std::vector<Eigen::Vector2d> corner = closed_polygon(length, turn);
  // 3. The harmonic extension of x and y: L_II X_I = -L_IB X_B.
  std::vector<Eigen::Vector2d> uv(static_cast<size_t>(nv), Eigen::Vector2d::Zero());
  Eigen::MatrixXd xb = Eigen::MatrixXd::Zero(nv, 2);
  for (int k = 0; k < nb; ++k) {
    const int v = region.boundary[static_cast<size_t>(k)];
    uv[static_cast<size_t>(v)] = corner[static_cast<size_t>(k)];
    xb.row(v) = corner[static_cast<size_t>(k)].transpose();
  }
  const Eigen::MatrixXd rhs = -(lib * xb);
  const Eigen::MatrixXd xi = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !xi.allFinite()) {
    return std::nullopt;
  }
  for (int v = 0; v < nv; ++v) {
    if (const int r = interior[static_cast<size_t>(v)]; r >= 0) {
      uv[static_cast<size_t>(v)] = xi.row(r).transpose();
    }
  }
  // Rigid motion: `first` to the origin, `second` onto the positive x axis.
  const Eigen::Vector2d origin = uv[static_cast<size_t>(first)];
  const Eigen::Vector2d axis = uv[static_cast<size_t>(second)] - origin;
  const double angle = axis.squaredNorm() > 0.0 ? std::atan2(axis.y(), axis.x()) : 0.0;
  const Eigen::Rotation2Dd rotate(-angle);
  for (Eigen::Vector2d& p : uv) {
    p = rotate * (p - origin);
  }
  return uv;
}

}  // namespace elastic
