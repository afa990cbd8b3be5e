#include "elastic/particles/spring_energy.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "elastic/core/error.h"
#include "elastic/particles/face_folds.h"

namespace elastic {

namespace {

// Grain of the parallel loops. It is fixed (not derived from the thread count) so that the
// deterministic reduction splits the sums the same way whatever the number of threads.
constexpr std::size_t kGrain = 4096;

bool finite_non_negative(double value) {
  return std::isfinite(value) && value >= 0.0;
}

// Builds compressed-row incidence from (particle, entry) pairs given in a stable order.
void build_incidence(int num_particles, const std::vector<std::pair<int, int>>& pairs,
                     std::vector<int>& offset, std::vector<int>& entry) {
  offset.assign(static_cast<std::size_t>(num_particles) + 1, 0);
  for (const auto& [particle, code] : pairs) {
    ++offset[static_cast<std::size_t>(particle) + 1];
  }
  for (std::size_t p = 0; p < static_cast<std::size_t>(num_particles); ++p) {
    offset[p + 1] += offset[p];
  }
  entry.resize(pairs.size());
  std::vector<int> fill(offset.begin(), offset.end() - 1);
  for (const auto& [particle, code] : pairs) {
    entry[static_cast<std::size_t>(fill[particle]++)] = code;
  }
}

}  // namespace

std::string_view to_string(RestScale mode) {
  switch (mode) {
    case RestScale::Auto:
      return "auto";
    case RestScale::Boundary:
      return "boundary";
    case RestScale::Area:
      return "area";
    case RestScale::None:
      return "none";
  }
  return "unknown";
}

RestScale parse_rest_scale(std::string_view text, std::string_view input) {
  if (text == "auto") {
    return RestScale::Auto;
  }
  if (text == "boundary") {
    return RestScale::Boundary;
  }
  if (text == "area") {
    return RestScale::Area;
  }
  if (text == "none") {
    return RestScale::None;
  }
  throw InvalidInputError(std::string(input), "unknown rest scale '" + std::string(text) +
                                                  "' (expected auto, boundary, area or none)");
}

double rest_scale_factor(RestScale mode, const RegionSizes& sizes) {
  const auto check = [](double value, const char* what) {
    if (!std::isfinite(value) || value <= 0.0) {
      throw InvalidInputError("rest scale", std::string(what) + " is not finite and positive");
    }
  };
  switch (mode) {
    case RestScale::Auto:
      return std::min(rest_scale_factor(RestScale::Boundary, sizes),
                      rest_scale_factor(RestScale::Area, sizes));
    case RestScale::Boundary:
      check(sizes.source_boundary_length, "source boundary length");
      check(sizes.target_boundary_length, "target boundary length");
      return sizes.target_boundary_length / sizes.source_boundary_length;
    case RestScale::Area:
      check(sizes.source_area, "source area");
      check(sizes.target_area, "target area");
      // Lengths scale with the square root of areas.
      return std::sqrt(sizes.target_area / sizes.source_area);
    case RestScale::None:
      return 1.0;
  }
  return 1.0;
}

SpringSystem::SpringSystem(const ParticleGrid& grid, const SpringEnergyOptions& options)
    : grid_(&grid), options_(options), num_particles_(static_cast<int>(grid.mesh.n_vertices())) {
  const std::string name = "particle grid";
  if (!finite_non_negative(options.stiffness) || !finite_non_negative(options.angular_stiffness)) {
    throw InvalidInputError(name, "spring stiffness must be finite and non-negative");
  }
  if (!std::isfinite(options.rest_scale) || options.rest_scale <= 0.0) {
    throw InvalidInputError(name, "rest scale must be finite and positive");
  }
  if (grid.springs.empty() && num_particles_ > 1) {
    throw InvalidInputError(name, "springs are not built (call build_springs())");
  }

  const int n = num_particles_;
  const auto in_range = [n](int index) { return index >= 0 && index < n; };

  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(2 * grid.springs.size());
  for (std::size_t s = 0; s < grid.springs.size(); ++s) {
    const Spring& spring = grid.springs[s];
    if (!in_range(spring.i) || !in_range(spring.j) || spring.i == spring.j) {
      throw InvalidInputError(name,
                              "spring " + std::to_string(s) + " has invalid particle indices");
    }
    if (!finite_non_negative(spring.rest)) {
      throw InvalidInputError(name, "spring " + std::to_string(s) + " has an invalid rest length");
    }
    const int code = 2 * static_cast<int>(s);
    pairs.emplace_back(spring.i, code + 1);
    pairs.emplace_back(spring.j, code);
  }
  build_incidence(n, pairs, spring_offset_, spring_entry_);

  pairs.clear();
  pairs.reserve(3 * grid.angular_springs.size());
  for (std::size_t c = 0; c < grid.angular_springs.size(); ++c) {
    const AngularSpring& spring = grid.angular_springs[c];
    if (!in_range(spring.i) || !in_range(spring.a) || !in_range(spring.b) || spring.a == spring.i ||
        spring.b == spring.i || spring.a == spring.b) {
      throw InvalidInputError(
          name, "angular spring " + std::to_string(c) + " has invalid particle indices");
    }
    if (!finite_non_negative(spring.rest)) {
      throw InvalidInputError(
          name, "angular spring " + std::to_string(c) + " has an invalid rest length");
    }
    const int code = 2 * static_cast<int>(c);
    pairs.emplace_back(spring.i, code);
    pairs.emplace_back(spring.a, code + 1);
    pairs.emplace_back(spring.b, code + 1);
  }
  build_incidence(n, pairs, angular_offset_, angular_entry_);

  // Face corners in the faces' stored (counter-clockwise) order, walking the halfedges.
  corners_.reserve(4 * grid.mesh.n_faces());
  std::vector<int> face;
  for (const auto fh : grid.mesh.faces()) {
    face.clear();
    const auto first = grid.mesh.halfedge_handle(fh);
    auto heh = first;
    do {
      face.push_back(grid.mesh.to_vertex_handle(heh).idx());
      heh = grid.mesh.next_halfedge_handle(heh);
    } while (heh != first);
    const std::size_t k = face.size();
    for (std::size_t c = 0; c < k; ++c) {
      corners_.push_back({face[c], face[(c + 1) % k], face[(c + k - 1) % k], fh.idx()});
    }
  }

  if (!finite_non_negative(options.barrier_stiffness) ||
      !(options.barrier_sigma > 0.0 && options.barrier_sigma < 1.0)) {
    throw InvalidInputError(name,
                            "barrier stiffness must be finite and non-negative and its "
                            "threshold in (0, 1)");
  }
  if (!finite_non_negative(options.distortion_stiffness)) {
    throw InvalidInputError(name, "distortion stiffness must be finite and non-negative");
  }
  if (options.triangle_terms()) {
    build_barrier(grid);
  }

  spring_force_.resize(3, static_cast<Eigen::Index>(grid.springs.size()));
  angular_force_.resize(3, static_cast<Eigen::Index>(grid.angular_springs.size()));
}

void SpringSystem::build_barrier(const ParticleGrid& grid) {
  const auto source = [&](int p) {
    const auto& q = grid.mesh.point(GridMesh::VertexHandle(p));
    return Eigen::Vector3d(q[0], q[1], q[2]);
  };
  // Corners of one face are consecutive in corners_: body(first, count) for each face.
  const auto each_face = [&](const auto& body) {
    for (std::size_t first = 0; first < corners_.size();) {
      std::size_t end = first;
      while (end < corners_.size() && corners_[end].face == corners_[first].face) {
        ++end;
      }
      body(first, end - first);
      first = end;
    }
  };
  // A triangle once (weight 1); a quad by the four corner triangles of its two splits (1/2).
  // Counted first and reserved exactly: the triangles (48 bytes each, four per particle of a quad
  // grid) take no spare capacity.
  std::size_t triangles = 0;
  each_face([&](std::size_t, std::size_t k) { triangles += k == 3 ? 1 : k; });
  barrier_.reserve(triangles);
  each_face([&](std::size_t first, std::size_t k) {
    const std::size_t count = k == 3 ? 1 : k;
    const double weight = k == 3 ? 1.0 : 2.0 / static_cast<double>(k);
    for (std::size_t c = first; c < first + count; ++c) {
      const Corner& corner = corners_[c];
      const Eigen::Vector3d s0 = source(corner.next) - source(corner.i);
      const Eigen::Vector3d s1 = source(corner.prev) - source(corner.i);
      const double g00 = s0.dot(s0), g01 = s0.dot(s1), g11 = s1.dot(s1);
      const double det = g00 * g11 - g01 * g01;
      if (!(det > 1e-24 * g00 * g11)) {
        continue;  // a degenerate source triangle has no map to measure
      }
      BarrierTriangle t;
      t.i = corner.i;
      t.next = corner.next;
      t.prev = corner.prev;
      // w sigma^2 A_s, A_s = sqrt(det(S^T S)) / 2: the rest area at the target's scale, as the
      // springs' rest lengths are sigma k, so the barrier weighs the same against the springs
      // whatever the ratio of the two meshes' units.
      t.weight = weight * options_.rest_scale * options_.rest_scale * 0.5 * std::sqrt(det);
      t.b00 = g11 / det;
      t.b01 = -g01 / det;
      t.b11 = g00 / det;
      t.source_det = det;
      barrier_.push_back(t);
    }
  });
  barrier_active_.assign(barrier_.size(), 1);
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(3 * barrier_.size());
  for (std::size_t t = 0; t < barrier_.size(); ++t) {
    const int code = 3 * static_cast<int>(t);
    pairs.emplace_back(barrier_[t].i, code);
    pairs.emplace_back(barrier_[t].next, code + 1);
    pairs.emplace_back(barrier_[t].prev, code + 2);
  }
  build_incidence(num_particles_, pairs, barrier_offset_, barrier_entry_);
}

int SpringSystem::set_barrier_mask(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& normals) {
  int left_out = 0;
  for (std::size_t t = 0; t < barrier_.size(); ++t) {
    const BarrierTriangle& b = barrier_[t];
    barrier_active_[t] =
        triangle_inverted(x.col(b.i), x.col(b.next), x.col(b.prev), normals.col(b.i),
                          normals.col(b.next), normals.col(b.prev))
            ? 0
            : 1;
    left_out += barrier_active_[t] ? 0 : 1;
  }
  return left_out;
}

SpringEnergies SpringSystem::evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient,
                                      const Eigen::Matrix3Xd* normals,
                                      Eigen::Matrix3Xd* normal_gradient) const {
  check_positions(x);
  const bool want_gradient = gradient != nullptr;
  SpringEnergies energies;
  energies.length = length_energy(x, want_gradient);
  energies.angular = angular_energy(x, want_gradient);
  const bool with_barrier =
      options_.triangle_terms() && options_.stiffness > 0.0 && !barrier_.empty();
  if (with_barrier) {
    const Eigen::Vector2d triangles = triangle_energy(x, normals, want_gradient);
    energies.barrier = triangles[0];
    energies.distortion = triangles[1];
  }
  if (want_gradient) {
    gather_gradient(with_barrier, *gradient);
  }
  if (normal_gradient != nullptr) {
    if (with_barrier && normals != nullptr && want_gradient) {
      gather_normal_gradient(*normal_gradient);
    } else {
      normal_gradient->setZero(3, num_particles_);
    }
  }
  return energies;
}

void SpringSystem::check_positions(const Eigen::Matrix3Xd& x) const {
  if (x.cols() != num_particles_) {
    throw InvalidInputError("particle positions", "expected " + std::to_string(num_particles_) +
                                                      " columns, got " + std::to_string(x.cols()));
  }
}

SpringEnergies SpringSystem::evaluate_springs(const Eigen::Matrix3Xd& x,
                                              Eigen::Matrix3Xd* gradient) const {
  check_positions(x);
  SpringEnergies energies;
  energies.length = length_energy(x, gradient != nullptr);
  energies.angular = angular_energy(x, gradient != nullptr);
  if (gradient != nullptr) {
    gather_gradient(false, *gradient);
  }
  return energies;
}

// Normal springs, eq. 13: E = C (|d| - sigma k)^2, dE/dx_j = 2C (|d| - sigma k) d/|d| (eq. 14 up to
// the factor 2, see the header); the forces go to spring_force_.
double SpringSystem::length_energy(const Eigen::Matrix3Xd& x, bool want_gradient) const {
  const std::vector<Spring>& springs = grid_->springs;
  const double C = options_.stiffness;
  const double sigma = options_.rest_scale;
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, springs.size(), kGrain), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double sum) {
        for (std::size_t s = range.begin(); s != range.end(); ++s) {
          const Spring& spring = springs[s];
          const Eigen::Vector3d d = x.col(spring.j) - x.col(spring.i);
          const double length = d.norm();
          const double stretch = length - sigma * spring.rest;
          sum += C * stretch * stretch;
          if (want_gradient) {
            const auto col = static_cast<Eigen::Index>(s);
            if (length > 0.0) {
              spring_force_.col(col) = (2.0 * C * stretch / length) * d;
            } else {
              spring_force_.col(col).setZero();  // cone point: no gradient (see header)
            }
          }
        }
        return sum;
      },
      std::plus<double>());
}

// Angular springs: E = C_a (|e| - sigma r)^2 with e = x_i - (x_a + x_b)/2; dE/dx_i = 2 C_a (|e| -
// sigma r) e/|e|, and de/dx_a = de/dx_b = -I/2 gives the half-magnitude reactions; the forces go
// to angular_force_.
double SpringSystem::angular_energy(const Eigen::Matrix3Xd& x, bool want_gradient) const {
  const std::vector<AngularSpring>& angular = grid_->angular_springs;
  const double Ca = options_.angular_stiffness;
  const double sigma = options_.rest_scale;
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, angular.size(), kGrain), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double sum) {
        for (std::size_t c = range.begin(); c != range.end(); ++c) {
          const AngularSpring& spring = angular[c];
          const Eigen::Vector3d e = x.col(spring.i) - 0.5 * (x.col(spring.a) + x.col(spring.b));
          const double length = e.norm();
          const double stretch = length - sigma * spring.rest;
          sum += Ca * stretch * stretch;
          if (want_gradient) {
            const auto col = static_cast<Eigen::Index>(c);
            if (length > 0.0) {
              angular_force_.col(col) = (2.0 * Ca * stretch / length) * e;
            } else {
              angular_force_.col(col).setZero();
            }
          }
        }
        return sum;
      },
      std::plus<double>());
}

// Terms over grid triangles (header): E_bar and E_sd, returned as (E_bar, E_sd).
// Injectivity barrier: mu C w A h(g), g = sigma^2 tr(B G) det(S^T S) / D with
// G = T^T T the target Gram matrix and D = det(G) = |c|^2, c = T0 x T1 (Lagrange's identity;
// the cross product keeps a sliver's D accurate where G00 G11 - G01^2 would cancel to
// round-off), or with normals D = (c . u)^2, the area seen along the unit sum u of the three
// corners' normals (header).
// With q = sigma^2 det(S^T S), a = tr(B G) and m = c (or (c . u) u), both terms are functions
// of a and D (dg/da = q / D, dg/dD = -g / D), so dE/dT = dE/da da/dT + dE/dD dD/dT with
//   da/dT0 = 2 (b00 T0 + b01 T1),   da/dT1 = 2 (b11 T1 + b01 T0),
//   dD/dT0 = 2 T1 x m,              dD/dT1 = 2 m x T0.
// A collapsed (or, with normals, inverted) target triangle has infinite energy: the line search
// backs off.
//
// triangle_terms: one barrier triangle's terms at x, E_bar and E_sd, and with `gradient`
// dE/dx_next, dE/dx_prev (corner i's is minus their sum) and dE/dn of its corners.
SpringSystem::TriangleTerms SpringSystem::triangle_terms(std::size_t t, const Eigen::Matrix3Xd& x,
                                                         const Eigen::Matrix3Xd* normals,
                                                         bool gradient) const {
  TriangleTerms out;
  if (!barrier_active_[t]) {
    return out;
  }
  const double mu = options_.barrier_stiffness * options_.stiffness;
  const double sigma = options_.rest_scale;
  const double g0 = 1.0 / (options_.barrier_sigma * options_.barrier_sigma);
  const double lambda = options_.distortion_stiffness * options_.stiffness;
  const BarrierTriangle& b = barrier_[t];
  const Eigen::Vector3d t0 = x.col(b.next) - x.col(b.i);
  const Eigen::Vector3d t1 = x.col(b.prev) - x.col(b.i);
  const Eigen::Vector3d c = t0.cross(t1);
  Eigen::Vector3d m = c;
  Eigen::Vector3d u = Eigen::Vector3d::Zero();  // unit sum of the corner normals
  double seen = 0.0, sum_norm = 0.0;            // c . u and |n_i + n_next + n_prev|
  if (normals != nullptr) {
    const Eigen::Vector3d s = normals->col(b.i) + normals->col(b.next) + normals->col(b.prev);
    sum_norm = s.norm();
    if (sum_norm > 0.0) {
      u = s / sum_norm;
      seen = c.dot(u);
    }
    if (!(seen > 0.0)) {  // also |s| = 0 (opposed normals) and NaN
      out.barrier = std::numeric_limits<double>::infinity();
      return out;
    }
    m = seen * u;
  }
  const double D = m.squaredNorm();
  if (!(D > 0.0)) {
    out.barrier = std::numeric_limits<double>::infinity();
    return out;
  }
  const double a = b.b00 * t0.squaredNorm() + 2.0 * b.b01 * t0.dot(t1) + b.b11 * t1.squaredNorm();
  const double q = sigma * sigma * b.source_det;
  const double g = q * a / D;
  // dE/da and dE/dD of each term; the barrier's (dh = dE/dg q: dE/da = dh / D, dE/dD =
  // -dh a / D^2) in the form the barrier had alone, so its bits do not depend on E_sd.
  double dh = 0.0, sd_da = 0.0, sd_dd = 0.0;
  if (g > g0) {
    const double r = g / g0 - 1.0;
    out.barrier = mu * b.weight * r * r * r;
    dh = mu * b.weight * 3.0 * r * r / g0 * q;
  }
  if (lambda > 0.0) {
    // E_sd: lambda w (a / sigma^2 + g - 4), dg/da = q / D, dg/dD = -g / D.
    out.distortion = lambda * b.weight * (a / (sigma * sigma) + g - 4.0);
    sd_da = lambda * b.weight * (1.0 / (sigma * sigma) + q / D);
    sd_dd = -lambda * b.weight * g / D;
  }
  out.has_gradient = dh != 0.0 || sd_da != 0.0 || sd_dd != 0.0;
  if (!gradient || !out.has_gradient) {
    return out;
  }
  const double over_d = 1.0 / D, a_over_d2 = a / (D * D);
  const Eigen::Vector3d da0 = 2.0 * (b.b00 * t0 + b.b01 * t1);             // da/dT0
  const Eigen::Vector3d da1 = 2.0 * (b.b11 * t1 + b.b01 * t0);             // da/dT1
  const Eigen::Vector3d dd0 = 2.0 * t1.cross(m), dd1 = 2.0 * m.cross(t0);  // dD/dT0, dD/dT1
  double de_dd = 0.0;
  if (dh != 0.0) {
    out.f0 = dh * (over_d * da0 - a_over_d2 * dd0);
    out.f1 = dh * (over_d * da1 - a_over_d2 * dd1);
    de_dd = -dh * a_over_d2;
  }
  if (lambda > 0.0) {
    out.f0 += sd_da * da0 + sd_dd * dd0;
    out.f1 += sd_da * da1 + sd_dd * dd1;
    de_dd += sd_dd;
  }
  if (normals != nullptr) {
    // dE/dn_j for each corner j: with s = n_i + n_next + n_prev, u = s / |s| and
    // D = (c . u)^2, dD/dn_j = dD/ds = 2 (c . u) (I - u u^T) c / |s|.
    out.fn = (2.0 * de_dd * seen / sum_norm) * (c - seen * u);
  }
  return out;
}

// The energies in a deterministic reduce; with the gradient, the triangles whose terms have one
// get a slot (in triangle order) and their forces are computed again into it, in parallel. Most
// triangles of a map sit below the barrier's threshold: dense force buffers were 72 bytes a
// triangle, 290 MB at a million particles, rewritten at every evaluation.
Eigen::Vector2d SpringSystem::triangle_energy(const Eigen::Matrix3Xd& x,
                                              const Eigen::Matrix3Xd* normals,
                                              bool want_gradient) const {
  if (normals != nullptr && normals->cols() != num_particles_) {
    throw InvalidInputError("particle normals", "expected " + std::to_string(num_particles_) +
                                                    " columns, got " +
                                                    std::to_string(normals->cols()));
  }
  if (want_gradient) {
    barrier_slot_.resize(barrier_.size());
  }
  Eigen::Vector2d energies = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, barrier_.size(), kGrain), Eigen::Vector2d(0.0, 0.0),
      [&](const tbb::blocked_range<std::size_t>& range, Eigen::Vector2d sum) {
        for (std::size_t t = range.begin(); t != range.end(); ++t) {
          const TriangleTerms terms = triangle_terms(t, x, normals, false);
          sum[0] += terms.barrier;
          sum[1] += terms.distortion;
          if (want_gradient) {
            barrier_slot_[t] = terms.has_gradient && std::isfinite(terms.barrier) ? 0 : -1;
          }
        }
        return sum;
      },
      std::plus<Eigen::Vector2d>());
  if (!want_gradient) {
    return energies;
  }
  std::vector<std::size_t> slotted;
  for (std::size_t t = 0; t < barrier_.size(); ++t) {
    if (barrier_slot_[t] == 0) {
      barrier_slot_[t] = static_cast<int>(slotted.size());
      slotted.push_back(t);
    }
  }
  const auto count = static_cast<Eigen::Index>(slotted.size());
  if (barrier_force_.cols() < 2 * count) {  // grown only: the next evaluations reuse it
    barrier_force_.resize(3, 2 * count);
    barrier_normal_force_.resize(3, count);
  }
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, count, 256),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
                      for (Eigen::Index k = range.begin(); k != range.end(); ++k) {
                        const TriangleTerms terms =
                            triangle_terms(slotted[static_cast<std::size_t>(k)], x, normals, true);
                        barrier_force_.col(2 * k) = terms.f0;
                        barrier_force_.col(2 * k + 1) = terms.f1;
                        barrier_normal_force_.col(k) = terms.fn;
                      }
                    });
  return energies;
}

// Gathers the forces per particle in the fixed incidence order: no races, same bits for any thread
// count.
void SpringSystem::gather_gradient(bool with_barrier, Eigen::Matrix3Xd& gradient) const {
  gradient.resize(3, num_particles_);
  tbb::parallel_for(tbb::blocked_range<int>(0, num_particles_, static_cast<int>(kGrain)),
                    [&](const tbb::blocked_range<int>& range) {
                      for (int p = range.begin(); p != range.end(); ++p) {
                        Eigen::Vector3d g = Eigen::Vector3d::Zero();
                        for (int k = spring_offset_[p]; k < spring_offset_[p + 1]; ++k) {
                          const int code = spring_entry_[k];
                          if (code & 1) {
                            g -= spring_force_.col(code >> 1);
                          } else {
                            g += spring_force_.col(code >> 1);
                          }
                        }
                        for (int k = angular_offset_[p]; k < angular_offset_[p + 1]; ++k) {
                          const int code = angular_entry_[k];
                          if (code & 1) {
                            g -= 0.5 * angular_force_.col(code >> 1);
                          } else {
                            g += angular_force_.col(code >> 1);
                          }
                        }
                        if (with_barrier) {
                          for (int k = barrier_offset_[p]; k < barrier_offset_[p + 1]; ++k) {
                            const int code = barrier_entry_[k], role = code % 3;
                            const int slot = barrier_slot_[static_cast<std::size_t>(code / 3)];
                            if (slot < 0) {
                              continue;  // no gradient
                            }
                            const auto col = 2 * static_cast<Eigen::Index>(slot);
                            if (role == 0) {
                              g += -(barrier_force_.col(col) + barrier_force_.col(col + 1));
                            } else {
                              g += barrier_force_.col(col + role - 1);
                            }
                          }
                        }
                        gradient.col(p) = g;
                      }
                    });
}

// dE/dn_p: the entries of the barrier triangles at p (any role), in the fixed incidence order.
void SpringSystem::gather_normal_gradient(Eigen::Matrix3Xd& normal_gradient) const {
  normal_gradient.resize(3, num_particles_);
  tbb::parallel_for(tbb::blocked_range<int>(0, num_particles_, static_cast<int>(kGrain)),
                    [&](const tbb::blocked_range<int>& range) {
                      for (int p = range.begin(); p != range.end(); ++p) {
                        Eigen::Vector3d g = Eigen::Vector3d::Zero();
                        for (int k = barrier_offset_[p]; k < barrier_offset_[p + 1]; ++k) {
                          // Every corner of a triangle has the same dE/dn (its sum s).
                          const int slot =
                              barrier_slot_[static_cast<std::size_t>(barrier_entry_[k] / 3)];
                          if (slot >= 0) {
                            g += barrier_normal_force_.col(slot);
                          }
                        }
                        normal_gradient.col(p) = g;
                      }
                    });
}

void SpringSystem::folded_corners(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& normals,
                                  std::vector<char>& folded) const {
  folded.resize(corners_.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, corners_.size(), kGrain),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t c = range.begin(); c != range.end(); ++c) {
                        const Corner& corner = corners_[c];
                        const Eigen::Vector3d xi = x.col(corner.i);
                        // The one fold test (face_folds.h): against the sum of the three corners'
                        // normals; degenerate (collapsed) corners and NaN count as folded.
                        folded[c] = triangle_inverted(
                            xi, x.col(corner.next), x.col(corner.prev), normals.col(corner.i),
                            normals.col(corner.next), normals.col(corner.prev));
                      }
                    });
}

int SpringSystem::folded_faces(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& normals) const {
  std::vector<char> folded;
  folded_corners(x, normals, folded);
  int count = 0;
  int last_face = -1;
  for (std::size_t c = 0; c < corners_.size(); ++c) {
    // Corners of one face are consecutive; count each face once.
    if (folded[c] && corners_[c].face != last_face) {
      ++count;
      last_face = corners_[c].face;
    }
  }
  return count;
}

SpringEnergies spring_energy(const ParticleGrid& grid, const Eigen::Matrix3Xd& x,
                             const SpringEnergyOptions& options, Eigen::Matrix3Xd* gradient) {
  return SpringSystem(grid, options).evaluate(x, gradient);
}

double magnet_energy(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& closest, double stiffness,
                     const std::vector<char>& active, Eigen::Matrix3Xd* gradient) {
  if (closest.cols() != x.cols() || (!active.empty() && active.size() != std::size_t(x.cols())) ||
      (gradient != nullptr && gradient->cols() != x.cols())) {
    throw InvalidInputError("magnet", "positions, closest points and gradient differ in size");
  }
  double energy = 0.0;
  for (Eigen::Index p = 0; p < x.cols(); ++p) {
    if (!active.empty() && !active[static_cast<std::size_t>(p)]) {
      continue;
    }
    const Eigen::Vector3d offset = x.col(p) - closest.col(p);
    energy += 0.5 * stiffness * offset.squaredNorm();
    if (gradient != nullptr) {
      gradient->col(p) += stiffness * offset;
    }
  }
  return energy;
}

}  // namespace elastic
