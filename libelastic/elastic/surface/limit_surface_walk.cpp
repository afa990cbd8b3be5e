// Ptex adjacency and walking on the limit surface (limit_surface.h): which ptex face lies across
// each stretch of each ptex edge and how (u, v) carries over; walks across ptex edges; the
// boundary test.
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <complex>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "elastic/surface/detail/limit_surface_impl.h"
#include "elastic/surface/limit_surface.h"

namespace elastic {
namespace {

using limit_surface_detail::EdgeLink;
using limit_surface_detail::PtexAdjacency;

// ---------------------------------------------------------------------------------------------
// Ptex adjacency. Every ptex edge covers a stretch of a control edge (a whole edge for quads and
// triangles, half of one for the sub-faces of an n-gon) or is a "spoke" between two sub-faces of
// the same n-gon. A control edge's parameter tau runs from the face's corner e (tau = 0) to corner
// e+1; a ptex edge's parameter t from its corner k to k+1, and tau = alpha + beta * t along it.

/// A ptex edge covering part of a control edge: tau = alpha + beta * t.
struct Piece {
  int ptex, edge;
  double alpha, beta;
};

/// The opposite half-edge of every (face, local edge) of a control mesh: sorted directed edges.
class OppositeHalfEdges {
 public:
  explicit OppositeHalfEdges(const PolygonMesh& mesh) : mesh_(mesh), nv_(mesh.num_vertices()) {
    halves_.reserve(mesh.face_vertices.size());
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const auto fv = mesh.face(f);
      const int n = static_cast<int>(fv.size());
      for (int i = 0; i < n; ++i) {
        halves_.push_back({static_cast<int64_t>(fv[static_cast<size_t>(i)]) * nv_ +
                               fv[static_cast<size_t>((i + 1) % n)],
                           f, i});
      }
    }
    std::sort(halves_.begin(), halves_.end(),
              [](const Half& x, const Half& y) { return x.key < y.key; });
  }

  /// (face, local edge) across edge e of face f; (-1, -1) on the boundary.
  std::pair<int, int> operator()(int f, int e) const {
    const auto fv = mesh_.face(f);
    const int n = static_cast<int>(fv.size());
    const int64_t key = static_cast<int64_t>(fv[static_cast<size_t>((e + 1) % n)]) * nv_ +
                        fv[static_cast<size_t>(e)];
    const auto it = std::lower_bound(halves_.begin(), halves_.end(), key,
                                     [](const Half& h, int64_t k) { return h.key < k; });
    if (it == halves_.end() || it->key != key) {
      return {-1, -1};
    }
    return {it->face, it->edge};
  }

 private:
  struct Half {
    int64_t key;  // a * nv + b for the directed edge a -> b
    int face, edge;
  };
  const PolygonMesh& mesh_;
  int nv_;
  std::vector<Half> halves_;
};

/// The affine map taking ptex edge k's stretch [ta, tb] (this side) onto the neighbour g's edge m
/// stretch [ua, ub] (reversed direction), extended across the edge: a similarity for quads (it
/// unfolds the two squares into one plane, scaling by 2 between a quad and an n-gon's sub-face);
/// for triangles the map that unfolds the two triangles into a parallelogram (the neighbour's far
/// corner is the reflection of ours through the edge midpoint).
EdgeLink make_link(const PtexDomain& domain, int k, double ta, double tb, int g, int m, double ua,
                   double ub) {
  EdgeLink link;
  link.t_end = tb;
  link.face = g;
  const Eigen::Vector2d pa = domain.edge_point(k, ta), pb = domain.edge_point(k, tb);
  const Eigen::Vector2d qa = domain.edge_point(m, ua), qb = domain.edge_point(m, ub);
  if (!domain.triangle()) {
    // Complex-linear map z -> c z + d with c = (qb - qa) / (pb - pa).
    const std::complex<double> zp(pb.x() - pa.x(), pb.y() - pa.y());
    const std::complex<double> zq(qb.x() - qa.x(), qb.y() - qa.y());
    const std::complex<double> c = zq / zp;
    link.linear << c.real(), -c.imag(), c.imag(), c.real();
  } else {
    const Eigen::Vector2d pc = domain.corner((k + 2) % 3);
    const Eigen::Vector2d qd = domain.corner((m + 2) % 3);
    const Eigen::Vector2d qc = qa + qb - qd;  // both edges are whole edges here
    Eigen::Matrix2d from, to;
    from << pb - pa, pc - pa;
    to << qb - qa, qc - qa;
    link.linear = to * from.inverse();
  }
  link.offset = qa - link.linear * pa;
  return link;
}

/// Builds the adjacency of every ptex face from the control mesh, its ptex numbering and the
/// domain (the fields of LimitSurface::Impl it reads and writes).
class AdjacencyBuilder {
 public:
  AdjacencyBuilder(const PolygonMesh& mesh, const std::vector<int>& control_to_ptex,
                   const PtexDomain& domain, std::vector<PtexAdjacency>& adjacency)
      : mesh_(mesh), control_to_ptex_(control_to_ptex), domain_(domain), adjacency_(adjacency) {}

  void build() {
    const OppositeHalfEdges opposite(mesh_);
    for (int f = 0; f < mesh_.num_faces(); ++f) {
      const int n = mesh_.face_size(f);
      for (int e = 0; e < n; ++e) {
        const auto [mine, mine_count] = pieces(f, e);
        const auto [g, ge] = opposite(f, e);
        for (int i = 0; i < mine_count; ++i) {
          link_piece(mine[static_cast<size_t>(i)], g, ge);
        }
      }
      if (!domain_.triangle() && n != 4) {
        link_spokes(control_to_ptex_[static_cast<size_t>(f)], n);
      }
    }
  }

 private:
  /// The ptex edges covering control edge e of face f, in order of increasing tau, and their
  /// count.
  std::pair<std::array<Piece, 2>, int> pieces(int f, int e) const {
    std::array<Piece, 2> out{};
    int count = 0;
    const int first = control_to_ptex_[static_cast<size_t>(f)];
    const int n = mesh_.face_size(f);
    if (domain_.triangle() || n == 4) {
      out[0] = {first, e, 0.0, 1.0};
      count = 1;
    } else {
      out[0] = {first + e, 0, 0.0, 0.5};            // sub-face e: corner e to the midpoint
      out[1] = {first + (e + 1) % n, 3, 0.5, 0.5};  // sub-face e+1: midpoint to corner e+1
      count = 2;
    }
    return std::make_pair(out, count);
  }

  /// Links ptex edge piece `p` of a control edge to the pieces of edge ge of face g across it,
  /// or marks it as boundary (g < 0).
  void link_piece(const Piece& p, int g, int ge) {
    PtexAdjacency& adj = adjacency_[static_cast<size_t>(p.ptex)];
    auto& row = adj.links[static_cast<size_t>(p.edge)];
    int& count = adj.count[static_cast<size_t>(p.edge)];
    if (g < 0) {
      row[0] = EdgeLink{};  // boundary: no neighbour along the whole ptex edge
      count = 1;
      return;
    }
    const auto [theirs, theirs_count] = pieces(g, ge);
    for (int j = 0; j < theirs_count; ++j) {
      const Piece& q = theirs[static_cast<size_t>(j)];
      // Their stretch covers tau' in [q.alpha, q.alpha + q.beta], i.e. tau = 1 - tau'.
      const double lo = std::max(p.alpha, 1.0 - q.alpha - q.beta);
      const double hi = std::min(p.alpha + p.beta, 1.0 - q.alpha);
      if (hi - lo <= 1e-12) {
        continue;
      }
      const double ta = (lo - p.alpha) / p.beta, tb = (hi - p.alpha) / p.beta;
      const double ua = (1.0 - lo - q.alpha) / q.beta, ub = (1.0 - hi - q.alpha) / q.beta;
      row[static_cast<size_t>(count++)] =
          make_link(domain_, p.edge, ta, tb, q.ptex, q.edge, ua, ub);
    }
    // Stretches were produced in order of their tau' pieces, which is decreasing t: sort.
    std::sort(row.begin(), row.begin() + count,
              [](const EdgeLink& a, const EdgeLink& b) { return a.t_end < b.t_end; });
  }

  /// Spokes inside an n-gon (Catmull-Clark, n != 4) whose sub-faces start at ptex face `first`:
  /// sub-face i's edge 1 (edge midpoint to centre) is sub-face i+1's edge 2.
  void link_spokes(int first, int n) {
    for (int i = 0; i < n; ++i) {
      const int a = first + i, b = first + (i + 1) % n;
      adjacency_[static_cast<size_t>(a)].links[1][0] =
          make_link(domain_, 1, 0.0, 1.0, b, 2, 1.0, 0.0);
      adjacency_[static_cast<size_t>(a)].count[1] = 1;
      adjacency_[static_cast<size_t>(b)].links[2][0] =
          make_link(domain_, 2, 0.0, 1.0, a, 1, 1.0, 0.0);
      adjacency_[static_cast<size_t>(b)].count[2] = 1;
    }
  }

  const PolygonMesh& mesh_;
  const std::vector<int>& control_to_ptex_;
  PtexDomain domain_;
  std::vector<PtexAdjacency>& adjacency_;
};

}  // namespace

void LimitSurface::Impl::build_adjacency() {
  adjacency.assign(ptex_to_control.size(), PtexAdjacency{});
  AdjacencyBuilder(mesh, control_to_ptex, domain, adjacency).build();
}

SurfacePoint LimitSurface::walk(const SurfacePoint& from, const Eigen::Vector2d& delta,
                                int* crossed) const {
  const Impl& m = *impl_;
  m.check_point(from);
  if (!delta.allFinite()) {
    m.fail("walk with a non-finite step");
  }
  const bool tri = m.triangle;
  int face = from.face;
  const PtexDomain& domain = m.domain;
  Eigen::Vector2d x = domain.clamp(from.uv());
  Eigen::Vector2d d = delta;
  int count = 0;
  int zero_steps = 0;  // consecutive crossings without progress (circling a vertex)
  constexpr int kMaxCrossings = 1 << 20;
  for (int iteration = 0; iteration < kMaxCrossings; ++iteration) {
    // Smallest s >= 0 at which x + s d leaves the domain, and through which edge.
    double s_exit = std::numeric_limits<double>::infinity();
    int edge = -1;
    auto consider = [&](double s, int k) {
      if (s < s_exit) {
        s_exit = std::max(s, 0.0);
        edge = k;
      }
    };
    if (d.y() < 0.0) {
      consider(-x.y() / d.y(), 0);  // v = 0
    }
    if (d.x() < 0.0) {
      consider(-x.x() / d.x(), tri ? 2 : 3);  // u = 0
    }
    if (tri) {
      const double g = d.x() + d.y();
      if (g > 0.0) {
        consider((1.0 - x.x() - x.y()) / g, 1);  // u + v = 1
      }
    } else {
      if (d.x() > 0.0) {
        consider((1.0 - x.x()) / d.x(), 1);  // u = 1
      }
      if (d.y() > 0.0) {
        consider((1.0 - x.y()) / d.y(), 2);  // v = 1
      }
    }
    if (edge < 0 || s_exit >= 1.0) {
      x = domain.clamp(x + d);
      break;
    }
    const Eigen::Vector2d q = x + s_exit * d;
    const double t = std::clamp(domain.edge_parameter(edge, q), 0.0, 1.0);
    const EdgeLink& link = m.adjacency[static_cast<size_t>(face)].find(edge, t);
    const Eigen::Vector2d on_edge = domain.edge_point(edge, t);
    if (link.face < 0 || zero_steps > 64) {
      x = on_edge;  // the boundary stops the walk (or we gave up circling a vertex)
      break;
    }
    zero_steps = s_exit == 0.0 ? zero_steps + 1 : 0;
    d = link.linear * ((1.0 - s_exit) * d);
    x = domain.clamp(link.linear * on_edge + link.offset);
    face = link.face;
    ++count;
  }
  if (crossed) {
    *crossed = count;
  }
  return {face, x.x(), x.y()};
}

bool LimitSurface::on_boundary(const SurfacePoint& p, double tolerance) const {
  if (!in_domain(p, tolerance)) {
    return false;
  }
  const Impl& m = *impl_;
  const Eigen::Vector2d x = p.uv();
  for (int k = 0; k < m.domain.num_corners(); ++k) {
    if (std::abs(m.domain.inside_distance(k, x)) > tolerance) {
      continue;
    }
    const double t = std::clamp(m.domain.edge_parameter(k, x), 0.0, 1.0);
    if (m.adjacency[static_cast<size_t>(p.face)].find(k, t).face < 0) {
      return true;
    }
  }
  return false;
}

}  // namespace elastic
