#pragma once
/// \file
/// The L-BFGS solver's vectors over the interior particles (internal to the solvers, like
/// solver_common.h): chunked parallel kernels whose reductions give the same bits for any number
/// of threads, and the layout of interior vectors with their projection on the tangent spaces.
///
/// dot and axpy do what numerics/vector_kernels.h's parallel_dot and parallel_axpy do, with
/// another fixed summation order (TBB's deterministic reduce over 16,384-entry chunks against
/// 4,096-entry blocks added in order) and mixed precision for the single-precision L-BFGS pairs.
/// One of the two should go; which order stays changes the bits of every map (docs/results.md
/// then needs regenerating), so it is a change of its own.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Core>
#include <cstddef>
#include <functional>

#include "elastic/solvers/solver_common.h"

namespace elastic::solver_detail {

// Vector kernels over [0, n) in fixed chunks. Reductions join the chunks' partial sums in a fixed
// tree (parallel_deterministic_reduce), so every result is the same for any number of threads; at
// a million particles the serial Eigen versions of these passes took about a third of an
// iteration.
inline constexpr Eigen::Index kChunk = 16384;

// Per-particle work that evaluates the surface (retraction, frames): microseconds per item, so
// small chunks still pay for themselves.
inline constexpr Eigen::Index kSurfaceChunk = 256;

template <typename Body>
void for_chunks(Eigen::Index n, const Body& body, Eigen::Index chunk = kChunk) {
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, chunk),
                    [&](const tbb::blocked_range<Eigen::Index>& r) {
                      for (Eigen::Index i = r.begin(); i != r.end(); ++i) {
                        body(i);
                      }
                    });
}

template <typename Term>
double sum_chunks(Eigen::Index n, const Term& term) {
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<Eigen::Index>(0, n, kChunk), 0.0,
      [&](const tbb::blocked_range<Eigen::Index>& r, double sum) {
        for (Eigen::Index i = r.begin(); i != r.end(); ++i) {
          sum += term(i);
        }
        return sum;
      },
      std::plus<double>());
}

// In double precision whatever the vectors' own (the memory's pairs are stored in single).
template <typename A, typename B>
double dot(const A& a, const B& b) {
  return sum_chunks(a.size(), [&](Eigen::Index i) {
    return static_cast<double>(a[i]) * static_cast<double>(b[i]);
  });
}

// y += alpha x
template <typename X>
void axpy(double alpha, const X& x, Eigen::VectorXd& y) {
  for_chunks(x.size(), [&](Eigen::Index i) { y[i] += alpha * static_cast<double>(x[i]); });
}

// Interior vectors have 3n entries laid out as an n x 3 column-major matrix (all x, then all y,
// then all z), so that the Laplacian solve takes the three coordinates as three right-hand sides.
struct InteriorLayout {
  const RelaxationSetup* setup;
  Eigen::Index n;

  // The tangent space of free entry k: the surface's tangent plane (g - n (n . g)), or for a
  // sliding boundary particle the curve's tangent line (t (t . g)); `tangents` holds the curve
  // tangents of the state the normals belong to.
  Eigen::Vector3d to_tangent(Eigen::Index k, const Eigen::Vector3d& g,
                             const Eigen::Matrix3Xd& normals,
                             const Eigen::Matrix3Xd& tangents) const {
    const int p = setup->interior[static_cast<std::size_t>(k)];
    if (setup->sliding[static_cast<std::size_t>(k)] >= 0) {
      const Eigen::Vector3d t = tangents.col(p);
      return t * t.dot(g);
    }
    const Eigen::Vector3d nrm = normals.col(p);
    return g - nrm * nrm.dot(g);
  }

  // q = tangential part of the gradient at the free particles.
  void tangential(const Eigen::Matrix3Xd& gradient, const Eigen::Matrix3Xd& normals,
                  const Eigen::Matrix3Xd& tangents, Eigen::VectorXd& q) const {
    for_chunks(n, [&](Eigen::Index k) {
      const int p = setup->interior[static_cast<std::size_t>(k)];
      const Eigen::Vector3d t = to_tangent(k, gradient.col(p), normals, tangents);
      for (int c = 0; c < 3; ++c) {
        q[c * n + k] = t[c];
      }
    });
  }

  void project(Eigen::VectorXd& v, const Eigen::Matrix3Xd& normals,
               const Eigen::Matrix3Xd& tangents) const {
    for_chunks(n, [&](Eigen::Index k) {
      const Eigen::Vector3d u =
          to_tangent(k, Eigen::Vector3d(v[k], v[n + k], v[2 * n + k]), normals, tangents);
      for (int c = 0; c < 3; ++c) {
        v[c * n + k] = u[c];
      }
    });
  }

  Eigen::Vector3d at(const Eigen::VectorXd& v, Eigen::Index k) const {
    return {v[k], v[n + k], v[2 * n + k]};
  }
};

}  // namespace elastic::solver_detail
