// SpringSystem::hessian (spring_energy.h): the second derivatives of the energies of
// spring_energy.cpp, term by term, reduced to the callers' coordinates.

#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "elastic/core/error.h"
#include "elastic/particles/spring_energy.h"

namespace elastic {

namespace {

// Terms per parallel chunk. Each chunk writes its own triplets, joined in chunk order, so the
// matrix does not depend on the number of threads.
constexpr std::size_t kHessianGrain = 2048;

using Triplets = std::vector<Eigen::Triplet<double>>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// The Hessian of stiffness * (|d| - rest)^2 with respect to d:
//   2 stiffness (n n^T + (1 - rest / |d|) (I - n n^T)),  n = d / |d|.
// The second part is negative for a compressed spring (|d| < rest); `project` drops it then.
bool spring_block(const Eigen::Vector3d& d, double rest, double stiffness, bool project,
                  Eigen::Matrix3d& block) {
  const double length = d.norm();
  if (!(length > 0.0)) {
    return false;
  }
  const Eigen::Vector3d n = d / length;
  double across = 1.0 - rest / length;
  if (project) {
    across = std::max(across, 0.0);
  }
  const Eigen::Matrix3d along = n * n.transpose();
  block = 2.0 * stiffness * (along + across * (Eigen::Matrix3d::Identity() - along));
  return true;
}

// Adds sum_{a, b} B_pa^T H_ab B_pb for the term's particles p (H: 3M x 3M in their order).
template <int M>
void scatter(const SpringSystem::HessianBasis& basis, const std::array<int, M>& particles,
             const Eigen::Matrix<double, 3 * M, 3 * M>& h, Triplets& out) {
  for (int a = 0; a < M; ++a) {
    const auto pa = static_cast<std::size_t>(particles[static_cast<std::size_t>(a)]);
    const int ca = basis.count[pa];
    for (int b = 0; b < M && ca > 0; ++b) {
      const auto pb = static_cast<std::size_t>(particles[static_cast<std::size_t>(b)]);
      const int cb = basis.count[pb];
      if (cb == 0) {
        continue;
      }
      const Eigen::Matrix3d block = h.template block<3, 3>(3 * a, 3 * b);
      for (int r = 0; r < ca; ++r) {
        const Eigen::Vector3d row =
            block.transpose() * basis.vectors.col(basis.first[pa] + r);  // (B_a^T H_ab) row r
        for (int c = 0; c < cb; ++c) {
          out.emplace_back(basis.first[pa] + r, basis.first[pb] + c,
                           row.dot(basis.vectors.col(basis.first[pb] + c)));
        }
      }
    }
  }
}

// A term c c^T (x) block over particles p (c: the term's linear map from positions to d or e).
template <int M>
Eigen::Matrix<double, 3 * M, 3 * M> outer_blocks(const std::array<double, M>& c,
                                                 const Eigen::Matrix3d& block) {
  Eigen::Matrix<double, 3 * M, 3 * M> h;
  for (int a = 0; a < M; ++a) {
    for (int b = 0; b < M; ++b) {
      h.template block<3, 3>(3 * a, 3 * b) =
          (c[static_cast<std::size_t>(a)] * c[static_cast<std::size_t>(b)]) * block;
    }
  }
  return h;
}

}  // namespace

// The triangle terms E(T0, T1) = F(a, D) of triangle_energy (spring_energy.cpp), with a = tr(B G)
// and D = phi^2, phi = (T0 x T1) . u (u held fixed):
//   H = F_aa da da^T + F_aD (da dD^T + dD da^T) + F_DD dD dD^T + F_a d2a + F_D d2D,
//   d2a = 2 [b00 I, b01 I; b01 I, b11 I],  dphi = (T1 x u, u x T0),
//   dD = 2 phi dphi,  d2D = 2 dphi dphi^T + 2 phi d2phi,  d2phi = [0, -[u]x; [u]x, 0].
// F's derivatives follow from g = q a / D (g_a = q / D, g_D = -g / D, g_aD = -q / D^2,
// g_DD = 2 g / D^2) and the barrier h(g) = mu w r^3, r = g / g0 - 1, or the distortion term
// lambda w (a / sigma^2 + g - 4). Then mapped to the corners: T0 = x_next - x_i, T1 = x_prev - x_i.
bool SpringSystem::triangle_hessian(std::size_t t, const Eigen::Matrix3Xd& x,
                                    const Eigen::Matrix3Xd* normals, bool project,
                                    Eigen::Matrix<double, 9, 9>& h) const {
  const BarrierTriangle& b = barrier_[t];
  if (!barrier_active_[t]) {
    return false;
  }
  const Eigen::Vector3d t0 = x.col(b.next) - x.col(b.i);
  const Eigen::Vector3d t1 = x.col(b.prev) - x.col(b.i);
  const Eigen::Vector3d c = t0.cross(t1);
  Eigen::Vector3d u;
  if (normals != nullptr) {
    const Eigen::Vector3d s = normals->col(b.i) + normals->col(b.next) + normals->col(b.prev);
    if (!(s.norm() > 0.0)) {
      return false;
    }
    u = s.normalized();
  } else {
    if (!(c.norm() > 0.0)) {
      return false;
    }
    u = c.normalized();
  }
  const double phi = c.dot(u);
  if (!(phi > 0.0)) {
    return false;  // infinite energy: no Hessian
  }
  const double sigma = options_.rest_scale;
  const double mu = options_.barrier_stiffness * options_.stiffness;
  const double lambda = options_.distortion_stiffness * options_.stiffness;
  const double g0 = 1.0 / (options_.barrier_sigma * options_.barrier_sigma);
  const double D = phi * phi;
  const double a = b.b00 * t0.squaredNorm() + 2.0 * b.b01 * t0.dot(t1) + b.b11 * t1.squaredNorm();
  const double q = sigma * sigma * b.source_det;
  const double g = q * a / D;
  const double g_a = q / D, g_d = -g / D, g_ad = -q / (D * D), g_dd = 2.0 * g / (D * D);
  double f_a = 0.0, f_d = 0.0, f_aa = 0.0, f_ad = 0.0, f_dd = 0.0;
  if (mu > 0.0 && g > g0) {
    const double r = g / g0 - 1.0;
    const double h1 = mu * b.weight * 3.0 * r * r / g0;
    const double h2 = mu * b.weight * 6.0 * r / (g0 * g0);
    f_a += h1 * g_a;
    f_d += h1 * g_d;
    f_aa += h2 * g_a * g_a;
    f_ad += h2 * g_a * g_d + h1 * g_ad;
    f_dd += h2 * g_d * g_d + h1 * g_dd;
  }
  if (lambda > 0.0) {
    const double lw = lambda * b.weight;
    f_a += lw * (1.0 / (sigma * sigma) + g_a);
    f_d += lw * g_d;
    f_ad += lw * g_ad;
    f_dd += lw * g_dd;
  }
  if (f_a == 0.0 && f_d == 0.0 && f_aa == 0.0 && f_ad == 0.0 && f_dd == 0.0) {
    return false;
  }
  Vector6d da, dphi;
  da << 2.0 * (b.b00 * t0 + b.b01 * t1), 2.0 * (b.b11 * t1 + b.b01 * t0);
  dphi << t1.cross(u), u.cross(t0);
  const Vector6d dd = 2.0 * phi * dphi;
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  Matrix6d d2a;
  d2a << 2.0 * b.b00 * identity, 2.0 * b.b01 * identity, 2.0 * b.b01 * identity,
      2.0 * b.b11 * identity;
  const Eigen::Matrix3d ux = cross_matrix(u);
  Matrix6d d2phi = Matrix6d::Zero();
  d2phi.topRightCorner<3, 3>() = -ux;
  d2phi.bottomLeftCorner<3, 3>() = ux;
  const Matrix6d d2d = 2.0 * dphi * dphi.transpose() + 2.0 * phi * d2phi;
  Matrix6d h6 = f_aa * da * da.transpose() + f_ad * (da * dd.transpose() + dd * da.transpose()) +
                f_dd * dd * dd.transpose() + f_a * d2a + f_d * d2d;
  h6 = 0.5 * (h6 + h6.transpose()).eval();
  if (project) {
    const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(h6);
    if (eigen.info() != Eigen::Success) {
      return false;
    }
    h6 = eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).asDiagonal() *
         eigen.eigenvectors().transpose();
  }
  // J: (T0, T1) from (x_i, x_next, x_prev).
  Eigen::Matrix<double, 6, 9> j = Eigen::Matrix<double, 6, 9>::Zero();
  j.block<3, 3>(0, 0) = -identity;
  j.block<3, 3>(0, 3) = identity;
  j.block<3, 3>(3, 0) = -identity;
  j.block<3, 3>(3, 6) = identity;
  h = j.transpose() * h6 * j;
  return true;
}

Eigen::SparseMatrix<double> SpringSystem::hessian(const Eigen::Matrix3Xd& x,
                                                  const Eigen::Matrix3Xd* normals,
                                                  const HessianBasis& basis, bool project) const {
  if (x.cols() != num_particles_ ||
      basis.first.size() != static_cast<std::size_t>(num_particles_) ||
      basis.count.size() != static_cast<std::size_t>(num_particles_)) {
    throw InvalidInputError("particle positions", "expected " + std::to_string(num_particles_) +
                                                      " particles for the Hessian");
  }
  if (normals != nullptr && normals->cols() != num_particles_) {
    throw InvalidInputError("particle normals", "expected " + std::to_string(num_particles_) +
                                                    " columns, got " +
                                                    std::to_string(normals->cols()));
  }
  const std::vector<Spring>& springs = grid_->springs;
  const std::vector<AngularSpring>& angular = grid_->angular_springs;
  const bool triangles = options_.triangle_terms() && options_.stiffness > 0.0;
  const std::size_t num_springs = springs.size(), num_angular = angular.size();
  const std::size_t num_terms = num_springs + num_angular + (triangles ? barrier_.size() : 0);
  const std::size_t chunks = (num_terms + kHessianGrain - 1) / kHessianGrain;
  std::vector<Triplets> parts(chunks);
  const double C = options_.stiffness, Ca = options_.angular_stiffness;
  const double sigma = options_.rest_scale;
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t chunk) {
    Triplets& out = parts[chunk];
    const std::size_t end = std::min(num_terms, (chunk + 1) * kHessianGrain);
    Eigen::Matrix3d block;
    for (std::size_t k = chunk * kHessianGrain; k < end; ++k) {
      // Every spring's blocks are written, zero where it has none, so that the matrix's pattern
      // depends only on the grid and the basis (a caller can keep its symbolic factorisation).
      if (k < num_springs) {
        const Spring& s = springs[k];
        if (!(C > 0.0 &&
              spring_block(x.col(s.j) - x.col(s.i), sigma * s.rest, C, project, block))) {
          block.setZero();
        }
        scatter<2>(basis, {s.i, s.j}, outer_blocks<2>({-1.0, 1.0}, block), out);
      } else if (k < num_springs + num_angular) {
        const AngularSpring& s = angular[k - num_springs];
        const Eigen::Vector3d e = x.col(s.i) - 0.5 * (x.col(s.a) + x.col(s.b));
        if (!(Ca > 0.0 && spring_block(e, sigma * s.rest, Ca, project, block))) {
          block.setZero();
        }
        scatter<3>(basis, {s.i, s.a, s.b}, outer_blocks<3>({1.0, -0.5, -0.5}, block), out);
      } else {
        const std::size_t t = k - num_springs - num_angular;
        Eigen::Matrix<double, 9, 9> h;
        if (triangle_hessian(t, x, normals, project, h)) {
          const BarrierTriangle& b = barrier_[t];
          scatter<3>(basis, {b.i, b.next, b.prev}, h, out);
        }
      }
    }
  });
  std::size_t total = 0;
  for (const Triplets& part : parts) {
    total += part.size();
  }
  Triplets all;
  all.reserve(total);
  for (const Triplets& part : parts) {
    all.insert(all.end(), part.begin(), part.end());
  }
  Eigen::SparseMatrix<double> k(basis.size(), basis.size());
  k.setFromTriplets(all.begin(), all.end());
  return k;
}

}  // namespace elastic
