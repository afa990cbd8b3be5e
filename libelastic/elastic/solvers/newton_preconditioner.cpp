#include "elastic/solvers/newton_preconditioner.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "elastic/solvers/solver_common.h"

namespace elastic::solver_detail {

namespace {

/// eps of the Laplacian share in K (newton_preconditioner.h).
constexpr double kLaplacianShare = 1e-3;

// Two unit vectors across n, orthogonal to each other.
void tangent_pair(const Eigen::Vector3d& n, Eigen::Vector3d& e1, Eigen::Vector3d& e2) {
  const Eigen::Vector3d helper =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  e1 = n.cross(helper).normalized();
  e2 = n.cross(e1);
}

}  // namespace

NewtonPreconditioner::NewtonPreconditioner(const RelaxationSetup& setup,
                                           const Eigen::SparseMatrix<double>& laplacian)
    : setup_(&setup), laplacian_(laplacian) {}

bool NewtonPreconditioner::refresh(const Eigen::Matrix3Xd& positions,
                                   const Eigen::Matrix3Xd& normals,
                                   const Eigen::Matrix3Xd& tangents,
                                   const Eigen::Matrix3Xd& gradient,
                                   const std::vector<SurfaceDerivatives>& frames,
                                   const std::vector<char>& held) {
  build_basis(normals, tangents, held);
  if (basis_.size() == 0) {
    ready_ = false;  // every free particle held: nothing to factorise
    return false;
  }
  const Eigen::SparseMatrix<double> k = regularised_hessian(positions, normals);
  Triplets curvature, clamped;
  curvature_blocks(normals, gradient, frames, curvature, clamped);
  ready_ = factorise(k, curvature, clamped);
  return ready_;
}

// B: the free entries in order, two tangent vectors each, or the curve's tangent for a sliding
// boundary particle, none when held.
void NewtonPreconditioner::build_basis(const Eigen::Matrix3Xd& normals,
                                       const Eigen::Matrix3Xd& tangents,
                                       const std::vector<char>& held) {
  const RelaxationSetup& setup = *setup_;
  const auto particles = static_cast<std::size_t>(setup.num_particles);
  basis_.first.assign(particles, 0);
  basis_.count.assign(particles, 0);
  Eigen::Index size = 0;
  const int free = static_cast<int>(setup.interior.size());
  for (int k = 0; k < free; ++k) {
    if (held[static_cast<std::size_t>(k)] == 0) {
      size += setup.sliding[static_cast<std::size_t>(k)] >= 0 ? 1 : 2;
    }
  }
  basis_.vectors.resize(3, size);
  int next = 0;
  for (int k = 0; k < free; ++k) {
    if (held[static_cast<std::size_t>(k)] != 0) {
      continue;
    }
    const auto p = static_cast<std::size_t>(setup.interior[static_cast<std::size_t>(k)]);
    const auto col = static_cast<Eigen::Index>(p);
    basis_.first[p] = next;
    if (setup.sliding[static_cast<std::size_t>(k)] >= 0) {
      basis_.count[p] = 1;
      basis_.vectors.col(next++) = tangents.col(col);
    } else {
      Eigen::Vector3d e1, e2;
      tangent_pair(normals.col(col), e1, e2);
      basis_.count[p] = 2;
      basis_.vectors.col(next++) = e1;
      basis_.vectors.col(next++) = e2;
    }
  }
}

// B^T H B + eps B^T (L (x) I) B: for L_ab (a, b free entries) the blocks eps L_ab B_a^T B_b.
Eigen::SparseMatrix<double> NewtonPreconditioner::regularised_hessian(
    const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xd& normals) const {
  const RelaxationSetup& setup = *setup_;
  Eigen::SparseMatrix<double> k = setup.springs.hessian(positions, &normals, basis_, true);
  Triplets shares;
  const auto vector = [&](std::size_t p, int c) { return basis_.vectors.col(basis_.first[p] + c); };
  for (Eigen::Index col = 0; col < laplacian_.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian_, col); it; ++it) {
      const auto pa = static_cast<std::size_t>(setup.interior[static_cast<std::size_t>(it.row())]);
      const auto pb = static_cast<std::size_t>(setup.interior[static_cast<std::size_t>(col)]);
      for (int r = 0; r < basis_.count[pa]; ++r) {
        for (int c = 0; c < basis_.count[pb]; ++c) {
          const double value = kLaplacianShare * it.value() * vector(pa, r).dot(vector(pb, c));
          shares.emplace_back(basis_.first[pa] + r, basis_.first[pb] + c, value);
          if (pa != pb) {
            shares.emplace_back(basis_.first[pb] + c, basis_.first[pa] + r, value);
          }
        }
      }
    }
  }
  Eigen::SparseMatrix<double> regular(k.rows(), k.cols());
  regular.setFromTriplets(shares.begin(), shares.end());
  return k + regular;
}

// The surface's curvature: along a geodesic x(t) with x'(0) = v the energy's second derivative is
// v^T H v + (g . n) II(v, v), II the second fundamental form: n . x'' = a^T S a for v = J a,
// J = [du dv], S = [n.duu n.duv; n.duv n.dvv], and in the basis (e1, e2) a_i = (J^T J)^-1 J^T e_i.
// `full` gets each particle's 2 x 2 block, `clamped` its positive part. Both write the same
// entries (zeros included), so K + either has one pattern.
void NewtonPreconditioner::curvature_blocks(const Eigen::Matrix3Xd& normals,
                                            const Eigen::Matrix3Xd& gradient,
                                            const std::vector<SurfaceDerivatives>& frames,
                                            Triplets& full, Triplets& clamped) const {
  const RelaxationSetup& setup = *setup_;
  for (int k = 0; k < setup.num_free(); ++k) {
    const auto p = static_cast<std::size_t>(setup.interior[static_cast<std::size_t>(k)]);
    if (basis_.count[p] != 2) {
      continue;
    }
    const SurfaceDerivatives& d = frames[static_cast<std::size_t>(k)];
    const auto col = static_cast<Eigen::Index>(p);
    const Eigen::Vector3d n = normals.col(col);
    Eigen::Matrix<double, 3, 2> j;
    j << d.du, d.dv;
    const Eigen::Matrix2d metric = j.transpose() * j;
    Eigen::Matrix2d shape;
    shape << n.dot(d.duu), n.dot(d.duv), n.dot(d.duv), n.dot(d.dvv);
    Eigen::Matrix2d w = Eigen::Matrix2d::Zero(), positive = Eigen::Matrix2d::Zero();
    if (metric.determinant() > 1e-300) {
      const Eigen::Matrix2d a =
          metric.inverse() * j.transpose() * basis_.vectors.middleCols<2>(basis_.first[p]);
      w = gradient.col(col).dot(n) * (a.transpose() * shape * a);
      w = 0.5 * (w + w.transpose()).eval();
    }
    if (!w.allFinite()) {
      w.setZero();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(w);
    positive = eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).asDiagonal() *
               eigen.eigenvectors().transpose();
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < 2; ++c) {
        full.emplace_back(basis_.first[p] + r, basis_.first[p] + c, w(r, c));
        clamped.emplace_back(basis_.first[p] + r, basis_.first[p] + c, positive(r, c));
      }
    }
  }
}

// LDL^T of K + the curvature, or of K + its positive part where that is not positive definite; the
// symbolic analysis is kept while the pattern stays (it changes only with the held set).
bool NewtonPreconditioner::factorise(const Eigen::SparseMatrix<double>& k, const Triplets& full,
                                     const Triplets& clamped) {
  for (const Triplets* term : {&full, &clamped}) {
    Eigen::SparseMatrix<double> bent(k.rows(), k.cols());
    bent.setFromTriplets(term->begin(), term->end());
    const Eigen::SparseMatrix<double> total = k + bent;
    const bool same_pattern =
        total.rows() == pattern_.rows() && total.nonZeros() == pattern_.nonZeros() &&
        std::equal(total.outerIndexPtr(), total.outerIndexPtr() + total.outerSize() + 1,
                   pattern_.outerIndexPtr()) &&
        std::equal(total.innerIndexPtr(), total.innerIndexPtr() + total.nonZeros(),
                   pattern_.innerIndexPtr());
    if (!same_pattern) {
      factor_.analyzePattern(total);
      pattern_ = total;
    }
    factor_.factorize(total);
    bool positive = factor_.info() == Eigen::Success;
    const Eigen::VectorXd& pivots = factor_.vectorD();
    for (Eigen::Index i = 0; positive && i < pivots.size(); ++i) {
      positive = pivots[i] > 0.0 && std::isfinite(pivots[i]);
    }
    if (positive) {
      return true;
    }
  }
  return false;
}

void NewtonPreconditioner::apply(Eigen::VectorXd& v) const {
  const RelaxationSetup& setup = *setup_;
  const Eigen::Index n = setup.num_free();
  Eigen::VectorXd reduced(basis_.size());
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto p = static_cast<std::size_t>(setup.interior[static_cast<std::size_t>(k)]);
    const Eigen::Vector3d w(v[k], v[n + k], v[2 * n + k]);
    for (int c = 0; c < basis_.count[p]; ++c) {
      reduced[basis_.first[p] + c] = basis_.vectors.col(basis_.first[p] + c).dot(w);
    }
  }
  const Eigen::VectorXd z = factor_.solve(reduced);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto p = static_cast<std::size_t>(setup.interior[static_cast<std::size_t>(k)]);
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    for (int c = 0; c < basis_.count[p]; ++c) {
      w += z[basis_.first[p] + c] * basis_.vectors.col(basis_.first[p] + c);
    }
    v[k] = w.x();
    v[n + k] = w.y();
    v[2 * n + k] = w.z();
  }
}

}  // namespace elastic::solver_detail
