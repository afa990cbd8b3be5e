#include "elastic/solvers/solver_common.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "elastic/core/error.h"
#include "elastic/core/huge_pages.h"

namespace elastic::solver_detail {

namespace {

const std::string kName = "relaxation";

const ParticleGrid& checked_grid(const RelaxationProblem& problem) {
  if (problem.grid == nullptr) {
    throw InvalidInputError(kName, "no particle grid given");
  }
  if (problem.target == nullptr) {
    throw InvalidInputError(kName, "no target surface given");
  }
  return *problem.grid;
}

SpringEnergyOptions energy_options(const RelaxationProblem& problem,
                                   const RelaxationOptions& options) {
  const bool barrier = options.energy == EnergyKind::Robust && options.solver == SolverKind::Fast;
  return {.stiffness = options.stiffness,
          .angular_stiffness = options.angular_stiffness,
          .rest_scale = problem.rest_scale,
          .barrier_stiffness = barrier ? options.barrier_stiffness : 0.0,
          .barrier_sigma = options.barrier_sigma};
}

}  // namespace

RelaxationSetup::RelaxationSetup(const RelaxationProblem& problem, const RelaxationOptions& options)
    : grid(checked_grid(problem)),
      target(*problem.target),
      springs(*problem.grid, energy_options(problem, options)),
      num_particles(problem.grid->num_particles()) {
  const auto P = static_cast<std::size_t>(num_particles);
  if (problem.initial_positions.cols() != num_particles || problem.initial_points.size() != P) {
    throw InvalidInputError(kName, "initial positions/points do not have one entry per particle (" +
                                       std::to_string(num_particles) + ")");
  }
  if (grid.is_boundary.size() != P) {
    throw InvalidInputError(kName,
                            "particle grid: is_boundary does not have one entry per particle");
  }
  if (!problem.initial_positions.allFinite()) {
    throw InvalidInputError(kName, "initial positions are not finite");
  }
  if (problem.boundary_targets.cols() != 0 &&
      problem.boundary_targets.cols() != static_cast<Eigen::Index>(grid.boundary_loop.size())) {
    throw InvalidInputError(kName, "boundary targets do not have one entry per boundary particle");
  }
  if (!(options.relative_gradient_tolerance >= 0.0) ||
      !(options.absolute_gradient_tolerance >= 0.0)) {
    throw InvalidInputError(kName, "gradient tolerances must be non-negative");
  }
  if (options.max_iterations < 0 || options.frame_interval < 1 || options.threads < 0) {
    throw InvalidInputError(kName, "max_iterations, frame_interval or threads out of range");
  }
  for (std::size_t p = 0; p < P; ++p) {
    if (!problem.initial_points[p].valid() ||
        problem.initial_points[p].face >= target.surface().num_faces()) {
      throw InvalidInputError(kName,
                              "particle " + std::to_string(p) + " has no valid surface point");
    }
  }

  interior_index.assign(P, -1);
  is_free.assign(P, 0);
  for (std::size_t p = 0; p < P; ++p) {
    if (grid.is_boundary[p]) {
      continue;
    }
    interior_index[p] = static_cast<int>(interior.size());
    is_free[p] = 1;
    interior.push_back(static_cast<int>(p));
  }
  sliding.assign(interior.size(), -1);
  slide = options.boundary == BoundaryMode::Slide && options.solver == SolverKind::Fast;
  if (slide) {
    if (!problem.boundary_curve) {
      throw InvalidInputError(kName, "a sliding boundary needs the target boundary curve");
    }
    const std::vector<double>& start =
        problem.boundary_parameters.empty() ? grid.boundary_parameter : problem.boundary_parameters;
    if (start.size() != grid.boundary_loop.size()) {
      throw InvalidInputError(kName, "boundary parameters do not match the boundary loop");
    }
    curve = &problem.boundary_curve;
    curve_s = start;
    curve_speed.assign(start.size(), 0.0);
    for (std::size_t k = 0; k < grid.boundary_loop.size(); ++k) {
      const auto p = static_cast<std::size_t>(grid.boundary_loop[k]);
      interior_index[p] = static_cast<int>(interior.size());
      is_free[p] = 1;
      interior.push_back(static_cast<int>(p));
      sliding.push_back(static_cast<int>(k));
    }
  }

  // Fresh buffers advised before they are written (core/huge_pages.h).
  resize_huge(positions, 3, num_particles);
  positions = problem.initial_positions;
  points.reserve(P);
  advise_huge_pages(points.data(), P * sizeof(SurfacePoint));
  points.assign(problem.initial_points.begin(), problem.initial_points.end());

  // Unit normals du x dv / |du x dv| at the given surface points (the fold test and the tangent
  // projection need them for every particle; interior ones are refreshed by each retraction).
  resize_huge(normals, 3, num_particles);
  const LimitSurface& surface = target.surface();
  tbb::parallel_for(tbb::blocked_range<int>(0, num_particles, 256),
                    [&](const tbb::blocked_range<int>& range) {
                      for (int p = range.begin(); p != range.end(); ++p) {
                        const SurfaceDerivatives d = surface.derivatives(points[p]);
                        const Eigen::Vector3d n = d.du.cross(d.dv);
                        const double length = n.norm();
                        if (length > 1e-300) {
                          normals.col(p) = n / length;
                        } else {
                          // Degenerate parameterisation (a singular corner): ask the magnet.
                          normals.col(p) = target.closest(positions.col(p), points[p]).normal;
                        }
                      }
                    });

  if (slide) {
    resize_huge(curve_tangent, 3, num_particles);
    curve_tangent.setZero();
    for (std::size_t k = 0; k < grid.boundary_loop.size(); ++k) {
      const int p = grid.boundary_loop[k];
      SurfacePoint point;
      Eigen::Vector3d position, tangent;
      curve_frame(curve_s[k], point, position, tangent, curve_speed[k]);
      curve_tangent.col(p) = tangent;
    }
  }

  // Triangles folded at the start stay out of the barrier (it cannot be crossed: they could only
  // be held folded). The fold guard still keeps them from folding again once they unfold.
  springs.set_barrier_mask(positions, normals);

  double sum = 0.0;
  for (const Spring& s : grid.springs) {
    sum += s.rest;
  }
  mean_rest = grid.springs.empty()
                  ? 0.0
                  : problem.rest_scale * sum / static_cast<double>(grid.springs.size());
  // |P g| has units of stiffness x length per particle, summed in quadrature over #P particles.
  const double stiffness = std::max(options.stiffness, options.angular_stiffness);
  absolute_bound = options.absolute_gradient_tolerance * stiffness * mean_rest *
                   std::sqrt(static_cast<double>(num_particles));
}

double tangential_norm(const RelaxationSetup& setup, const Eigen::Matrix3Xd& gradient,
                       const Eigen::Matrix3Xd& normals) {
  double sum = 0.0;
  for (std::size_t k = 0; k < setup.interior.size(); ++k) {
    const int p = setup.interior[k];
    const Eigen::Vector3d g = gradient.col(p);
    if (setup.sliding[k] >= 0) {  // along the curve only
      const double along = setup.curve_tangent.col(p).dot(g);
      sum += along * along;
      continue;
    }
    const Eigen::Vector3d n = normals.col(p);
    sum += (g - n * n.dot(g)).squaredNorm();
  }
  return std::sqrt(sum);
}

void RelaxationSetup::curve_frame(double s, SurfacePoint& point, Eigen::Vector3d& position,
                                  Eigen::Vector3d& tangent, double& speed) const {
  // c is piecewise smooth (linear in ptex parameters between the curve's vertices): a central
  // difference over 1e-7 of the curve sees at most one kink, where it gives the mean direction.
  constexpr double kDelta = 1e-7;
  const LimitSurface& surface = target.surface();
  const auto wrap = [](double t) { return t - std::floor(t); };
  point = (*curve)(wrap(s));
  position = surface.position(point);
  const Eigen::Vector3d d =
      surface.position((*curve)(wrap(s + kDelta))) - surface.position((*curve)(wrap(s - kDelta)));
  speed = d.norm() / (2.0 * kDelta);
  tangent = speed > 0.0 ? Eigen::Vector3d(d / d.norm()) : Eigen::Vector3d::Zero();
}

bool RelaxationSetup::in_order(const std::vector<double>& s) {
  const std::size_t m = s.size();
  for (std::size_t k = 0; k < m; ++k) {
    const double gap = k + 1 < m ? s[k + 1] - s[k] : s[0] + 1.0 - s[k];
    if (!(gap > 0.0 && gap < 1.0)) {
      return false;
    }
  }
  return true;
}

Eigen::SparseMatrix<double> interior_laplacian(const RelaxationSetup& setup,
                                               const RelaxationOptions& options) {
  const int n = setup.num_free();
  // Normal spring: C (|d| - k)^2 has Hessian 2C d d^T/|d|^2 at rest; the isotropic 2C I per
  // coordinate. Angular spring: e = x_i - (x_a + x_b)/2 = v . (x_i, x_a, x_b), Gram matrix
  // 2 C_a v v^T with v = (1, -1/2, -1/2): diagonal (2, 1/2, 1/2) C_a, (i,a) and (i,b) -C_a,
  // (a,b) +C_a/2. `visit` hands every contribution (particle, particle, value) to `emit`.
  const double w = 2.0 * options.stiffness, ca = options.angular_stiffness;
  const auto visit = [&](const auto& emit) {
    for (const Spring& sp : setup.grid.springs) {
      emit(sp.i, sp.i, w);
      emit(sp.j, sp.j, w);
      emit(sp.i, sp.j, -w);
    }
    for (const AngularSpring& sp : setup.grid.angular_springs) {
      emit(sp.i, sp.i, 2.0 * ca);
      emit(sp.a, sp.a, 0.5 * ca);
      emit(sp.b, sp.b, 0.5 * ca);
      emit(sp.i, sp.a, -ca);
      emit(sp.i, sp.b, -ca);
      emit(sp.a, sp.b, 0.5 * ca);
    }
  };
  // Only the lower triangle is stored (what the LDL^T factorisation reads), column by column:
  // entry (max, min) goes to column min. Counted, scattered into per-column buckets, then each
  // column sorted and its duplicates summed, in parallel (a triplet list and Eigen's
  // setFromTriplets took 2 s at a million particles).
  const auto interior = [&](int p) { return setup.interior_index[static_cast<std::size_t>(p)]; };
  std::vector<std::int64_t> start;
  assign_huge(start, static_cast<std::size_t>(n) + 2, std::int64_t{0});
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(n);
  visit([&](int p, int q, double value) {
    const int a = interior(p), b = interior(q);
    if (a < 0 || b < 0) {
      return;
    }
    if (a == b) {
      // A sliding boundary row is weighted up by a tenth: with no particle held the spring
      // Laplacian is singular (translations), and the preconditioner must stay definite.
      diagonal[a] += setup.sliding[static_cast<std::size_t>(a)] >= 0 ? 1.1 * value : value;
    } else {
      ++start[static_cast<std::size_t>(std::min(a, b)) + 2];
    }
  });
  // start[c + 2] counts column c's off-diagonal entries; one more slot per column for the
  // diagonal, stored first.
  for (int c = 0; c < n; ++c) {
    start[static_cast<std::size_t>(c) + 2] += 1;
  }
  for (std::size_t c = 2; c < start.size(); ++c) {
    start[c] += start[c - 1];
  }
  std::vector<int> rows;
  std::vector<double> values;
  assign_huge(rows, static_cast<std::size_t>(start.back()));
  assign_huge(values, rows.size());
  // start[c + 1] is now the fill position of column c.
  for (int c = 0; c < n; ++c) {
    const auto slot = static_cast<std::size_t>(start[static_cast<std::size_t>(c) + 1]++);
    rows[slot] = c;
    values[slot] = diagonal[c];
  }
  visit([&](int p, int q, double value) {
    const int a = interior(p), b = interior(q);
    if (a < 0 || b < 0 || a == b) {
      return;
    }
    const auto slot =
        static_cast<std::size_t>(start[static_cast<std::size_t>(std::min(a, b)) + 1]++);
    rows[slot] = std::max(a, b);
    values[slot] = value;
  });
  // Column c spans [start[c], start[c + 1]). Sort by row (a dozen entries: insertion sort) and sum
  // duplicates in place; `kept` receives each column's length.
  std::vector<int> kept(static_cast<std::size_t>(n));
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 4096), [&](const tbb::blocked_range<int>& r) {
    for (int c = r.begin(); c != r.end(); ++c) {
      const auto first = static_cast<std::size_t>(start[static_cast<std::size_t>(c)]);
      const auto last = static_cast<std::size_t>(start[static_cast<std::size_t>(c) + 1]);
      for (std::size_t i = first + 1; i < last; ++i) {
        for (std::size_t j = i; j > first && rows[j - 1] > rows[j]; --j) {
          std::swap(rows[j - 1], rows[j]);
          std::swap(values[j - 1], values[j]);
        }
      }
      std::size_t out = first;
      for (std::size_t i = first + 1; i < last; ++i) {
        if (rows[i] == rows[out]) {
          values[out] += values[i];
        } else {
          ++out;
          rows[out] = rows[i];
          values[out] = values[i];
        }
      }
      kept[static_cast<std::size_t>(c)] = static_cast<int>(out + 1 - first);
    }
  });
  Eigen::SparseMatrix<double> laplacian(n, n);
  std::int64_t nonzeros = 0;
  for (const int k : kept) {
    nonzeros += k;
  }
  laplacian.resizeNonZeros(static_cast<Eigen::Index>(nonzeros));
  int* outer = laplacian.outerIndexPtr();
  outer[0] = 0;
  for (int c = 0; c < n; ++c) {
    outer[c + 1] = outer[c] + kept[static_cast<std::size_t>(c)];
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 4096), [&](const tbb::blocked_range<int>& r) {
    for (int c = r.begin(); c != r.end(); ++c) {
      const auto from = static_cast<std::ptrdiff_t>(start[static_cast<std::size_t>(c)]);
      const auto count = static_cast<std::ptrdiff_t>(kept[static_cast<std::size_t>(c)]);
      std::copy(rows.begin() + from, rows.begin() + from + count,
                laplacian.innerIndexPtr() + outer[c]);
      std::copy(values.begin() + from, values.begin() + from + count,
                laplacian.valuePtr() + outer[c]);
    }
  });
  return laplacian;
}

Eigen::Matrix3Xd interior_coordinates(const RelaxationSetup& setup) {
  Eigen::Matrix3Xd x(3, setup.num_free());
  for (int k = 0; k < setup.num_free(); ++k) {
    x.col(k) = setup.positions.col(setup.interior[static_cast<std::size_t>(k)]);
  }
  return x;
}

namespace {

// Recursive geometric bisection (see nested_dissection_order). `nodes` is the subset to order;
// `side` and `stamp` are scratch arrays over all n particles; the ordered subset is appended to
// `order`.
struct Dissection {
  const std::vector<int>& start;  // symmetric adjacency, compressed rows
  const std::vector<int>& adjacent;
  const Eigen::Matrix3Xd& coordinates;
  std::vector<int>& side;   // 0: lower half, 1: upper half, valid where stamp == current
  std::vector<int>& stamp;  // which call last labelled the particle
  std::vector<int>& order;
  int calls = 0;

  static constexpr std::size_t kLeaf = 64;

  void run(std::vector<int> nodes) {
    if (nodes.size() <= kLeaf) {
      std::sort(nodes.begin(), nodes.end());
      order.insert(order.end(), nodes.begin(), nodes.end());
      return;
    }
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const int v : nodes) {
      lo = lo.cwiseMin(coordinates.col(v));
      hi = hi.cwiseMax(coordinates.col(v));
    }
    Eigen::Index axis = 0;
    (hi - lo).maxCoeff(&axis);
    // Median split along the axis; ties by index so that the result never depends on the sort.
    const auto half = nodes.begin() + static_cast<std::ptrdiff_t>(nodes.size() / 2);
    std::nth_element(nodes.begin(), half, nodes.end(), [&](int a, int b) {
      const double ca = coordinates(axis, a), cb = coordinates(axis, b);
      return ca < cb || (ca == cb && a < b);
    });
    const int call = ++calls;
    for (auto it = nodes.begin(); it != nodes.end(); ++it) {
      stamp[static_cast<std::size_t>(*it)] = call;
      side[static_cast<std::size_t>(*it)] = it < half ? 0 : 1;
    }
    // Separator: lower-half particles coupled to the upper half. Removing them disconnects the
    // halves, so their elimination creates no fill between the halves.
    std::vector<int> lower, upper, separator;
    for (auto it = nodes.begin(); it != nodes.end(); ++it) {
      const int v = *it;
      if (it >= half) {
        upper.push_back(v);
        continue;
      }
      bool on_cut = false;
      for (int k = start[static_cast<std::size_t>(v)];
           !on_cut && k < start[static_cast<std::size_t>(v) + 1]; ++k) {
        const auto w = static_cast<std::size_t>(adjacent[static_cast<std::size_t>(k)]);
        on_cut = stamp[w] == call && side[w] == 1;
      }
      (on_cut ? separator : lower).push_back(v);
    }
    nodes.clear();
    nodes.shrink_to_fit();
    std::sort(separator.begin(), separator.end());
    run(std::move(lower));
    run(std::move(upper));
    order.insert(order.end(), separator.begin(), separator.end());
  }
};

}  // namespace

std::vector<int> nested_dissection_order(const Eigen::SparseMatrix<double>& laplacian,
                                         const Eigen::Matrix3Xd& coordinates) {
  const auto n = static_cast<std::size_t>(laplacian.rows());
  // Symmetric adjacency from the stored lower triangle.
  std::vector<int> start(n + 1, 0);
  for (Eigen::Index col = 0; col < laplacian.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, col); it; ++it) {
      if (it.row() != col) {
        ++start[static_cast<std::size_t>(it.row()) + 1];
        ++start[static_cast<std::size_t>(col) + 1];
      }
    }
  }
  for (std::size_t v = 0; v < n; ++v) {
    start[v + 1] += start[v];
  }
  std::vector<int> adjacent(static_cast<std::size_t>(start[n]));
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (Eigen::Index col = 0; col < laplacian.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, col); it; ++it) {
      if (it.row() != col) {
        const auto r = static_cast<std::size_t>(it.row()), c = static_cast<std::size_t>(col);
        adjacent[static_cast<std::size_t>(fill[r]++)] = static_cast<int>(c);
        adjacent[static_cast<std::size_t>(fill[c]++)] = static_cast<int>(r);
      }
    }
  }
  std::vector<int> side(n, 0), stamp(n, 0), order;
  order.reserve(n);
  std::vector<int> all(n);
  for (std::size_t v = 0; v < n; ++v) {
    all[v] = static_cast<int>(v);
  }
  Dissection{start, adjacent, coordinates, side, stamp, order}.run(std::move(all));
  return order;
}

LaplacianFactor::LaplacianFactor(const Eigen::SparseMatrix<double>& laplacian,
                                 const Eigen::Matrix3Xd& coordinates)
    : order_(nested_dissection_order(laplacian, coordinates)) {
  const auto n = static_cast<std::size_t>(laplacian.rows());
  std::vector<int> position(n);
  for (std::size_t k = 0; k < n; ++k) {
    position[static_cast<std::size_t>(order_[k])] = static_cast<int>(k);
  }
  // P L P^T, lower triangle again.
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(laplacian.nonZeros()));
  for (Eigen::Index col = 0; col < laplacian.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, col); it; ++it) {
      const int a = position[static_cast<std::size_t>(it.row())];
      const int b = position[static_cast<std::size_t>(col)];
      triplets.emplace_back(std::max(a, b), std::min(a, b), it.value());
    }
  }
  Eigen::SparseMatrix<double> permuted(laplacian.rows(), laplacian.cols());
  permuted.setFromTriplets(triplets.begin(), triplets.end());
  factor_.compute(permuted);
  bool positive = factor_.info() == Eigen::Success;
  const Eigen::VectorXd& pivots = factor_.vectorD();
  for (Eigen::Index k = 0; positive && k < pivots.size(); ++k) {
    positive = pivots[k] > 0.0;
  }
  if (!positive) {
    throw NumericalError(kName,
                         "the spring Laplacian of the interior particles is singular (an interior "
                         "part of the grid is not connected to the boundary)");
  }
}

Eigen::VectorXd LaplacianFactor::solve(const Eigen::VectorXd& b) const {
  const Eigen::Index n = size();
  Eigen::VectorXd permuted(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    permuted[k] = b[order_[static_cast<std::size_t>(k)]];
  }
  const Eigen::VectorXd y = factor_.solve(permuted);
  Eigen::VectorXd x(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    x[order_[static_cast<std::size_t>(k)]] = y[k];
  }
  return x;
}

Eigen::VectorXd LaplacianFactor::solve3(const Eigen::VectorXd& b) const {
  const Eigen::Index n = size();
  Eigen::VectorXd r(3 * n);
  const auto solve_column = [&](int c) { r.segment(c * n, n) = solve(b.segment(c * n, n)); };
  // Independent const solves of one factor; each column's arithmetic is the same either way.
  if (n >= 20000) {
    tbb::parallel_for(0, 3, solve_column);
  } else {
    for (int c = 0; c < 3; ++c) {
      solve_column(c);
    }
  }
  return r;
}

TangentFrame tangent_frame(const SurfaceDerivatives& d) {
  return {d.du, d.dv, d.duu, d.duv, d.dvv};
}
TangentFrame tangent_frame(const LimitSurface& surface, const SurfacePoint& point) {
  return tangent_frame(surface.derivatives(point));
}

namespace {

// Least-squares pull-back of a 3D vector w into the parameter plane of `frame`:
// (J^T J)^-1 J^T w, J = [du dv]. False when du and dv are (nearly) parallel.
bool pull_back(const TangentFrame& frame, const Eigen::Vector3d& w, Eigen::Vector2d& out) {
  const double a = frame.du.squaredNorm(), b = frame.du.dot(frame.dv), c = frame.dv.squaredNorm();
  const double det = a * c - b * b;
  // det = |du x dv|^2: relative to a c it is sin^2 of the angle between du and dv.
  if (!(det > 1e-12 * a * c)) {
    return false;
  }
  const double wu = frame.du.dot(w), wv = frame.dv.dot(w);
  out = Eigen::Vector2d((c * wu - b * wv) / det, (a * wv - b * wu) / det);
  return true;
}

// Evaluates `to` into `out` and `out_frame`; false where the parameterisation is degenerate.
bool land(const LimitSurface& surface, const SurfacePoint& to, ClosestPoint& out,
          TangentFrame& out_frame) {
  const SurfaceDerivatives d = surface.derivatives(to);
  const Eigen::Vector3d normal = d.du.cross(d.dv);
  const double length = normal.norm();
  if (!(length > 1e-6 * d.du.norm() * d.dv.norm())) {
    return false;
  }
  out.point = to;
  out.position = d.position;
  out.normal = normal / length;
  out.distance = 0.0;
  out.on_boundary = false;
  out.converged = true;
  out_frame = tangent_frame(d);
  return true;
}

// Gauss-Newton steps of the landing point towards the foot of `goal` (the closest point of goal
// near it) while the tangential miss exceeds this fraction of the step.
constexpr double kRetractionMiss = 1e-3;
constexpr int kRetractionCorrections = 3;

}  // namespace

// The retraction of the line search: a tangent step t at surface point `from` (position x)
// becomes the parameter step delta = (J^T J)^-1 J^T t, J = [du dv] (the least-squares pull-back
// of t), walked across ptex faces (LimitSurface::walk), and the particle goes to the limit position
// there. To first order in |t| this is x + t, as is the closest point of x + t (the magnet): both
// are retractions, and a minimum of the energy on the surface does not depend on which one the
// line search uses. This one costs one patch evaluation per particle, against the Newton
// iterations of the closest-point query.
//
// The walk carries delta across an edge in parameter units, so where the neighbouring face's
// parameterisation runs at another speed or direction (around an extraordinary vertex, into the
// sub-faces of a non-quad face) the landing point can miss x + t by O(|t|) along the surface. Such
// misses fold grids whose spacing is small against the step (seen at 300,000 particles on the cap,
// around its four extraordinary vertices), so the landing point is checked: if the part of
// x + t - landing tangent to the surface there exceeds kRetractionMiss |t|, Gauss-Newton steps
// move it to the foot of x + t, which is the magnet's answer. Returns false, leaving the magnet to
// the caller, when the parameterisation is degenerate, the walk stops on the surface boundary, or
// the corrections do not converge.
bool parametric_retraction(const LimitSurface& surface, const SurfacePoint& from,
                           const Eigen::Vector3d& x, const TangentFrame& frame,
                           const Eigen::Vector3d& t, ClosestPoint& out, TangentFrame& out_frame) {
  Eigen::Vector2d first;
  if (!pull_back(frame, t, first)) {
    return false;
  }
  // Second order: d(delta) = x + J delta + 1/2 delta^T H delta + O(delta^3). Removing the tangent
  // part of the quadratic term makes the tangent displacement t + O(|t|^3), like the closest point
  // of x + t, so the L-BFGS pairs see the same curvature as with the magnet.
  const Eigen::Vector3d bend =
      0.5 * (first.x() * first.x() * frame.duu + 2.0 * first.x() * first.y() * frame.duv +
             first.y() * first.y() * frame.dvv);
  Eigen::Vector2d correction;
  if (!pull_back(frame, bend, correction)) {
    return false;
  }
  SurfacePoint to = surface.walk(from, first - correction);
  if (surface.on_boundary(to) || !land(surface, to, out, out_frame)) {
    return false;
  }
  const Eigen::Vector3d goal = x + t;
  const double allowed = kRetractionMiss * t.norm();
  for (int k = 0;; ++k) {
    const Eigen::Vector3d miss = goal - out.position;
    const Eigen::Vector3d tangential = miss - out.normal * out.normal.dot(miss);
    if (tangential.norm() <= allowed) {
      return true;
    }
    if (k == kRetractionCorrections) {
      return false;
    }
    Eigen::Vector2d step;
    if (!pull_back(out_frame, tangential, step)) {
      return false;
    }
    to = surface.walk(to, step);
    if (surface.on_boundary(to) || !land(surface, to, out, out_frame)) {
      return false;
    }
  }
}

LaplacianInverse::LaplacianInverse(const Eigen::SparseMatrix<double>& laplacian,
                                   const Eigen::Matrix3Xd& coordinates,
                                   const LbfgsOptions& options) {
  kind_ = options.preconditioner;
  if (kind_ == Preconditioner::Direct) {
    direct_ = std::make_unique<LaplacianFactor>(laplacian, coordinates);
    return;
  }
  try {
    multigrid_ = std::make_unique<Multigrid>(laplacian, true, options.multigrid);
  } catch (const NumericalError&) {
    // Only a singular Laplacian makes a coarse level indefinite: the same message as the direct
    // factorisation gives.
    throw NumericalError(kName,
                         "the spring Laplacian of the interior particles is singular (an interior "
                         "part of the grid is not connected to the boundary)");
  }
}

void LaplacianInverse::solve3(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  if (direct_) {
    x = direct_->solve3(b);
    return;
  }
  const Eigen::Index n = multigrid_->size();
  if (block_b_.rows() != n) {
    resize_huge(block_b_, n, 3);
    resize_huge(block_x_, n, 3);
  }
  if (x.size() != 3 * n) {
    resize_huge(x, 3 * n, 1);
  }
  // Column blocks <-> rows of three, in parallel chunks.
  const auto rows = [&](const auto& body) {
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, 16384),
                      [&](const tbb::blocked_range<Eigen::Index>& r) {
                        for (Eigen::Index i = r.begin(); i != r.end(); ++i) {
                          body(i);
                        }
                      });
  };
  rows([&](Eigen::Index i) {
    for (int c = 0; c < 3; ++c) {
      block_b_(i, c) = b[c * n + i];
    }
  });
  multigrid_->apply(block_b_, block_x_);
  rows([&](Eigen::Index i) {
    for (int c = 0; c < 3; ++c) {
      x[c * n + i] = block_x_(i, c);
    }
  });
}

double boundary_residual(const RelaxationProblem& problem, const Eigen::Matrix3Xd& positions) {
  const std::vector<int>& loop = problem.grid->boundary_loop;
  double residual = 0.0;
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const Eigen::Vector3d target =
        problem.boundary_targets.cols() != 0
            ? Eigen::Vector3d(problem.boundary_targets.col(static_cast<Eigen::Index>(k)))
            : Eigen::Vector3d(problem.initial_positions.col(loop[k]));
    residual = std::max(residual, (positions.col(loop[k]) - target).norm());
  }
  return residual;
}

double spring_gradient_norm(const RelaxationSetup& setup) {
  SpringEnergyOptions paper = setup.springs.options();
  paper.barrier_stiffness = 0.0;
  Eigen::Matrix3Xd gradient;
  SpringSystem(setup.grid, paper).evaluate(setup.positions, &gradient);
  return tangential_norm(setup, gradient, setup.normals);
}

void finish_result(const RelaxationSetup& setup, const RelaxationProblem& problem,
                   double initial_gradient_norm, RelaxationResult& result) {
  Eigen::Matrix3Xd gradient;
  const SpringEnergies energies = setup.springs.evaluate(setup.positions, &gradient);
  result.positions = setup.positions;
  result.points = setup.points;
  result.length_energy = energies.length;
  result.angular_energy = energies.angular;
  result.barrier_energy = energies.barrier;
  result.energy =
      setup.springs.options().barrier_stiffness > 0.0 ? EnergyKind::Robust : EnergyKind::Paper;
  result.initial_gradient_norm = initial_gradient_norm;
  result.gradient_norm = tangential_norm(setup, gradient, setup.normals);
  result.relative_gradient =
      initial_gradient_norm > 0.0 ? result.gradient_norm / initial_gradient_norm : 0.0;
  result.folded_faces = setup.springs.folded_faces(setup.positions, setup.normals);
  result.boundary = setup.slide ? BoundaryMode::Slide : BoundaryMode::Fixed;
  if (setup.slide) {
    // On the curve by construction: measured against the curve point at each final parameter.
    const std::vector<double>& start = problem.boundary_parameters.empty()
                                           ? setup.grid.boundary_parameter
                                           : problem.boundary_parameters;
    result.boundary_parameters = setup.curve_s;
    result.boundary_residual = 0.0;
    result.boundary_slide = 0.0;
    for (std::size_t k = 0; k < setup.curve_s.size(); ++k) {
      const double s = setup.curve_s[k] - std::floor(setup.curve_s[k]);
      const Eigen::Vector3d on_curve = setup.target.surface().position((*setup.curve)(s));
      const int p = setup.grid.boundary_loop[k];
      result.boundary_residual =
          std::max(result.boundary_residual, (setup.positions.col(p) - on_curve).norm());
      result.boundary_slide =
          std::max(result.boundary_slide, std::abs(setup.curve_s[k] - start[k]));
      result.boundary_parameters[k] = s;
    }
  } else {
    result.boundary_parameters = problem.boundary_parameters.empty() ? setup.grid.boundary_parameter
                                                                     : problem.boundary_parameters;
    result.boundary_residual = boundary_residual(problem, setup.positions);
  }
  result.rest_scale = problem.rest_scale;
  result.rest_scale_mode = problem.rest_scale_mode;
  result.converged = is_converged(result.reason);
}

long long now_ticks() {
  return std::chrono::steady_clock::now().time_since_epoch().count();
}

double seconds_since(long long start_ticks) {
  const auto elapsed = std::chrono::steady_clock::now().time_since_epoch().count() - start_ticks;
  return std::chrono::duration<double>(std::chrono::steady_clock::duration(elapsed)).count();
}

}  // namespace elastic::solver_detail
