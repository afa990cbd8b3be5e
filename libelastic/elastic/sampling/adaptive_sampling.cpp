#include "elastic/sampling/adaptive_sampling.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "elastic/core/error.h"
#include "elastic/sampling/boundary_sampler.h"

namespace elastic {
namespace {

/// Compressed rows: items of row r are items[start[r] .. start[r+1]).
struct Csr {
  std::vector<int> start{0};
  std::vector<int> items;
  int begin(int r) const { return start[r]; }
  int end(int r) const { return start[r + 1]; }
};

/// Sine of the angle at corner c of a face (neighbours a before, b after), signed by the normal at
/// c: positive when the corner turns counter-clockwise seen from the normal side, 1 for a right
/// angle.
double corner_sine(const Eigen::Vector3d& xa, const Eigen::Vector3d& xc, const Eigen::Vector3d& xb,
                   const Eigen::Vector3d& normal) {
  const Eigen::Vector3d e1 = xb - xc, e2 = xa - xc;
  const double scale = e1.norm() * e2.norm();
  if (!(scale > 0.0)) {
    return 0.0;
  }
  return e1.cross(e2).dot(normal) / scale;
}

/// Texture coordinates at a surface point, interpolated in the region triangle (of the same ptex
/// face) that contains its (u, v).
class RegionTexcoords {
 public:
  explicit RegionTexcoords(const Region& region) : region_(region) {
    if (region.texcoords.empty()) {
      return;
    }
    for (int t = 0; t < region.num_triangles(); ++t) {
      const int f = region.triangle_face[t];
      if (f >= static_cast<int>(by_face_.size())) {
        by_face_.resize(f + 1);
      }
      by_face_[f].push_back(t);
    }
  }
  /// False (and `uv` untouched) when no triangle of the point's ptex face holds it.
  bool at(const SurfacePoint& p, Eigen::Vector2d& uv) const {
    if (p.face < 0 || p.face >= static_cast<int>(by_face_.size())) {
      return false;
    }
    int best = -1;
    Eigen::Vector3d best_w = Eigen::Vector3d::Zero();
    for (const int t : by_face_[p.face]) {
      const auto& c = region_.triangle_uv[t];
      const Eigen::Vector2d e1 = c[1] - c[0], e2 = c[2] - c[0], d = p.uv() - c[0];
      const double det = e1.x() * e2.y() - e1.y() * e2.x();
      if (det == 0.0) {
        continue;
      }
      const double b1 = (d.x() * e2.y() - d.y() * e2.x()) / det;
      const double b2 = (e1.x() * d.y() - e1.y() * d.x()) / det;
      const Eigen::Vector3d w(1.0 - b1 - b2, b1, b2);
      if (best < 0 || w.minCoeff() > best_w.minCoeff()) {
        best = t;
        best_w = w;
      }
    }
    // A point slightly outside every triangle of its face (round-off on the region's edge) still
    // takes the nearest one; farther ones keep their previous UV.
    if (best < 0 || best_w.minCoeff() < -1e-3) {
      return false;
    }
    const Eigen::Vector3i& tri = region_.triangles[best];
    uv = best_w[0] * region_.texcoords[tri[0]] + best_w[1] * region_.texcoords[tri[1]] +
         best_w[2] * region_.texcoords[tri[2]];
    return true;
  }

 private:
  const Region& region_;
  std::vector<std::vector<int>> by_face_;
};

}  // namespace

AdaptiveSamplingResult adaptive_sampling(const ParticleGrid& input, const Region& region,
                                         const SurfaceProjector& projector,
                                         const AdaptiveSamplingOptions& options) {
  const std::string& name = options.name;
  if (!(options.floor >= 0.0) || !(options.relaxation > 0.0 && options.relaxation <= 1.0) ||
      options.max_iterations < 0 || !(options.tolerance > 0.0) || !(options.jitter >= 0.0) ||
      !(options.min_corner_sine < 1.0)) {
    throw InvalidInputError(name, "adaptive sampling options out of range");
  }
  const int np = input.num_particles();
  if (static_cast<int>(input.source_points.size()) != np ||
      static_cast<int>(input.is_boundary.size()) != np ||
      input.boundary_loop.size() != input.boundary_parameter.size()) {
    throw InvalidInputError(name,
                            "the particle grid is incomplete (source points, boundary flags)");
  }
  const LimitSurface& surface = projector.surface();

  AdaptiveSamplingResult result;
  result.grid = input;
  ParticleGrid& grid = result.grid;
  const GridMesh& mesh = grid.mesh;

  // Flat connectivity: neighbours, faces, faces around each vertex.
  Csr nbr, faces, vertex_faces;
  for (int p = 0; p < np; ++p) {
    for (const auto v : mesh.vv_range(GridMesh::VertexHandle(p))) {
      nbr.items.push_back(v.idx());
    }
    nbr.start.push_back(static_cast<int>(nbr.items.size()));
    for (const auto f : mesh.vf_range(GridMesh::VertexHandle(p))) {
      vertex_faces.items.push_back(f.idx());
    }
    vertex_faces.start.push_back(static_cast<int>(vertex_faces.items.size()));
  }
  for (const auto f : mesh.faces()) {
    for (const auto v : mesh.fv_range(f)) {
      faces.items.push_back(v.idx());
    }
    faces.start.push_back(static_cast<int>(faces.items.size()));
  }

  // Boundary bookkeeping: position of each boundary particle in the loop, and its parameter s.
  std::vector<int> loop_index(np, -1);
  for (size_t k = 0; k < grid.boundary_loop.size(); ++k) {
    loop_index[grid.boundary_loop[k]] = static_cast<int>(k);
  }
  for (int p = 0; p < np; ++p) {
    if (grid.is_boundary[p] && loop_index[p] < 0) {
      throw InvalidInputError(
          name, "boundary particle " + std::to_string(p) + " is not in the boundary loop");
    }
  }
  const int nb = static_cast<int>(grid.boundary_loop.size());
  std::vector<double> s = grid.boundary_parameter;
  std::unique_ptr<BoundarySampler> sampler;
  if (nb > 0 && options.move_boundary) {
    sampler = std::make_unique<BoundarySampler>(region, name);
  }

  std::vector<Eigen::Vector3d> x(np);
  for (int p = 0; p < np; ++p) {
    const auto& q = mesh.point(GridMesh::VertexHandle(p));
    x[p] = Eigen::Vector3d(q[0], q[1], q[2]);
  }
  std::vector<SurfacePoint>& sp = grid.source_points;
  std::vector<Eigen::Vector3d> normal(np);
  std::vector<double> r(np);
  // Normal and curvature weight r = sqrt((k1^2 + k2^2) / 2) at a surface point.
  auto weight_at = [&](const SurfacePoint& q, Eigen::Vector3d& n, double& w) {
    const SurfaceCurvature c = surface.curvature(q);
    n = c.normal;
    w = std::sqrt(0.5 * (c.k1 * c.k1 + c.k2 * c.k2));
  };
  tbb::parallel_for(0, np, [&](int p) { weight_at(sp[p], normal[p], r[p]); });

  auto mean_spring_length = [&] {
    double sum = 0.0;
    for (const auto e : mesh.edges()) {
      const auto h = mesh.halfedge_handle(e, 0);
      sum += (x[mesh.to_vertex_handle(h).idx()] - x[mesh.from_vertex_handle(h).idx()]).norm();
    }
    return mesh.n_edges() > 0 ? sum / static_cast<double>(mesh.n_edges()) : 0.0;
  };

  // Smallest corner sine over the faces around p, given the current positions.
  auto min_sine_around = [&](int p) {
    double m = 1.0;
    for (int k = vertex_faces.begin(p); k < vertex_faces.end(p); ++k) {
      const int f = vertex_faces.items[k];
      const int n = faces.end(f) - faces.begin(f);
      const int* v = faces.items.data() + faces.begin(f);
      for (int c = 0; c < n; ++c) {
        const int a = v[(c + n - 1) % n], i = v[c], b = v[(c + 1) % n];
        m = std::min(m, corner_sine(x[a], x[i], x[b], normal[i]));
      }
    }
    return m;
  };

  // Candidate moves of one round, and their acceptance (sequential, in particle order).
  std::vector<Eigen::Vector3d> new_x(np);
  std::vector<SurfacePoint> new_sp(np);
  std::vector<double> new_s(np, 0.0);
  std::vector<Eigen::Vector3d> new_normal(np);
  std::vector<double> new_r(np, 0.0);
  std::vector<char> moving(np, 0);
  long rejected = 0;

  // Re-evaluates a halfway move of particle p (between its current state and the candidate).
  auto halfway = [&](int p) {
    if (grid.is_boundary[p]) {
      const int k = loop_index[p];
      double ds = new_s[p] - s[k];
      ds -= std::round(ds);
      const BoundarySampler::Sample smp = sampler->at(s[k] + 0.5 * ds);
      new_x[p] = smp.position;
      new_sp[p] = smp.point;
      new_s[p] = smp.s;
    } else {
      const ClosestPoint cp = projector.closest(0.5 * (x[p] + new_x[p]), sp[p]);
      new_x[p] = cp.position;
      new_sp[p] = cp.point;
    }
  };

  auto accept_moves = [&]() {
    // Normals and weights at the candidate positions, in parallel; acceptance is sequential.
    tbb::parallel_for(0, np, [&](int p) {
      if (moving[p]) {
        weight_at(new_sp[p], new_normal[p], new_r[p]);
      }
    });
    double largest = 0.0;
    for (int p = 0; p < np; ++p) {
      if (!moving[p]) {
        continue;
      }
      const double before = min_sine_around(p);
      const Eigen::Vector3d old_x = x[p], old_n = normal[p];
      const double old_r = r[p];
      const SurfacePoint old_sp = sp[p];
      bool ok = false;
      for (int attempt = 0; attempt < 2 && !ok; ++attempt) {
        if (attempt == 1) {
          halfway(p);
          weight_at(new_sp[p], new_normal[p], new_r[p]);
        }
        x[p] = new_x[p];
        sp[p] = new_sp[p];
        normal[p] = new_normal[p];
        r[p] = new_r[p];
        const double after = min_sine_around(p);
        ok = after > 0.0 && (after > options.min_corner_sine || after >= before);
      }
      if (!ok) {
        x[p] = old_x;
        sp[p] = old_sp;
        normal[p] = old_n;
        r[p] = old_r;
        ++rejected;
        continue;
      }
      if (grid.is_boundary[p]) {
        s[loop_index[p]] = new_s[p];
      }
      largest = std::max(largest, (x[p] - old_x).norm());
    }
    return largest;
  };

  // Interior particles, for the batched magnet.
  std::vector<int> interior;
  for (int p = 0; p < np; ++p) {
    if (!grid.is_boundary[p]) {
      interior.push_back(p);
    }
  }
  std::vector<Eigen::Vector3d> targets(interior.size());
  std::vector<SurfacePoint> hints(interior.size());
  std::vector<ClosestPoint> projected(interior.size());
  auto project_interior = [&] {
    for (size_t k = 0; k < interior.size(); ++k) {
      hints[k] = sp[interior[k]];
    }
    projector.closest(targets, projected, hints);
    for (size_t k = 0; k < interior.size(); ++k) {
      new_x[interior[k]] = projected[k].position;
      new_sp[interior[k]] = projected[k].point;
    }
  };

  double spacing = mean_spring_length();
  if (!(spacing > 0.0)) {
    throw InvalidInputError(name, "the particle grid has no springs");
  }

  // Optional seeded jitter: a random tangent displacement of every interior particle.
  if (options.jitter > 0.0 && !interior.empty()) {
    std::mt19937_64 rng(options.seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    std::fill(moving.begin(), moving.end(), 0);
    for (size_t k = 0; k < interior.size(); ++k) {
      const int p = interior[k];
      const Eigen::Vector3d& n = normal[p];
      const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
      const double a = uniform(rng), b = uniform(rng);
      targets[k] = x[p] + options.jitter * spacing * (a * t1 + b * t2);
      moving[p] = 1;
    }
    project_interior();
    accept_moves();
  }

  // The floor's reference: the mean weight over the initial particles. The layout spreads them
  // evenly over the surface, so this is (close to) the area mean of r over the region, and it stays
  // fixed while the particles migrate (a mean over the moving particles would grow as they gather
  // in curved parts and drain the flat parts further).
  double rbar = 0.0;
  for (int p = 0; p < np; ++p) {
    rbar += r[p];
  }
  rbar /= np;
  const double cap = options.max_weight > 0.0 ? options.max_weight * rbar : 0.0;

  for (int it = 0; it < options.max_iterations; ++it) {
    // Weights (see the header): all 1 on a flat region, where eq. 8 degenerates to Laplacian
    // smoothing.
    std::vector<double> w(np);
    for (int p = 0; p < np; ++p) {
      const double rp = cap > 0.0 ? std::min(r[p], cap) : r[p];
      w[p] = rbar > 0.0 ? rp + options.floor * rbar : 1.0;
    }

    auto force = [&](int p) {
      Eigen::Vector3d f = Eigen::Vector3d::Zero();
      double wsum = 0.0;
      for (int k = nbr.begin(p); k < nbr.end(p); ++k) {
        const int j = nbr.items[k];
        f += w[j] * (x[j] - x[p]);
        wsum += w[j];
      }
      return wsum > 0.0 ? Eigen::Vector3d(f / wsum) : Eigen::Vector3d::Zero();
    };
    std::fill(moving.begin(), moving.end(), 0);
    tbb::parallel_for(size_t{0}, interior.size(), [&](size_t k) {
      const int p = interior[k];
      const Eigen::Vector3d f = force(p);
      // T_i: the tangent-plane component (eq. 8); the magnet below handles what remains of the
      // normal.
      targets[k] = x[p] + options.relaxation * (f - f.dot(normal[p]) * normal[p]);
      moving[p] = 1;
    });
    project_interior();
    if (sampler) {
      const double length = sampler->length();
      tbb::parallel_for(0, nb, [&](int k) {
        const int p = grid.boundary_loop[k];
        const BoundarySampler::Sample here = sampler->at(s[k]);
        // Arc-length step from the force's component along the chord, at most a quarter of the gap
        // to either neighbour so that two neighbours moving towards each other cannot meet or
        // cross.
        double ds = options.relaxation * force(p).dot(here.tangent) / length;
        auto gap = [&](int other) {
          double g = s[other] - s[k];
          return g - std::floor(g);  // forward gap in [0, 1)
        };
        const double gap_next = nb > 1 ? gap((k + 1) % nb) : 1.0;
        const double gap_prev = nb > 1 ? 1.0 - gap((k + nb - 1) % nb) : 1.0;
        ds = std::clamp(ds, -0.25 * gap_prev, 0.25 * gap_next);
        const BoundarySampler::Sample there = sampler->at(s[k] + ds);
        new_x[p] = there.position;
        new_sp[p] = there.point;
        new_s[p] = there.s;
        moving[p] = 1;
      });
    }
    const double largest = accept_moves();
    spacing = mean_spring_length();
    result.iterations = it + 1;
    result.max_move = largest / spacing;
    result.converged = result.max_move < options.tolerance;
    if (!report_progress(options.progress, Progress{.stage = "adaptive sampling",
                                                    .iteration = it + 1,
                                                    .total = options.max_iterations,
                                                    .energy = 0.0,
                                                    .gradient = result.max_move})) {
      result.cancelled = true;
      break;
    }
    if (result.converged) {
      break;
    }
  }

  // Write back: positions, boundary parameters, UVs, springs.
  for (int p = 0; p < np; ++p) {
    grid.mesh.point(GridMesh::VertexHandle(p)) = GridMesh::Point(x[p].x(), x[p].y(), x[p].z());
  }
  grid.boundary_parameter = s;
  if (!grid.source_uv.empty()) {
    const RegionTexcoords texcoords(region);
    for (int p = 0; p < np; ++p) {
      texcoords.at(sp[p], grid.source_uv[p]);
    }
  }
  grid.build_springs();
  double rbar_end = 0.0;
  for (int p = 0; p < np; ++p) {
    rbar_end += r[p];
  }
  result.mean_curvature_weight = np > 0 ? rbar_end / np : 0.0;
  result.rejected_moves = rejected;
  return result;
}

}  // namespace elastic
