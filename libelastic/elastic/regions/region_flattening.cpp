#include "elastic/regions/region_flattening.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <optional>

#include "elastic/core/error.h"
#include "elastic/numerics/bicgstab.h"
#include "elastic/numerics/graph_laplacian.h"
#include "elastic/numerics/multigrid.h"
#include "elastic/regions/boundary_first_flattening.h"

namespace elastic {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

std::string region_name(const Region& region) {
  return region.surface ? region.surface->name() + " region" : std::string("region");
}

/// True when the triangle has zero area in 3D (two corners at the same position, or three on a
/// line). Such triangles occur where a limit tessellation welds two copies of a vertex with a
/// zero-area filler triangle; every map sends them to zero area as well, so they carry no
/// orientation and are left out of the fold count and of the conformal energy.
bool degenerate_in_3d(const Region& region, const Eigen::Vector3i& t) {
  const Eigen::Vector3d& p0 = region.positions[static_cast<size_t>(t[0])];
  const Eigen::Vector3d a = region.positions[static_cast<size_t>(t[1])] - p0;
  const Eigen::Vector3d b = region.positions[static_cast<size_t>(t[2])] - p0;
  return a.cross(b).squaredNorm() == 0.0;
}

int count_folds(const Region& region, const std::vector<Eigen::Vector2d>& uv) {
  int folds = 0;
  for (const Eigen::Vector3i& t : region.triangles) {
    if (degenerate_in_3d(region, t)) {
      continue;
    }
    const Eigen::Vector2d a = uv[static_cast<size_t>(t[1])] - uv[static_cast<size_t>(t[0])];
    const Eigen::Vector2d b = uv[static_cast<size_t>(t[2])] - uv[static_cast<size_t>(t[0])];
    if (a.x() * b.y() - a.y() * b.x() <= 0.0) {
      ++folds;
    }
  }
  return folds;
}

/// Interior unknowns from which the mean-value system is solved iteratively rather than by a sparse
/// LU: below it the LU takes a few milliseconds.
constexpr Eigen::Index kIterativeMeanValueSize = 4096;

/// The mean-value system by sparse LU.
Eigen::MatrixXd solve_mean_value_lu(const Eigen::SparseMatrix<double>& a,
                                    const Eigen::MatrixXd& rhs, const std::string& name) {
  Eigen::SparseLU<Eigen::SparseMatrix<double>> solver;
  solver.compute(a);
  if (solver.info() != Eigen::Success) {
    throw NumericalError(name, "flattening: the mean-value system is singular");
  }
  Eigen::MatrixXd x = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !x.allFinite()) {
    throw NumericalError(name, "flattening: the mean-value solve failed");
  }
  return x;
}

/// Solves the mean-value system A X = R (one column per disk coordinate).
///
/// A is a nonsymmetric M-matrix: positive diagonal a_ii = sum_j w_ij, off-diagonal -w_ij <= 0,
/// rows summing to the weights towards boundary vertices (>= 0). A sparse LU of it costs
/// O(n^1.5) on a 2D mesh: 0.36 s of the 0.55 s naive map of grid.off's disk onto the whole
/// 28,561-vertex hemisphere.off (5,775 particles, 2 threads). Above
/// kIterativeMeanValueSize unknowns it is solved instead by BiCGSTAB (numerics/bicgstab.h) to a
/// relative residual of 1e-12, preconditioned by one AMG V-cycle (numerics/multigrid.h) on the
/// symmetrised Laplacian (numerics/graph_laplacian.h `symmetrised_laplacian`: off-diagonal
/// -(w_ij + w_ji) / 2, rows summing to A's), positive definite since the region's vertices reach
/// its boundary, and close to A where the weights are nearly symmetric (a well-shaped mesh). A
/// system the iteration does not solve falls back to the sparse LU. On the hemisphere BiCGSTAB
/// takes 9 iterations per coordinate and the naive map 0.22 s.
Eigen::MatrixXd solve_mean_value(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& rhs,
                                 const std::string& name) {
  const Eigen::Index n = a.rows();
  if (n < kIterativeMeanValueSize) {
    return solve_mean_value_lu(a, rhs, name);
  }
  std::optional<Multigrid> multigrid;
  try {
    multigrid.emplace(symmetrised_laplacian(a));
  } catch (const Error&) {
    return solve_mean_value_lu(a, rhs, name);  // e.g. an unknown without weights: LU says why
  }
  const LinearOperator apply_a = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
    out.noalias() = a * in;
  };
  const LinearOperator apply_b = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
    out = multigrid->apply(in);
  };
  Eigen::MatrixXd x(n, rhs.cols());
  std::vector<char> solved(static_cast<size_t>(rhs.cols()), 0);
  // The columns are independent solves; the multigrid allows concurrent applications.
  tbb::parallel_for(Eigen::Index{0}, rhs.cols(), [&](Eigen::Index c) {
    Eigen::VectorXd column;
    const BicgstabResult r = bicgstab(apply_a, apply_b, rhs.col(c), column);
    if (r.converged && column.allFinite()) {
      x.col(c) = column;
      solved[static_cast<size_t>(c)] = 1;
    }
  });
  if (std::find(solved.begin(), solved.end(), 0) != solved.end()) {
    return solve_mean_value_lu(a, rhs, name);
  }
  return x;
}

/// Floater's mean-value coordinates (Floater 2003, "Mean value coordinates", CAGD 20(1)):
/// w_ij = (tan(alpha_ij / 2) + tan(beta_ij / 2)) / |x_i - x_j|, alpha and beta the angles at x_i of
/// the two triangles sharing edge ij. Every weight is positive, so with the boundary on a convex
/// polygon (the unit circle) the map is a bijection onto it (Floater's theorem, Tutte's in the
/// limit).
RegionFlattening flatten_disk(const Region& region) {
  const int nv = region.num_vertices();
  const std::string name = region_name(region);
  std::vector<int> index(static_cast<size_t>(nv), -1);
  std::vector<Eigen::Vector2d> uv(static_cast<size_t>(nv), Eigen::Vector2d::Zero());
  // Boundary on the unit circle at normalised arc length, angle 0 at the anchor, counter-clockwise.
  const SurfaceCurve curve = region.boundary_curve();
  const std::vector<double> cum = curve.arc_lengths();
  const double total = curve.length();
  if (!(total > 0.0)) {
    throw NumericalError(name, "flattening: the boundary has zero length");
  }
  for (size_t k = 0; k < region.boundary.size(); ++k) {
    const double angle = 2.0 * std::numbers::pi * (cum[k] / total - region.anchor);
    uv[static_cast<size_t>(region.boundary[k])] = Eigen::Vector2d(std::cos(angle), std::sin(angle));
    index[static_cast<size_t>(region.boundary[k])] = -2;
  }
  int free = 0;
  for (int v = 0; v < nv; ++v) {
    if (index[static_cast<size_t>(v)] == -1) {
      index[static_cast<size_t>(v)] = free++;
    }
  }
  RegionFlattening out;
  out.method = FlatteningMethod::Disk;
  if (free > 0) {
    // The diagonal is summed apart and the off-diagonal triplets reserved up front (at most two
    // per triangle corner): a growing vector of 12 triplets per triangle was most of this map's
    // fresh memory (page faults) on a large region.
    Triplets trip;
    trip.reserve(6 * region.triangles.size() + static_cast<size_t>(free));
    Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(free);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(free, 2);
    for (const Eigen::Vector3i& t : region.triangles) {
      for (int k = 0; k < 3; ++k) {
        const int i = t[k], j = t[(k + 1) % 3], l = t[(k + 2) % 3];
        const Eigen::Vector3d& xi = region.positions[static_cast<size_t>(i)];
        const Eigen::Vector3d eij = region.positions[static_cast<size_t>(j)] - xi;
        const Eigen::Vector3d eil = region.positions[static_cast<size_t>(l)] - xi;
        const double lij = eij.norm(), lil = eil.norm();
        if (lij == 0.0 || lil == 0.0) {
          continue;
        }
        // tan(a/2) = (1 - cos a) / sin a = |e1 x e2| ... written as (|e1||e2| - e1.e2) / |e1 x e2|.
        const double cross = eij.cross(eil).norm();
        if (cross == 0.0) {
          continue;
        }
        const double tan_half = (lij * lil - eij.dot(eil)) / cross;
        const int ri = index[static_cast<size_t>(i)];
        if (ri < 0) {
          continue;
        }
        // The angle at i in this triangle contributes to the weights of both edges (i,j) and (i,l).
        for (const auto& [other, len] : {std::pair{j, lij}, std::pair{l, lil}}) {
          const double w = tan_half / len;
          diagonal[ri] += w;
          const int ro = index[static_cast<size_t>(other)];
          if (ro >= 0) {
            trip.emplace_back(ri, ro, -w);
          } else {
            rhs.row(ri) += w * uv[static_cast<size_t>(other)].transpose();
          }
        }
      }
    }
    for (int r = 0; r < free; ++r) {
      trip.emplace_back(r, r, diagonal[r]);
    }
    Eigen::SparseMatrix<double> a(free, free);
    a.setFromTriplets(trip.begin(), trip.end());
    const Eigen::MatrixXd x = solve_mean_value(a, rhs, name);
    for (int v = 0; v < nv; ++v) {
      const int r = index[static_cast<size_t>(v)];
      if (r >= 0) {
        uv[static_cast<size_t>(v)] = x.row(r).transpose();
      }
    }
  }
  out.uv = std::move(uv);
  out.folded_triangles = count_folds(region, out.uv);
  return out;
}

/// A flat region's own coordinates, when every vertex lies on one plane (to 1e-12 of the region's
/// size): the frame has its origin at pin0 and its first axis towards pin1, the second axis n x e1
/// with n the area-weighted normal of the triangles (so counter-clockwise triangles stay
/// counter-clockwise). On such a region the conformal energy's minimum with pin0 at (0, 0) and pin1
/// on the positive u axis is exactly this isometry, so flatten_conformal returns it without the
/// solve (the image sources' planes and grid.off; 0.05-0.3 s of each map).
std::optional<std::vector<Eigen::Vector2d>> planar_coordinates(const Region& region, int pin0,
                                                               int pin1) {
  const auto& x = region.positions;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3i& t : region.triangles) {
    normal += (x[static_cast<size_t>(t[1])] - x[static_cast<size_t>(t[0])])
                  .cross(x[static_cast<size_t>(t[2])] - x[static_cast<size_t>(t[0])]);
  }
  const Eigen::Vector3d origin = x[static_cast<size_t>(pin0)];
  Eigen::Vector3d e1 = x[static_cast<size_t>(pin1)] - origin;
  if (!(normal.norm() > 0.0) || !(e1.norm() > 0.0)) {
    return std::nullopt;
  }
  normal.normalize();
  const double size = e1.norm();
  e1.normalize();
  for (const Eigen::Vector3d& p : x) {
    if (std::abs((p - origin).dot(normal)) > 1e-12 * size) {
      return std::nullopt;
    }
  }
  const Eigen::Vector3d e2 = normal.cross(e1);
  std::vector<Eigen::Vector2d> uv;
  uv.reserve(x.size());
  for (const Eigen::Vector3d& p : x) {
    uv.emplace_back((p - origin).dot(e1), (p - origin).dot(e2));
  }
  return uv;
}

// The two pinned vertices of the conformal map: the boundary vertex nearest the anchor and the one
// nearest half the boundary length away (another when they coincide), and their 3D distance.
struct ConformalPins {
  int first = 0, second = 0;
  double distance = 0.0;
};

ConformalPins conformal_pins(const Region& region) {
  const SurfaceCurve curve = region.boundary_curve();
  const auto nb = static_cast<int>(region.boundary.size());
  const std::vector<double> cum = curve.arc_lengths();
  const double total = curve.length();
  auto nearest_vertex = [&](double s) {
    double target = s - std::floor(s);
    int best = 0;
    double best_d = 2.0;
    for (int k = 0; k < nb; ++k) {
      double d = std::abs(cum[static_cast<size_t>(k)] / total - target);
      d = std::min(d, 1.0 - d);
      if (d < best_d) {
        best_d = d;
        best = k;
      }
    }
    return region.boundary[static_cast<size_t>(best)];
  };
  ConformalPins pins;
  pins.first = nearest_vertex(region.anchor);
  pins.second = nearest_vertex(region.anchor + 0.5);
  if (pins.second == pins.first) {
    pins.second = region.boundary[static_cast<size_t>(1)];
  }
  pins.distance = (region.positions[static_cast<size_t>(pins.second)] -
                   region.positions[static_cast<size_t>(pins.first)])
                      .norm();
  return pins;
}

using Complex = std::complex<double>;

// The conformal energy E_C = E_D - A as a Hermitian form z^H H z over z = u + i v, one complex
// unknown per vertex, with the first pin at 0 and the second at `distance` on the real axis. The
// Dirichlet energy 1/2 sum_edges w_ij |z_i - z_j|^2 puts the cotangent Laplacian in H's real part
// (the same matrix for u and for v, which is why one complex unknown carries both). The signed area
// is 1/2 sum over boundary edges i -> j of u_i v_j - u_j v_i = Im(conj(z_i) z_j), and
// -1/2 Im(w) = 2 Re(i/4 w), so -A puts i/4 at (i, j) and -i/4 at (j, i). Against the real form over
// (u, v) of twice the size, the factorisation does about half the arithmetic and keeps half the
// memory (its fill is the Laplacian's).
//
// The free unknowns minimise it where H_ff z_f = -H_fp z_p (Hermitian positive definite once two
// vertices are pinned). Assembled straight into that system: the lower triangle of H_ff (all the
// factorisation reads), the diagonal summed apart, and the pinned columns moved to the right side.
struct PinnedConformalSystem {
  std::vector<int> index;  ///< free unknown of each vertex, -1 for the pins
  Eigen::VectorXcd fixed;  ///< the pins' values (0 elsewhere)
  Eigen::SparseMatrix<Complex> lower;
  Eigen::VectorXcd rhs;
};

PinnedConformalSystem pinned_conformal_system(const Region& region, const ConformalPins& pins) {
  const int nv = region.num_vertices();
  const auto nb = static_cast<int>(region.boundary.size());
  PinnedConformalSystem system;
  system.index.assign(static_cast<size_t>(nv), -1);
  system.fixed = Eigen::VectorXcd::Zero(nv);
  system.fixed[pins.second] = pins.distance;
  int free = 0;
  for (int v = 0; v < nv; ++v) {
    if (v != pins.first && v != pins.second) {
      system.index[static_cast<size_t>(v)] = free++;
    }
  }
  system.rhs = Eigen::VectorXcd::Zero(free);
  std::vector<double> diagonal(static_cast<size_t>(nv), 0.0);
  std::vector<Eigen::Triplet<Complex>> lower;
  lower.reserve(3 * region.triangles.size() + static_cast<size_t>(nv + nb));
  // H_ij += value and H_ji += conj(value), i != j.
  const auto add_pair = [&](int i, int j, Complex value) {
    const int fi = system.index[static_cast<size_t>(i)], fj = system.index[static_cast<size_t>(j)];
    if (fi >= 0 && fj >= 0) {
      if (fi > fj) {
        lower.emplace_back(fi, fj, value);
      } else {
        lower.emplace_back(fj, fi, std::conj(value));
      }
    } else if (fi >= 0) {
      system.rhs[fi] -= value * system.fixed[j];
    } else if (fj >= 0) {
      system.rhs[fj] -= std::conj(value) * system.fixed[i];
    }
  };
  for (const Eigen::Vector3i& t : region.triangles) {
    if (degenerate_in_3d(region, t)) {
      continue;  // no Dirichlet term and, below, no area term
    }
    for (int k = 0; k < 3; ++k) {
      const int i = t[k], j = t[(k + 1) % 3], l = t[(k + 2) % 3];
      const Eigen::Vector3d a =
          region.positions[static_cast<size_t>(i)] - region.positions[static_cast<size_t>(l)];
      const Eigen::Vector3d b =
          region.positions[static_cast<size_t>(j)] - region.positions[static_cast<size_t>(l)];
      const double cross = a.cross(b).norm();
      if (cross == 0.0) {
        continue;
      }
      // Edge (i, j) opposite corner l: 1/2 cot(l) |z_i - z_j|^2 enters E_D with 1/2.
      const double w = 0.25 * a.dot(b) / cross;
      diagonal[static_cast<size_t>(i)] += w;
      diagonal[static_cast<size_t>(j)] += w;
      add_pair(i, j, -w);
    }
  }
  const auto add_area_edge = [&](int i, int j, double sign) {
    add_pair(i, j, Complex(0.0, 0.25 * sign));
  };
  for (int k = 0; k < nb; ++k) {
    add_area_edge(region.boundary[static_cast<size_t>(k)],
                  region.boundary[static_cast<size_t>((k + 1) % nb)], 1.0);
  }
  // The boundary sum is the sum of every triangle's signed area. A triangle of zero 3D area has no
  // Dirichlet term above (its cotangents are undefined), so its area must leave the energy too:
  // otherwise E_C is no longer a sum of per-triangle conformal energies (each >= 0), and the
  // minimiser gains by opening the triangle, which distorts the whole map and can fold the
  // boundary (seen on a star region whose side runs through two welded copies of a tessellation
  // vertex). Subtracting it keeps E_C >= 0 with the exact isometry of a planar region as minimiser.
  for (const Eigen::Vector3i& t : region.triangles) {
    if (degenerate_in_3d(region, t)) {
      for (int k = 0; k < 3; ++k) {
        add_area_edge(t[k], t[(k + 1) % 3], -1.0);
      }
    }
  }
  for (int v = 0; v < nv; ++v) {
    if (const int f = system.index[static_cast<size_t>(v)]; f >= 0) {
      lower.emplace_back(f, f, diagonal[static_cast<size_t>(v)]);
    }
  }
  system.lower.resize(free, free);
  system.lower.setFromTriplets(lower.begin(), lower.end());
  return system;
}

// The conformal map's vertex coordinates (u, v): the pinned system solved.
std::vector<Eigen::Vector2d> minimise_pinned(const PinnedConformalSystem& system,
                                             const std::string& name) {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<Complex>, Eigen::Lower> solver(system.lower);
  if (solver.info() != Eigen::Success) {
    throw NumericalError(name, "flattening: the LSCM system is singular");
  }
  const Eigen::VectorXcd x = solver.solve(system.rhs);
  if (solver.info() != Eigen::Success || !x.allFinite()) {
    throw NumericalError(name, "flattening: the LSCM solve failed");
  }
  const auto nv = static_cast<int>(system.index.size());
  std::vector<Eigen::Vector2d> uv(static_cast<size_t>(nv));
  for (int v = 0; v < nv; ++v) {
    const int r = system.index[static_cast<size_t>(v)];
    const Complex z = r >= 0 ? x[r] : system.fixed[v];
    uv[static_cast<size_t>(v)] = Eigen::Vector2d(z.real(), z.imag());
  }
  return uv;
}

// Scales uv to the region's 3D area (the pin distance only fixes the scale approximately).
void scale_to_area(const Region& region, std::vector<Eigen::Vector2d>& uv) {
  double area2d = 0.0;
  for (const Eigen::Vector3i& t : region.triangles) {
    const Eigen::Vector2d e1 = uv[static_cast<size_t>(t[1])] - uv[static_cast<size_t>(t[0])];
    const Eigen::Vector2d e2 = uv[static_cast<size_t>(t[2])] - uv[static_cast<size_t>(t[0])];
    area2d += 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
  }
  if (area2d > 0.0) {
    const double s = std::sqrt(region.area() / area2d);
    for (auto& p : uv) {
      p *= s;
    }
  }
}

/// Least-squares conformal map (Lévy et al. 2002), written as E_C = E_D - A (Desbrun et al. 2002;
/// Mullen et al. 2008): the Dirichlet energy 1/2 sum_edges w_ij |U_i - U_j|^2 (cotangent weights
/// w_ij = (cot a + cot b) / 2) minus the signed area of the image, 1/2 sum over boundary edges (i
/// -> j, counter-clockwise) of (u_i v_j - u_j v_i). E_C >= 0 and vanishes exactly on conformal
/// maps. Two boundary vertices (at the anchor and half the boundary length away) are pinned to
/// remove the similarity freedom; the result is then scaled to the region's 3D area. A planar
/// region is laid out in its own plane instead (the exact minimiser).
///
/// Boundary first flattening (boundary_first_flattening.h) shares the rest: the planar shortcut,
/// the scaling to the 3D area and the fold count; where it does not apply, the result is reported
/// as folded everywhere (the caller falls back).
RegionFlattening flatten_conformal(const Region& region, FlatteningMethod method) {
  const std::string name = region_name(region);
  if (region.boundary.size() < 3) {
    throw NumericalError(name, "flattening: the boundary has fewer than 3 vertices");
  }
  const ConformalPins pins = conformal_pins(region);
  RegionFlattening out;
  out.method = method;
  if (std::optional<std::vector<Eigen::Vector2d>> flat =
          planar_coordinates(region, pins.first, pins.second)) {
    out.uv = std::move(*flat);
  } else {
    std::optional<std::vector<Eigen::Vector2d>> uv =
        method == FlatteningMethod::BoundaryFirst
            ? boundary_first_flattening(region, pins.first, pins.second)
            : minimise_pinned(pinned_conformal_system(region, pins), name);
    if (!uv) {
      out.folded_triangles = region.num_triangles();
      return out;
    }
    out.uv = std::move(*uv);
    scale_to_area(region, out.uv);
  }
  out.folded_triangles = count_folds(region, out.uv);
  return out;
}

}  // namespace

RegionFlattening flatten_region(const Region& region, const FlatteningOptions& options) {
  if (region.triangles.empty() || region.boundary.size() < 3) {
    throw InvalidInputError(region_name(region), "flattening: the region is empty");
  }
  if (options.method == FlatteningMethod::BoundaryFirst) {
    if (RegionFlattening flat = flatten_conformal(region, FlatteningMethod::BoundaryFirst);
        flat.folded_triangles == 0) {
      return flat;
    }
  }
  if (options.method != FlatteningMethod::Disk) {
    RegionFlattening conformal = flatten_conformal(region, FlatteningMethod::Conformal);
    if (conformal.folded_triangles == 0) {
      return conformal;
    }
    // Folded: fall back to the always-bijective disk map (method says which one was used).
  }
  return flatten_disk(region);
}

}  // namespace elastic
