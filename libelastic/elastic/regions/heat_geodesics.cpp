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

/// Vertices with a non-negligible weight in a location.
std::vector<int> support(const MeshLocation& p, const std::vector<Eigen::Vector3i>& tri) {
  std::vector<int> out;
  for (int k = 0; k < 3; ++k) {
    if (p.bary[k] > 0.0) {
      out.push_back(tri[static_cast<size_t>(p.triangle)][k]);
    }
  }
  return out;
}

}  // namespace

HeatGeodesics::HeatGeodesics(const std::vector<Eigen::Vector3d>& positions,
                             const std::vector<Eigen::Vector3i>& triangles, std::string name)
    : x_(positions), tri_(triangles), name_(std::move(name)) {
  const int nv = static_cast<int>(x_.size());
  Triplets lap, mass;
  double total_edge = 0.0;
  vertex_triangles_.resize(x_.size());
  for (size_t t = 0; t < tri_.size(); ++t) {
    const Eigen::Vector3i& v = tri_[t];
    const Eigen::Vector3d normal =
        (x_[static_cast<size_t>(v[1])] - x_[static_cast<size_t>(v[0])])
            .cross(x_[static_cast<size_t>(v[2])] - x_[static_cast<size_t>(v[0])]);
    const double double_area = normal.norm();
    for (int k = 0; k < 3; ++k) {
      vertex_triangles_[static_cast<size_t>(v[k])].push_back(static_cast<int>(t));
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

std::vector<int> HeatGeodesics::triangles_at(const MeshLocation& p) const {
  const std::vector<int> s = support(p, tri_);
  if (s.size() == 3) {
    return {p.triangle};
  }
  std::vector<int> out;
  for (int t : vertex_triangles_[static_cast<size_t>(s[0])]) {
    const Eigen::Vector3i& v = tri_[static_cast<size_t>(t)];
    bool all = true;
    for (int w : s) {
      all = all && (v[0] == w || v[1] == w || v[2] == w);
    }
    if (all) {
      out.push_back(t);
    }
  }
  return out;
}

Eigen::Vector3d HeatGeodesics::bary_in(const MeshLocation& p, int t) const {
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  const Eigen::Vector3i& from = tri_[static_cast<size_t>(p.triangle)];
  const Eigen::Vector3i& to = tri_[static_cast<size_t>(t)];
  for (int k = 0; k < 3; ++k) {
    if (p.bary[k] <= 0.0) {
      continue;
    }
    for (int l = 0; l < 3; ++l) {
      if (to[l] == from[k]) {
        b[l] = p.bary[k];
      }
    }
  }
  return b;
}

std::vector<PathNode> HeatGeodesics::trace_path(const MeshLocation& from,
                                                const MeshLocation& to) const {
  const Eigen::VectorXd u = heat(to);
  const std::vector<int> target = support(to, tri_);
  auto holds_target = [&](int t) {
    const Eigen::Vector3i& v = tri_[static_cast<size_t>(t)];
    return std::all_of(target.begin(), target.end(),
                       [&](int w) { return v[0] == w || v[1] == w || v[2] == w; });
  };
  auto value = [&](const MeshLocation& p) {
    double s = 0.0;
    for (int k = 0; k < 3; ++k) {
      s += p.bary[k] * u[tri_[static_cast<size_t>(p.triangle)][k]];
    }
    return s;
  };
  std::vector<PathNode> path;
  MeshLocation cur = from;
  const size_t limit = 4 * tri_.size() + 64;
  for (size_t step = 0; step < limit; ++step) {
    const std::vector<int> cands = triangles_at(cur);
    for (int t : cands) {
      if (holds_target(t)) {
        path.push_back({cur, t});
        return path;
      }
    }
    // Move up the heat gradient across the candidate triangle the gradient points into.
    int best = -1;
    double best_progress = 0.0;
    Eigen::Vector3d best_bary;
    for (int t : cands) {
      const Eigen::Vector3d g = gradient(t, u);
      if (g.norm() == 0.0) {
        continue;
      }
      const Eigen::Vector3d b = bary_in(cur, t);
      const Eigen::Vector3i& v = tri_[static_cast<size_t>(t)];
      const Eigen::Vector3d& x0 = x_[static_cast<size_t>(v[0])];
      const Eigen::Vector3d& x1 = x_[static_cast<size_t>(v[1])];
      const Eigen::Vector3d& x2 = x_[static_cast<size_t>(v[2])];
      const Eigen::Vector3d normal = (x1 - x0).cross(x2 - x0);
      const double double_area = normal.norm();
      if (double_area == 0.0) {
        continue;
      }
      const Eigen::Vector3d n = normal / double_area;
      // Rate of change of the barycentric coordinates along g (grad lambda_i = n x e_i / 2A).
      const Eigen::Vector3d db(g.dot(n.cross(x2 - x1)), g.dot(n.cross(x0 - x2)),
                               g.dot(n.cross(x1 - x0)));
      const Eigen::Vector3d rate = db / double_area;
      const double tiny = 1e-12 * rate.cwiseAbs().maxCoeff();
      bool enters = true;
      double s = std::numeric_limits<double>::infinity();
      int exit = -1;
      for (int k = 0; k < 3; ++k) {
        if (rate[k] >= -tiny) {
          continue;
        }
        if (b[k] <= 0.0) {
          enters = false;  // the gradient points out of t through this corner's opposite edge
          break;
        }
        const double sk = b[k] / -rate[k];
        if (sk < s) {
          s = sk;
          exit = k;
        }
      }
      if (!enters || exit < 0) {
        continue;
      }
      const double progress = s * g.norm();
      if (progress > best_progress) {
        best_progress = progress;
        best = t;
        Eigen::Vector3d nb = (b + s * rate).cwiseMax(0.0);
        nb[exit] = 0.0;
        // Snap coordinates within 1e-7 of zero so the path meets vertices instead of crawling near
        // them.
        for (int k = 0; k < 3; ++k) {
          nb[k] = nb[k] < 1e-7 ? 0.0 : nb[k];
        }
        best_bary = nb / nb.sum();
      }
    }
    if (best >= 0) {
      path.push_back({cur, best});
      cur = MeshLocation{best, best_bary};
      continue;
    }
    // The gradient points out of every triangle at cur (a ridge of u along an edge or at a vertex):
    // move along an edge to the neighbouring vertex of largest heat.
    const double here = value(cur);
    int move_to = -1, move_tri = -1;
    double best_u = here;
    for (int t : cands) {
      for (int k = 0; k < 3; ++k) {
        const int w = tri_[static_cast<size_t>(t)][k];
        if (u[w] > best_u) {
          best_u = u[w];
          move_to = w;
          move_tri = t;
        }
      }
    }
    if (move_to < 0) {
      throw NumericalError(name_,
                           "cannot trace a shortest path on the surface (stuck at a heat maximum)");
    }
    path.push_back({cur, move_tri});
    const Eigen::Vector3i& v = tri_[static_cast<size_t>(move_tri)];
    cur =
        MeshLocation{move_tri, Eigen::Vector3d(v[0] == move_to, v[1] == move_to, v[2] == move_to)};
  }
  throw NumericalError(name_, "cannot trace a shortest path on the surface (too many steps)");
}

}  // namespace elastic::regions_detail
