// SurfaceProjector: BVH seed (Embree point query on a tessellation) + Newton on the limit surface.
// See closest_point.h for the method; the numerics are commented where they happen.

#include "elastic/projection/closest_point.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "elastic/core/detail/embree_handles.h"
#include "elastic/core/error.h"
#include "elastic/projection/detail/closest_point_newton.h"

namespace elastic {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------------
// Closest point on a triangle (Ericson, "Real-Time Collision Detection", §5.1.5, re-derived):
// classify the query against the Voronoi regions of the vertices, edges and face. Returns the
// barycentric coordinates (w0, w1, w2) of the closest point; everything in double.

struct TriangleHit {
  double dist2 = kInf;
  double w1 = 0.0;  // weight of corner 1
  double w2 = 0.0;  // weight of corner 2 (corner 0 has 1 - w1 - w2)
};

TriangleHit closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  TriangleHit hit;
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  auto finish = [&](double w1, double w2) {
    hit.w1 = w1;
    hit.w2 = w2;
    hit.dist2 = (a + w1 * ab + w2 * ac - p).squaredNorm();
    return hit;
  };
  if (d1 <= 0.0 && d2 <= 0.0) {
    return finish(0.0, 0.0);  // vertex a
  }
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    return finish(1.0, 0.0);  // vertex b
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    return finish(d1 / (d1 - d3), 0.0);  // edge ab
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    return finish(0.0, 1.0);  // vertex c
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    return finish(0.0, d2 / (d2 - d6));  // edge ac
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {  // edge bc
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return finish(1.0 - t, t);
  }
  const double sum = va + vb + vc;
  if (!(sum > 0.0)) {  // degenerate (zero-area) triangle: fall back to the best vertex
    const double da = ap.squaredNorm(), db = bp.squaredNorm(), dc = cp.squaredNorm();
    if (da <= db && da <= dc) {
      return finish(0.0, 0.0);
    }
    return db <= dc ? finish(1.0, 0.0) : finish(0.0, 1.0);
  }
  return finish(vb / sum, vc / sum);  // face interior
}

// An Embree point query over the tessellation's triangles, in one of two modes: the nearest
// triangle (limit < 0), or the collection of the candidates nearer than `limit`, the nearest few
// kept.
struct TriangleQuery {
  const LimitTessellation* tessellation = nullptr;
  double scale = 1.0;  // bounding-box diagonal (absolute slack for the BVH's float rounding)
  Eigen::Vector3d x;
  // Nearest-triangle mode.
  TriangleHit best;
  int best_triangle = -1;
  // Collection mode.
  double limit = -1.0;
  std::array<std::pair<TriangleHit, int>, 16> candidates{};
  int num_candidates = 0;

  TriangleHit hit(int triangle) const {
    const Eigen::Vector3i& tri = tessellation->triangles[static_cast<size_t>(triangle)];
    return closest_on_triangle(x, tessellation->positions[static_cast<size_t>(tri[0])],
                               tessellation->positions[static_cast<size_t>(tri[1])],
                               tessellation->positions[static_cast<size_t>(tri[2])]);
  }

  // Embree's callback: true when it shrank the query radius.
  static bool visit(RTCPointQueryFunctionArguments* args) {
    TriangleQuery& q = *static_cast<TriangleQuery*>(args->userPtr);
    const TriangleHit hit = q.hit(static_cast<int>(args->primID));
    if (q.limit < 0.0) {
      if (hit.dist2 >= q.best.dist2) {
        return false;
      }
      q.best = hit;
      q.best_triangle = static_cast<int>(args->primID);
      // The BVH holds float vertices: keep a little slack so float rounding does not cull the
      // triangle that is nearest in double.
      const double radius = std::sqrt(hit.dist2) * (1.0 + 1e-5) + 1e-6 * q.scale;
      args->query->radius = std::min(args->query->radius, static_cast<float>(radius) * 1.0001f);
      return true;
    }
    if (hit.dist2 > q.limit * q.limit) {
      return false;
    }
    const int capacity = static_cast<int>(q.candidates.size());
    if (q.num_candidates < capacity) {
      q.candidates[static_cast<size_t>(q.num_candidates++)] = {hit, static_cast<int>(args->primID)};
    } else {
      auto worst = std::max_element(
          q.candidates.begin(), q.candidates.end(),
          [](const auto& a, const auto& b) { return a.first.dist2 < b.first.dist2; });
      if (hit.dist2 < worst->first.dist2) {
        *worst = {hit, static_cast<int>(args->primID)};
      }
    }
    return false;
  }

  // Visits the triangles within `radius` of x.
  void run(RTCScene scene, float radius) {
    RTCPointQuery point_query;
    point_query.x = static_cast<float>(x.x());
    point_query.y = static_cast<float>(x.y());
    point_query.z = static_cast<float>(x.z());
    point_query.time = 0.0f;
    point_query.radius = radius;
    RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    rtcPointQuery(scene, &point_query, &context, &TriangleQuery::visit, this);
  }

  // The nearest triangle by a scan (only when the query point overflows float).
  void scan() {
    for (size_t k = 0; k < tessellation->triangles.size(); ++k) {
      const TriangleHit h = hit(static_cast<int>(k));
      if (h.dist2 < best.dist2) {
        best = h;
        best_triangle = static_cast<int>(k);
      }
    }
  }
};

}  // namespace

// ---------------------------------------------------------------------------------------------------

struct SurfaceProjector::Impl {
  const LimitSurface* surface = nullptr;
  ProjectionOptions options;
  LimitTessellation tessellation;
  PtexDomain domain{false};  // every ptex face's parameter domain
  // Per triangle: its three corners as grid nodes (i, j) of its own ptex face f, (u, v) = (i, j) /
  // n_f.
  std::vector<std::array<std::uint16_t, 6>> corner_nodes;
  // Per ptex face: its grid resolution n_f (tessellate() documents it: the resolution, halved for
  // the sub-faces of Catmull-Clark n-gons, whose edges are half control edges).
  std::vector<int> face_resolution;
  // Per ptex face: bit k set when domain edge k lies on the surface boundary.
  std::vector<std::uint8_t> boundary_edges;
  // Estimated largest distance between the tessellation and the limit surface.
  double tessellation_error = 0.0;
  // Bounding-box diagonal of the tessellation (absolute slack for float rounding in the BVH).
  double scale = 1.0;
  // Embree: the process's shared device, and the scene of the tessellation's triangles.
  std::shared_ptr<detail::EmbreeDevice> device;
  std::unique_ptr<detail::EmbreeScene> scene;

  void build_corner_nodes();
  void build_boundary_edges();
  void estimate_tessellation_error();
  void build_scene();

  Eigen::Vector2d node_uv(int triangle, int corner) const {
    const auto& nodes = corner_nodes[static_cast<size_t>(triangle)];
    const double n = face_resolution[static_cast<size_t>(
        tessellation.triangle_face[static_cast<size_t>(triangle)])];
    return {nodes[2 * static_cast<size_t>(corner)] / n,
            nodes[2 * static_cast<size_t>(corner) + 1] / n};
  }
  SurfacePoint seed(int triangle, double w1, double w2) const;

  void check_query(const Eigen::Vector3d& x) const;
  detail::NewtonRun newton(const Eigen::Vector3d& x, const SurfacePoint& start) const {
    return detail::newton_closest_point({surface, domain, &options, &boundary_edges}, x, start);
  }
  ClosestPoint finish(const Eigen::Vector3d& x, const detail::NewtonRun& run) const;
  ClosestPoint global(const Eigen::Vector3d& x) const;
  void try_candidates(const TriangleQuery& query, detail::NewtonRun& best) const;
  ClosestPoint warm(const Eigen::Vector3d& x, const SurfacePoint& hint) const;
};

// Re-expresses every triangle's corners in the triangle's own ptex face. A corner whose
// SurfacePoint is in that face is rounded to its grid node. A corner welded from another face lies
// on this face's domain boundary: it is the boundary grid node of this face whose limit position
// matches the vertex position (evaluated once per face, only for faces that need it).
void SurfaceProjector::Impl::build_corner_nodes() {
  const LimitTessellation& t = tessellation;
  const size_t num_triangles = t.triangles.size();
  corner_nodes.assign(num_triangles, {});
  const int num_faces = surface->num_faces();
  face_resolution.assign(static_cast<size_t>(num_faces), t.resolution);
  if (!domain.triangle()) {
    const PolygonMesh& mesh = surface->control_mesh();
    for (int f = 0; f < num_faces; ++f) {
      if (mesh.face_size(surface->control_face(f)) != 4) {
        face_resolution[static_cast<size_t>(f)] = std::max(1, t.resolution / 2);
      }
    }
  }

  // Triangles grouped by face (counting sort), so each face's boundary nodes are evaluated once.
  std::vector<int> start(static_cast<size_t>(num_faces) + 1, 0);
  for (int f : t.triangle_face) {
    ++start[static_cast<size_t>(f) + 1];
  }
  for (int f = 0; f < num_faces; ++f) {
    start[static_cast<size_t>(f) + 1] += start[static_cast<size_t>(f)];
  }
  std::vector<int> order(num_triangles);
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (size_t i = 0; i < num_triangles; ++i) {
      order[static_cast<size_t>(fill[static_cast<size_t>(t.triangle_face[i])]++)] =
          static_cast<int>(i);
    }
  }

  tbb::parallel_for(tbb::blocked_range<int>(0, num_faces), [&](const tbb::blocked_range<int>& r) {
    std::vector<std::array<int, 2>> nodes;
    std::vector<Eigen::Vector3d> node_positions;
    for (int f = r.begin(); f < r.end(); ++f) {
      const int n = face_resolution[static_cast<size_t>(f)];
      bool have_nodes = false;
      for (int k = start[static_cast<size_t>(f)]; k < start[static_cast<size_t>(f) + 1]; ++k) {
        const size_t tri = static_cast<size_t>(order[static_cast<size_t>(k)]);
        for (int c = 0; c < 3; ++c) {
          const int vertex = t.triangles[tri][c];
          const SurfacePoint& sp = t.points[static_cast<size_t>(vertex)];
          int i = -1, j = -1;
          if (sp.face == f) {  // a node of this face's grid, up to round-off
            i = static_cast<int>(std::lround(std::clamp(sp.u, 0.0, 1.0) * n));
            j = static_cast<int>(std::lround(std::clamp(sp.v, 0.0, 1.0) * n));
          }
          if (i < 0) {
            if (!have_nodes) {
              nodes.clear();
              node_positions.clear();
              for (int a = 0; a <= n; ++a) {
                for (int b = 0; b <= n; ++b) {
                  const bool on_edge = domain.triangle() ? (a == 0 || b == 0 || a + b == n)
                                                         : (a == 0 || b == 0 || a == n || b == n);
                  if (!on_edge || (domain.triangle() && a + b > n)) {
                    continue;
                  }
                  nodes.push_back({a, b});
                  node_positions.push_back(surface->position(
                      {f, static_cast<double>(a) / n, static_cast<double>(b) / n}));
                }
              }
              have_nodes = true;
            }
            const Eigen::Vector3d& pos = t.positions[static_cast<size_t>(vertex)];
            double best = kInf;
            for (size_t m = 0; m < nodes.size(); ++m) {
              const double d2 = (node_positions[m] - pos).squaredNorm();
              if (d2 < best) {
                best = d2;
                i = nodes[m][0];
                j = nodes[m][1];
              }
            }
          }
          corner_nodes[tri][2 * static_cast<size_t>(c)] = static_cast<std::uint16_t>(i);
          corner_nodes[tri][2 * static_cast<size_t>(c) + 1] = static_cast<std::uint16_t>(j);
        }
      }
    }
  });
}

// A domain edge is a boundary edge when its midpoint (which lies on no other edge) is on the
// boundary.
void SurfaceProjector::Impl::build_boundary_edges() {
  const int num_faces = surface->num_faces();
  boundary_edges.assign(static_cast<size_t>(num_faces), 0);
  for (int f = 0; f < num_faces; ++f) {
    std::uint8_t mask = 0;
    for (int k = 0; k < domain.num_corners(); ++k) {
      const Eigen::Vector2d m = domain.edge(k).midpoint;
      if (surface->on_boundary({f, m.x(), m.y()})) {
        mask = static_cast<std::uint8_t>(mask | (1u << k));
      }
    }
    boundary_edges[static_cast<size_t>(f)] = mask;
  }
}

// The limit surface's deviation from a flat triangle is largest near the triangle's middle (for a
// quadratic patch it peaks at the centroid or an edge midpoint, at most 4/3 of the centroid's value
// for right triangles). We measure it at every centroid and keep twice the largest as the bound
// used to discard BVH candidates: a heuristic, not a proof (the surface varies smoothly at the grid
// scale).
void SurfaceProjector::Impl::estimate_tessellation_error() {
  const LimitTessellation& t = tessellation;
  std::vector<double> worst(t.triangles.size(), 0.0);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, t.triangles.size()), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k < r.end(); ++k) {
          const int tk = static_cast<int>(k);
          const Eigen::Vector2d uv = (node_uv(tk, 0) + node_uv(tk, 1) + node_uv(tk, 2)) / 3.0;
          const Eigen::Vector3i& tri = t.triangles[k];
          const Eigen::Vector3d centroid =
              (t.positions[static_cast<size_t>(tri[0])] + t.positions[static_cast<size_t>(tri[1])] +
               t.positions[static_cast<size_t>(tri[2])]) /
              3.0;
          const SurfacePoint p{t.triangle_face[k], uv.x(), uv.y()};
          worst[k] = (surface->position(p) - centroid).norm();
        }
      });
  double largest = 0.0;
  for (double w : worst) {
    largest = std::max(largest, w);
  }
  tessellation_error = 2.0 * largest;
}

void SurfaceProjector::Impl::build_scene() {
  const std::string& name = surface->name();
  device = detail::shared_embree_device(name);
  const LimitTessellation& t = tessellation;
  scene = std::make_unique<detail::EmbreeScene>(device->get(), name);
  RTCGeometry geometry = rtcNewGeometry(device->get(), RTC_GEOMETRY_TYPE_TRIANGLE);
  if (!geometry) {
    throw Error(name, "cannot create the Embree geometry");
  }
  // Float vertices are enough: the BVH only picks seed triangles, whose distances are recomputed in
  // double from the tessellation's own positions in the callback.
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                               t.positions.size()));
  auto* indices = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                              3 * sizeof(unsigned), t.triangles.size()));
  if (!vertices || !indices) {
    rtcReleaseGeometry(geometry);
    throw Error(name, "cannot allocate the Embree buffers");
  }
  for (size_t v = 0; v < t.positions.size(); ++v) {
    for (int c = 0; c < 3; ++c) {
      vertices[3 * v + static_cast<size_t>(c)] = static_cast<float>(t.positions[v][c]);
    }
  }
  for (size_t k = 0; k < t.triangles.size(); ++k) {
    for (int c = 0; c < 3; ++c) {
      indices[3 * k + static_cast<size_t>(c)] = static_cast<unsigned>(t.triangles[k][c]);
    }
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene->get(), geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene->get());
  detail::check_embree(device->get(), name, "build the BVH");
}

SurfacePoint SurfaceProjector::Impl::seed(int triangle, double w1, double w2) const {
  // Pull the barycentrics 1e-3 towards the centroid: a seed exactly on a triangle corner may be a
  // face corner at an extraordinary vertex, where no chart is regular (and the shift is far below
  // the seed's own error, the tessellation's deviation from the surface).
  constexpr double kPull = 1e-3;
  w1 = (1.0 - kPull) * w1 + kPull / 3.0;
  w2 = (1.0 - kPull) * w2 + kPull / 3.0;
  const Eigen::Vector2d uv = (1.0 - w1 - w2) * node_uv(triangle, 0) + w1 * node_uv(triangle, 1) +
                             w2 * node_uv(triangle, 2);
  // Round-off in the blend must not leave the domain.
  return domain.clamp(
      SurfacePoint{tessellation.triangle_face[static_cast<size_t>(triangle)], uv.x(), uv.y()});
}

void SurfaceProjector::Impl::check_query(const Eigen::Vector3d& x) const {
  if (!x.allFinite()) {
    throw InvalidInputError(surface->name(),
                            "closest-point query at a non-finite point (" + std::to_string(x.x()) +
                                ", " + std::to_string(x.y()) + ", " + std::to_string(x.z()) + ")");
  }
}

ClosestPoint SurfaceProjector::Impl::finish(const Eigen::Vector3d& x,
                                            const detail::NewtonRun& run) const {
  ClosestPoint out;
  out.point = run.point;
  out.position = run.d.position;
  // Newton stopped on a short step s without taking it (below the tolerance, or a pure Newton step
  // below 1e-2 sqrt(tolerance)). Taking it costs no evaluation: d(p + s) = d(p) + J s + O(|s|^2)
  // with |s|^2 <= 1e-16 (for the default tolerance), at the level of round-off; likewise the
  // tangents for the normal. Only when p + s stays in the face (a step off it would need walk()).
  const Eigen::Vector2d uv = run.point.uv() + run.last_step;
  const bool inside = domain.contains(uv);
  if (inside && run.last_step != Eigen::Vector2d::Zero()) {
    out.point.u = uv.x();
    out.point.v = uv.y();
    out.position += run.last_step.x() * run.d.du + run.last_step.y() * run.d.dv;
  }
  out.distance = (x - out.position).norm();
  out.on_boundary = run.on_boundary;
  out.converged = run.converged;
  Eigen::Vector3d du = run.d.du, dv = run.d.dv;
  if (inside) {  // first-order update of the tangents to p + s, for the normal
    du += run.last_step.x() * run.d.duu + run.last_step.y() * run.d.duv;
    dv += run.last_step.x() * run.d.duv + run.last_step.y() * run.d.dvv;
  }
  Eigen::Vector3d n = du.cross(dv);
  if (!(n.norm() > 1e-12 * du.norm() * dv.norm())) {
    // Degenerate parametrisation at this point (a collapsed partial derivative at an extraordinary
    // vertex, say): take the normal a hair towards the face centre, where it is regular (the one
    // nudge off a singular parameterisation, as LimitSurface::curvature takes it).
    const SurfaceDerivatives dq =
        surface->derivatives(domain.towards_centre(run.point, kSingularNudge));
    n = dq.du.cross(dq.dv);
  }
  const double length = n.norm();
  if (length > 0.0) {
    out.normal = n / length;
  }
  return out;
}

ClosestPoint SurfaceProjector::Impl::global(const Eigen::Vector3d& x) const {
  TriangleQuery query;
  query.tessellation = &tessellation;
  query.scale = scale;
  query.x = x;
  query.run(scene->get(), std::numeric_limits<float>::infinity());
  if (query.best_triangle < 0) {
    query.scan();
  }
  detail::NewtonRun best = newton(x, seed(query.best_triangle, query.best.w1, query.best.w2));

  // Second pass: triangles nearer than D + eps may carry a nearer limit point (see the header).
  if (options.max_global_seeds > 1) {
    const double limit = std::sqrt(best.dist2) + tessellation_error;
    query.limit = limit;
    query.run(scene->get(), static_cast<float>(limit * (1.0 + 1e-5) + 1e-6 * scale) * 1.0001f);
    try_candidates(query, best);
  }
  return finish(x, best);
}

// Newton from the collected candidates, nearest first, up to max_global_seeds runs in all; `best`
// becomes the best converged answer.
void SurfaceProjector::Impl::try_candidates(const TriangleQuery& query,
                                            detail::NewtonRun& best) const {
  std::array<std::pair<TriangleHit, int>, 16> candidates = query.candidates;
  std::sort(candidates.begin(), candidates.begin() + query.num_candidates,
            [](const auto& a, const auto& b) { return a.first.dist2 < b.first.dist2; });
  std::array<Eigen::Vector3d, 16> tried;
  int num_tried = 0;
  tried[static_cast<size_t>(num_tried++)] = best.d.position;
  int runs = 1;
  for (int c = 0; c < query.num_candidates && runs < options.max_global_seeds; ++c) {
    const auto& [hit, triangle] = candidates[static_cast<size_t>(c)];
    if (triangle == query.best_triangle) {
      continue;
    }
    // A triangle cannot hide a limit point nearer than its own distance minus eps.
    const double lower = std::sqrt(hit.dist2) - tessellation_error;
    if (lower * std::abs(lower) >= best.dist2) {
      continue;
    }
    // Skip candidates within one triangle size of a Newton answer: they lie in its basin.
    const Eigen::Vector3i& tri = tessellation.triangles[static_cast<size_t>(triangle)];
    const Eigen::Vector3d& a = tessellation.positions[static_cast<size_t>(tri[0])];
    const Eigen::Vector3d& b = tessellation.positions[static_cast<size_t>(tri[1])];
    const Eigen::Vector3d& cc = tessellation.positions[static_cast<size_t>(tri[2])];
    const Eigen::Vector3d foot = (1.0 - hit.w1 - hit.w2) * a + hit.w1 * b + hit.w2 * cc;
    const double size2 =
        std::max({(b - a).squaredNorm(), (cc - b).squaredNorm(), (a - cc).squaredNorm()});
    bool near_tried = false;
    for (int k = 0; k < num_tried; ++k) {
      near_tried |= (tried[static_cast<size_t>(k)] - foot).squaredNorm() <= size2;
    }
    if (near_tried) {
      continue;
    }
    detail::NewtonRun run = newton(query.x, seed(triangle, hit.w1, hit.w2));
    ++runs;
    if (num_tried < static_cast<int>(tried.size())) {
      tried[static_cast<size_t>(num_tried++)] = run.d.position;
    }
    const bool better = run.converged == best.converged ? run.dist2 < best.dist2 : run.converged;
    if (better) {
      best = run;
    }
  }
}

ClosestPoint SurfaceProjector::Impl::warm(const Eigen::Vector3d& x,
                                          const SurfacePoint& hint) const {
  if (!hint.valid()) {
    return global(x);
  }
  if (hint.face >= surface->num_faces() || !surface->in_domain(hint, 1e-9)) {
    throw InvalidInputError(surface->name(), "warm-start hint (face " + std::to_string(hint.face) +
                                                 ", u " + std::to_string(hint.u) + ", v " +
                                                 std::to_string(hint.v) +
                                                 ") is not on the surface");
  }
  const detail::NewtonRun run = newton(x, domain.clamp(hint));
  if (!run.converged || run.travel > options.warm_start_max_travel) {
    return global(x);
  }
  return finish(x, run);
}

// ---------------------------------------------------------------------------------------------------

SurfaceProjector::SurfaceProjector(const LimitSurface& surface, const ProjectionOptions& options)
    : impl_(std::make_unique<Impl>()) {
  const std::string& name = surface.name();
  if (options.max_newton_iterations < 1) {
    throw InvalidInputError(name, "max_newton_iterations must be at least 1");
  }
  if (!(options.parameter_tolerance > 0.0) || !std::isfinite(options.parameter_tolerance)) {
    throw InvalidInputError(name, "parameter_tolerance must be positive and finite");
  }
  if (!(options.max_step > 0.0)) {
    throw InvalidInputError(name, "max_step must be positive");
  }
  if (!(options.warm_start_max_travel >= 0.0)) {
    throw InvalidInputError(name, "warm_start_max_travel must not be negative");
  }
  if (options.max_global_seeds < 1) {
    throw InvalidInputError(name, "max_global_seeds must be at least 1");
  }

  Impl& impl = *impl_;
  impl.surface = &surface;
  impl.options = options;
  impl.domain = surface.domain();
  impl.tessellation = tessellate(surface, options.tessellation);
  if (impl.tessellation.triangles.empty()) {
    throw InvalidInputError(name, "the surface has no triangles to project on");
  }
  if (impl.tessellation.resolution > 65535) {
    throw InvalidInputError(name, "tessellation resolution too large for the projector");
  }
  {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInf), hi = -lo;
    for (const Eigen::Vector3d& p : impl.tessellation.positions) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    impl.scale = (hi - lo).norm();
  }
  impl.build_corner_nodes();
  impl.build_boundary_edges();
  impl.estimate_tessellation_error();
  impl.build_scene();
}

SurfaceProjector::~SurfaceProjector() = default;
SurfaceProjector::SurfaceProjector(SurfaceProjector&&) noexcept = default;
SurfaceProjector& SurfaceProjector::operator=(SurfaceProjector&&) noexcept = default;

const LimitSurface& SurfaceProjector::surface() const {
  return *impl_->surface;
}
const LimitTessellation& SurfaceProjector::tessellation() const {
  return impl_->tessellation;
}

ClosestPoint SurfaceProjector::closest(const Eigen::Vector3d& x) const {
  impl_->check_query(x);
  return impl_->global(x);
}

ClosestPoint SurfaceProjector::closest(const Eigen::Vector3d& x, const SurfacePoint& hint) const {
  impl_->check_query(x);
  return impl_->warm(x, hint);
}

void SurfaceProjector::closest(std::span<const Eigen::Vector3d> xs, std::span<ClosestPoint> out,
                               std::span<const SurfacePoint> hints) const {
  const std::string& name = impl_->surface->name();
  if (out.size() != xs.size()) {
    throw InvalidInputError(name, "batched closest-point query: " + std::to_string(xs.size()) +
                                      " points but " + std::to_string(out.size()) + " outputs");
  }
  if (!hints.empty() && hints.size() != xs.size()) {
    throw InvalidInputError(name, "batched closest-point query: " + std::to_string(xs.size()) +
                                      " points but " + std::to_string(hints.size()) + " hints");
  }
  // Validate up front so that a bad input throws before any work and on the calling thread.
  for (const Eigen::Vector3d& x : xs) {
    impl_->check_query(x);
  }
  const Impl& impl = *impl_;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, xs.size(), 64),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i < r.end(); ++i) {
                        out[i] = hints.empty() ? impl.global(xs[i]) : impl.warm(xs[i], hints[i]);
                      }
                    });
}

}  // namespace elastic
