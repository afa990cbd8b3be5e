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
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "elastic/core/error.h"

namespace elastic {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------------
// Embree device shared by the process: created with the first projector, released with the last.

struct EmbreeDevice {
  RTCDevice device = nullptr;
  EmbreeDevice() : device(rtcNewDevice(nullptr)) {}
  ~EmbreeDevice() {
    if (device) {
      rtcReleaseDevice(device);
    }
  }
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;
};

std::shared_ptr<EmbreeDevice> shared_embree_device(const std::string& name) {
  static std::mutex mutex;
  static std::weak_ptr<EmbreeDevice> weak;
  std::lock_guard<std::mutex> lock(mutex);
  std::shared_ptr<EmbreeDevice> device = weak.lock();
  if (!device) {
    device = std::make_shared<EmbreeDevice>();
    if (!device->device) {
      throw Error(name, "cannot create an Embree device (error " +
                            std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
    }
    weak = device;
  }
  return device;
}

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

// ---------------------------------------------------------------------------------------------------
// The edges of a ptex face's parameter domain, as half-planes n.(u,v) >= c with inward unit normal
// n and unit tangent t. Quads: v=0, u=1, v=1, u=0. Loop triangles: v=0, u+v=1, u=0.

struct DomainEdge {
  Eigen::Vector2d normal;   // inward
  double offset;            // n.(u,v) >= offset inside
  Eigen::Vector2d tangent;  // along the edge
  Eigen::Vector2d midpoint;
};

const std::array<DomainEdge, 4>& quad_edges() {
  static const std::array<DomainEdge, 4> edges{{
      {{0.0, 1.0}, 0.0, {1.0, 0.0}, {0.5, 0.0}},
      {{-1.0, 0.0}, -1.0, {0.0, 1.0}, {1.0, 0.5}},
      {{0.0, -1.0}, -1.0, {1.0, 0.0}, {0.5, 1.0}},
      {{1.0, 0.0}, 0.0, {0.0, 1.0}, {0.0, 0.5}},
  }};
  return edges;
}

const std::array<DomainEdge, 3>& triangle_edges() {
  static const double h = std::sqrt(0.5);
  static const std::array<DomainEdge, 3> edges{{
      {{0.0, 1.0}, 0.0, {1.0, 0.0}, {0.5, 0.0}},
      {{-h, -h}, -h, {-h, h}, {0.5, 0.5}},
      {{1.0, 0.0}, 0.0, {0.0, 1.0}, {0.0, 0.5}},
  }};
  return edges;
}

// A point closer than this (in ptex units) to a boundary edge is on it: walk() clips exactly onto
// the boundary, so the slack only absorbs round-off in (u, v).
constexpr double kActiveTolerance = 1e-11;

// Most backtracking halvings of a Newton step before the iteration gives up.
constexpr int kMaxHalvings = 30;

// Most chart hops at face corners per Newton run (a vertex has rarely more than 8 faces).
constexpr int kMaxHops = 8;

// One Newton run's outcome.
struct NewtonRun {
  SurfacePoint point;
  SurfaceDerivatives d;
  double dist2 = kInf;
  double travel = 0.0;                                  // summed parameter-space step lengths
  Eigen::Vector2d last_step = Eigen::Vector2d::Zero();  // the sub-tolerance step not taken
  bool converged = false;
  bool on_boundary = false;
};

}  // namespace

// ---------------------------------------------------------------------------------------------------

struct SurfaceProjector::Impl {
  const LimitSurface* surface = nullptr;
  ProjectionOptions options;
  LimitTessellation tessellation;
  bool triangular = false;
  int num_edges = 4;  // domain edges per ptex face
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
  std::shared_ptr<EmbreeDevice> device;
  RTCScene scene = nullptr;

  ~Impl() {
    if (scene) {
      rtcReleaseScene(scene);
    }
  }

  const DomainEdge& edge(int k) const {
    return triangular ? triangle_edges()[static_cast<size_t>(k)]
                      : quad_edges()[static_cast<size_t>(k)];
  }

  void build_corner_nodes();
  void build_boundary_edges();
  void estimate_tessellation_error();
  void build_scene();

  Eigen::Vector2d node_uv(int triangle, int corner) const {
    const auto& nodes = corner_nodes[static_cast<size_t>(triangle)];
    const double n = face_resolution[static_cast<size_t>(
        tessellation.triangle_face[static_cast<size_t>(triangle)])];
    return {nodes[static_cast<size_t>(2 * corner)] / n,
            nodes[static_cast<size_t>(2 * corner + 1)] / n};
  }
  SurfacePoint seed(int triangle, double w1, double w2) const;

  void check_query(const Eigen::Vector3d& x) const;
  NewtonRun newton(const Eigen::Vector3d& x, SurfacePoint start) const;
  ClosestPoint finish(const Eigen::Vector3d& x, const NewtonRun& run) const;
  ClosestPoint global(const Eigen::Vector3d& x) const;
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
  if (!triangular) {
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
                  const bool on_edge = triangular ? (a == 0 || b == 0 || a + b == n)
                                                  : (a == 0 || b == 0 || a == n || b == n);
                  if (!on_edge || (triangular && a + b > n)) {
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
          corner_nodes[tri][static_cast<size_t>(2 * c)] = static_cast<std::uint16_t>(i);
          corner_nodes[tri][static_cast<size_t>(2 * c + 1)] = static_cast<std::uint16_t>(j);
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
    for (int k = 0; k < num_edges; ++k) {
      const Eigen::Vector2d m = edge(k).midpoint;
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
  device = shared_embree_device(name);
  const LimitTessellation& t = tessellation;
  scene = rtcNewScene(device->device);
  RTCGeometry geometry = rtcNewGeometry(device->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  if (!scene || !geometry) {
    throw Error(name, "cannot create the Embree scene");
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
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene);
  const RTCError error = rtcGetDeviceError(device->device);
  if (error != RTC_ERROR_NONE) {
    throw Error(name, "Embree failed to build the BVH (error " +
                          std::to_string(static_cast<int>(error)) + ")");
  }
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
  SurfacePoint p{tessellation.triangle_face[static_cast<size_t>(triangle)], uv.x(), uv.y()};
  // Round-off in the blend must not leave the domain.
  p.u = std::clamp(p.u, 0.0, 1.0);
  p.v = std::clamp(p.v, 0.0, 1.0);
  if (triangular && p.u + p.v > 1.0) {
    const double s = p.u + p.v;
    p.u /= s;
    p.v /= s;
  }
  return p;
}

void SurfaceProjector::Impl::check_query(const Eigen::Vector3d& x) const {
  if (!x.allFinite()) {
    throw InvalidInputError(surface->name(),
                            "closest-point query at a non-finite point (" + std::to_string(x.x()) +
                                ", " + std::to_string(x.y()) + ", " + std::to_string(x.z()) + ")");
  }
}

// Newton's method on E(u,v) = 1/2 |d(u,v) - x|^2 from `start`.
//
//   gradient  g = J^T r,                      r = d - x, J = [d_u d_v]
//   Hessian   H = J^T J + sum_i r_i d2 d_i    (the second term is r . d_uu, r . d_uv, r . d_vv)
//
// H is positive definite near a non-degenerate minimum (it fails only when the query is beyond a
// focal point, e.g. near the centre of curvature). When it is not, a modified Newton step with the
// absolute values of H's eigenvalues (floored) gives a descent step (see free_step). Steps are
// capped at `max_step`, applied with walk() (which crosses ptex edges), and halved until E does not
// grow beyond its round-off (the backtracking guard). Every accepted trial point's derivatives are
// the next iteration's, so an iteration costs one evaluation.
//
// Boundaries are an active set: on a boundary edge of the domain, if steepest descent points out of
// the surface, the step is a 1D Newton step along the edge tangent t (g_t = t.g, h_t = |t^T H t|);
// at a corner of two boundary edges the descent direction is projected on each edge ray and the
// iteration stops (a KKT point) when neither ray descends.
//
// Convergence: the step is below `parameter_tolerance`, or the (projected) gradient is zero to
// round-off. r carries an absolute error of a few eps (|x| + |d|) per component, so g_u = d_u . r
// cannot be resolved below |d_u| times that.
//
// Face corners: where a step leaves the face through a corner and no step length descends, the
// iteration hops into the neighbouring face (see the hop below) and continues in that chart.
NewtonRun SurfaceProjector::Impl::newton(const Eigen::Vector3d& x, SurfacePoint p) const {
  const LimitSurface& s = *surface;
  const double tolerance = options.parameter_tolerance;
  const double early_tolerance = 1e-2 * std::sqrt(tolerance);
  NewtonRun run;
  SurfaceDerivatives d = s.derivatives(p);
  Eigen::Vector3d r = d.position - x;
  double energy = 0.5 * r.squaredNorm();
  int hops = 0;  // chart hops at face corners (see below)
  auto at_corner = [&](const SurfacePoint& q) {
    int on = 0;
    for (int k = 0; k < num_edges; ++k) {
      on += edge(k).normal.dot(q.uv()) - edge(k).offset <= 1e-9;
    }
    return on >= 2;
  };

  for (int iteration = 0; iteration < options.max_newton_iterations; ++iteration) {
    const Eigen::Vector2d g(d.du.dot(r), d.dv.dot(r));
    const double g00 = d.du.squaredNorm(), g01 = d.du.dot(d.dv), g11 = d.dv.squaredNorm();
    const double h00 = g00 + r.dot(d.duu), h01 = g01 + r.dot(d.duv), h11 = g11 + r.dot(d.dvv);
    const double r_noise =
        8.0 * kEps * (x.cwiseAbs().maxCoeff() + d.position.cwiseAbs().maxCoeff());
    const double noise_u = 2.0 * r_noise * std::sqrt(g00), noise_v = 2.0 * r_noise * std::sqrt(g11);

    // Solves A s = -b for the 2x2 symmetric A; false when A is not safely positive definite.
    // Curvatures smaller than this (relative to the metric J^T J) are raised to it: the step along
    // such a direction is then long and capped by max_step.
    const double curvature_floor = 1e-6 * (g00 + g11) + 1e-300;
    // Newton step when H is safely positive definite. Otherwise (beyond a focal point, or where E
    // is flat) the "saddle-free" Newton step: H's eigenvalues replaced by their absolute values
    // (floored), so a direction of negative curvature is followed downhill with a long step instead
    // of the creeping Gauss-Newton step (J^T J overestimates the curvature there: measured on a
    // torus, GN needed more than 30 iterations from inside the tube where this takes a few).
    bool pure_newton = false;  // the step below is an exact Newton step (H positive definite)
    auto free_step = [&]() {
      const double det = h00 * h11 - h01 * h01;
      if (h00 > 0.0 && h11 > 0.0 && det > 1e-12 * h00 * h11) {
        pure_newton = true;
        return Eigen::Vector2d(-(h11 * g.x() - h01 * g.y()) / det,
                               -(h00 * g.y() - h01 * g.x()) / det);
      }
      const double mean = 0.5 * (h00 + h11);
      const double radius = std::hypot(0.5 * (h00 - h11), h01);
      const double l1 = mean + radius, l2 = mean - radius;
      Eigen::Vector2d v1 = std::abs(h01) > 1e-300 ? Eigen::Vector2d(l1 - h11, h01).normalized()
                           : h00 >= h11           ? Eigen::Vector2d(1.0, 0.0)
                                                  : Eigen::Vector2d(0.0, 1.0);
      const Eigen::Vector2d v2(-v1.y(), v1.x());
      return Eigen::Vector2d(-v1.dot(g) / std::max(std::abs(l1), curvature_floor) * v1 -
                             v2.dot(g) / std::max(std::abs(l2), curvature_floor) * v2);
    };
    // 1D Newton along a unit direction t (a boundary edge), with the same absolute-curvature rule.
    auto edge_step = [&](const Eigen::Vector2d& t) {
      const double ht = t.x() * t.x() * h00 + 2.0 * t.x() * t.y() * h01 + t.y() * t.y() * h11;
      const double jt = t.x() * t.x() * g00 + 2.0 * t.x() * t.y() * g01 + t.y() * t.y() * g11;
      pure_newton = ht > 1e-6 * jt;
      return Eigen::Vector2d(-t.dot(g) / std::max(std::abs(ht), 1e-6 * jt + 1e-300) * t);
    };
    // Steepest descent scaled by the curvature along it (a Cauchy step), used when Newton's step
    // would leave through a boundary edge although descent points inside.
    auto descent_step = [&]() {
      const double gg = g.squaredNorm();
      if (!(gg > 0.0)) {
        return Eigen::Vector2d(Eigen::Vector2d::Zero());
      }
      const double ghg = g.x() * g.x() * h00 + 2.0 * g.x() * g.y() * h01 + g.y() * g.y() * h11;
      const double gjg = g.x() * g.x() * g00 + 2.0 * g.x() * g.y() * g01 + g.y() * g.y() * g11;
      return Eigen::Vector2d(-gg / std::max(std::abs(ghg), 1e-6 * gjg + 1e-300) * g);
    };
    auto gradient_zero = [&](const Eigen::Vector2d& direction) {
      // Round-off bound of g along a unit parameter direction.
      const double noise = std::abs(direction.x()) * noise_u + std::abs(direction.y()) * noise_v;
      return std::abs(direction.dot(g)) <= noise;
    };

    // Active boundary edges of this face at p.
    int active[2] = {-1, -1};
    int num_active = 0;
    const std::uint8_t mask = boundary_edges[static_cast<size_t>(p.face)];
    if (mask) {
      const Eigen::Vector2d uv = p.uv();
      for (int k = 0; k < num_edges && num_active < 2; ++k) {
        if (!(mask & (1u << k))) {
          continue;
        }
        const DomainEdge& e = edge(k);
        if (e.normal.dot(uv) - e.offset <= kActiveTolerance) {
          active[num_active++] = k;
        }
      }
    }

    Eigen::Vector2d step;
    bool constrained = false;
    if (num_active == 0) {
      if (gradient_zero({1.0, 0.0}) && gradient_zero({0.0, 1.0})) {
        run.converged = true;
        break;
      }
      step = free_step();
    } else if (num_active == 1) {
      const DomainEdge& e = edge(active[0]);
      if (-g.dot(e.normal) <= 0.0) {  // descent points out of the surface: slide along the edge
        constrained = true;
        if (gradient_zero(e.tangent)) {
          run.converged = true;
          run.on_boundary = true;
          break;
        }
        step = edge_step(e.tangent);
      } else {
        step = free_step();
        if (step.dot(e.normal) < 0.0) {
          step = descent_step();
        }
      }
    } else {
      const DomainEdge& a = edge(active[0]);
      const DomainEdge& b = edge(active[1]);
      if (-g.dot(a.normal) > 0.0 && -g.dot(b.normal) > 0.0) {
        step = free_step();
        if (step.dot(a.normal) < 0.0 || step.dot(b.normal) < 0.0) {
          step = descent_step();
        }
      } else {
        // Rays from the corner along each boundary edge, pointing into the domain.
        const Eigen::Vector2d ray_a =
            a.tangent.dot(b.normal) >= 0.0 ? a.tangent : Eigen::Vector2d(-a.tangent);
        const Eigen::Vector2d ray_b =
            b.tangent.dot(a.normal) >= 0.0 ? b.tangent : Eigen::Vector2d(-b.tangent);
        constrained = true;
        if (-g.dot(ray_a) > 0.0 && !gradient_zero(ray_a)) {
          step = edge_step(ray_a);
        } else if (-g.dot(ray_b) > 0.0 && !gradient_zero(ray_b)) {
          step = edge_step(ray_b);
        } else {
          run.converged = true;  // KKT point at a boundary corner
          run.on_boundary = true;
          break;
        }
      }
    }

    const double length = step.norm();
    if (length > options.max_step) {
      step *= options.max_step / length;
    }
    if (!(step.norm() >= tolerance)) {  // also catches a NaN step
      run.converged = step.allFinite();
      run.on_boundary = constrained;
      if (run.converged) {
        run.last_step = step;
      }
      break;
    }
    // A pure Newton step this short ends within ~C |s|^2 (~1e-16 C) of the minimum, and d(p + s) is
    // d(p) + J s to O(|s|^2): finish() takes it without another evaluation (the last of the ~4 a
    // warm start costs). Only inside the face (a step off it needs walk()).
    if (pure_newton && step.norm() <= early_tolerance) {
      const Eigen::Vector2d uv = p.uv() + step;
      if (uv.x() >= 0.0 && uv.y() >= 0.0 &&
          (triangular ? uv.x() + uv.y() <= 1.0 : uv.x() <= 1.0 && uv.y() <= 1.0)) {
        run.converged = true;
        run.on_boundary = constrained;
        run.last_step = step;
        break;
      }
    }

    // Backtracking guard on E: accept when E does not grow beyond its own round-off.
    const double slack = 4.0 * std::sqrt(2.0 * energy) * r_noise + 1e-300;
    const Eigen::Vector2d first_step = step;
    bool accepted = false;
    SurfacePoint trial;
    SurfaceDerivatives trial_d;
    Eigen::Vector3d trial_r;
    double trial_energy = energy;
    for (int halving = 0; halving < kMaxHalvings; ++halving) {
      trial = s.walk(p, step);
      if (trial == p) {
        // walk() cannot leave through a face corner (around an extraordinary vertex there is no
        // continuous chart to carry the direction on); start a hair (1e-9) inside the face so the
        // path leaves through an edge instead. A boundary still stops it.
        SurfacePoint inside = p;
        const double centre = triangular ? 1.0 / 3.0 : 0.5;
        const Eigen::Vector2d towards = Eigen::Vector2d(centre - p.u, centre - p.v).normalized();
        inside.u += 1e-9 * towards.x();
        inside.v += 1e-9 * towards.y();
        trial = s.walk(inside, step);
      }
      trial_d = s.derivatives(trial);
      trial_r = trial_d.position - x;
      trial_energy = 0.5 * trial_r.squaredNorm();
      if (trial_energy <= energy + slack) {
        accepted = true;
        break;
      }
      step *= 0.5;
      if (step.norm() < tolerance) {
        break;
      }
    }
    if (!accepted && hops < kMaxHops && at_corner(p)) {
      // At a face corner a straight step in this face's chart may leave through the corner into a
      // sector where the chart does not continue smoothly (ptex charts are only C0 across edges at
      // an extraordinary vertex), so no step length descends. Hop 1e-7 into the neighbouring face
      // the step points to and recompute the step in that chart; E may grow by ~1e-7 |g| once per
      // hop.
      const double centre = triangular ? 1.0 / 3.0 : 0.5;
      const Eigen::Vector2d towards = Eigen::Vector2d(centre - p.u, centre - p.v).normalized();
      const SurfacePoint inside{p.face, p.u + 1e-9 * towards.x(), p.v + 1e-9 * towards.y()};
      trial = s.walk(inside, 1e-7 * first_step.normalized());
      if (trial.face != p.face) {
        ++hops;
        trial_d = s.derivatives(trial);
        trial_r = trial_d.position - x;
        trial_energy = 0.5 * trial_r.squaredNorm();
        accepted = true;
        step = Eigen::Vector2d::Zero();
      }
    }
    if (!accepted) {
      // No descent at any step length above the tolerance: p is a minimum to within round-off.
      run.converged = step.norm() < tolerance;
      run.on_boundary = constrained;
      break;
    }
    if (trial == p) {
      break;  // blocked (walk could not move): leave it unconverged
    }
    run.travel += step.norm();
    p = trial;
    d = trial_d;
    r = trial_r;
    energy = trial_energy;
  }

  run.point = p;
  run.d = d;
  run.dist2 = r.squaredNorm();
  if (!run.on_boundary && run.converged) {
    // A converged interior point can still sit on a boundary edge when descent points along it.
    const std::uint8_t mask = boundary_edges[static_cast<size_t>(p.face)];
    for (int k = 0; k < num_edges && mask; ++k) {
      if ((mask & (1u << k)) && edge(k).normal.dot(p.uv()) - edge(k).offset <= kActiveTolerance) {
        run.on_boundary = true;
      }
    }
  }
  return run;
}

ClosestPoint SurfaceProjector::Impl::finish(const Eigen::Vector3d& x, const NewtonRun& run) const {
  ClosestPoint out;
  out.point = run.point;
  out.position = run.d.position;
  // Newton stopped on a short step s without taking it (below the tolerance, or a pure Newton step
  // below 1e-2 sqrt(tolerance)). Taking it costs no evaluation: d(p + s) = d(p) + J s + O(|s|^2)
  // with |s|^2 <= 1e-16 (for the default tolerance), at the level of round-off; likewise the
  // tangents for the normal. Only when p + s stays in the face (a step off it would need walk()).
  const Eigen::Vector2d uv = run.point.uv() + run.last_step;
  const bool inside = uv.x() >= 0.0 && uv.y() >= 0.0 &&
                      (triangular ? uv.x() + uv.y() <= 1.0 : uv.x() <= 1.0 && uv.y() <= 1.0);
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
    // vertex, say): take the normal a hair towards the face centre, where it is regular.
    SurfacePoint q = run.point;
    const double centre = triangular ? 1.0 / 3.0 : 0.5;
    q.u += 1e-7 * (centre - q.u);
    q.v += 1e-7 * (centre - q.v);
    const SurfaceDerivatives dq = surface->derivatives(q);
    n = dq.du.cross(dq.dv);
  }
  const double length = n.norm();
  if (length > 0.0) {
    out.normal = n / length;
  }
  return out;
}

ClosestPoint SurfaceProjector::Impl::global(const Eigen::Vector3d& x) const {
  struct Query {
    const Impl* impl;
    Eigen::Vector3d x;
    // Nearest-triangle mode.
    TriangleHit best;
    int best_triangle = -1;
    // Collection mode (limit > 0): the candidates nearer than `limit`, the nearest few kept.
    double limit = -1.0;
    std::array<std::pair<TriangleHit, int>, 16> candidates{};
    int num_candidates = 0;
  };
  Query query{this, x, {}, -1, -1.0, {}, 0};

  auto callback = [](RTCPointQueryFunctionArguments* args) -> bool {
    Query& q = *static_cast<Query*>(args->userPtr);
    const LimitTessellation& t = q.impl->tessellation;
    const Eigen::Vector3i& tri = t.triangles[args->primID];
    const TriangleHit hit = closest_on_triangle(q.x, t.positions[static_cast<size_t>(tri[0])],
                                                t.positions[static_cast<size_t>(tri[1])],
                                                t.positions[static_cast<size_t>(tri[2])]);
    if (q.limit < 0.0) {
      if (hit.dist2 >= q.best.dist2) {
        return false;
      }
      q.best = hit;
      q.best_triangle = static_cast<int>(args->primID);
      // The BVH holds float vertices: keep a little slack so float rounding does not cull the
      // triangle that is nearest in double.
      const double radius = std::sqrt(hit.dist2) * (1.0 + 1e-5) + 1e-6 * q.impl->scale;
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
  };

  RTCPointQuery point_query;
  point_query.x = static_cast<float>(x.x());
  point_query.y = static_cast<float>(x.y());
  point_query.z = static_cast<float>(x.z());
  point_query.time = 0.0f;
  point_query.radius = std::numeric_limits<float>::infinity();
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  rtcPointQuery(scene, &point_query, &context, callback, &query);
  if (query.best_triangle < 0) {
    // Only when the query point overflows float: fall back to a scan.
    for (size_t k = 0; k < tessellation.triangles.size(); ++k) {
      const Eigen::Vector3i& tri = tessellation.triangles[k];
      const TriangleHit hit =
          closest_on_triangle(x, tessellation.positions[static_cast<size_t>(tri[0])],
                              tessellation.positions[static_cast<size_t>(tri[1])],
                              tessellation.positions[static_cast<size_t>(tri[2])]);
      if (hit.dist2 < query.best.dist2) {
        query.best = hit;
        query.best_triangle = static_cast<int>(k);
      }
    }
  }
  NewtonRun best = newton(x, seed(query.best_triangle, query.best.w1, query.best.w2));

  // Second pass: triangles nearer than D + eps may carry a nearer limit point (see the header).
  if (options.max_global_seeds > 1) {
    const double limit = std::sqrt(best.dist2) + tessellation_error;
    query.limit = limit;
    point_query.radius = static_cast<float>(limit * (1.0 + 1e-5) + 1e-6 * scale) * 1.0001f;
    rtcInitPointQueryContext(&context);
    rtcPointQuery(scene, &point_query, &context, callback, &query);
    std::sort(query.candidates.begin(), query.candidates.begin() + query.num_candidates,
              [](const auto& a, const auto& b) { return a.first.dist2 < b.first.dist2; });
    std::array<Eigen::Vector3d, 16> tried;
    int num_tried = 0;
    tried[static_cast<size_t>(num_tried++)] = best.d.position;
    int runs = 1;
    for (int c = 0; c < query.num_candidates && runs < options.max_global_seeds; ++c) {
      const auto& [hit, triangle] = query.candidates[static_cast<size_t>(c)];
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
      NewtonRun run = newton(x, seed(triangle, hit.w1, hit.w2));
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
  return finish(x, best);
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
  SurfacePoint start = hint;
  start.u = std::clamp(start.u, 0.0, 1.0);
  start.v = std::clamp(start.v, 0.0, 1.0);
  if (triangular && start.u + start.v > 1.0) {
    const double sum = start.u + start.v;
    start.u /= sum;
    start.v /= sum;
  }
  const NewtonRun run = newton(x, start);
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
  impl.triangular = surface.triangular_domain();
  impl.num_edges = impl.triangular ? 3 : 4;
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
