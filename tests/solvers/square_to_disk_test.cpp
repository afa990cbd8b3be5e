// The square-to-round case of the fast solver: the whole square of a plane (four 90-degree boundary
// corners) onto the round boundary region of a cap, with the boundary fixed at arc length. The
// corners must open to 180 degrees on the round side, and the energy minimum folds faces next to
// them (the explicit solver run to equilibrium ends with folded faces there and a lower energy).
// The fast solver must not stall: it settles every particle except a few held next to the corners
// and says so (FoldConstrained, held particles listed), without folding anything.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "elastic/mapping/initial_map.h"
#include "elastic/metrics/map_metrics.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/region_spec.h"
#include "elastic/sampling/sample_region.h"
#include "elastic/shapes/procedural_shapes.h"
#include "elastic/solvers/relaxation.h"
#include "elastic/surface/limit_surface.h"

namespace elastic {
namespace {

// A region of the procedural plane mapped onto a region of another surface by the naive disk map,
// with the boundary rest scale: the relaxation problem of the tests below, and everything it points
// into (construct in place; the members reference each other).
struct NaiveProblem {
  LimitSurface plane, surface;
  SurfaceProjector plane_projector, projector;
  Region source, target;
  ParticleGrid grid;
  RelaxationProblem problem;

  NaiveProblem(const ShapeOptions& shape, const PolygonMesh& target_mesh,
               const std::string& source_spec, long particles, bool adaptive)
      : plane(make_plane(shape)),
        surface(target_mesh),
        plane_projector(plane),
        projector(surface),
        source(make_region(plane_projector, parse_region_spec(source_spec))),
        target(make_region(projector, parse_region_spec("boundary"))) {
    SampleRegionOptions sampling;
    sampling.layout.particles = particles;
    sampling.adaptive = adaptive;
    // The goblet cases were built on the grid of the paper's Jacobi sweeps (300, unconverged on
    // the plane disk); the converged Newton equilibrium of the default makes the goblet map
    // converge without untangling, so these fixtures keep the sweeps to keep exercising it.
    sampling.sampling.method = SamplingMethod::Jacobi;
    grid = sample_region(source, plane_projector, sampling).grid;
    const RegionDiskMap source_disk(source), target_disk(target);
    const InitialMap naive = naive_map(grid, source_disk, target_disk);
    problem.grid = &grid;
    problem.target = &projector;
    problem.initial_positions = naive.positions;
    problem.initial_points = naive.points;
    problem.rest_scale = rest_scale_factor(
        RestScale::Boundary, {.source_boundary_length = source.boundary_curve().length(),
                              .target_boundary_length = target.boundary_curve().length()});
  }
};

// Folds the start of `naive`: the interior particle nearest the source region's centre is
// reflected across one of its grid neighbours (x_p <- 2 x_q - x_p, then onto the target surface),
// so that the faces around it invert in the report's sense (face_folds.h). The naive disk map of
// the goblet's stem is fold-free by that test; until 2026-12-04 these fixtures relied on its start
// being folded by the solver's old per-corner test, which the report did not share.
void fold_the_start(NaiveProblem& naive) {
  const ParticleGrid& grid = naive.grid;
  const Eigen::Matrix3Xd source = grid.source_positions();
  int p = -1;
  for (int i = 0; i < grid.num_particles(); ++i) {
    if (grid.is_boundary[static_cast<std::size_t>(i)]) {
      continue;
    }
    if (p < 0 || source.col(i).norm() < source.col(p).norm()) {
      p = i;
    }
  }
  ASSERT_GE(p, 0);
  int q = -1;
  for (const Spring& s : grid.springs) {
    const int other = s.i == p ? s.j : (s.j == p ? s.i : -1);
    if (other >= 0 && !grid.is_boundary[static_cast<std::size_t>(other)]) {
      q = other;
    }
  }
  ASSERT_GE(q, 0);
  RelaxationProblem& problem = naive.problem;
  const Eigen::Vector3d reflected =
      2.0 * problem.initial_positions.col(q) - problem.initial_positions.col(p);
  const ClosestPoint c = naive.projector.closest(reflected);
  problem.initial_positions.col(p) = c.position;
  problem.initial_points[static_cast<std::size_t>(p)] = c.point;
}

TEST(SquareToDisk, SettlesEveryParticleExceptAFewHeldAtTheCorners) {
  const ShapeOptions shape{.faces = ShapeFaces::Quads, .resolution = 16, .scale = 1.0};
  // Below ~1,000 particles the minimum does not fold.
  const NaiveProblem naive(shape, make_cap(shape), "boundary", 2000, false);
  const ParticleGrid& grid = naive.grid;
  const RelaxationProblem& problem = naive.problem;
  const LimitSurface& cap = naive.surface;
  RelaxationOptions options;
  options.energy = EnergyKind::Paper;  // the paper's energy: its minimum folds
  const RelaxationResult result = relax(problem, options);

  // Before the fix the line search stalled on this case (LineSearchFailed at a relative gradient
  // of 2e-2..2e-1, zero folds): the same corners were halved into and blocked at every step.
  EXPECT_LT(result.iterations, 200);
  EXPECT_EQ(result.folded_faces, 0);
  EXPECT_LT(result.length_energy + result.angular_energy, result.initial_energy);
  ASSERT_EQ(result.reason, StopReason::FoldConstrained);  // at 2,000 particles the minimum folds
  // The explicit integrator run from there (RelaxationOptions::untangle_steps) finds no fold-free
  // equilibrium with lower energy: the stop stands.
  EXPECT_EQ(result.untangle_steps, options.untangle_steps);
  EXPECT_FALSE(result.untangled);

  // Held particles are few and sit next to the square's corners (the plane is [-1, 1]^2: a corner
  // is at distance sqrt(2) from the centre; "next to" = within a quarter of the side).
  ASSERT_FALSE(result.held_particles.empty());
  EXPECT_LE(result.held_particles.size(), grid.num_particles() / 10u);
  const Eigen::Matrix3Xd source_positions = grid.source_positions();
  for (const int p : result.held_particles) {
    ASSERT_FALSE(grid.is_boundary[static_cast<std::size_t>(p)]);
    const Eigen::Vector3d s = source_positions.col(p);
    const double to_corner =
        (Eigen::Vector2d(std::abs(s.x()), std::abs(s.y())) - Eigen::Vector2d(1.0, 1.0)).norm();
    EXPECT_LT(to_corner, 0.5) << "held particle " << p << " at " << s.transpose();
  }

  // Every other interior particle is at equilibrium: the tangential spring gradient over them,
  // recomputed here from the energy and the surface normals, meets the relative tolerance (1e-6
  // of the initial |P g|; 1e-5 leaves room for the different summation order).
  Eigen::Matrix3Xd gradient;
  SpringSystem(grid, {.rest_scale = problem.rest_scale}).evaluate(result.positions, &gradient);
  std::vector<char> held(static_cast<std::size_t>(grid.num_particles()), 0);
  for (const int p : result.held_particles) {
    held[static_cast<std::size_t>(p)] = 1;
  }
  double free_sum = 0.0;
  for (int p = 0; p < grid.num_particles(); ++p) {
    if (grid.is_boundary[static_cast<std::size_t>(p)] || held[static_cast<std::size_t>(p)]) {
      continue;
    }
    const SurfaceDerivatives d = cap.derivatives(result.points[static_cast<std::size_t>(p)]);
    const Eigen::Vector3d n = d.du.cross(d.dv).normalized();
    const Eigen::Vector3d g = gradient.col(p);
    free_sum += (g - n * n.dot(g)).squaredNorm();
  }
  EXPECT_LE(std::sqrt(free_sum), 1e-5 * result.initial_gradient_norm);
}

// A disk of the plane onto the whole goblet (foot, stem and cup, open at the rim), started from a
// folded map (fold_the_start). The fold-guarded line search does not untangle it and L-BFGS stops
// against its no-fold constraint; the explicit integrator run from there
// (RelaxationOptions::untangle_steps) passes through folded states and reaches a fold-free
// equilibrium of lower energy, which is taken.
TEST(Untangle, ExplicitStepsLeaveAFoldConstrainedStopOnTheGoblet) {
  const ShapeOptions shape{.faces = ShapeFaces::Quads, .resolution = 32, .scale = 1.0};
  NaiveProblem naive(shape, make_goblet(shape), "disk:0,0,0,0.9", 1000, true);
  fold_the_start(naive);
  const RelaxationProblem& problem = naive.problem;

  RelaxationOptions without;
  without.energy = EnergyKind::Paper;
  without.untangle_steps = 0;
  const RelaxationResult stuck = relax(problem, without);
  ASSERT_EQ(stuck.reason, StopReason::FoldConstrained)
      << "the case no longer needs untangling: " << to_string(stuck.reason);
  EXPECT_GT(stuck.initial_folded_faces, 0);
  EXPECT_FALSE(stuck.held_particles.empty());

  RelaxationOptions paper;
  paper.energy = EnergyKind::Paper;
  const RelaxationResult result = relax(problem, paper);
  EXPECT_TRUE(result.untangled);
  EXPECT_GT(result.untangle_steps, 0);
  EXPECT_LE(result.untangle_steps, RelaxationOptions{}.untangle_steps);
  EXPECT_TRUE(result.converged) << to_string(result.reason);
  EXPECT_LE(result.relative_gradient, 1e-6);
  EXPECT_EQ(result.folded_faces, 0);
  EXPECT_TRUE(result.held_particles.empty());
  EXPECT_LT(result.length_energy + result.angular_energy,
            stuck.length_energy + stuck.angular_energy);
  EXPECT_EQ(result.boundary_residual, 0.0);
  // The fast solver's own record is kept: its iterations, and its initial state.
  EXPECT_EQ(result.iterations, stuck.iterations);
  EXPECT_EQ(result.initial_energy, stuck.initial_energy);
}

// The smallest singular value of every triangle of both splits of each face (and of every
// triangle face), between source and target positions, divided by sigma: computed here from the
// 2 x 2 metric tensors (eigenvalues of (S^T S)^-1 T^T T), independently of the solver.
double smallest_stretch(const ParticleGrid& grid, const Eigen::Matrix3Xd& target, double sigma) {
  const Eigen::Matrix3Xd source = grid.source_positions();
  double smallest = std::numeric_limits<double>::infinity();
  for (const auto fh : grid.mesh.faces()) {
    std::vector<int> v;
    for (const auto vh : grid.mesh.fv_range(fh)) {
      v.push_back(vh.idx());
    }
    const int k = static_cast<int>(v.size());
    for (int c = 0; c < k; ++c) {
      const int i = v[c], a = v[(c + 1) % k], b = v[(c + k - 1) % k];
      Eigen::Matrix<double, 3, 2> S, T;
      S << source.col(a) - source.col(i), source.col(b) - source.col(i);
      T << target.col(a) - target.col(i), target.col(b) - target.col(i);
      const Eigen::Matrix2d M = (S.transpose() * S).inverse() * (T.transpose() * T);
      const double tr = M.trace(), det = M.determinant();
      const double low = 0.5 * (tr - std::sqrt(std::max(tr * tr - 4.0 * det, 0.0)));
      smallest = std::min(smallest, std::sqrt(std::max(low, 0.0)) / sigma);
    }
  }
  return smallest;
}

// The robust energy (the default) on the same case: the barrier keeps every triangle of both
// quad splits from collapsing, so the relaxation converges to a fold-free minimum instead of
// stopping against the no-fold constraint, and its smallest stretch stays above the robustness
// bar (0.2) where the paper's energy leaves slivers.
TEST(SquareToDisk, RobustEnergyConvergesWithoutSlivers) {
  const ShapeOptions shape{.faces = ShapeFaces::Quads, .resolution = 16, .scale = 1.0};
  const NaiveProblem naive(shape, make_cap(shape), "boundary", 2000, false);
  const RelaxationResult result = relax(naive.problem, RelaxationOptions{});
  EXPECT_TRUE(result.converged) << to_string(result.reason);
  EXPECT_EQ(result.folded_faces, 0);
  EXPECT_TRUE(result.held_particles.empty());
  // The barrier at the opened corners makes the L^-1-based direction too long at every
  // iteration. Both answers to it (LbfgsOptions::scale_h0 and step_memory, on by default) reach
  // the same minimum with fewer energy evaluations, and together with the fewest. Measured: 107
  // evaluations in 73 iterations; scaled H0 alone 120 in 72; step memory alone 161 in 87; every
  // line search from the unscaled full step 205 in 77. The counts move with the start's round-off
  // (the cap's conformal layout solved as one complex system instead of two real ones moved them
  // from 102, 122, 142 and 244), hence the margin on the last comparison.
  const auto with = [&](bool scale, bool memory) {
    RelaxationOptions options;
    options.lbfgs.scale_h0 = scale;
    options.lbfgs.step_memory = memory;
    RelaxationResult other = relax(naive.problem, options);
    EXPECT_TRUE(other.converged) << to_string(other.reason);
    const double energy = result.length_energy + result.angular_energy;
    EXPECT_NEAR(energy, other.length_energy + other.angular_energy, 1e-6 * energy);
    return other.evaluations;
  };
  EXPECT_LT(result.evaluations, with(false, true));
  EXPECT_LT(result.evaluations, with(true, false));
  EXPECT_LT(result.evaluations, 0.6 * with(false, false));
  const double robust = smallest_stretch(naive.grid, result.positions, naive.problem.rest_scale);
  EXPECT_GE(robust, 0.2);
  RelaxationOptions paper;
  paper.energy = EnergyKind::Paper;
  const RelaxationResult plain = relax(naive.problem, paper);
  EXPECT_LT(smallest_stretch(naive.grid, plain.positions, naive.problem.rest_scale), robust);
}

// The distortion term trades length for angles: a flat disk onto the whole cap (a hump, more area
// than the boundary's rest scale gives) relaxed with E_sd on (lambda 0.5) has a lower symmetric
// Dirichlet energy and mean angle error than the robust default, and a higher length energy; both
// converge fold-free.
TEST(SquareToDisk, DistortionWeightTradesLengthForAngles) {
  const ShapeOptions shape{.faces = ShapeFaces::Quads, .resolution = 16, .scale = 1.0};
  const NaiveProblem naive(shape, make_cap(shape), "disk:0,0,0,0.8", 1000, false);
  const auto measured = [&](double lambda) {
    RelaxationOptions options;
    options.distortion_stiffness = lambda;
    const RelaxationResult result = relax(naive.problem, options);
    EXPECT_TRUE(result.converged) << lambda << ": " << to_string(result.reason);
    EXPECT_EQ(result.folded_faces, 0) << lambda;
    EXPECT_EQ(result.distortion_energy > 0.0, lambda > 0.0) << lambda;
    return measure_on_target(naive.grid, naive.surface, naive.problem.rest_scale, result.positions,
                             result.points);
  };
  const MapMetrics plain = measured(0.0), weighed = measured(0.5);
  EXPECT_EQ(weighed.folds, 0);
  // Measured: SD 4.4932 -> 4.4865, mean angle error 3.89 -> 3.42 degrees, length energy 0.0659 ->
  // 0.0664 (the cap's SD is mostly its area excess, which no map of this boundary removes).
  EXPECT_LT(weighed.symmetric_dirichlet, plain.symmetric_dirichlet - 0.003);
  EXPECT_LT(weighed.angle_error_mean_deg, 0.95 * plain.angle_error_mean_deg);
  EXPECT_GT(weighed.length_energy, plain.length_energy);
}

// A relaxation in phases (the held phase after a slide, the barrier run after untangling) judges
// every phase against the first phase's gradient (RelaxationProblem::reference_gradient_norm). A
// restart from an equilibrium with that reference is already converged: nothing moves. Before,
// the held phase after a slide was judged against its own, already tiny, start gradient and had
// to reduce it a million times more: round-off forbids that, and the whole camel head (a disk onto
// a mesh with one boundary loop) failed "line search found no fold-free decrease" at a gradient
// of 3e-6 (relative 1.9 to the held start).
TEST(SquareToDisk, RestartFromEquilibriumWithTheFirstReferenceIsConverged) {
  const ShapeOptions shape{.faces = ShapeFaces::Quads, .resolution = 16, .scale = 1.0};
  const NaiveProblem naive(shape, make_cap(shape), "disk:0,0,0,0.8", 500, false);
  const RelaxationResult first = relax(naive.problem, RelaxationOptions{});
  ASSERT_TRUE(first.converged) << to_string(first.reason);
  ASSERT_GT(first.initial_gradient_norm, 0.0);
  RelaxationProblem again = naive.problem;
  again.initial_positions = first.positions;
  again.initial_points = first.points;
  again.reference_gradient_norm = first.initial_gradient_norm;
  const RelaxationResult second = relax(again, RelaxationOptions{});
  EXPECT_TRUE(second.converged) << to_string(second.reason);
  EXPECT_EQ(second.iterations, 0);
  EXPECT_EQ(second.initial_gradient_norm, first.initial_gradient_norm);
  EXPECT_LE(second.relative_gradient, RelaxationOptions{}.relative_gradient_tolerance);
  EXPECT_EQ((second.positions - first.positions).cwiseAbs().maxCoeff(), 0.0);
}

// C_a in effect: the paper's energy and the faithful solver keep C_a = C, the robust energy softens
// it to kRobustAngularStiffness C; a value set by the caller always wins.
TEST(AngularStiffness, DefaultsPerEnergyAndOverride) {
  RelaxationOptions options;
  options.stiffness = 2.0;
  EXPECT_EQ(angular_stiffness(options), 2.0 * kRobustAngularStiffness);
  options.energy = EnergyKind::Paper;
  EXPECT_EQ(angular_stiffness(options), 2.0 * kPaperAngularStiffness);
  options.energy = EnergyKind::Robust;
  options.solver = SolverKind::Faithful;
  EXPECT_EQ(angular_stiffness(options), 2.0 * kPaperAngularStiffness);
  options.angular_stiffness = 0.7;
  EXPECT_EQ(angular_stiffness(options), 0.7);
}

// Why the robust default is softer: the square's corners must open onto the cap's round boundary,
// and stiff angular springs hold the map away from the length energy's minimum there. With the
// robust default the relaxed map's length energy (eq. 13, the spring sum over sigma k, measured
// here from the positions) is lower than with C_a = C, with the reported C_a.
TEST(AngularStiffness, RobustDefaultKeepsLengthsBetterOnASquareIntoADisk) {
  const ShapeOptions shape{.faces = ShapeFaces::Quads, .resolution = 16, .scale = 1.0};
  const NaiveProblem naive(shape, make_cap(shape), "boundary", 500, false);
  const auto length_error = [&](const Eigen::Matrix3Xd& x) {
    double error = 0.0, total = 0.0;
    for (const Spring& s : naive.grid.springs) {
      const double rest = naive.problem.rest_scale * s.rest;
      error += std::pow((x.col(s.j) - x.col(s.i)).norm() - rest, 2);
      total += rest * rest;
    }
    return error / total;
  };
  const RelaxationResult soft = relax(naive.problem, RelaxationOptions{});
  RelaxationOptions stiff_options;
  stiff_options.angular_stiffness = 1.0;
  const RelaxationResult stiff = relax(naive.problem, stiff_options);
  ASSERT_TRUE(soft.converged) << to_string(soft.reason);
  ASSERT_TRUE(stiff.converged) << to_string(stiff.reason);
  EXPECT_EQ(soft.angular_stiffness, kRobustAngularStiffness);
  EXPECT_EQ(stiff.angular_stiffness, 1.0);
  EXPECT_EQ(soft.folded_faces, 0);
  // Measured at 0.3 C: 0.2173 against 0.2194 (500 particles; the whole square onto the whole cap is
  // extreme, the corners open to 180 degrees; on the robustness cases the gain is 2-37%).
  EXPECT_LT(length_error(soft.positions), length_error(stiff.positions));
}

// The robust energy from the folded goblet start (fold_the_start): the folded start is untangled
// with the paper's energy first (the barrier cannot cross a fold), then the barrier run converges
// fold-free. C_a is pinned at 0.3 C: from this start the barrier run with the default 0.25 C
// unfolds the reflected particle by itself (no untangling phase), and the phase is what is tested
// here.
TEST(Untangle, RobustEnergyUntanglesThenConvergesOnTheGoblet) {
  const ShapeOptions shape{.faces = ShapeFaces::Quads, .resolution = 32, .scale = 1.0};
  NaiveProblem naive(shape, make_goblet(shape), "disk:0,0,0,0.85", 1000, true);
  fold_the_start(naive);
  RelaxationOptions options;
  options.angular_stiffness = 0.3;
  // Every line search from the unscaled full step, as when this start was chosen: it is the
  // untangling phase that is tested here, whatever the line search's first trial.
  options.lbfgs.step_memory = false;
  options.lbfgs.scale_h0 = false;
  const RelaxationResult result = relax(naive.problem, options);
  EXPECT_GT(result.initial_folded_faces, 0);
  EXPECT_EQ(result.untangle_phases, 1);
  EXPECT_TRUE(result.converged) << to_string(result.reason);
  EXPECT_EQ(result.folded_faces, 0);
  EXPECT_GT(smallest_stretch(naive.grid, result.positions, naive.problem.rest_scale), 0.0);
}

}  // namespace
}  // namespace elastic
