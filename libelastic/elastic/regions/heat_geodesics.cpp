#include "elastic/regions/heat_geodesics.h"

#include <tbb/parallel_invoke.h>

#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include "elastic/core/directed_edges.h"
#include "elastic/core/error.h"

namespace elastic::regions_detail {
namespace {

/// A shift on the Poisson operator's diagonal that keeps the connected components not holding the
/// pin non-singular.
constexpr double kShift = 1e-12;

// The cotangent Laplacian L (positive semi-definite, both triangles stored, columns sorted, every
// diagonal entry present), the lumped (barycentric) mass per vertex and the mean edge length,
// written straight into compressed columns: the 15 triplets per triangle and setFromTriplets they
// replace took 36 ms of a 0.15 s disk cut on bob (19,161 vertices, 2 threads). Every entry is
// summed in the triangles' order, corner by corner, from -0.0 (x + -0.0 == x for every x), so the
// values are the same bits as the triplets' sum, which kept their first value and added the rest in
// that order. Degenerate triangles (zero area) add mass and edge length but no weights, so their
// edges enter the pattern only through other triangles, as the triplets left them.
struct CotanParts {
  Eigen::SparseMatrix<double> laplacian;
  Eigen::VectorXd mass;
  double mean_edge = 0.0;
};

CotanParts cotan_parts(const std::vector<Eigen::Vector3d>& x,
                       const std::vector<Eigen::Vector3i>& tri) {
  const int nv = static_cast<int>(x.size());
  const auto at = [&](int v) -> const Eigen::Vector3d& { return x[static_cast<size_t>(v)]; };
  const auto double_area = [&](const Eigen::Vector3i& v) {
    return (at(v[1]) - at(v[0])).cross(at(v[2]) - at(v[0])).norm();
  };
  // Pattern: each column's diagonal and the other two corners of every non-degenerate triangle
  // around it (DirectedEdges groups the triangles by vertex), sorted and deduplicated.
  std::vector<int> solid;
  solid.reserve(tri.size());
  for (size_t t = 0; t < tri.size(); ++t) {
    if (double_area(tri[t]) != 0.0) {
      solid.push_back(static_cast<int>(t));
    }
  }
  const DirectedEdges around(tri, nv, &solid);
  std::vector<int> column(static_cast<size_t>(nv) + 1, 0), rows, neighbours;
  rows.reserve(static_cast<size_t>(nv) + 6 * solid.size());
  for (int v = 0; v < nv; ++v) {
    neighbours.assign(1, v);
    for (int e = around.begin(v); e < around.end(v); ++e) {
      const Eigen::Vector3i& t = tri[static_cast<size_t>(around.triangle(e))];
      neighbours.push_back(around.to(e));
      neighbours.push_back(t.sum() - v - around.to(e));  // the triangle's third corner
    }
    std::sort(neighbours.begin(), neighbours.end());
    rows.insert(rows.end(), neighbours.begin(), std::unique(neighbours.begin(), neighbours.end()));
    column[static_cast<size_t>(v) + 1] = static_cast<int>(rows.size());
  }
  CotanParts parts;
  Eigen::SparseMatrix<double>& lap = parts.laplacian;
  lap.resize(nv, nv);
  lap.makeCompressed();
  const auto nnz = static_cast<Eigen::Index>(rows.size());
  lap.resizeNonZeros(nnz);
  std::copy(column.begin(), column.end(), lap.outerIndexPtr());
  std::copy(rows.begin(), rows.end(), lap.innerIndexPtr());
  std::fill(lap.valuePtr(), lap.valuePtr() + nnz, -0.0);
  const auto entry = [&](int r, int c) -> double& {
    const int* first = lap.innerIndexPtr() + column[static_cast<size_t>(c)];
    const int* last = lap.innerIndexPtr() + column[static_cast<size_t>(c) + 1];
    return lap.valuePtr()[std::lower_bound(first, last, r) - lap.innerIndexPtr()];
  };
  parts.mass = Eigen::VectorXd::Constant(nv, -0.0);
  double total_edge = 0.0;
  for (size_t t = 0; t < tri.size(); ++t) {
    const Eigen::Vector3i& v = tri[t];
    const double area2 = double_area(v);
    for (int k = 0; k < 3; ++k) {
      const int i = v[k], j = v[(k + 1) % 3], l = v[(k + 2) % 3];
      total_edge += (at(j) - at(i)).norm();
      parts.mass[i] += area2 / 6.0;
      if (area2 == 0.0) {
        continue;
      }
      // cot of the angle at i weighs the opposite edge (j, l): cot = (a.b) / |a x b|.
      const double w = 0.5 * ((at(j) - at(i)).dot(at(l) - at(i)) / area2);
      entry(j, j) += w;
      entry(l, l) += w;
      entry(j, l) += -w;
      entry(l, j) += -w;
    }
  }
  parts.mean_edge = total_edge / static_cast<double>(3 * std::max<size_t>(tri.size(), 1));
  return parts;
}

}  // namespace

HeatGeodesics::HeatGeodesics(const std::vector<Eigen::Vector3d>& positions,
                             const std::vector<Eigen::Vector3i>& triangles, std::string name)
    : x_(positions), tri_(triangles), name_(std::move(name)) {
  CotanParts parts = cotan_parts(x_, tri_);
  h_ = parts.mean_edge;
  laplacian_.swap(parts.laplacian);
  mass_ = std::move(parts.mass);
}

void HeatGeodesics::factor_heat() const {
  std::call_once(heat_factored_, [&] {
    // Time step t = h^2 (Crane et al. §3.2.4, m = 1).
    Eigen::SparseMatrix<double> a = (h_ * h_) * laplacian_;
    for (int v = 0; v < a.cols(); ++v) {
      a.coeffRef(v, v) = mass_[v] + a.coeff(v, v);
    }
    auto solver = std::make_unique<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>>(a);
    if (solver->info() != Eigen::Success) {
      throw NumericalError(name_, "heat method: factorisation of the heat operator failed");
    }
    heat_solver_ = std::move(solver);
  });
}

Eigen::VectorXd HeatGeodesics::heat(const MeshLocation& source) const {
  factor_heat();
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(x_.size()));
  for (int k = 0; k < 3; ++k) {
    rhs[tri_[static_cast<size_t>(source.triangle)][k]] += source.bary[k];
  }
  Eigen::VectorXd u = heat_solver_->solve(rhs);
  if (heat_solver_->info() != Eigen::Success || !u.allFinite()) {
    throw NumericalError(name_, "heat method: heat solve failed");
  }
  return u;
}

Eigen::Vector3d HeatGeodesics::gradient(int t, const Eigen::VectorXd& f) const {
  const Eigen::Vector3i& v = tri_[static_cast<size_t>(t)];
  const Eigen::Vector3d& x0 = x_[static_cast<size_t>(v[0])];
  const Eigen::Vector3d& x1 = x_[static_cast<size_t>(v[1])];
  const Eigen::Vector3d& x2 = x_[static_cast<size_t>(v[2])];
  const Eigen::Vector3d normal = (x1 - x0).cross(x2 - x0);
  const double double_area = normal.norm();
  if (double_area == 0.0) {
    return Eigen::Vector3d::Zero();
  }
  const Eigen::Vector3d n = normal / double_area;
  // grad f = sum_i f_i (n x e_i) / (2A), e_i the edge opposite corner i, counter-clockwise.
  return (f[v[0]] * n.cross(x2 - x1) + f[v[1]] * n.cross(x0 - x2) + f[v[2]] * n.cross(x1 - x0)) /
         double_area;
}

Eigen::VectorXd HeatGeodesics::divergence(const Eigen::VectorXd& u) const {
  const int nv = static_cast<int>(x_.size());
  // Divergence of the unit field X = -grad u / |grad u| at every vertex (Crane et al. eq. 4):
  // div_i = 1/2 sum_T cot(theta_1) (e_1 . X) + cot(theta_2) (e_2 . X), e_1, e_2 the edges from i.
  Eigen::VectorXd div = Eigen::VectorXd::Zero(nv);
  for (size_t t = 0; t < tri_.size(); ++t) {
    Eigen::Vector3d g = gradient(static_cast<int>(t), u);
    if (g.norm() == 0.0) {
      continue;
    }
    const Eigen::Vector3d field = -g.normalized();
    const Eigen::Vector3i& v = tri_[t];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& xi = x_[static_cast<size_t>(v[k])];
      const Eigen::Vector3d& xj = x_[static_cast<size_t>(v[(k + 1) % 3])];
      const Eigen::Vector3d& xl = x_[static_cast<size_t>(v[(k + 2) % 3])];
      const double cross = (xj - xi).cross(xl - xi).norm();
      if (cross == 0.0) {
        continue;
      }
      const double cot_l = (xi - xl).dot(xj - xl) / cross;  // angle at l, opposite edge i-j
      const double cot_j = (xi - xj).dot(xl - xj) / cross;  // angle at j, opposite edge i-l
      div[v[k]] += 0.5 * (cot_l * (xj - xi).dot(field) + cot_j * (xl - xi).dot(field));
    }
  }
  return div;
}

Eigen::SparseMatrix<double> HeatGeodesics::pinned_laplacian(int pin) const {
  // L without the pin's row and column (rows and columns past it move up by one), plus kShift on
  // the diagonal.
  const int nv = static_cast<int>(laplacian_.cols());
  const int* outer = laplacian_.outerIndexPtr();
  const int* inner = laplacian_.innerIndexPtr();
  const double* value = laplacian_.valuePtr();
  Eigen::SparseMatrix<double> a(nv - 1, nv - 1);
  a.makeCompressed();
  a.resizeNonZeros(laplacian_.nonZeros());
  int nnz = 0;
  for (int c = 0; c < nv; ++c) {
    if (c == pin) {
      continue;
    }
    const int cc = c - (c > pin ? 1 : 0);
    a.outerIndexPtr()[cc] = nnz;
    for (int k = outer[c]; k < outer[c + 1]; ++k) {
      if (inner[k] != pin) {
        a.innerIndexPtr()[nnz] = inner[k] - (inner[k] > pin ? 1 : 0);
        a.valuePtr()[nnz++] = inner[k] == c ? value[k] + kShift : value[k];
      }
    }
  }
  a.outerIndexPtr()[nv - 1] = nnz;
  a.resizeNonZeros(nnz);
  return a;
}

Eigen::VectorXd HeatGeodesics::distance(const MeshLocation& source) const {
  const int nv = static_cast<int>(x_.size());
  // Pin the source triangle's heaviest corner; solve Crane's Delta phi = div X on the other
  // vertices. Our L is positive semi-definite (L = -Delta), so the system is L phi = -div X.
  const int pin = pin_of(source);
  // The Poisson factorisation needs only the pin: it runs beside the heat step (with the heat
  // operator's factorisation on first use) and the divergence, two factorisations of the same
  // cost at once (each on one thread, so the bits do not depend on the thread count).
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  Eigen::VectorXd div;
  tbb::parallel_invoke([&] { div = divergence(heat(source)); },
                       [&] { solver.compute(pinned_laplacian(pin)); });
  if (solver.info() != Eigen::Success) {
    throw NumericalError(name_, "heat method: factorisation of the Poisson problem failed");
  }
  Eigen::VectorXd rhs(nv - 1);
  for (int i = 0; i < nv; ++i) {
    if (i != pin) {
      rhs[i - (i > pin ? 1 : 0)] = -div[i];
    }
  }
  const Eigen::VectorXd y = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !y.allFinite()) {
    throw NumericalError(name_, "heat method: Poisson solve failed");
  }
  Eigen::VectorXd phi(nv);
  for (int i = 0; i < nv; ++i) {
    phi[i] = i == pin ? 0.0 : y[i - (i > pin ? 1 : 0)];
  }
  return shifted_to_source(std::move(phi), source);
}

int HeatGeodesics::pin_of(const MeshLocation& source) const {
  int kmax = 0;
  source.bary.maxCoeff(&kmax);
  return tri_[static_cast<size_t>(source.triangle)][kmax];
}

void HeatGeodesics::factor_poisson() const {
  std::call_once(poisson_factored_, [&] {
    // A = L + kShift I + e_0 e_0^T: the pinned operator's shift (pinned_laplacian) and a rank-one
    // term at vertex 0 that makes A positive definite on vertex 0's component.
    Eigen::SparseMatrix<double> a = laplacian_;
    for (int v = 0; v < a.cols(); ++v) {
      a.coeffRef(v, v) += v == 0 ? kShift + 1.0 : kShift;
    }
    auto solver = std::make_unique<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>>(a);
    if (solver->info() != Eigen::Success) {
      throw NumericalError(name_, "heat method: factorisation of the Poisson problem failed");
    }
    poisson_w0_ = solver->solve(Eigen::VectorXd::Unit(a.cols(), 0));
    poisson_solver_ = std::move(solver);
  });
}

Eigen::VectorXd HeatGeodesics::distance_reusing(const MeshLocation& source) const {
  // The pinned system of distance(), (L + kShift I) phi = b on every vertex but the pin p, with
  // phi_p = 0, written with A = L + kShift I + e_0 e_0^T (factored once, factor_poisson) as
  // A phi = b + mu e_p + nu e_0 with nu = phi_0 (mu frees row p). So phi = u + mu w_p + nu w_0
  // with u = A^-1 b, w_p = A^-1 e_p, w_0 = A^-1 e_0, and mu, nu from the two conditions
  //   phi_p = 0:    u_p + mu w_p[p] + nu w_0[p] = 0,
  //   phi_0 = nu:   u_0 + mu w_p[0] + nu (w_0[0] - 1) = 0.
  // (For p = 0 the second is phi_0 = 0 itself and nu drops out with w_p = w_0.)
  const int pin = pin_of(source);
  Eigen::VectorXd div;
  tbb::parallel_invoke([&] { div = divergence(heat(source)); }, [&] { factor_poisson(); });
  const auto& solver = *poisson_solver_;
  const Eigen::VectorXd u = solver.solve(-div);
  Eigen::VectorXd phi;
  if (pin == 0) {
    phi = u - (u[0] / poisson_w0_[0]) * poisson_w0_;
  } else {
    const Eigen::VectorXd wp = solver.solve(Eigen::VectorXd::Unit(u.size(), pin));
    Eigen::Matrix2d m;
    m << wp[pin], poisson_w0_[pin], wp[0], poisson_w0_[0] - 1.0;
    const Eigen::Vector2d coef = m.fullPivLu().solve(Eigen::Vector2d(-u[pin], -u[0]));
    phi = u + coef[0] * wp + coef[1] * poisson_w0_;
    phi[pin] = 0.0;
  }
  if (solver.info() != Eigen::Success || !phi.allFinite()) {
    throw NumericalError(name_, "heat method: Poisson solve failed");
  }
  return shifted_to_source(std::move(phi), source);
}

Eigen::VectorXd HeatGeodesics::shifted_to_source(Eigen::VectorXd phi,
                                                 const MeshLocation& source) const {
  const int nv = static_cast<int>(x_.size());
  double at_source = 0.0;
  for (int k = 0; k < 3; ++k) {
    at_source += source.bary[k] * phi[tri_[static_cast<size_t>(source.triangle)][k]];
  }
  phi.array() -= at_source;
  // The heat step rounds off the distance cone's tip, which shifts phi by a roughly constant amount
  // everywhere away from the source (phi underestimates the distance). Near the source the geodesic
  // distance equals the chord length to third order (their difference is about k^2 d^3 / 24 for
  // curvature k), so the shift is measured as the median of phi - |x - source| over the vertices
  // between 3 and 6 mean edge lengths from the source, and removed.
  const Eigen::Vector3d centre = position_of(x_, tri_, source);
  std::vector<double> offsets;
  for (int i = 0; i < nv; ++i) {
    const double chord = (x_[static_cast<size_t>(i)] - centre).norm();
    if (chord >= 3.0 * h_ && chord <= 6.0 * h_ && phi[i] < 8.0 * h_) {
      offsets.push_back(phi[i] - chord);
    }
  }
  if (offsets.size() >= 8) {
    std::nth_element(offsets.begin(),
                     offsets.begin() + static_cast<std::ptrdiff_t>(offsets.size() / 2),
                     offsets.end());
    phi.array() -= offsets[offsets.size() / 2];
  }
  return phi;
}

namespace {

/// The part of the mesh local_geodesic_distance works on: the triangles with a corner within `ball`
/// of the source point, connected to the source's triangle through them.
struct Part {
  bool whole = false;  ///< more than 70% of the triangles: use the whole mesh (the lists below are
                       ///< then incomplete)
  std::vector<int> global;                 ///< part vertex -> mesh vertex
  std::vector<int> triangles;              ///< the mesh triangles in the part, increasing
  std::vector<Eigen::Vector3d> positions;  ///< of the part's vertices
  std::vector<Eigen::Vector3i> local;      ///< the part's triangles on its own vertices
};

Part select_part(const std::vector<Eigen::Vector3d>& positions,
                 const std::vector<Eigen::Vector3i>& triangles, const Eigen::Vector3d& centre,
                 int source_triangle, double ball) {
  const auto nt = triangles.size();
  const auto nv = positions.size();
  // Triangles near the source, then the ones connected to the source's triangle through shared
  // corners (breadth first over vertex -> triangle incidences of the near ones).
  std::vector<char> near(nv, 0), selected(nt, 0);
  for (size_t v = 0; v < nv; ++v) {
    near[v] = (positions[v] - centre).squaredNorm() <= ball * ball;
  }
  std::vector<int> start(nv + 1, 0);
  for (size_t t = 0; t < nt; ++t) {
    const Eigen::Vector3i& tri = triangles[t];
    if (near[static_cast<size_t>(tri[0])] || near[static_cast<size_t>(tri[1])] ||
        near[static_cast<size_t>(tri[2])] || static_cast<int>(t) == source_triangle) {
      selected[t] = 1;
      for (int k = 0; k < 3; ++k) {
        ++start[static_cast<size_t>(tri[k]) + 1];
      }
    }
  }
  for (size_t v = 0; v < nv; ++v) {
    start[v + 1] += start[v];
  }
  std::vector<int> incident(static_cast<size_t>(start[nv]));
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (size_t t = 0; t < nt; ++t) {
    if (selected[t]) {
      for (int k = 0; k < 3; ++k) {
        incident[static_cast<size_t>(fill[static_cast<size_t>(triangles[t][k])]++)] =
            static_cast<int>(t);
      }
    }
  }
  std::vector<char> reached(nt, 0);
  Part part;
  std::vector<int>& queue = part.triangles;
  queue.push_back(source_triangle);
  reached[static_cast<size_t>(source_triangle)] = 1;
  for (size_t q = 0; q < queue.size(); ++q) {
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<size_t>(triangles[static_cast<size_t>(queue[q])][k]);
      for (int i = start[v]; i < start[v + 1]; ++i) {
        const auto t = static_cast<size_t>(incident[static_cast<size_t>(i)]);
        if (!reached[t]) {
          reached[t] = 1;
          queue.push_back(static_cast<int>(t));
        }
      }
    }
  }
  if (10 * queue.size() > 7 * nt) {
    part.whole = true;  // the callers solve on the whole mesh: the lists are not needed
    return part;
  }
  // The part as a mesh of its own, in the whole mesh's triangle order.
  std::sort(queue.begin(), queue.end());
  std::vector<int> local(nv, -1);
  part.local.reserve(queue.size());
  for (const int t : queue) {
    Eigen::Vector3i tri;
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<size_t>(triangles[static_cast<size_t>(t)][k]);
      if (local[v] < 0) {
        local[v] = static_cast<int>(part.global.size());
        part.global.push_back(static_cast<int>(v));
        part.positions.push_back(positions[v]);
      }
      tri[k] = local[v];
    }
    part.local.push_back(tri);
  }
  return part;
}

/// The source in the part's own triangles (the part's triangles are increasing mesh triangles).
MeshLocation source_in(const Part& part, const MeshLocation& source) {
  MeshLocation s = source;
  const auto found = std::lower_bound(part.triangles.begin(), part.triangles.end(), s.triangle);
  s.triangle = static_cast<int>(found - part.triangles.begin());
  return s;
}

Eigen::VectorXd spread(const Part& part, const Eigen::VectorXd& on_part, size_t nv, double far) {
  Eigen::VectorXd distance = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(nv), far);
  for (size_t i = 0; i < part.global.size(); ++i) {
    distance[part.global[i]] = on_part[static_cast<Eigen::Index>(i)];
  }
  return distance;
}

}  // namespace

Eigen::VectorXd local_geodesic_distance(const std::vector<Eigen::Vector3d>& positions,
                                        const std::vector<Eigen::Vector3i>& triangles,
                                        const MeshLocation& source, double reach, double far,
                                        const std::string& name) {
  const Part part = select_part(positions, triangles, position_of(positions, triangles, source),
                                source.triangle, 2.0 * reach);
  if (part.whole) {
    return HeatGeodesics(positions, triangles, name).distance(source);
  }
  return spread(part,
                HeatGeodesics(part.positions, part.local, name).distance(source_in(part, source)),
                positions.size(), far);
}

struct LocalHeatCache::Held {
  Eigen::Vector3d centre;  // the part holds the triangles within 2 reach of it
  double reach = 0.0;
  size_t nv = 0, nt = 0;  // of the mesh
  Part part;
  std::unique_ptr<HeatGeodesics> heat;  // on the part (or the mesh, part.whole)

  // Whether the part is still the mesh's (the same vertices at the same places and triangles).
  bool matches(const std::vector<Eigen::Vector3d>& positions,
               const std::vector<Eigen::Vector3i>& triangles) const {
    if (positions.size() != nv || triangles.size() != nt) {
      return false;
    }
    for (size_t i = 0; i < part.global.size(); ++i) {
      if (positions[static_cast<size_t>(part.global[i])] != part.positions[i]) {
        return false;
      }
    }
    for (size_t t = 0; t < part.triangles.size(); ++t) {
      const Eigen::Vector3i& mesh = triangles[static_cast<size_t>(part.triangles[t])];
      const Eigen::Vector3i& local = part.local[t];
      for (int k = 0; k < 3; ++k) {
        if (part.global[static_cast<size_t>(local[k])] != mesh[k]) {
          return false;
        }
      }
    }
    return true;
  }
};

LocalHeatCache::LocalHeatCache() = default;
LocalHeatCache::~LocalHeatCache() = default;

Eigen::VectorXd LocalHeatCache::distance(const std::vector<Eigen::Vector3d>& positions,
                                         const std::vector<Eigen::Vector3i>& triangles,
                                         const MeshLocation& source, double reach, double far,
                                         const std::string& name) {
  const Eigen::Vector3d centre = position_of(positions, triangles, source);
  const auto holds = [&](const Held& h) {
    return !h.part.whole && (centre - h.centre).norm() + 2.0 * reach <= 2.0 * h.reach &&
           h.reach <= kMaxRoom * reach &&
           std::binary_search(h.part.triangles.begin(), h.part.triangles.end(), source.triangle) &&
           h.matches(positions, triangles);
  };
  if (!held_ || !holds(*held_)) {
    held_.reset();
    auto h = std::make_unique<Held>();
    h->centre = centre;
    h->reach = kRoom * reach;
    h->nv = positions.size();
    h->nt = triangles.size();
    h->part = select_part(positions, triangles, centre, source.triangle, 2.0 * h->reach);
    if (h->part.whole) {
      return HeatGeodesics(positions, triangles, name).distance(source);
    }
    h->heat = std::make_unique<HeatGeodesics>(h->part.positions, h->part.local, name);
    held_ = std::move(h);
    ++builds_;
  }
  return spread(held_->part, held_->heat->distance_reusing(source_in(held_->part, source)),
                positions.size(), far);
}

}  // namespace elastic::regions_detail
