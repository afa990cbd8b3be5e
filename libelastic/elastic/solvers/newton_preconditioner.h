#pragma once
/// \file
/// The tangent-space Hessian of the relaxation's energy as the L-BFGS solver's H0
/// (LbfgsOptions::newton, relaxation.h). Internal to the solvers (solver_detail).
///
/// Each free particle moves in its tangent space: two orthonormal vectors across its surface
/// normal, or the curve's tangent for a sliding boundary particle, none while it is held. With B
/// that basis (3n x r, block-diagonal),
///     K = B^T H B + eps B^T (L (x) I_3) B + (g . n) II,    H0 v = B K^-1 B^T v,
/// - H the Hessian of E_len + E_ang + E_bar + E_sd at the current positions with each term's
///   negative eigenvalues clamped (SpringSystem::hessian; the normals held fixed, their turning
///   left out: the L-BFGS pairs make up for it);
/// - L the interior spring Laplacian (spring_laplacian.h) on each coordinate, eps =
///   kLaplacianShare: it keeps K positive definite where the clamped terms leave a direction
///   without stiffness (a quad's shear with compressed springs), small enough not to blunt the
///   barrier's stiff directions;
/// - (g . n) II the surface's curvature times the normal force, per particle (the Riemannian
///   Hessian's second term); where it makes K indefinite, its positive part per particle.
/// K is factorised by a sparse LDL^T in approximate minimum degree order (Eigen's AMD), its
/// symbolic analysis kept while the pattern stays. On K (two unknowns a particle, angular springs
/// and barrier triangles reaching two rings) AMD fills less than the particles' geometric nested
/// dissection (nested_dissection.h), which serves the scalar spring Laplacian of grids up to
/// millions: at 4,776 particles (9,552 unknowns) 0.62 against 0.94 million entries in the factor,
/// 0.028 against 0.056 s a factorisation, for 6 ms of analysis per pattern. The Newton H0 serves
/// grids of at most NewtonOptions::max_particles, where AMD's analysis stays cheap.

#include <Eigen/Core>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <vector>

#include "elastic/particles/spring_energy.h"
#include "elastic/surface/limit_surface.h"

namespace elastic::solver_detail {

struct RelaxationSetup;

class NewtonPreconditioner {
 public:
  /// `laplacian`: interior_laplacian(setup) (lower triangle stored).
  NewtonPreconditioner(const RelaxationSetup& setup, const Eigen::SparseMatrix<double>& laplacian);

  /// Rebuilds K at `positions` (3 x #P) with unit `normals` and curve `tangents` (3 x #P, the
  /// setup's layout), free entries k with held[k] != 0 left out. False when K is not positive
  /// definite in working precision (the previous factor is then kept).
  bool refresh(const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xd& normals,
               const Eigen::Matrix3Xd& tangents, const Eigen::Matrix3Xd& gradient,
               const std::vector<SurfaceDerivatives>& frames, const std::vector<char>& held);

  /// v (3n: the x, then y, then z entries of the free particles) := B K^-1 B^T v. Held rows of
  /// the result are zero.
  void apply(Eigen::VectorXd& v) const;

  bool ready() const { return ready_; }

 private:
  using Triplets = std::vector<Eigen::Triplet<double>>;
  void build_basis(const Eigen::Matrix3Xd& normals, const Eigen::Matrix3Xd& tangents,
                   const std::vector<char>& held);
  Eigen::SparseMatrix<double> regularised_hessian(const Eigen::Matrix3Xd& positions,
                                                  const Eigen::Matrix3Xd& normals) const;
  void curvature_blocks(const Eigen::Matrix3Xd& normals, const Eigen::Matrix3Xd& gradient,
                        const std::vector<SurfaceDerivatives>& frames, Triplets& full,
                        Triplets& clamped) const;
  bool factorise(const Eigen::SparseMatrix<double>& k, const Triplets& full,
                 const Triplets& clamped);

  const RelaxationSetup* setup_;
  Eigen::SparseMatrix<double> laplacian_;
  SpringSystem::HessianBasis basis_;
  Eigen::SparseMatrix<double> pattern_;  // the last K whose symbolic factorisation factor_ holds
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> factor_;
  bool ready_ = false;
};

}  // namespace elastic::solver_detail
