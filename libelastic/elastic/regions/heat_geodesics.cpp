#include "elastic/regions/heat_geodesics.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>

#include "elastic/core/error.h"

namespace elastic::regions_detail {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

}  // namespace

HeatGeodesics::HeatGeodesics(const std::vector<Eigen::Vector3d>& positions,
                             const std::vector<Eigen::Vector3i>& triangles, std::string name)
    : x_(positions), tri_(triangles), name_(std::move(name)) {
  const int nv = static_cast<int>(x_.size());
  Triplets lap, mass;
  double total_edge = 0.0;
  for (size_t t = 0; t < tri_.size(); ++t) {
    const Eigen::Vector3i& v = tri_[t];
    const Eigen::Vector3d normal =
        (x_[static_cast<size_t>(v[1])] - x_[static_cast<size_t>(v[0])])
            .cross(x_[static_cast<size_t>(v[2])] - x_[static_cast<size_t>(v[0])]);
    const double double_area = normal.norm();
    for (int k = 0; k < 3; ++k) {
      const int i = v[k], j = v[(k + 1) % 3], l = v[(k + 2) % 3];
      total_edge += (x_[static_cast<size_t>(j)] - x_[static_cast<size_t>(i)]).norm();
      mass.emplace_back(i, i, double_area / 6.0);
      if (double_area == 0.0) {
        continue;
      }
      // cot of the angle at i weighs the opposite edge (j, l): cot = (a.b) / |a x b|.
      const double cot = (x_[static_cast<size_t>(j)] - x_[static_cast<size_t>(i)])
                             .dot(x_[static_cast<size_t>(l)] - x_[static_cast<size_t>(i)]) /
                         double_area;
      const double w = 0.5 * cot;
      lap.emplace_back(j, j, w);
      lap.emplace_back(l, l, w);
      lap.emplace_back(j, l, -w);
      lap.emplace_back(l, j, -w);
    }
  }
  h_ = total_edge / static_cast<double>(3 * std::max<size_t>(tri_.size(), 1));
  laplacian_.resize(nv, nv);
  laplacian_.setFromTriplets(lap.begin(), lap.end());
  Eigen::SparseMatrix<double> m(nv, nv);
  m.setFromTriplets(mass.begin(), mass.end());
  // Time step t = h^2 (Crane et al. §3.2.4, m = 1).
  const Eigen::SparseMatrix<double> a = m + (h_ * h_) * laplacian_;
  heat_solver_ = std::make_unique<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>>(a);
  if (heat_solver_->info() != Eigen::Success) {
    throw NumericalError(name_, "heat method: factorisation of the heat operator failed");
  }
}

Eigen::VectorXd HeatGeodesics::heat(const MeshLocation& source) const {
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

Eigen::VectorXd HeatGeodesics::distance(const MeshLocation& source) const {
  const Eigen::VectorXd u = heat(source);
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
  // Pin the source triangle's heaviest corner; solve Crane's Delta phi = div X on the other
  // vertices. Our L is positive semi-definite (L = -Delta), so the system is L phi = -div X.
  int kmax = 0;
  source.bary.maxCoeff(&kmax);
  const int pin = tri_[static_cast<size_t>(source.triangle)][kmax];
  std::vector<int> index(static_cast<size_t>(nv), -1);
  int free = 0;
  for (int i = 0; i < nv; ++i) {
    if (i != pin) {
      index[static_cast<size_t>(i)] = free++;
    }
  }
  Triplets trip;
  for (int c = 0; c < laplacian_.outerSize(); ++c) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian_, c); it; ++it) {
      const int r = index[static_cast<size_t>(it.row())], cc = index[static_cast<size_t>(it.col())];
      if (r >= 0 && cc >= 0) {
        trip.emplace_back(r, cc, it.value());
      }
    }
  }
  // A tiny shift keeps other connected components (not holding the pin) non-singular.
  const double shift = 1e-12;
  for (int i = 0; i < free; ++i) {
    trip.emplace_back(i, i, shift);
  }
  Eigen::SparseMatrix<double> a(free, free);
  a.setFromTriplets(trip.begin(), trip.end());
  Eigen::VectorXd rhs(free);
  for (int i = 0; i < nv; ++i) {
    if (index[static_cast<size_t>(i)] >= 0) {
      rhs[index[static_cast<size_t>(i)]] = -div[i];
    }
  }
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(a);
  if (solver.info() != Eigen::Success) {
    throw NumericalError(name_, "heat method: factorisation of the Poisson problem failed");
  }
  const Eigen::VectorXd y = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !y.allFinite()) {
    throw NumericalError(name_, "heat method: Poisson solve failed");
  }
  Eigen::VectorXd phi(nv);
  for (int i = 0; i < nv; ++i) {
    phi[i] = i == pin ? 0.0 : y[index[static_cast<size_t>(i)]];
  }
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
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    centre +=
        source.bary[k] * x_[static_cast<size_t>(tri_[static_cast<size_t>(source.triangle)][k])];
  }
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

Eigen::VectorXd local_geodesic_distance(const std::vector<Eigen::Vector3d>& positions,
                                        const std::vector<Eigen::Vector3i>& triangles,
                                        const MeshLocation& source, double reach, double far,
                                        const std::string& name) {
  const auto nt = triangles.size();
  const auto nv = positions.size();
  const Eigen::Vector3i& home = triangles[static_cast<size_t>(source.triangle)];
  const Eigen::Vector3d centre = source.bary[0] * positions[static_cast<size_t>(home[0])] +
                                 source.bary[1] * positions[static_cast<size_t>(home[1])] +
                                 source.bary[2] * positions[static_cast<size_t>(home[2])];
  // Triangles near the source, then the ones connected to the source's triangle through shared
  // corners (breadth first over vertex -> triangle incidences of the near ones).
  const double ball = 2.0 * reach;
  std::vector<char> near(nv, 0), selected(nt, 0);
  for (size_t v = 0; v < nv; ++v) {
    near[v] = (positions[v] - centre).squaredNorm() <= ball * ball;
  }
  std::vector<int> start(nv + 1, 0);
  for (size_t t = 0; t < nt; ++t) {
    const Eigen::Vector3i& tri = triangles[t];
    if (near[static_cast<size_t>(tri[0])] || near[static_cast<size_t>(tri[1])] ||
        near[static_cast<size_t>(tri[2])] || static_cast<int>(t) == source.triangle) {
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
  std::vector<int> queue{source.triangle};
  reached[static_cast<size_t>(source.triangle)] = 1;
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
    return HeatGeodesics(positions, triangles, name).distance(source);
  }
  // The part as a mesh of its own, in the whole mesh's triangle order.
  std::sort(queue.begin(), queue.end());
  std::vector<int> local(nv, -1), global;
  std::vector<Eigen::Vector3d> part_positions;
  std::vector<Eigen::Vector3i> part_triangles;
  part_triangles.reserve(queue.size());
  MeshLocation part_source = source;
  for (const int t : queue) {
    Eigen::Vector3i tri;
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<size_t>(triangles[static_cast<size_t>(t)][k]);
      if (local[v] < 0) {
        local[v] = static_cast<int>(global.size());
        global.push_back(static_cast<int>(v));
        part_positions.push_back(positions[v]);
      }
      tri[k] = local[v];
    }
    if (t == source.triangle) {
      part_source.triangle = static_cast<int>(part_triangles.size());
    }
    part_triangles.push_back(tri);
  }
  const Eigen::VectorXd part =
      HeatGeodesics(part_positions, part_triangles, name).distance(part_source);
  Eigen::VectorXd distance = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(nv), far);
  for (size_t i = 0; i < global.size(); ++i) {
    distance[global[i]] = part[static_cast<Eigen::Index>(i)];
  }
  return distance;
}

}  // namespace elastic::regions_detail
