#include "elastic/mapping/refine_map.h"

#include <chrono>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/particles/detail/parents_closest.h"

namespace elastic {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The boundary parameter of every particle (-1 inside).
std::vector<double> particle_parameters(const ParticleGrid& grid) {
  std::vector<double> s(static_cast<size_t>(grid.num_particles()), -1.0);
  for (size_t k = 0; k < grid.boundary_loop.size(); ++k) {
    s[static_cast<size_t>(grid.boundary_loop[k])] = grid.boundary_parameter[k];
  }
  return s;
}

// Step 1: subdivide on the source, interior particles averaged on the source disk. A particle the
// disk map cannot place gets NaN coordinates, so its children fall back to the magnet.
GridSubdivisionResult subdivide_on_source(const ParticleGrid& coarse,
                                          const SurfaceProjector& source,
                                          const RegionDiskMap& source_disk,
                                          const std::string& name) {
  const int nc = coarse.num_particles();
  GridSubdivisionOptions subdivision;
  subdivision.name = name;
  subdivision.plane_coordinates.resize(static_cast<size_t>(nc));
  for (int i = 0; i < nc; ++i) {
    Eigen::Vector2d disk;
    if (!source_disk.to_disk(coarse.source_points[static_cast<size_t>(i)], disk)) {
      disk.setConstant(std::numeric_limits<double>::quiet_NaN());
    }
    subdivision.plane_coordinates[static_cast<size_t>(i)] = disk;
  }
  subdivision.plane_to_surface = [&](const Eigen::Vector2d& disk, SurfacePoint& p) {
    return source_disk.from_disk(disk, p);
  };
  subdivision.boundary_point = [&](double s) { return source_disk.boundary_point(s); };
  return subdivide_grid(coarse, source, source_disk.region().boundary_curve(), subdivision);
}

// Step 2: the refined particles' start on the target (file comment): an old particle where it
// was relaxed, a new boundary particle on the target disk's boundary at its parameter, a new
// interior one at the closest point of its parents' mean (warm-started at the first parent).
// The boundary targets are the boundary particles' starts.
RelaxationProblem initial_placement(const GridSubdivisionResult& refined,
                                    const RelaxationResult& coarse, const SurfaceProjector& target,
                                    const RegionDiskMap& target_disk) {
  const LimitSurface& target_surface = target.surface();
  const int nf = refined.grid.num_particles();
  const std::vector<double> parameter = particle_parameters(refined.grid);
  RelaxationProblem problem;
  problem.target = &target;
  problem.initial_positions.resize(3, nf);
  problem.initial_points.resize(static_cast<size_t>(nf));
  std::vector<int> magnet;
  for (int p = 0; p < nf; ++p) {
    const SubdivisionParents& parents = refined.parents[static_cast<size_t>(p)];
    if (parents.count == 1) {
      problem.initial_positions.col(p) = coarse.positions.col(parents.parent[0]);
      problem.initial_points[static_cast<size_t>(p)] =
          coarse.points[static_cast<size_t>(parents.parent[0])];
    } else if (parameter[static_cast<size_t>(p)] >= 0.0) {
      const SurfacePoint q = target_disk.boundary_point(parameter[static_cast<size_t>(p)]);
      problem.initial_points[static_cast<size_t>(p)] = q;
      problem.initial_positions.col(p) = target_surface.position(q);
    } else {
      magnet.push_back(p);
    }
  }
  const std::vector<ClosestPoint> answers = detail::closest_to_parents_mean(
      target, refined.parents, magnet, coarse.positions, coarse.points);
  for (size_t k = 0; k < magnet.size(); ++k) {
    problem.initial_positions.col(magnet[k]) = answers[k].position;
    problem.initial_points[static_cast<size_t>(magnet[k])] = answers[k].point;
  }
  const std::vector<int>& loop = refined.grid.boundary_loop;
  problem.boundary_targets.resize(3, static_cast<Eigen::Index>(loop.size()));
  for (size_t k = 0; k < loop.size(); ++k) {
    problem.boundary_targets.col(static_cast<Eigen::Index>(k)) =
        problem.initial_positions.col(loop[k]);
  }
  return problem;
}

// The level's report from the relaxation of the refined grid.
void record_relaxation(const RelaxationResult& relaxation, RefinementLevel& report) {
  report.iterations = relaxation.iterations;
  report.converged = relaxation.converged;
  report.reason = relaxation.reason;
  report.initial_folded_faces = relaxation.initial_folded_faces;
  report.folded_faces = relaxation.folded_faces;
  report.initial_energy = relaxation.initial_energy;
  report.energy = relaxation.length_energy + relaxation.angular_energy;
}

}  // namespace

RefineMapResult refine_map(const ParticleGrid& grid, const RelaxationResult& relaxed,
                           const SurfaceProjector& source, const RegionDiskMap& source_disk,
                           const SurfaceProjector& target, const RegionDiskMap& target_disk,
                           const RefineMapOptions& options) {
  const std::string& name = options.name;
  const int np = grid.num_particles();
  if (relaxed.positions.cols() != np || static_cast<int>(relaxed.points.size()) != np) {
    throw InvalidInputError(name, "relaxed placement has " +
                                      std::to_string(relaxed.positions.cols()) + " positions for " +
                                      std::to_string(np) + " particles");
  }
  if (options.levels < 0) {
    throw InvalidInputError(name, "negative number of subdivision levels");
  }
  if (options.relaxation.solver != SolverKind::Fast) {
    throw InvalidInputError(name, "refinement relaxes with the fast solver only");
  }
  auto stage = [&](std::string_view what, int level) {
    if (!report_progress(options.progress,
                         {.stage = what, .iteration = level, .total = options.levels})) {
      throw Error(name, "cancelled during " + std::string(what));
    }
  };
  const auto start_all = std::chrono::steady_clock::now();

  RefineMapResult result;
  result.grid = grid;
  result.relaxation = relaxed;
  for (int level = 0; level < options.levels; ++level) {
    stage("subdivide", level);
    auto start = std::chrono::steady_clock::now();
    const int nc = result.grid.num_particles();
    GridSubdivisionResult refined = subdivide_on_source(result.grid, source, source_disk, name);
    RelaxationProblem problem = initial_placement(refined, result.relaxation, target, target_disk);
    problem.rest_scale = relaxed.rest_scale;
    problem.rest_scale_mode = relaxed.rest_scale_mode;
    RefinementLevel report;
    report.particles_before = nc;
    report.particles_after = refined.grid.num_particles();
    report.faces_after = static_cast<int>(refined.grid.mesh.n_faces());
    report.boundary_particles = static_cast<int>(refined.grid.boundary_loop.size());
    report.source_magnet_placements = refined.magnet_placements;
    report.seconds_subdivide = seconds_since(start);

    // Step 3: brief relaxation of the refined grid.
    stage("relax refined", level);
    start = std::chrono::steady_clock::now();
    result.grid = std::move(refined.grid);
    problem.grid = &result.grid;
    result.relaxation = relax(problem, options.relaxation);
    report.seconds_relax = seconds_since(start);
    record_relaxation(result.relaxation, report);
    result.iterations += report.iterations;
    result.levels.push_back(report);
  }
  result.seconds = seconds_since(start_all);
  return result;
}

}  // namespace elastic
