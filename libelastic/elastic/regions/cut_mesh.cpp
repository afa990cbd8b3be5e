#include "elastic/regions/cut_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <unordered_map>

#include "elastic/core/directed_edges.h"
#include "elastic/core/error.h"
#include "elastic/regions/texture_coordinates.h"

namespace elastic::regions_detail {
namespace {

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

}  // namespace

Eigen::Vector3d barycentric_2d(const std::array<Eigen::Vector2d, 3>& tri,
                               const Eigen::Vector2d& p) {
  const double area = cross2(tri[1] - tri[0], tri[2] - tri[0]);
  if (area == 0.0) {
    return Eigen::Vector3d::Zero();
  }
  const double b1 = cross2(p - tri[0], tri[2] - tri[0]) / area;
  const double b2 = cross2(tri[1] - tri[0], p - tri[0]) / area;
  return {1.0 - b1 - b2, b1, b2};
}

std::vector<std::array<Eigen::Vector2d, 3>> tessellation_corner_uv(const LimitSurface& surface,
                                                                   const LimitTessellation& tess,
                                                                   const std::vector<int>& which) {
  const PolygonMesh& control = surface.control_mesh();
  const bool loop = surface.triangular_domain();
  // Boundary grid nodes of a ptex face and their limit positions, evaluated once per face that
  // needs them. A quad's grid has `resolution` segments per edge; an n-gon's sub-face has half as
  // many (limit_tessellation.cpp samples every control edge with `resolution` segments).
  std::unordered_map<int, std::vector<std::pair<Eigen::Vector2d, Eigen::Vector3d>>> nodes;
  auto boundary_nodes =
      [&](int f) -> const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector3d>>& {
    auto it = nodes.find(f);
    if (it != nodes.end()) {
      return it->second;
    }
    auto& list = nodes[f];
    const int cf = surface.control_face(f);
    const int m = (!loop && control.face_size(cf) != 4) ? tess.resolution / 2 : tess.resolution;
    for (int j = 0; j <= m; ++j) {
      for (int i = 0; i <= m; ++i) {
        const bool on_edge = loop ? (i + j <= m && (i == 0 || j == 0 || i + j == m))
                                  : (i == 0 || j == 0 || i == m || j == m);
        if (!on_edge) {
          continue;
        }
        const SurfacePoint p{f, static_cast<double>(i) / m, static_cast<double>(j) / m};
        list.emplace_back(p.uv(), surface.position(p));
      }
    }
    return list;
  };

  std::vector<std::array<Eigen::Vector2d, 3>> out(which.size());
  for (size_t i = 0; i < which.size(); ++i) {
    const auto t = static_cast<size_t>(which[i]);
    const int f = tess.triangle_face[t];
    for (int k = 0; k < 3; ++k) {
      const int v = tess.triangles[t][k];
      const SurfacePoint& p = tess.points[static_cast<size_t>(v)];
      if (p.face == f) {
        out[i][static_cast<size_t>(k)] = p.uv();
        continue;
      }
      // Welded from a neighbouring face: the coincident boundary node of f. Distinct nodes are a
      // grid step apart while the same point evaluated from two faces agrees to round-off, so the
      // nearest node is unambiguous.
      double best = std::numeric_limits<double>::infinity();
      for (const auto& [uv, x] : boundary_nodes(f)) {
        const double d = (x - tess.positions[static_cast<size_t>(v)]).squaredNorm();
        if (d < best) {
          best = d;
          out[i][static_cast<size_t>(k)] = uv;
        }
      }
    }
  }
  return out;
}

std::vector<std::array<Eigen::Vector2d, 3>> tessellation_corner_uv(const LimitSurface& surface,
                                                                   const LimitTessellation& tess) {
  std::vector<int> all(tess.triangles.size());
  std::iota(all.begin(), all.end(), 0);
  return tessellation_corner_uv(surface, tess, all);
}

CutMesh::CutMesh(const LimitSurface& surface, const LimitTessellation& tess,
                 std::vector<std::array<Eigen::Vector2d, 3>> corner_uv, std::string name)
    : positions(tess.positions),
      points(tess.points),
      triangles(tess.triangles),
      face(tess.triangle_face),
      uv(corner_uv),
      origin_uv(std::move(corner_uv)),
      surface_(&surface),
      name_(std::move(name)) {
  const int nt = num_triangles();
  origin.resize(static_cast<size_t>(nt));
  std::iota(origin.begin(), origin.end(), 0);
  children.resize(static_cast<size_t>(nt));
  vertex_triangles.resize(positions.size());
  for (int t = 0; t < nt; ++t) {
    children[static_cast<size_t>(t)].push_back(t);
    for (int k = 0; k < 3; ++k) {
      vertex_triangles[static_cast<size_t>(triangles[t][k])].push_back(t);
    }
  }
  on_curve.assign(positions.size(), 0);
}

void CutMesh::enable_texture_chart() {
  tex.resize(triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (size_t k = 0; k < 3; ++k) {
      tex[t][k] = texture_coordinate(*surface_, SurfacePoint{face[t], uv[t][k].x(), uv[t][k].y()});
    }
  }
}

int CutMesh::corner(int t, int v) const {
  for (int k = 0; k < 3; ++k) {
    if (triangles[static_cast<size_t>(t)][k] == v) {
      return k;
    }
  }
  return -1;
}

int CutMesh::add_vertex(const SurfacePoint& p) {
  const int id = num_vertices();
  points.push_back(p);
  positions.push_back(surface_->position(p));
  vertex_triangles.emplace_back();
  on_curve.push_back(0);
  return id;
}

int CutMesh::add_triangle(const Eigen::Vector3i& tri, int parent) {
  const int id = num_triangles();
  triangles.push_back(tri);
  face.push_back(face[static_cast<size_t>(parent)]);
  uv.push_back(uv[static_cast<size_t>(parent)]);
  if (!tex.empty()) {
    tex.push_back(tex[static_cast<size_t>(parent)]);
  }
  origin.push_back(origin[static_cast<size_t>(parent)]);
  children[static_cast<size_t>(origin.back())].push_back(id);
  return id;
}

std::vector<int> CutMesh::edge_triangles(int a, int b) const {
  std::vector<int> out;
  for (int t : vertex_triangles[static_cast<size_t>(a)]) {
    if (corner(t, b) >= 0) {
      out.push_back(t);
    }
  }
  return out;
}

int CutMesh::split_edge(int a, int b, double t) {
  const std::vector<int> tris = edge_triangles(a, b);
  int n = -1;
  for (int tri : tris) {
    const size_t ti = static_cast<size_t>(tri);
    const int ka = corner(tri, a), kb = corner(tri, b);
    // Orient the edge along the triangle's winding: x -> y, then z opposite.
    const bool forward = (ka + 1) % 3 == kb;
    const int kx = forward ? ka : kb, ky = forward ? kb : ka, kz = 3 - kx - ky;
    const double s = forward ? t : 1.0 - t;
    const Eigen::Vector2d uv_n =
        (1.0 - s) * uv[ti][static_cast<size_t>(kx)] + s * uv[ti][static_cast<size_t>(ky)];
    if (n < 0) {
      n = add_vertex(SurfacePoint{face[ti], uv_n.x(), uv_n.y()});
    }
    const int x = triangles[ti][kx], y = triangles[ti][ky], z = triangles[ti][kz];
    // (x, y, z) -> (x, n, z) + (n, y, z), both keep the winding.
    const int t2 = add_triangle(Eigen::Vector3i(n, y, z), tri);
    const size_t t2i = static_cast<size_t>(t2);
    uv[t2i] = {uv_n, uv[ti][static_cast<size_t>(ky)], uv[ti][static_cast<size_t>(kz)]};
    if (!tex.empty()) {
      const Eigen::Vector2d tex_n =
          (1.0 - s) * tex[ti][static_cast<size_t>(kx)] + s * tex[ti][static_cast<size_t>(ky)];
      tex[t2i] = {tex_n, tex[ti][static_cast<size_t>(ky)], tex[ti][static_cast<size_t>(kz)]};
      tex[ti] = {tex[ti][static_cast<size_t>(kx)], tex_n, tex[ti][static_cast<size_t>(kz)]};
    }
    uv[ti] = {uv[ti][static_cast<size_t>(kx)], uv_n, uv[ti][static_cast<size_t>(kz)]};
    triangles[ti] = Eigen::Vector3i(x, n, z);
    auto& ylist = vertex_triangles[static_cast<size_t>(y)];
    *std::find(ylist.begin(), ylist.end(), tri) = t2;
    vertex_triangles[static_cast<size_t>(z)].push_back(t2);
    vertex_triangles[static_cast<size_t>(n)].push_back(tri);
    vertex_triangles[static_cast<size_t>(n)].push_back(t2);
  }
  if (n < 0) {
    throw NumericalError(name_, "internal: split of a missing edge");
  }
  return n;
}

int CutMesh::split_triangle(int tri, const Eigen::Vector3d& bary) {
  const size_t ti = static_cast<size_t>(tri);
  const Eigen::Vector2d uv_n = interpolate(uv[ti], bary);
  const int n = add_vertex(SurfacePoint{face[ti], uv_n.x(), uv_n.y()});
  const Eigen::Vector3i old = triangles[ti];
  const auto old_uv = uv[ti];
  const int t2 = add_triangle(Eigen::Vector3i(old[1], old[2], n), tri);
  const int t3 = add_triangle(Eigen::Vector3i(old[2], old[0], n), tri);
  triangles[ti] = Eigen::Vector3i(old[0], old[1], n);
  uv[ti] = {old_uv[0], old_uv[1], uv_n};
  uv[static_cast<size_t>(t2)] = {old_uv[1], old_uv[2], uv_n};
  uv[static_cast<size_t>(t3)] = {old_uv[2], old_uv[0], uv_n};
  if (!tex.empty()) {
    const auto old_tex = tex[ti];
    const Eigen::Vector2d tex_n = interpolate(old_tex, bary);
    tex[ti] = {old_tex[0], old_tex[1], tex_n};
    tex[static_cast<size_t>(t2)] = {old_tex[1], old_tex[2], tex_n};
    tex[static_cast<size_t>(t3)] = {old_tex[2], old_tex[0], tex_n};
  }
  vertex_triangles[static_cast<size_t>(old[0])].push_back(t3);
  vertex_triangles[static_cast<size_t>(old[1])].push_back(t2);
  auto& clist = vertex_triangles[static_cast<size_t>(old[2])];
  *std::find(clist.begin(), clist.end(), tri) = t2;
  clist.push_back(t3);
  vertex_triangles[static_cast<size_t>(n)] = {tri, t2, t3};
  return n;
}

int CutMesh::insert_in_triangle(int tri, Eigen::Vector3d bary, double snap) {
  // Coordinates within round-off of zero are zero (the point is on that edge or vertex).
  constexpr double zero = 1e-9;
  for (int k = 0; k < 3; ++k) {
    bary[k] = bary[k] < zero ? 0.0 : bary[k];
  }
  bary /= bary.sum();
  const Eigen::Vector3i v = triangles[static_cast<size_t>(tri)];
  int kmax = 0;
  bary.maxCoeff(&kmax);
  // Snap to a vertex (never onto the curve: that would create a false crossing).
  if (bary[kmax] >= 1.0 - zero ||
      (bary[kmax] > 1.0 - snap && !on_curve[static_cast<size_t>(v[kmax])])) {
    return v[kmax];
  }
  // Snap onto a nearby edge to avoid a sliver triangle, unless the edge is part of the curve.
  for (int k = 0; k < 3; ++k) {
    if (bary[k] > 0.0 && bary[k] < snap && !is_curve_edge(v[(k + 1) % 3], v[(k + 2) % 3])) {
      bary[k] = 0.0;
      bary /= bary.sum();
    }
  }
  for (int k = 0; k < 3; ++k) {
    if (bary[k] == 0.0) {
      const int a = v[(k + 1) % 3], b = v[(k + 2) % 3];
      const double t = bary[(k + 2) % 3] / (bary[(k + 1) % 3] + bary[(k + 2) % 3]);
      if (is_curve_edge(a, b)) {
        throw_crossing();
      }
      return split_edge(a, b, t);
    }
  }
  return split_triangle(tri, bary);
}

int CutMesh::insert_point(int origin_triangle, const Eigen::Vector2d& p, double snap) {
  const std::vector<int>& candidates = children[static_cast<size_t>(origin_triangle)];
  const MeshLocation best = deepest_triangle(
      candidates, [&](size_t i) -> const auto& { return uv[static_cast<size_t>(candidates[i])]; },
      p);
  if (best.triangle < 0) {
    throw NumericalError(name_, "internal: cannot locate a curve point in its triangle");
  }
  const Eigen::Vector3d b = best.bary.cwiseMax(0.0);
  return insert_in_triangle(best.triangle, b / b.sum(), snap);
}

Eigen::Vector2d CutMesh::chart_coordinate(Chart chart, int t, int v) const {
  const int k = corner(t, v);
  return chart == Chart::Ptex ? uv[static_cast<size_t>(t)][static_cast<size_t>(k)]
                              : tex[static_cast<size_t>(t)][static_cast<size_t>(k)];
}

void CutMesh::throw_crossing() const {
  throw InvalidInputError(name_, "the curve crosses itself");
}

void CutMesh::walk(int a, Eigen::Vector2d ca, int b, Chart chart, int walk_face, double snap) {
  constexpr double chart_tol = 1e-9;
  // The target's chart coordinate: from a triangle of the same chart as the start (for texture
  // charts, the one nearest the straight line's other end is found as we go; here any triangle of
  // b whose face passes the filter).
  Eigen::Vector2d cb = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  auto find_cb = [&]() {
    double best = std::numeric_limits<double>::infinity();
    for (int t : vertex_triangles[static_cast<size_t>(b)]) {
      if (walk_face >= 0 && face[static_cast<size_t>(t)] != walk_face) {
        continue;
      }
      const Eigen::Vector2d c = chart_coordinate(chart, t, b);
      // Among several coordinates (a texture seam through b) take the nearest to a's.
      const double d = (c - ca).squaredNorm();
      if (d < best) {
        best = d;
        cb = c;
      }
    }
  };
  find_cb();
  if (!std::isfinite(cb.x())) {
    throw NumericalError(name_, "internal: curve point not in the walked face");
  }
  const int limit = 4 * num_triangles() + 16;
  for (int step = 0; step < limit; ++step) {
    if (a == b) {
      return;
    }
    if (!edge_triangles(a, b).empty()) {
      add_curve_edge(a, b);
      return;
    }
    const Eigen::Vector2d d = cb - ca;
    if (d.norm() == 0.0) {
      throw NumericalError(name_, "internal: coincident curve points");
    }
    const Eigen::Vector2d dn = d.normalized();
    // The triangle at a whose angular sector (in the chart) contains the direction to b.
    int best = -1;
    double best_score = -std::numeric_limits<double>::infinity();
    for (int t : vertex_triangles[static_cast<size_t>(a)]) {
      if (walk_face >= 0 && face[static_cast<size_t>(t)] != walk_face) {
        continue;
      }
      if ((chart_coordinate(chart, t, a) - ca).norm() > chart_tol) {
        continue;
      }
      const int k = corner(t, a);
      const int p = triangles[static_cast<size_t>(t)][(k + 1) % 3];
      const int q = triangles[static_cast<size_t>(t)][(k + 2) % 3];
      const Eigen::Vector2d ep = (chart_coordinate(chart, t, p) - ca).normalized();
      const Eigen::Vector2d eq = (chart_coordinate(chart, t, q) - ca).normalized();
      if (cross2(ep, eq) <= 0.0) {
        continue;  // degenerate in the chart
      }
      const double score = std::min(cross2(ep, dn), cross2(dn, eq));
      if (score > best_score) {
        best_score = score;
        best = t;
      }
    }
    if (best < 0 || best_score < -1e-6) {
      throw InvalidInputError(name_,
                              "the curve leaves the surface's chart (a texture seam or the edge of "
                              "the domain) and cannot be embedded");
    }
    const int k = corner(best, a);
    const int p = triangles[static_cast<size_t>(best)][(k + 1) % 3];
    const int q = triangles[static_cast<size_t>(best)][(k + 2) % 3];
    const Eigen::Vector2d cp = chart_coordinate(chart, best, p),
                          cq = chart_coordinate(chart, best, q);
    // Ray a + s d meets edge p + r (q - p): solve the 2x2 system for r.
    const Eigen::Vector2d e = cq - cp;
    const double den = cross2(d, e);
    double r = den != 0.0 ? cross2(d, cp - ca) / -den : 0.5;
    r = std::clamp(r, 0.0, 1.0);
    int next = -1;
    Eigen::Vector2d cnext;
    if ((r < snap && (!on_curve[static_cast<size_t>(p)] || p == b)) || r == 0.0) {
      next = p;
      cnext = cp;
    } else if ((r > 1.0 - snap && (!on_curve[static_cast<size_t>(q)] || q == b)) || r == 1.0) {
      next = q;
      cnext = cq;
    } else {
      if (is_curve_edge(p, q)) {
        throw_crossing();
      }
      cnext = (1.0 - r) * cp + r * cq;
      next = split_edge(p, q, r);
    }
    if (next != b && on_curve[static_cast<size_t>(next)]) {
      throw_crossing();
    }
    on_curve[static_cast<size_t>(next)] = 1;
    add_curve_edge(a, next);
    a = next;
    ca = cnext;
  }
  throw NumericalError(name_, "internal: the curve walk did not reach its end");
}

std::vector<std::vector<int>> CutMesh::components(const std::vector<char>* keep) const {
  const int nt = num_triangles();
  std::vector<int> label(static_cast<size_t>(nt), -1);
  std::vector<std::vector<int>> out;
  std::vector<int> stack;
  for (int seed = 0; seed < nt; ++seed) {
    if (label[static_cast<size_t>(seed)] >= 0) {
      continue;
    }
    if (keep && !(*keep)[static_cast<size_t>(seed)]) {
      continue;
    }
    const int id = static_cast<int>(out.size());
    out.emplace_back();
    stack.assign(1, seed);
    label[static_cast<size_t>(seed)] = id;
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      out.back().push_back(t);
      for (int k = 0; k < 3; ++k) {
        const int a = triangles[static_cast<size_t>(t)][k],
                  b = triangles[static_cast<size_t>(t)][(k + 1) % 3];
        if (is_curve_edge(a, b)) {
          continue;
        }
        for (int n : edge_triangles(a, b)) {
          if (label[static_cast<size_t>(n)] >= 0) {
            continue;
          }
          if (keep && !(*keep)[static_cast<size_t>(n)]) {
            continue;
          }
          label[static_cast<size_t>(n)] = id;
          stack.push_back(n);
        }
      }
    }
  }
  return out;
}

PatchTopology patch_topology(const CutMesh& mesh, const std::vector<int>& tris) {
  PatchTopology topo;
  // The patch's directed edges grouped by the vertex they leave (core/directed_edges.h): this runs
  // on every region (57,600 triangles for a whole cap) before any map.
  int top = -1;
  for (int t : tris) {
    const Eigen::Vector3i& v = mesh.triangles[static_cast<size_t>(t)];
    top = std::max(top, v.maxCoeff());
    const Eigen::Vector3d& x0 = mesh.positions[static_cast<size_t>(v[0])];
    topo.area += 0.5 * (mesh.positions[static_cast<size_t>(v[1])] - x0)
                           .cross(mesh.positions[static_cast<size_t>(v[2])] - x0)
                           .norm();
  }
  const DirectedEdges edges(mesh.triangles, top + 1, &tris);
  // A boundary edge is one whose reverse is not in the patch; each vertex's `next` is the
  // smallest end of its boundary edges, and a second one pinches the patch. An edge that two
  // triangles repeat counts once.
  std::vector<int> next(static_cast<size_t>(top + 1), -1);
  long vertices = 0, halfedges = 0, interior_pairs = 0;
  for (int a = 0; a <= top; ++a) {
    vertices += edges.end(a) > edges.begin(a) ? 1 : 0;  // every corner has an outgoing edge
    for (int e = edges.begin(a); e < edges.end(a); ++e) {
      const int b = edges.to(e);
      if (edges.find(a, b) != e) {
        continue;  // a repeat of an earlier edge a -> b
      }
      ++halfedges;
      if (edges.find(b, a) >= 0) {
        ++interior_pairs;
      } else if (next[static_cast<size_t>(a)] < 0) {
        next[static_cast<size_t>(a)] = b;
      } else {
        topo.pinched = true;
        next[static_cast<size_t>(a)] = std::min(next[static_cast<size_t>(a)], b);
      }
    }
  }
  const long boundary_edges = halfedges - interior_pairs;
  const long edge_count = interior_pairs / 2 + boundary_edges;
  topo.euler = static_cast<int>(vertices - edge_count + static_cast<long>(tris.size()));
  std::vector<char> visited(next.size(), 0);
  for (int first = 0; first <= top; ++first) {
    if (next[static_cast<size_t>(first)] < 0 || visited[static_cast<size_t>(first)]) {
      continue;
    }
    std::vector<int> loop;
    int v = first;
    while (v >= 0 && !visited[static_cast<size_t>(v)]) {
      visited[static_cast<size_t>(v)] = 1;
      loop.push_back(v);
      v = next[static_cast<size_t>(v)];
    }
    topo.loops.push_back(std::move(loop));
  }
  return topo;
}

Region make_region_from_patch(const CutMesh& mesh, const std::vector<int>& tris,
                              const PatchTopology& topology) {
  Region region;
  region.surface = &mesh.surface();
  std::vector<int> index(static_cast<size_t>(mesh.num_vertices()), -1);
  std::vector<int> sorted = tris;
  std::sort(sorted.begin(), sorted.end());
  auto id = [&](int v) {
    int& slot = index[static_cast<size_t>(v)];
    if (slot < 0) {
      slot = region.num_vertices();
      region.positions.push_back(mesh.positions[static_cast<size_t>(v)]);
      region.points.push_back(mesh.points[static_cast<size_t>(v)]);
    }
    return slot;
  };
  for (int t : sorted) {
    const Eigen::Vector3i& v = mesh.triangles[static_cast<size_t>(t)];
    region.triangles.emplace_back(id(v[0]), id(v[1]), id(v[2]));
    region.triangle_face.push_back(mesh.face[static_cast<size_t>(t)]);
    region.triangle_uv.push_back(mesh.uv[static_cast<size_t>(t)]);
  }
  for (int v : topology.loops.front()) {
    region.boundary.push_back(index[static_cast<size_t>(v)]);
  }
  if (mesh.surface().control_mesh().has_texcoords()) {
    region.texcoords.reserve(region.points.size());
    for (const SurfacePoint& p : region.points) {
      region.texcoords.push_back(texture_coordinate(mesh.surface(), p));
    }
  }
  return region;
}

}  // namespace elastic::regions_detail
