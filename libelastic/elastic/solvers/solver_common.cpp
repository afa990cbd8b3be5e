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
          .angular_stiffness = angular_stiffness(options),
          .rest_scale = problem.rest_scale,
          .barrier_stiffness = barrier ? options.barrier_stiffness : 0.0,
          .barrier_sigma = options.barrier_sigma,
          .distortion_stiffness = barrier ? options.distortion_stiffness : 0.0};
}

void check_problem(const RelaxationProblem& problem, const RelaxationOptions& options,
                   const RelaxationSetup& setup) {
  const ParticleGrid& grid = setup.grid;
  const int num_particles = setup.num_particles;
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
      !(options.absolute_gradient_tolerance >= 0.0) || !(options.slide_tolerance >= 0.0)) {
    throw InvalidInputError(kName, "gradient tolerances must be non-negative");
  }
  if (options.max_iterations < 0 || options.frame_interval < 1 || options.threads < 0) {
    throw InvalidInputError(kName, "max_iterations, frame_interval or threads out of range");
  }
  for (std::size_t p = 0; p < P; ++p) {
    if (!problem.initial_points[p].valid() ||
        problem.initial_points[p].face >= setup.target.surface().num_faces()) {
      throw InvalidInputError(kName,
                              "particle " + std::to_string(p) + " has no valid surface point");
    }
  }
}

// The free particles: the interior ones, then (sliding boundary) the boundary loop's, with their
// curve parameters.
void choose_free_particles(const RelaxationProblem& problem, const RelaxationOptions& options,
                           RelaxationSetup& setup) {
  const ParticleGrid& grid = setup.grid;
  const auto P = static_cast<std::size_t>(setup.num_particles);
  setup.interior_index.assign(P, -1);
  setup.is_free.assign(P, 0);
  const auto make_free = [&](std::size_t p) {
    setup.interior_index[p] = static_cast<int>(setup.interior.size());
    setup.is_free[p] = 1;
    setup.interior.push_back(static_cast<int>(p));
  };
  if (options.boundary == BoundaryMode::Free) {
    // Every particle but the pinned ones (which remove the translations, and with them the spring
    // Laplacian's null space).
    std::vector<char> pinned(P, 0);
    for (const int p : problem.pinned) {
      if (p < 0 || static_cast<std::size_t>(p) >= P) {
        throw InvalidInputError(kName, "pinned particle " + std::to_string(p) + " out of range");
      }
      pinned[static_cast<std::size_t>(p)] = 1;
    }
    if (problem.pinned.empty()) {
      throw InvalidInputError(kName, "a free boundary needs at least one pinned particle");
    }
    for (std::size_t p = 0; p < P; ++p) {
      if (pinned[p] == 0) {
        make_free(p);
      }
    }
    setup.sliding.assign(setup.interior.size(), -1);
    setup.free_boundary = true;
    return;
  }
  for (std::size_t p = 0; p < P; ++p) {
    if (!grid.is_boundary[p]) {
      make_free(p);
    }
  }
  setup.sliding.assign(setup.interior.size(), -1);
  setup.slide = options.boundary == BoundaryMode::Slide && options.solver == SolverKind::Fast;
  if (!setup.slide) {
    return;
  }
  if (!problem.boundary_curve) {
    throw InvalidInputError(kName, "a sliding boundary needs the target boundary curve");
  }
  const std::vector<double>& start =
      problem.boundary_parameters.empty() ? grid.boundary_parameter : problem.boundary_parameters;
  if (start.size() != grid.boundary_loop.size()) {
    throw InvalidInputError(kName, "boundary parameters do not match the boundary loop");
  }
  setup.curve = &problem.boundary_curve;
  setup.curve_s = start;
  setup.curve_speed.assign(start.size(), 0.0);
  for (std::size_t k = 0; k < grid.boundary_loop.size(); ++k) {
    make_free(static_cast<std::size_t>(grid.boundary_loop[k]));
    setup.sliding.push_back(static_cast<int>(k));
  }
}

// Positions, surface points and unit normals du x dv / |du x dv| at the given surface points (the
// fold test and the tangent projection need them for every particle; interior ones are refreshed
// by each retraction), in fresh buffers advised before they are written (core/huge_pages.h).
void place_particles(const RelaxationProblem& problem, RelaxationSetup& setup) {
  const auto P = static_cast<std::size_t>(setup.num_particles);
  resize_huge(setup.positions, 3, setup.num_particles);
  setup.positions = problem.initial_positions;
  setup.points.reserve(P);
  advise_huge_pages(setup.points.data(), P * sizeof(SurfacePoint));
  setup.points.assign(problem.initial_points.begin(), problem.initial_points.end());

  resize_huge(setup.normals, 3, setup.num_particles);
  const LimitSurface& surface = setup.target.surface();
  tbb::parallel_for(tbb::blocked_range<int>(0, setup.num_particles, 256),
                    [&](const tbb::blocked_range<int>& range) {
                      for (int p = range.begin(); p != range.end(); ++p) {
                        const SurfaceDerivatives d = surface.derivatives(setup.points[p]);
                        const Eigen::Vector3d n = d.du.cross(d.dv);
                        const double length = n.norm();
                        if (length > 1e-300) {
                          setup.normals.col(p) = n / length;
                        } else {
                          // Degenerate parameterisation (a singular corner): ask the magnet.
                          setup.normals.col(p) =
                              setup.target.closest(setup.positions.col(p), setup.points[p]).normal;
                        }
                      }
                    });
}

}  // namespace

RelaxationSetup::RelaxationSetup(const RelaxationProblem& problem, const RelaxationOptions& options)
    : grid(checked_grid(problem)),
      target(*problem.target),
      springs(*problem.grid, energy_options(problem, options)),
      num_particles(problem.grid->num_particles()) {
  check_problem(problem, options, *this);
  choose_free_particles(problem, options, *this);
  place_particles(problem, *this);
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
  const double stiffness = std::max(options.stiffness, angular_stiffness(options));
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

void add_normal_motion(const RelaxationSetup& setup, const Eigen::Matrix3Xd& normal_gradient,
                       const std::vector<SurfaceDerivatives>* frames, Eigen::Matrix3Xd& gradient) {
  const auto n = static_cast<Eigen::Index>(setup.interior.size());
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, 256),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
                      for (Eigen::Index k = range.begin(); k != range.end(); ++k) {
                        const auto kk = static_cast<std::size_t>(k);
                        const int p = setup.interior[kk];
                        const Eigen::Vector3d v = normal_gradient.col(p);
                        if (v.isZero(0.0)) {
                          continue;
                        }
                        const SurfaceDerivatives frame =
                            frames != nullptr
                                ? (*frames)[kk]
                                : tangent_frame(setup.target.surface(),
                                                setup.points[static_cast<std::size_t>(p)]);
                        gradient.col(p) += LimitSurface::normal_variation_adjoint(frame, v);
                      }
                    });
}

double spring_gradient_norm(const RelaxationSetup& setup) {
  Eigen::Matrix3Xd gradient;
  setup.springs.evaluate_springs(setup.positions, &gradient);
  return tangential_norm(setup, gradient, setup.normals);
}

void finish_result(RelaxationSetup& setup, const RelaxationProblem& problem,
                   double initial_gradient_norm, RelaxationResult& result) {
  Eigen::Matrix3Xd gradient, normal_gradient;
  const SpringEnergies energies =
      setup.springs.evaluate(setup.positions, &gradient, &setup.normals, &normal_gradient);
  add_normal_motion(setup, normal_gradient, nullptr, gradient);
  result.length_energy = energies.length;
  result.angular_energy = energies.angular;
  result.barrier_energy = energies.barrier;
  result.distortion_energy = energies.distortion;
  result.angular_stiffness = setup.springs.options().angular_stiffness;
  result.energy = setup.springs.options().triangle_terms() ? EnergyKind::Robust : EnergyKind::Paper;
  result.initial_gradient_norm = initial_gradient_norm;
  result.gradient_norm = tangential_norm(setup, gradient, setup.normals);
  result.relative_gradient =
      initial_gradient_norm > 0.0 ? result.gradient_norm / initial_gradient_norm : 0.0;
  result.folded_faces = setup.springs.folded_faces(setup.positions, setup.normals);
  result.boundary = setup.slide ? BoundaryMode::Slide : BoundaryMode::Fixed;
  if (setup.free_boundary) {
    result.boundary = BoundaryMode::Free;
    result.boundary_parameters = setup.grid.boundary_parameter;
    result.boundary_residual = 0.0;
    for (const int p : problem.pinned) {
      result.boundary_residual =
          std::max(result.boundary_residual,
                   (setup.positions.col(p) - problem.initial_positions.col(p)).norm());
    }
  } else if (setup.slide) {
    // On the curve by construction: measured against the curve point at each final parameter.
    result.boundary_parameters = setup.curve_s;
    result.boundary_residual = 0.0;
    for (std::size_t k = 0; k < setup.curve_s.size(); ++k) {
      const double s = setup.curve_s[k] - std::floor(setup.curve_s[k]);
      const Eigen::Vector3d on_curve = setup.target.surface().position((*setup.curve)(s));
      const int p = setup.grid.boundary_loop[k];
      result.boundary_residual =
          std::max(result.boundary_residual, (setup.positions.col(p) - on_curve).norm());
      result.boundary_parameters[k] = s;
    }
    result.boundary_slide = boundary_slide(boundary_start(problem), result.boundary_parameters);
  } else {
    result.boundary_parameters = problem.boundary_parameters.empty() ? setup.grid.boundary_parameter
                                                                     : problem.boundary_parameters;
    result.boundary_residual = boundary_residual(problem, setup.positions);
  }
  result.rest_scale = problem.rest_scale;
  result.rest_scale_mode = problem.rest_scale_mode;
  result.converged = is_converged(result.reason);
  result.positions = std::move(setup.positions);  // moved, not copied: the setup is done with them
  result.points = std::move(setup.points);
}

const std::vector<double>& boundary_start(const RelaxationProblem& problem) {
  return problem.boundary_parameters.empty() ? problem.grid->boundary_parameter
                                             : problem.boundary_parameters;
}

double boundary_slide(const std::vector<double>& start, const std::vector<double>& end) {
  double slide = 0.0;
  for (std::size_t k = 0; k < start.size() && k < end.size(); ++k) {
    const double d = std::abs(end[k] - start[k]);
    const double wrapped = d - std::floor(d);
    slide = std::max(slide, std::min(wrapped, 1.0 - wrapped));
  }
  return slide;
}

}  // namespace elastic::solver_detail
