#include "elastic/regions/exact_geodesics.h"

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_shortest_path.h>

#include <algorithm>
#include <array>

#include "elastic/core/error.h"

namespace elastic::regions_detail {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
using Traits = CGAL::Surface_mesh_shortest_path_traits<Kernel, Mesh>;
using ShortestPath = CGAL::Surface_mesh_shortest_path<Traits>;
using VertexIndex = Mesh::Vertex_index;
using FaceIndex = Mesh::Face_index;

/// How far (in barycentric terms) a path's end point is moved into its triangle for CGAL
/// (Impl::cgal_bary).
constexpr double kInside = 1e-9;
/// Crossings closer than this times the end's triangle perimeter to a path end are dropped (the
/// moved end's own edge, see path()).
constexpr double kDropNearEnd = 1e-6;
using HalfedgeIndex = Mesh::Halfedge_index;

/// A point of the path as weights on at most three mesh vertices (an edge point has two, a
/// vertex one).
struct Weights {
  std::vector<std::pair<int, double>> w;
};

}  // namespace

struct ExactGeodesics::Impl {
  const std::vector<Eigen::Vector3d>& x;
  const std::vector<Eigen::Vector3i>& tri;
  std::string name;
  std::vector<std::vector<int>> vertex_triangles;

  // The band's halfedge mesh of one query: face f is triangle faces[f], vertex w is vertices[w].
  Mesh mesh;
  std::vector<int> faces, vertices;
  std::vector<int> face_of, vertex_of;  // inverse maps (-1 outside the band)

  Impl(const std::vector<Eigen::Vector3d>& positions, const std::vector<Eigen::Vector3i>& triangles,
       std::string n)
      : x(positions), tri(triangles), name(std::move(n)) {
    vertex_triangles.resize(x.size());
    for (size_t t = 0; t < tri.size(); ++t) {
      for (int k = 0; k < 3; ++k) {
        vertex_triangles[static_cast<size_t>(tri[t][k])].push_back(static_cast<int>(t));
      }
    }
  }

  // The band's triangles in increasing order. The inverse maps are reset where the last band set
  // them, not over the whole tessellation: a decal's boundary on a million-triangle head has
  // hundreds of small bands.
  void build(const std::vector<int>& band) {
    if (face_of.size() != tri.size()) {
      face_of.assign(tri.size(), -1);
      vertex_of.assign(x.size(), -1);
    }
    for (const int t : faces) {
      face_of[static_cast<size_t>(t)] = -1;
    }
    for (const int v : vertices) {
      vertex_of[static_cast<size_t>(v)] = -1;
    }
    mesh.clear();
    faces.clear();
    vertices.clear();
    for (const int band_triangle : band) {
      const auto t = static_cast<size_t>(band_triangle);
      std::array<VertexIndex, 3> v;
      for (int k = 0; k < 3; ++k) {
        const size_t g = static_cast<size_t>(tri[t][k]);
        if (vertex_of[g] < 0) {
          vertex_of[g] = static_cast<int>(vertices.size());
          vertices.push_back(static_cast<int>(g));
          mesh.add_vertex(Kernel::Point_3(x[g].x(), x[g].y(), x[g].z()));
        }
        v[static_cast<size_t>(k)] = VertexIndex(static_cast<Mesh::size_type>(vertex_of[g]));
      }
      const FaceIndex f = mesh.add_face(v[0], v[1], v[2]);
      if (f == Mesh::null_face()) {
        throw InvalidInputError(
            name,
            "the tessellation is not an oriented 2-manifold at triangle " + std::to_string(t + 1));
      }
      face_of[t] = static_cast<int>(faces.size());
      faces.push_back(static_cast<int>(t));
    }
  }

  ShortestPath::Barycentric_coordinates cgal_bary(const MeshLocation& p, double inside) const {
    // CGAL's coordinate k weighs source(next^k(halfedge(f))) (its triangle_from_halfedge), a
    // cycle that need not start at our corner 0.
    //
    // The point is moved kInside (relative) towards the triangle's centre: CGAL 5.5 (Debian 12's)
    // grows wrong cones from a point exactly on an edge (CGAL issue 6681, fixed in 5.6 by
    // PR 6739) and may root a point exactly on a vertex at another vertex (issue 9646). A corner
    // of a points: polygon on an edge of the tessellation made the whole side aim at a point one
    // triangle away: a square's side on grid.off ran straight to 0.0112 beside its far corner
    // and turned there. The path's end points are taken as given (path()), so only the
    // crossings in between see the shift, of kInside times the triangle's size.
    const FaceIndex f(static_cast<Mesh::size_type>(face_of[static_cast<size_t>(p.triangle)]));
    std::array<double, 3> b{0.0, 0.0, 0.0};
    HalfedgeIndex h = mesh.halfedge(f);
    for (int k = 0; k < 3; ++k) {
      const int v = vertices[mesh.source(h).idx()];
      for (int c = 0; c < 3; ++c) {
        if (tri[static_cast<size_t>(p.triangle)][c] == v) {
          b[static_cast<size_t>(k)] = p.bary[c];
        }
      }
      h = mesh.next(h);
    }
    const double n = 1.0 - 3.0 * inside;
    return {n * b[0] + inside, n * b[1] + inside, n * b[2] + inside};
  }

  Weights weights_of(const MeshLocation& p) const {
    Weights out;
    for (int k = 0; k < 3; ++k) {
      if (p.bary[k] > 0.0) {
        out.w.emplace_back(tri[static_cast<size_t>(p.triangle)][k], p.bary[k]);
      }
    }
    return out;
  }

  /// A triangle holding every vertex of both weight sets, or -1.
  int common_triangle(const Weights& a, const Weights& b) const {
    std::vector<int> need;
    for (const auto& [v, w] : a.w) {
      need.push_back(v);
    }
    for (const auto& [v, w] : b.w) {
      need.push_back(v);
    }
    for (int t : vertex_triangles[static_cast<size_t>(need.front())]) {
      const Eigen::Vector3i& c = tri[static_cast<size_t>(t)];
      if (std::all_of(need.begin(), need.end(),
                      [&](int v) { return c[0] == v || c[1] == v || c[2] == v; })) {
        return t;
      }
    }
    return -1;
  }

  /// The path's points without the crossings within kDropNearEnd of an end (see path()).
  std::vector<Weights> drop_crossings_near_ends(const std::vector<Weights>& seq,
                                                const MeshLocation& from,
                                                const MeshLocation& to) const {
    // An end moved kInside for CGAL makes the path cross the end's own edge (or pass its vertex)
    // within about kInside of it: such crossings are dropped, the ends are taken as given.
    const auto where = [&](const Weights& p) {
      Eigen::Vector3d s = Eigen::Vector3d::Zero();
      for (const auto& [v, w] : p.w) {
        s += w * x[static_cast<size_t>(v)];
      }
      return s;
    };
    const auto size_of = [&](const MeshLocation& p) {
      const Eigen::Vector3i& c = tri[static_cast<size_t>(p.triangle)];
      return (x[static_cast<size_t>(c[1])] - x[static_cast<size_t>(c[0])]).norm() +
             (x[static_cast<size_t>(c[2])] - x[static_cast<size_t>(c[1])]).norm() +
             (x[static_cast<size_t>(c[0])] - x[static_cast<size_t>(c[2])]).norm();
    };
    const Eigen::Vector3d start = where(seq.front()), end = where(seq.back());
    const double near_start = kDropNearEnd * size_of(from), near_end = kDropNearEnd * size_of(to);
    std::vector<Weights> kept{seq.front()};
    for (size_t i = 1; i + 1 < seq.size(); ++i) {
      const Eigen::Vector3d p = where(seq[i]);
      if ((p - start).norm() > near_start && (p - end).norm() > near_end) {
        kept.push_back(seq[i]);
      }
    }
    kept.push_back(seq.back());
    return kept;
  }

  MeshLocation location_in(const Weights& p, int t) const {
    MeshLocation m{t, Eigen::Vector3d::Zero()};
    for (const auto& [v, w] : p.w) {
      for (int k = 0; k < 3; ++k) {
        if (tri[static_cast<size_t>(t)][k] == v) {
          m.bary[k] += w;
        }
      }
    }
    m.bary /= m.bary.sum();
    return m;
  }
};

ExactGeodesics::ExactGeodesics(const std::vector<Eigen::Vector3d>& positions,
                               const std::vector<Eigen::Vector3i>& triangles, std::string name)
    : impl_(std::make_unique<Impl>(positions, triangles, std::move(name))) {}

ExactGeodesics::~ExactGeodesics() = default;

std::vector<char> geodesic_band(const std::vector<Eigen::Vector3i>& triangles,
                                const Eigen::VectorXd& d_from, const Eigen::VectorXd& d_to,
                                double slack, double margin) {
  // d: the smallest sum over the vertices (the ends' own triangles hold the minimum within the
  // fields' error).
  const Eigen::VectorXd sum = d_from + d_to;
  const double d = sum.minCoeff();
  const double bound = (1.0 + slack) * d + margin;
  std::vector<char> band(triangles.size(), 0);
  for (size_t t = 0; t < triangles.size(); ++t) {
    const Eigen::Vector3i& v = triangles[t];
    band[t] = std::min({sum[v[0]], sum[v[1]], sum[v[2]]}) <= bound ? 1 : 0;
  }
  return band;
}

GeodesicPath ExactGeodesics::path(const MeshLocation& from, const MeshLocation& to,
                                  const std::vector<char>& band) {
  if (band.size() != impl_->tri.size()) {
    throw NumericalError(impl_->name, "internal: the geodesic band is not one flag per triangle");
  }
  std::vector<int> list;
  for (size_t t = 0; t < band.size(); ++t) {
    if (band[t]) {
      list.push_back(static_cast<int>(t));
    }
  }
  return path(from, to, list);
}

GeodesicPath ExactGeodesics::path(const MeshLocation& from, const MeshLocation& to,
                                  const std::vector<int>& band) {
  Impl& m = *impl_;
  m.build(band);
  if (m.face_of[static_cast<size_t>(from.triangle)] < 0 ||
      m.face_of[static_cast<size_t>(to.triangle)] < 0) {
    throw NumericalError(m.name, "internal: the geodesic band misses a curve point");
  }
  ShortestPath smsp(m.mesh);
  const auto face = [&](const MeshLocation& p) {
    return FaceIndex(static_cast<Mesh::size_type>(m.face_of[static_cast<size_t>(p.triangle)]));
  };
  smsp.add_source_point(face(to), m.cgal_bary(to, kInside));
  smsp.build_sequence_tree();

  // The sequence runs from the query point (`from`) to the source (`to`); the end points are
  // taken as given, the crossings in between as vertex weights.
  std::vector<Weights> seq;
  seq.push_back(m.weights_of(from));
  struct Visitor {
    const Mesh& mesh;
    const std::vector<int>& global;  // band vertex -> mesh vertex
    std::vector<Weights>& out;
    void operator()(HalfedgeIndex h, double t) {
      // The crossing is CGAL's point(h, t); express it on the edge's two vertices by projection
      // (exact up to round-off, and independent of CGAL's convention for t).
      const int a = global[mesh.source(h).idx()];
      const int b = global[mesh.target(h).idx()];
      const Kernel::Point_3 pa = mesh.point(mesh.source(h));
      const Kernel::Point_3 pb = mesh.point(mesh.target(h));
      const Kernel::Point_3 p = CGAL::barycenter(pa, 1.0 - t, pb, t);
      const Kernel::Vector_3 e = pb - pa;
      const double len2 = e.squared_length();
      double s = len2 > 0.0 ? ((p - pa) * e) / len2 : 0.5;
      s = std::clamp(s, 0.0, 1.0);
      Weights w;
      if (s <= 0.0) {
        w.w = {{a, 1.0}};
      } else if (s >= 1.0) {
        w.w = {{b, 1.0}};
      } else {
        w.w = {{a, 1.0 - s}, {b, s}};
      }
      out.push_back(std::move(w));
    }
    void operator()(VertexIndex v) { out.push_back(Weights{{{global[v.idx()], 1.0}}}); }
    void operator()(FaceIndex, ShortestPath::Barycentric_coordinates) {}  // the end points
  };
  Visitor visitor{m.mesh, m.vertices, seq};
  const auto result =
      smsp.shortest_path_sequence_to_source_points(face(from), m.cgal_bary(from, kInside), visitor);
  if (!(result.first >= 0.0)) {
    throw NumericalError(m.name, "no path between two curve points (is the surface in pieces?)");
  }
  seq.push_back(m.weights_of(to));
  seq = m.drop_crossings_near_ends(seq, from, to);

  GeodesicPath out;
  out.length = result.first;
  for (size_t i = 0; i + 1 < seq.size(); ++i) {
    const int t = m.common_triangle(seq[i], seq[i + 1]);
    if (t < 0) {
      throw NumericalError(m.name, "internal: consecutive shortest-path points share no triangle");
    }
    const MeshLocation loc = i == 0 ? from : m.location_in(seq[i], t);
    out.nodes.push_back({loc, t});
  }
  return out;
}

}  // namespace elastic::regions_detail
