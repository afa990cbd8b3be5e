#include "elastic/sampling/adaptive_sampling.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>

#include "elastic/core/error.h"
#include "elastic/numerics/conjugate_gradient.h"
#include "elastic/numerics/graph_laplacian.h"
#include "elastic/numerics/multigrid.h"
#include "elastic/sampling/boundary_sampler.h"
#include "elastic/sampling/curvature_field.h"
#include "elastic/sampling/region_texcoords.h"

namespace elastic {
namespace {

/// Rounds of holding still the particles of failing faces in a Newton step (see newton_step).
constexpr int kHoldRounds = 8;
/// A Newton iteration whose largest move is above kContraction times the last one halves the
/// step, down to kMinDamping (Sampler::damping).
constexpr double kContraction = 0.9;
constexpr double kMinDamping = 1.0 / 16.0;
/// Newton iterations at kMinDamping without the largest move falling below kContraction times its
/// best before the iteration stops as stalled.
constexpr int kStallIterations = 30;

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

void validate(const ParticleGrid& input, const AdaptiveSamplingOptions& options) {
  const std::string& name = options.name;
  if (!(options.floor >= 0.0) || !(options.relaxation > 0.0 && options.relaxation <= 1.0) ||
      options.max_iterations < 0 || !(options.tolerance > 0.0) || !(options.jitter >= 0.0) ||
      !(options.curvature_radius >= 0.0) || !(options.min_corner_sine < 1.0)) {
    throw InvalidInputError(name, "adaptive sampling options out of range");
  }
  const int np = input.num_particles();
  if (static_cast<int>(input.source_points.size()) != np ||
      static_cast<int>(input.is_boundary.size()) != np ||
      input.boundary_loop.size() != input.boundary_parameter.size()) {
    throw InvalidInputError(name,
                            "the particle grid is incomplete (source points, boundary flags)");
  }
}

/// The state of the iteration: positions, surface points, normals and curvature weights of every
/// particle, the boundary parameters, the grid's connectivity, and the candidate moves of one
/// round. Each step of the algorithm is one member function.
class Sampler {
 public:
  Sampler(ParticleGrid& grid, const Region& region, const SurfaceProjector& projector,
          const AdaptiveSamplingOptions& options);

  void jitter();
  /// The floor's reference rbar0 and the clamp, from the current (laid-out) particles.
  void fix_weight_reference();
  /// Candidates of a Jacobi sweep of eq. 8 (all forces from the same state).
  void jacobi_candidates();
  /// Candidates of a tangent Newton step scaled by `step` (see newton_step); `solve` computes the
  /// step, else the last one is scaled.
  void newton_candidates(double step, bool solve);
  /// One tangent Newton step with backtracking, taken particle by particle (guarded) when no step
  /// length keeps every face valid; false when the step cannot be set up (an interior part not
  /// tied to the boundary). `largest` receives the largest move.
  bool newton_step(double& largest);
  /// Sequential, guarded acceptance of the candidates; returns the largest accepted move.
  double accept_sequentially();
  double mean_spring_length() const;
  void write_back(AdaptiveSamplingResult& result) const;

  long rejected = 0;
  long cg_iterations = 0;
  /// Scale of the Newton steps: halved when an iteration's largest move does not shrink (the
  /// fixed point on the weights cycles, as in the nostrils of a scan).
  double damping = 1.0;

 private:
  void weight_at(const Eigen::Vector3d& x, const SurfacePoint& q, Eigen::Vector3d& n,
                 double& w) const;
  double weight(int p) const;
  double face_min_sine(int f) const;
  double min_sine_around(int p) const;
  template <typename FaceBefore>
  bool move_acceptable(int p, double before, const FaceBefore& face_before) const;
  void project_interior();
  void halfway(int p);
  void evaluate_candidate_weights();
  void evaluate_candidate_normals();
  void update_moved_weights();
  /// Tangent bases of the Newton step's unknowns and the multigrid of its preconditioner.
  void prepare_newton();

  ParticleGrid& grid_;
  const Region& region_;
  const SurfaceProjector& projector_;
  const LimitSurface& surface_;
  const AdaptiveSamplingOptions& options_;
  int np_ = 0;
  GraphAdjacency nbr_, faces_, vertex_faces_;
  std::vector<int> loop_index_;
  std::vector<double> s_;
  std::unique_ptr<BoundarySampler> sampler_;
  std::unique_ptr<CurvatureField> field_;
  std::vector<Eigen::Vector3d> x_, normal_;
  std::vector<double> r_;
  std::vector<int> interior_;
  double rbar_ = 0.0, cap_ = 0.0;

  // Candidates of one round.
  std::vector<Eigen::Vector3d> new_x_, new_normal_, targets_;
  std::vector<SurfacePoint> new_sp_, hints_;
  std::vector<ClosestPoint> projected_;
  std::vector<double> new_s_, new_r_;
  std::vector<char> moving_;
  std::vector<double> face_before_;  // per face: accept_sequentially's smallest sine before a move

  // Newton step: per particle its first unknown (-1: held), its number of unknowns (2 interior,
  // 0 boundary) and tangent basis; the interior numbering of the preconditioner.
  std::vector<int> unknown_, dim_;
  std::vector<Eigen::Matrix<double, 3, 2>> basis_;
  std::vector<int> interior_row_;
  int unknowns_ = 0;
  std::unique_ptr<Multigrid> multigrid_;
  bool newton_ready_ = false;
  Eigen::VectorXd delta_;  // the step, in unknowns
};

Sampler::Sampler(ParticleGrid& grid, const Region& region, const SurfaceProjector& projector,
                 const AdaptiveSamplingOptions& options)
    : grid_(grid),
      region_(region),
      projector_(projector),
      surface_(projector.surface()),
      options_(options),
      np_(grid.num_particles()) {
  const GridMesh& mesh = grid.mesh;
  // Flat connectivity: neighbours, faces, faces around each vertex.
  for (int p = 0; p < np_; ++p) {
    for (const auto v : mesh.vv_range(GridMesh::VertexHandle(p))) {
      nbr_.items.push_back(v.idx());
    }
    nbr_.start.push_back(static_cast<int>(nbr_.items.size()));
    for (const auto f : mesh.vf_range(GridMesh::VertexHandle(p))) {
      vertex_faces_.items.push_back(f.idx());
    }
    vertex_faces_.start.push_back(static_cast<int>(vertex_faces_.items.size()));
  }
  for (const auto f : mesh.faces()) {
    for (const auto v : mesh.fv_range(f)) {
      faces_.items.push_back(v.idx());
    }
    faces_.start.push_back(static_cast<int>(faces_.items.size()));
  }
  // Boundary bookkeeping: position of each boundary particle in the loop, and its parameter s.
  loop_index_.assign(np_, -1);
  for (size_t k = 0; k < grid.boundary_loop.size(); ++k) {
    loop_index_[grid.boundary_loop[k]] = static_cast<int>(k);
  }
  for (int p = 0; p < np_; ++p) {
    if (grid.is_boundary[p] && loop_index_[p] < 0) {
      throw InvalidInputError(
          options.name, "boundary particle " + std::to_string(p) + " is not in the boundary loop");
    }
    if (!grid.is_boundary[p]) {
      interior_.push_back(p);
    }
  }
  s_ = grid.boundary_parameter;
  if (!grid.boundary_loop.empty() && options.move_boundary) {
    sampler_ = std::make_unique<BoundarySampler>(region, options.name);
  }
  x_.resize(np_);
  for (int p = 0; p < np_; ++p) {
    const auto& q = mesh.point(GridMesh::VertexHandle(p));
    x_[p] = Eigen::Vector3d(q[0], q[1], q[2]);
  }
  normal_.resize(np_);
  r_.resize(np_);
  field_ =
      std::make_unique<CurvatureField>(region, options.curvature_radius * mean_spring_length());
  tbb::parallel_for(0, np_,
                    [&](int p) { weight_at(x_[p], grid.source_points[p], normal_[p], r_[p]); });
  new_x_.resize(np_);
  new_normal_.resize(np_);
  new_sp_.resize(np_);
  new_s_.assign(np_, 0.0);
  new_r_.assign(np_, 0.0);
  moving_.assign(np_, 0);
  face_before_.assign(static_cast<size_t>(faces_.nodes()), 1.0);
  targets_.resize(interior_.size());
  hints_.resize(interior_.size());
  projected_.resize(interior_.size());
}

// Normal and curvature measure r = sqrt((k1^2 + k2^2) / 2), averaged about x (curvature_field.h),
// at a surface point q whose position is x.
void Sampler::weight_at(const Eigen::Vector3d& x, const SurfacePoint& q, Eigen::Vector3d& n,
                        double& w) const {
  const SurfaceCurvature c = surface_.curvature(q);
  n = c.normal;
  w = field_->radius() > 0.0 ? field_->at(x, q) : std::sqrt(0.5 * (c.k1 * c.k1 + c.k2 * c.k2));
}

// Weights (see the header): all 1 on a flat region, where eq. 8 degenerates to Laplacian
// smoothing.
double Sampler::weight(int p) const {
  const double rp = cap_ > 0.0 ? std::min(r_[p], cap_) : r_[p];
  return rbar_ > 0.0 ? rp + options_.floor * rbar_ : 1.0;
}

double Sampler::mean_spring_length() const {
  const GridMesh& mesh = grid_.mesh;
  double sum = 0.0;
  for (const auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    sum += (x_[mesh.to_vertex_handle(h).idx()] - x_[mesh.from_vertex_handle(h).idx()]).norm();
  }
  return mesh.n_edges() > 0 ? sum / static_cast<double>(mesh.n_edges()) : 0.0;
}

// Smallest corner sine of face f, given the current positions.
double Sampler::face_min_sine(int f) const {
  double m = 1.0;
  const int n = faces_.start[f + 1] - faces_.start[f];
  const int* v = faces_.items.data() + faces_.start[f];
  for (int c = 0; c < n; ++c) {
    const int a = v[(c + n - 1) % n], i = v[c], b = v[(c + 1) % n];
    m = std::min(m, corner_sine(x_[a], x_[i], x_[b], normal_[i]));
  }
  return m;
}

// Smallest corner sine over the faces around p, given the current positions.
double Sampler::min_sine_around(int p) const {
  double m = 1.0;
  for (int k = vertex_faces_.start[p]; k < vertex_faces_.start[p + 1]; ++k) {
    m = std::min(m, face_min_sine(vertex_faces_.items[k]));
  }
  return m;
}

// Whether the faces around p are acceptable in the current positions, `before` being their
// smallest corner sine before the move and face_before(f) face f's. The guard (header): no corner
// may turn over, nor fall to min_corner_sine and below its previous value. A particle of a face
// that is already turned over (the layout of a narrow protrusion or a crease of a scan can leave a
// few: the grid's sampling statistics count them) could never pass that test on its smallest
// sine, so neither it nor any neighbour sharing the face could move again, and no Newton step
// could be taken whole (camelhead.off's head, 5,000 particles: all 93 iterations ended in the
// particle-by-particle fallback). For such a particle the guard is applied face by face instead:
// a turned-over face may change (and unfold), every other face keeps the rule. Where no face is
// turned over the test is the particle's smallest sine, as always.
template <typename FaceBefore>
bool Sampler::move_acceptable(int p, double before, const FaceBefore& face_before) const {
  const double min_sine = options_.min_corner_sine;
  if (before > 0.0) {
    const double after = min_sine_around(p);
    return after > 0.0 && (after > min_sine || after >= before);
  }
  for (int k = vertex_faces_.start[p]; k < vertex_faces_.start[p + 1]; ++k) {
    const int f = vertex_faces_.items[k];
    const double was = face_before(f), now = face_min_sine(f);
    if (was > 0.0 && !(now > 0.0 && (now > min_sine || now >= was))) {
      return false;
    }
  }
  return true;
}

// The batched magnet: interior candidates from targets_, warm-started at the current points.
void Sampler::project_interior() {
  const std::vector<SurfacePoint>& sp = grid_.source_points;
  for (size_t k = 0; k < interior_.size(); ++k) {
    hints_[k] = sp[interior_[k]];
  }
  projector_.closest(targets_, projected_, hints_);
  for (size_t k = 0; k < interior_.size(); ++k) {
    new_x_[interior_[k]] = projected_[k].position;
    new_sp_[interior_[k]] = projected_[k].point;
  }
}

// Re-evaluates a halfway move of particle p (between its current state and the candidate).
void Sampler::halfway(int p) {
  if (grid_.is_boundary[p]) {
    const int k = loop_index_[p];
    double ds = new_s_[p] - s_[k];
    ds -= std::round(ds);
    const BoundarySampler::Sample smp = sampler_->at(s_[k] + 0.5 * ds);
    new_x_[p] = smp.position;
    new_sp_[p] = smp.point;
    new_s_[p] = smp.s;
  } else {
    const ClosestPoint cp = projector_.closest(0.5 * (x_[p] + new_x_[p]), grid_.source_points[p]);
    new_x_[p] = cp.position;
    new_sp_[p] = cp.point;
  }
}

void Sampler::evaluate_candidate_weights() {
  tbb::parallel_for(0, np_, [&](int p) {
    if (moving_[p]) {
      weight_at(new_x_[p], new_sp_[p], new_normal_[p], new_r_[p]);
    }
  });
}

// The normals alone at the candidate positions: the Newton step's trials are judged by their
// corners, and only the one taken needs the curvature field (update_moved_weights), a kernel sum
// over the tessellation vertices within three spacings: on a scan's region (camelhead.off, 2,000
// particles) evaluating it at every trial was most of the sampling's time.
void Sampler::evaluate_candidate_normals() {
  tbb::parallel_for(0, np_, [&](int p) {
    if (moving_[p]) {
      new_normal_[p] = surface_.curvature(new_sp_[p]).normal;
    }
  });
}

// The weights of the particles that moved, at their new positions (the same values
// evaluate_candidate_weights gives).
void Sampler::update_moved_weights() {
  tbb::parallel_for(0, np_, [&](int p) {
    if (moving_[p]) {
      const SurfacePoint& q = grid_.source_points[p];
      r_[p] =
          field_->radius() > 0.0 ? field_->at(x_[p], q) : CurvatureField::pointwise(surface_, q);
    }
  });
}

double Sampler::accept_sequentially() {
  // Normals and weights at the candidate positions, in parallel; acceptance is sequential.
  evaluate_candidate_weights();
  std::vector<SurfacePoint>& sp = grid_.source_points;
  double largest = 0.0;
  for (int p = 0; p < np_; ++p) {
    if (!moving_[p]) {
      continue;
    }
    const double before = min_sine_around(p);
    // The faces' own smallest sines, needed only around a turned-over face (move_acceptable).
    if (!(before > 0.0)) {
      for (int k = vertex_faces_.start[p]; k < vertex_faces_.start[p + 1]; ++k) {
        const int f = vertex_faces_.items[k];
        face_before_[f] = face_min_sine(f);
      }
    }
    const auto face_before = [&](int f) { return face_before_[f]; };
    const Eigen::Vector3d old_x = x_[p], old_n = normal_[p];
    const double old_r = r_[p];
    const SurfacePoint old_sp = sp[p];
    bool ok = false;
    for (int attempt = 0; attempt < 2 && !ok; ++attempt) {
      if (attempt == 1) {
        halfway(p);
        weight_at(new_x_[p], new_sp_[p], new_normal_[p], new_r_[p]);
      }
      x_[p] = new_x_[p];
      sp[p] = new_sp_[p];
      normal_[p] = new_normal_[p];
      r_[p] = new_r_[p];
      ok = move_acceptable(p, before, face_before);
    }
    if (!ok) {
      x_[p] = old_x;
      sp[p] = old_sp;
      normal_[p] = old_n;
      r_[p] = old_r;
      ++rejected;
      continue;
    }
    if (grid_.is_boundary[p]) {
      s_[loop_index_[p]] = new_s_[p];
    }
    largest = std::max(largest, (x_[p] - old_x).norm());
  }
  return largest;
}

// Optional seeded jitter: a random tangent displacement of every interior particle.
void Sampler::jitter() {
  if (!(options_.jitter > 0.0) || interior_.empty()) {
    return;
  }
  const double spacing = mean_spring_length();
  std::mt19937_64 rng(options_.seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::fill(moving_.begin(), moving_.end(), 0);
  for (size_t k = 0; k < interior_.size(); ++k) {
    const int p = interior_[k];
    const Eigen::Vector3d& n = normal_[p];
    const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    const double a = uniform(rng), b = uniform(rng);
    targets_[k] = x_[p] + options_.jitter * spacing * (a * t1 + b * t2);
    moving_[p] = 1;
  }
  project_interior();
  accept_sequentially();
}

// The floor's reference: the mean weight over the initial particles. The layout spreads them
// evenly over the surface, so this is (close to) the area mean of r over the region, and it stays
// fixed while the particles migrate (a mean over the moving particles would grow as they gather
// in curved parts and drain the flat parts further).
void Sampler::fix_weight_reference() {
  double sum = 0.0;
  for (int p = 0; p < np_; ++p) {
    sum += r_[p];
  }
  rbar_ = np_ > 0 ? sum / np_ : 0.0;
  cap_ = options_.max_weight > 0.0 ? options_.max_weight * rbar_ : 0.0;
}

void Sampler::jacobi_candidates() {
  std::vector<double> w(np_);
  for (int p = 0; p < np_; ++p) {
    w[p] = weight(p);
  }
  auto force = [&](int p) {
    Eigen::Vector3d f = Eigen::Vector3d::Zero();
    double wsum = 0.0;
    for (int k = nbr_.start[p]; k < nbr_.start[p + 1]; ++k) {
      const int j = nbr_.items[k];
      f += w[j] * (x_[j] - x_[p]);
      wsum += w[j];
    }
    return wsum > 0.0 ? Eigen::Vector3d(f / wsum) : Eigen::Vector3d::Zero();
  };
  std::fill(moving_.begin(), moving_.end(), 0);
  tbb::parallel_for(size_t{0}, interior_.size(), [&](size_t k) {
    const int p = interior_[k];
    const Eigen::Vector3d f = force(p);
    // T_i: the tangent-plane component (eq. 8); the magnet handles what remains of the normal.
    targets_[k] = x_[p] + options_.relaxation * (f - f.dot(normal_[p]) * normal_[p]);
    moving_[p] = 1;
  });
  project_interior();
  if (!sampler_) {
    return;
  }
  const int nb = static_cast<int>(grid_.boundary_loop.size());
  const double length = sampler_->length();
  tbb::parallel_for(0, nb, [&](int k) {
    const int p = grid_.boundary_loop[k];
    const BoundarySampler::Sample here = sampler_->at(s_[k]);
    // Arc-length step from the force's component along the chord, at most a quarter of the gap to
    // either neighbour so that two neighbours moving towards each other cannot meet or cross.
    double ds = options_.relaxation * force(p).dot(here.tangent) / length;
    auto gap = [&](int other) {
      double g = s_[other] - s_[k];
      return g - std::floor(g);  // forward gap in [0, 1)
    };
    const double gap_next = nb > 1 ? gap((k + 1) % nb) : 1.0;
    const double gap_prev = nb > 1 ? 1.0 - gap((k + nb - 1) % nb) : 1.0;
    ds = std::clamp(ds, -0.25 * gap_prev, 0.25 * gap_next);
    const BoundarySampler::Sample there = sampler_->at(s_[k] + ds);
    new_x_[p] = there.position;
    new_sp_[p] = there.point;
    new_s_[p] = there.s;
    moving_[p] = 1;
  });
}

// The Newton step's preconditioner is built once, from the weights of the first step: it only has
// to be spectrally close to the operator, and its set-up (aggregation, Galerkin products) is the
// dearest part of a step on large grids.
void Sampler::prepare_newton() {
  unknown_.assign(np_, -1);
  dim_.assign(np_, 0);
  basis_.assign(np_, Eigen::Matrix<double, 3, 2>::Zero());
  interior_row_.assign(np_, -1);
  unknowns_ = 0;
  int rows = 0;
  for (int p = 0; p < np_; ++p) {
    if (!grid_.is_boundary[p]) {
      unknown_[p] = unknowns_;
      dim_[p] = 2;
      unknowns_ += 2;
      interior_row_[p] = rows++;
    }
  }
  multigrid_ = std::make_unique<Multigrid>(
      graph_laplacian(nbr_, interior_row_, [&](int i, int j) { return weight(i) * weight(j); }));
  newton_ready_ = true;
}

// The tangent Newton step on eq. 8. With the weights w frozen at the current positions, eq. 8 is
// w_i^-1 times the tangential gradient of the quadratic energy
//
//     E(a) = 1/2 sum_{edges ij} w_i w_j |(x_i + B_i a_i) - (x_j + B_j a_j)|^2,
//
// a_i an interior particle's displacement in its tangent basis B_i (two unit tangents; boundary
// particles are held). Its minimiser solves M a = -grad E(0) with M = B^T (L (x) I_3) B, L the
// graph Laplacian with edge weights w_i w_j restricted to the interior rows (the boundary is a
// Dirichlet condition): symmetric positive definite, solved by conjugate gradients preconditioned
// with B^T L^-1 B (one multigrid V-cycle of the scalar L applied to x, y and z). If B were square
// (a flat region) the preconditioner would be exact up to the V-cycle; on a curved region it drops
// the normal part, which costs a few more iterations (4-13 on spot.obj). Where all weights are
// equal and the surface is flat this is one exact solve of Laplacian smoothing's equilibrium, which
// the Jacobi sweeps reach only after O(n) sweeps of one grid ring each; elsewhere it is repeated as
// the weights follow the particles (a fixed-point iteration on w with a Newton step inside).
void Sampler::newton_candidates(double step, bool solve) {
  if (solve) {
    for (int p = 0; p < np_; ++p) {
      if (dim_[p] == 2) {
        const Eigen::Vector3d t1 = normal_[p].unitOrthogonal();
        basis_[p].col(0) = t1;
        basis_[p].col(1) = normal_[p].cross(t1);
      }
    }
    std::vector<double> w(np_);
    for (int p = 0; p < np_; ++p) {
      w[p] = weight(p);
    }
    auto lift = [&](const Eigen::VectorXd& v, int p) -> Eigen::Vector3d {
      return dim_[p] == 2 ? Eigen::Vector3d(basis_[p] * v.segment<2>(unknown_[p]))
                          : Eigen::Vector3d::Zero();
    };
    auto drop = [&](const Eigen::Vector3d& f, int p, Eigen::VectorXd& out) {
      if (dim_[p] == 2) {
        out.segment<2>(unknown_[p]) = basis_[p].transpose() * f;
      }
    };
    Eigen::VectorXd rhs(unknowns_);
    tbb::parallel_for(0, np_, [&](int p) {
      Eigen::Vector3d f = Eigen::Vector3d::Zero();
      for (int k = nbr_.start[p]; k < nbr_.start[p + 1]; ++k) {
        const int j = nbr_.items[k];
        f += w[p] * w[j] * (x_[j] - x_[p]);
      }
      drop(f, p, rhs);
    });
    const LinearOperator apply_m = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
      out.resize(v.size());
      std::vector<Eigen::Vector3d> d(np_);
      tbb::parallel_for(0, np_, [&](int p) { d[p] = lift(v, p); });
      tbb::parallel_for(0, np_, [&](int p) {
        if (dim_[p] == 0) {
          return;
        }
        Eigen::Vector3d f = Eigen::Vector3d::Zero();
        for (int k = nbr_.start[p]; k < nbr_.start[p + 1]; ++k) {
          const int j = nbr_.items[k];
          f += w[p] * w[j] * (d[p] - d[j]);
        }
        drop(f, p, out);
      });
    };
    Multigrid::Block lifted(multigrid_->size(), 3), solved;
    const LinearOperator precondition = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
      out.resize(v.size());
      tbb::parallel_for(0, np_, [&](int p) {
        if (interior_row_[p] >= 0) {
          lifted.row(interior_row_[p]) = lift(v, p).transpose();
        }
      });
      multigrid_->apply(lifted, solved);
      tbb::parallel_for(0, np_, [&](int p) {
        if (interior_row_[p] >= 0) {
          drop(solved.row(interior_row_[p]).transpose(), p, out);
        }
      });
    };
    ConjugateGradientOptions cg;
    cg.max_iterations = 60;
    cg.tolerance = 1e-4;
    cg_iterations += conjugate_gradient(apply_m, precondition, rhs, delta_, cg).iterations;
  }
  std::fill(moving_.begin(), moving_.end(), 0);
  for (size_t k = 0; k < interior_.size(); ++k) {
    const int p = interior_[k];
    targets_[k] = x_[p] + step * basis_[p] * delta_.segment<2>(unknown_[p]);
    moving_[p] = 1;
  }
  project_interior();
}

// A Newton step moves every particle at once, coherently with its neighbours, so it is accepted
// or refused as a whole: with all candidates in place, no corner of any face may turn the wrong
// way or fall below min_corner_sine and below its previous value (move_acceptable). The full step,
// then half and a quarter of it, are tried. When all three fail (a few particles in a crease of a
// scan would fold a face), the quarter step is taken without the particles of the faces that would
// fail: they hold still for this iteration and the test is repeated (holding a particle can spoil a
// face of a neighbour that still moves, and the more so the longer the step: holding within the
// full step spread the failures from 6 particles to 45-68 on camelhead.off, and every iteration
// ended in the fallback). As a last resort every particle's move is guarded on its own, as in a
// sweep. The next iteration tries a whole Newton step again.
bool Sampler::newton_step(double& largest) {
  if (!newton_ready_) {
    try {
      prepare_newton();
    } catch (const NumericalError&) {
      return false;  // an interior part not tied to the boundary: the sweeps handle it
    }
  }
  // Each face's smallest corner sine before the step, and each particle's over its faces (the
  // same values as min_sine_around: a minimum is exact in any order).
  const int num_faces = faces_.nodes();
  std::vector<double> before_face(static_cast<size_t>(num_faces));
  tbb::parallel_for(0, num_faces, [&](int f) { before_face[f] = face_min_sine(f); });
  const auto face_before = [&](int f) { return before_face[f]; };
  std::vector<double> before(np_);
  tbb::parallel_for(0, np_, [&](int p) {
    double m = 1.0;
    for (int k = vertex_faces_.start[p]; k < vertex_faces_.start[p + 1]; ++k) {
      m = std::min(m, before_face[vertex_faces_.items[k]]);
    }
    before[p] = m;
  });
  std::vector<SurfacePoint>& sp = grid_.source_points;
  const std::vector<Eigen::Vector3d> old_x = x_, old_n = normal_;
  const std::vector<SurfacePoint> old_sp = sp;
  std::vector<char> bad(np_, 0);
  // Puts the moving candidates in place and marks the particles with a failing face; true when
  // none fails (the candidates stay), else the state is restored.
  const auto take = [&]() {
    for (int p = 0; p < np_; ++p) {
      if (moving_[p]) {
        x_[p] = new_x_[p];
        sp[p] = new_sp_[p];
        normal_[p] = new_normal_[p];
      }
    }
    tbb::parallel_for(0, np_, [&](int p) { bad[p] = !move_acceptable(p, before[p], face_before); });
    if (std::find(bad.begin(), bad.end(), 1) == bad.end()) {
      update_moved_weights();
      largest = 0.0;
      for (int p = 0; p < np_; ++p) {
        largest = std::max(largest, (x_[p] - old_x[p]).norm());
      }
      return true;
    }
    x_ = old_x;
    normal_ = old_n;
    sp = old_sp;
    return false;
  };
  for (const double fraction : {1.0, 0.5, 0.25}) {
    const double step = fraction * damping;
    newton_candidates(step, fraction == 1.0);
    evaluate_candidate_normals();
    if (take()) {
      return true;
    }
  }
  newton_candidates(0.25 * damping, false);  // the shortest step tried above
  evaluate_candidate_normals();
  for (int round = 0; round < kHoldRounds; ++round) {
    for (int p = 0; p < np_; ++p) {
      if (bad[p]) {
        for (int k = vertex_faces_.start[p]; k < vertex_faces_.start[p + 1]; ++k) {
          const int f = vertex_faces_.items[k];
          for (int c = faces_.start[f]; c < faces_.start[f + 1]; ++c) {
            moving_[faces_.items[c]] = 0;
          }
        }
      }
    }
    if (take()) {
      return true;
    }
  }
  largest = accept_sequentially();
  return true;
}

// Write back: positions, boundary parameters, UVs, springs.
void Sampler::write_back(AdaptiveSamplingResult& result) const {
  for (int p = 0; p < np_; ++p) {
    grid_.mesh.point(GridMesh::VertexHandle(p)) = GridMesh::Point(x_[p].x(), x_[p].y(), x_[p].z());
  }
  grid_.boundary_parameter = s_;
  if (!grid_.source_uv.empty()) {
    const RegionTexcoords texcoords(region_);
    for (int p = 0; p < np_; ++p) {
      texcoords.at(grid_.source_points[p], grid_.source_uv[p]);
    }
  }
  grid_.build_springs();
  double sum = 0.0;
  for (int p = 0; p < np_; ++p) {
    sum += r_[p];
  }
  result.mean_curvature_weight = np_ > 0 ? sum / np_ : 0.0;
  result.rejected_moves = rejected;
  result.cg_iterations = cg_iterations;
}

}  // namespace

AdaptiveSamplingResult adaptive_sampling(const ParticleGrid& grid, const Region& region,
                                         const SurfaceProjector& projector,
                                         const AdaptiveSamplingOptions& options) {
  validate(grid, options);
  return adaptive_sampling(ParticleGrid(grid), region, projector, options);
}

AdaptiveSamplingResult adaptive_sampling(ParticleGrid&& input, const Region& region,
                                         const SurfaceProjector& projector,
                                         const AdaptiveSamplingOptions& options) {
  validate(input, options);
  AdaptiveSamplingResult result;
  result.grid = std::move(input);
  Sampler sampler(result.grid, region, projector, options);
  if (!(sampler.mean_spring_length() > 0.0)) {
    throw InvalidInputError(options.name, "the particle grid has no springs");
  }
  sampler.jitter();
  sampler.fix_weight_reference();

  bool newton = options.method == SamplingMethod::Newton;
  double best_move = std::numeric_limits<double>::infinity();
  int best_at = 0;
  for (int it = 0; it < options.max_iterations; ++it) {
    double largest = 0.0;
    if (newton && sampler.newton_step(largest)) {
      ++result.newton_steps;
    } else {
      // No Newton step can be set up (an interior part not tied to the boundary): the guarded
      // sweeps take over for good.
      newton = false;
      sampler.jacobi_candidates();
      largest = sampler.accept_sequentially();
    }
    result.iterations = it + 1;
    const double previous = result.max_move;
    result.max_move = largest / sampler.mean_spring_length();
    if (newton && it > 0 && result.max_move > kContraction * previous) {
      sampler.damping = std::max(0.5 * sampler.damping, kMinDamping);
    }
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
    // At the smallest step the largest move has not fallen below kContraction times its best for
    // kStallIterations: the cycle does not contract any further (a crease of a scan), more
    // iterations only cost.
    if (result.max_move < kContraction * best_move) {
      best_move = result.max_move;
      best_at = it;
    } else if (newton && sampler.damping == kMinDamping && it - best_at >= kStallIterations) {
      result.stalled = true;
      break;
    }
  }
  sampler.write_back(result);
  return result;
}

}  // namespace elastic
