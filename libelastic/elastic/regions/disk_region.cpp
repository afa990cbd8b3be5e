// `disk:` regions (region_spec.h): the geodesic disk about a surface point, its boundary the
// level set of the heat-method distance (regions/heat_geodesics.h) at the radius, cut exactly
// into the tessellation near the disk.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/regions/cut_mesh.h"
#include "elastic/regions/heat_geodesics.h"
#include "elastic/regions/region_context.h"
#include "elastic/surface/limit_tessellation.h"

namespace elastic::regions_detail {
namespace {

// A disk's level set is cut from the tessellation, so the disk is only as round as the tessellation
// is fine about it: a radius of one or two edges cuts a polygon of a few dozen triangles with sharp
// tips (a radius-5.7 disk on cylinder.obj, whose edges are about 4 long, came out a diamond of 30
// triangles, and every map of it folded a tip). Below kMinRadiusInEdges mean edge lengths the
// disk's neighbourhood is refined in (u, v) until the radius spans that many edges.
constexpr double kMinRadiusInEdges = 6.0;
constexpr int kMaxRefinementLevels = 6;
// A disk's heat distance measured on a coarser tessellation (disk_distance) keeps at least this
// many of its edges across the radius: the heat method errs by about an edge near the source
// (3% of the radius measured at 3 edges on a sphere).
constexpr double kMinRadiusInCoarseEdges = 32.0;

// The edges of a triangle mesh once each, as (smaller, larger) vertex index, sorted.
std::vector<std::pair<int, int>> mesh_edges(const std::vector<Eigen::Vector3i>& triangles) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * triangles.size());
  for (const Eigen::Vector3i& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      edges.emplace_back(std::minmax(t[k], t[(k + 1) % 3]));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

// The part of the tessellation a disk's cut touches: every triangle with a corner strictly inside
// the disk (phi = distance - R < 0). It holds every edge the level set crosses (both triangles of
// such an edge have its inside end) and every triangle of the disk (an inside triangle has a
// negative corner, see below_zero_level), so cutting the part gives the disk of the whole
// tessellation. Vertices and triangles keep the tessellation's relative order, so the same edges
// are split in the same order and the region comes out identical, at a cost that follows the
// disk's size instead of the surface's.
struct DiskNeighbourhood {
  LimitTessellation tess;
  std::vector<int> triangles;  ///< tessellation triangle of each part triangle, increasing
  std::vector<double> phi;     ///< distance - R per part vertex
};

// The triangles `which` (increasing) of `tess` as a tessellation of their own, its vertices in
// `tess`'s relative order; `vertex[i]` is the `tess` vertex of local vertex i.
LimitTessellation sub_tessellation(const LimitTessellation& tess, const std::vector<int>& which,
                                   std::vector<int>& vertex) {
  LimitTessellation part;
  std::vector<int> local(tess.positions.size(), -1);
  for (const int t : which) {
    for (int k = 0; k < 3; ++k) {
      local[static_cast<size_t>(tess.triangles[static_cast<size_t>(t)][k])] = 0;
    }
  }
  vertex.clear();
  for (size_t v = 0; v < local.size(); ++v) {
    if (local[v] == 0) {
      local[v] = static_cast<int>(vertex.size());
      vertex.push_back(static_cast<int>(v));
      part.positions.push_back(tess.positions[v]);
      part.points.push_back(tess.points[v]);
    }
  }
  part.resolution = tess.resolution;
  part.triangles.reserve(which.size());
  part.triangle_face.reserve(which.size());
  for (const int t : which) {
    const Eigen::Vector3i& v = tess.triangles[static_cast<size_t>(t)];
    part.triangles.emplace_back(local[static_cast<size_t>(v[0])], local[static_cast<size_t>(v[1])],
                                local[static_cast<size_t>(v[2])]);
    part.triangle_face.push_back(tess.triangle_face[static_cast<size_t>(t)]);
  }
  return part;
}

DiskNeighbourhood disk_neighbourhood(const LimitTessellation& tess, const Eigen::VectorXd& distance,
                                     double radius) {
  DiskNeighbourhood part;
  for (size_t t = 0; t < tess.triangles.size(); ++t) {
    const Eigen::Vector3i& v = tess.triangles[t];
    if (distance[v[0]] < radius || distance[v[1]] < radius || distance[v[2]] < radius) {
      part.triangles.push_back(static_cast<int>(t));
    }
  }
  std::vector<int> vertex;
  part.tess = sub_tessellation(tess, part.triangles, vertex);
  part.phi.reserve(vertex.size());
  for (const int v : vertex) {
    part.phi.push_back(distance[v] - radius);
  }
  return part;
}

// Cuts the level set phi = 0 exactly: every edge whose ends have opposite signs is split where the
// linear interpolant vanishes. Crossings within kSnap of an end move to that end (phi := 0 there).
// phi gains a zero per new vertex.
void cut_zero_level(const std::vector<std::pair<int, int>>& edges, CutMesh& cut,
                    std::vector<double>& phi) {
  const auto crosses = [](double pa, double pb) {
    return (pa < 0.0 && pb > 0.0) || (pa > 0.0 && pb < 0.0);
  };
  std::vector<char> zero(phi.size(), 0);
  for (const auto& [a, b] : edges) {
    const double pa = phi[static_cast<size_t>(a)], pb = phi[static_cast<size_t>(b)];
    if (!crosses(pa, pb)) {
      continue;
    }
    const double t = pa / (pa - pb);
    if (t < kSnap) {
      zero[static_cast<size_t>(a)] = 1;
    }
    if (t > 1.0 - kSnap) {
      zero[static_cast<size_t>(b)] = 1;
    }
  }
  for (size_t i = 0; i < phi.size(); ++i) {
    if (zero[i]) {
      phi[i] = 0.0;
    }
  }
  for (const auto& [a, b] : edges) {
    const double pa = phi[static_cast<size_t>(a)], pb = phi[static_cast<size_t>(b)];
    if (!crosses(pa, pb)) {
      continue;
    }
    cut.split_edge(a, b, pa / (pa - pb));
    phi.push_back(0.0);
  }
}

// Per triangle of the cut mesh (each now on one side): inside when no corner is positive;
// all-zero triangles, on the level set itself, go by the unsnapped field `raw`.
std::vector<char> below_zero_level(const CutMesh& cut, const std::vector<double>& phi,
                                   const std::vector<double>& raw) {
  std::vector<char> inside(static_cast<size_t>(cut.num_triangles()), 0);
  for (int t = 0; t < cut.num_triangles(); ++t) {
    const Eigen::Vector3i& v = cut.triangles[static_cast<size_t>(t)];
    double max_phi = -std::numeric_limits<double>::infinity(), raw_sum = 0.0;
    for (int k = 0; k < 3; ++k) {
      max_phi = std::max(max_phi, phi[static_cast<size_t>(v[k])]);
      if (static_cast<size_t>(v[k]) < raw.size()) {
        raw_sum += raw[static_cast<size_t>(v[k])];
      }
    }
    inside[static_cast<size_t>(t)] = max_phi < 0.0;
    if (max_phi == 0.0) {
      bool any_negative = false;
      for (int k = 0; k < 3; ++k) {
        any_negative = any_negative || phi[static_cast<size_t>(v[k])] < 0.0;
      }
      inside[static_cast<size_t>(t)] = any_negative || raw_sum < 0.0;
    }
  }
  return inside;
}

// Mean edge length of the tessellation triangles `which` (each interior edge counted twice).
double mean_edge_length(const LimitTessellation& tess, const std::vector<int>& which) {
  double sum = 0.0;
  for (const int t : which) {
    const Eigen::Vector3i& v = tess.triangles[static_cast<size_t>(t)];
    for (int k = 0; k < 3; ++k) {
      sum += (tess.positions[static_cast<size_t>(v[(k + 1) % 3])] -
              tess.positions[static_cast<size_t>(v[k])])
                 .norm();
    }
  }
  return which.empty() ? 0.0 : sum / (3.0 * static_cast<double>(which.size()));
}

// A piece of a tessellation with its corners' (u, v) and the disk's centre in it.
struct UvPart {
  LimitTessellation tess;
  std::vector<std::array<Eigen::Vector2d, 3>> corner_uv;  ///< per triangle, in its ptex face
  MeshLocation centre;
};

// The triangles `which` (increasing) of `tess`, corners' (u, v) `which_uv` in that order, as a mesh
// of their own (sub_tessellation); `centre` (a location in `tess`) must lie in one of them.
UvPart gather(const LimitTessellation& tess, std::vector<std::array<Eigen::Vector2d, 3>> which_uv,
              const std::vector<int>& which, const MeshLocation& centre) {
  UvPart part;
  std::vector<int> vertex;
  part.tess = sub_tessellation(tess, which, vertex);
  part.corner_uv = std::move(which_uv);
  const auto home = std::lower_bound(which.begin(), which.end(), centre.triangle);
  part.centre = {static_cast<int>(home - which.begin()), centre.bary};
  return part;
}

// One level of refinement: every triangle split into four at its edges' midpoints in (u, v) of its
// ptex face, so the new vertices lie on the limit surface and inside one face the (u, v) stay a
// conforming triangulation, as CutMesh requires. An edge shared by two faces gets one vertex (its
// surface point from the first triangle met); each triangle keeps the midpoint's (u, v) in its own
// face.
UvPart subdivide(const LimitSurface& surface, const UvPart& coarse) {
  UvPart fine;
  LimitTessellation& tess = fine.tess;
  tess.positions = coarse.tess.positions;
  tess.points = coarse.tess.points;
  tess.resolution = 2 * coarse.tess.resolution;
  std::unordered_map<std::uint64_t, int> midpoint;
  const auto split = [&](int a, int b, int face, const Eigen::Vector2d& uv) {
    const auto key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
                     static_cast<std::uint32_t>(std::max(a, b));
    const auto [it, added] = midpoint.emplace(key, static_cast<int>(tess.points.size()));
    if (added) {
      tess.points.push_back(SurfacePoint{face, uv.x(), uv.y()});
    }
    return it->second;
  };
  for (size_t t = 0; t < coarse.tess.triangles.size(); ++t) {
    const Eigen::Vector3i& v = coarse.tess.triangles[t];
    const auto& uv = coarse.corner_uv[t];
    const int face = coarse.tess.triangle_face[t];
    const Eigen::Vector2d m01 = 0.5 * (uv[0] + uv[1]), m12 = 0.5 * (uv[1] + uv[2]),
                          m20 = 0.5 * (uv[2] + uv[0]);
    const int a = split(v[0], v[1], face, m01), b = split(v[1], v[2], face, m12),
              c = split(v[2], v[0], face, m20);
    // Three corner triangles and the middle one, all counter-clockwise like the parent.
    tess.triangles.insert(tess.triangles.end(),
                          {Eigen::Vector3i(v[0], a, c), Eigen::Vector3i(a, v[1], b),
                           Eigen::Vector3i(c, b, v[2]), Eigen::Vector3i(a, b, c)});
    fine.corner_uv.push_back({uv[0], m01, m20});
    fine.corner_uv.push_back({m01, uv[1], m12});
    fine.corner_uv.push_back({m20, m12, uv[2]});
    fine.corner_uv.push_back({m01, m12, m20});
    tess.triangle_face.insert(tess.triangle_face.end(), 4, face);
  }
  const size_t first_new = tess.positions.size();
  tess.positions.resize(tess.points.size());
  tbb::parallel_for(first_new, tess.points.size(),
                    [&](size_t i) { tess.positions[i] = surface.position(tess.points[i]); });
  // The centre: the piece of its triangle holding its (u, v).
  const auto home = static_cast<size_t>(coarse.centre.triangle);
  const Eigen::Vector2d centre_uv = interpolate(coarse.corner_uv[home], coarse.centre.bary);
  double best = -std::numeric_limits<double>::infinity();
  for (size_t t = 4 * home; t < 4 * home + 4; ++t) {
    const Eigen::Vector3d b = barycentric_2d(fine.corner_uv[t], centre_uv);
    if (b.minCoeff() > best) {
      best = b.minCoeff();
      fine.centre = {static_cast<int>(t), b.cwiseMax(0.0) / b.cwiseMax(0.0).sum()};
    }
  }
  return fine;
}

// The triangles of `tess` with a corner closer than `reach` to `centre` (and the centre's own), by
// the heat method's distance.
std::vector<int> triangles_within(const LimitTessellation& tess, const MeshLocation& centre,
                                  double reach, const std::string& name) {
  const Eigen::VectorXd d =
      local_geodesic_distance(tess.positions, tess.triangles, centre, reach, 4.0 * reach, name);
  std::vector<int> near;
  for (size_t t = 0; t < tess.triangles.size(); ++t) {
    const Eigen::Vector3i& v = tess.triangles[t];
    if (d[v[0]] < reach || d[v[1]] < reach || d[v[2]] < reach ||
        static_cast<int>(t) == centre.triangle) {
      near.push_back(static_cast<int>(t));
    }
  }
  return near;
}

// The component of the sub-level set that holds the centre (the discrete field may have far-away
// dips); refused when the disk is too small to hold a triangle of the cut there. `home` is the
// centre's triangle among the cut mesh's original triangles (-1: not among them).
int centre_component(const RegionContext& ctx, const LimitTessellation& tess, const CutMesh& cut,
                     const std::vector<std::vector<int>>& comps, const MeshLocation& centre,
                     int home_triangle, double radius) {
  for (size_t c = 0; c < comps.size(); ++c) {
    for (int t : comps[c]) {
      if (home_triangle >= 0 && cut.origin[static_cast<size_t>(t)] == home_triangle) {
        return static_cast<int>(c);
      }
    }
  }
  const double edge = mean_edge_length(tess, {centre.triangle});
  throw InvalidInputError(ctx.options.name,
                          "the disk of radius " + std::to_string(radius) +
                              " is too small for the surface's tessellation (edges about " +
                              std::to_string(edge) + " long at the centre)");
}

// The disk cut from `tess` about `centre`: the level set of `part`'s phi (distance - R per part
// vertex), with the corners' (u, v) `corner_uv` of `part`'s triangles.
Region cut_disk(const RegionContext& ctx, const LimitTessellation& tess, DiskNeighbourhood& part,
                std::vector<std::array<Eigen::Vector2d, 3>> corner_uv, const MeshLocation& centre,
                double radius) {
  const std::string& name = ctx.options.name;
  CutMesh cut(ctx.surface, part.tess, std::move(corner_uv), name);
  std::vector<double>& phi = part.phi;
  const std::vector<double> raw = phi;
  cut_zero_level(mesh_edges(part.tess.triangles), cut, phi);
  const std::vector<char> inside = below_zero_level(cut, phi, raw);
  const auto comps = cut.components(&inside);
  const auto home = std::lower_bound(part.triangles.begin(), part.triangles.end(), centre.triangle);
  const int home_triangle = home != part.triangles.end() && *home == centre.triangle
                                ? static_cast<int>(home - part.triangles.begin())
                                : -1;
  const int chosen = centre_component(ctx, tess, cut, comps, centre, home_triangle, radius);
  PatchTopology topo = patch_topology(cut, comps[static_cast<size_t>(chosen)]);
  if (topo.loops.empty()) {
    throw InvalidInputError(
        name, "the disk of radius " + std::to_string(radius) + " covers the whole closed surface");
  }
  if (!topo.is_disk()) {
    throw_not_disk(name);
  }
  return make_region_from_patch(cut, comps[static_cast<size_t>(chosen)], topo);
}

// How many times the disk's neighbourhood is refined (subdivide) so that the radius spans
// kMinRadiusInEdges mean edges of `part` (of the centre's triangle when the disk holds no vertex).
int refinement_levels(const LimitTessellation& tess, const DiskNeighbourhood& part,
                      const MeshLocation& centre, double radius, double* edge) {
  *edge = part.triangles.empty() ? mean_edge_length(tess, {centre.triangle})
                                 : mean_edge_length(tess, part.triangles);
  int levels = 0;
  while (levels < kMaxRefinementLevels &&
         radius * std::ldexp(1.0, levels) < kMinRadiusInEdges * *edge) {
    ++levels;
  }
  return levels;
}

// The tessellation triangles of each ptex face with their corners' (u, v), to locate a surface
// point by its parameters.
struct FaceLocator {
  std::vector<std::array<Eigen::Vector2d, 3>> corner_uv;
  std::vector<std::vector<int>> face_triangles;

  FaceLocator(const LimitSurface& surface, const LimitTessellation& t)
      : corner_uv(tessellation_corner_uv(surface, t)) {
    face_triangles.resize(static_cast<size_t>(surface.num_faces()));
    for (size_t k = 0; k < t.triangles.size(); ++k) {
      face_triangles[static_cast<size_t>(t.triangle_face[k])].push_back(static_cast<int>(k));
    }
  }

  // The triangle of ptex face `face` holding `uv` (deepest_triangle), barycentric coordinates
  // clamped to the triangle; triangle -1 when the face has none.
  MeshLocation locate(int face, const Eigen::Vector2d& uv) const {
    const std::vector<int>& candidates = face_triangles[static_cast<size_t>(face)];
    MeshLocation at = deepest_triangle(
        candidates,
        [&](size_t i) -> const auto& { return corner_uv[static_cast<size_t>(candidates[i])]; }, uv);
    if (at.triangle >= 0) {
      at.bary = at.bary.cwiseMax(0.0);
      at.bary /= at.bary.sum();
    }
    return at;
  }
};

// The heat method's distance from `centre` at every vertex of ctx.tess for a disk of `radius`.
//
// The distance is computed on the part of the tessellation within twice the radius of the centre
// (local_geodesic_distance), and its two LDL^T factorisations cost O(n^1.5) in that part's
// vertices: a radius-12.49 disk on mountain.obj took the whole 228,484-vertex tessellation, 7.0 s
// and 906 MB of a map's loading. Where the part would hold more than
// RegionOptions::max_heat_vertices vertices, the distance is computed instead on a coarser
// tessellation of the same limit surface, with the fewest segments per control edge taken away
// that bring it within the budget, and interpolated linearly in each ptex face's (u, v) to the
// vertices; the disk is still cut on ctx.tess. The heat method's error is about one edge of the
// mesh it runs on, so the coarser tessellation keeps at least kMinRadiusInCoarseEdges edges across
// the radius (the mountain's disk spans 131 edges of the full tessellation, 3 segments per control
// edge, and about 88 of the coarser one, 2 segments: 7.0 -> 1.2 s for `elastic region`, its area
// 363.45 -> 360.21).
Eigen::VectorXd disk_distance(const RegionContext& ctx, const MeshLocation& centre, double radius) {
  const std::string& name = ctx.options.name;
  const LimitTessellation& tess = ctx.tess;
  const Eigen::Vector3d at = position_of(tess.positions, tess.triangles, centre);
  const auto within = [&](int v) {
    return (tess.positions[static_cast<size_t>(v)] - at).squaredNorm() <= 4.0 * radius * radius;
  };
  long near = 0;
  for (int v = 0; v < static_cast<int>(tess.positions.size()); ++v) {
    near += within(v) ? 1 : 0;
  }
  const long budget = ctx.options.max_heat_vertices;
  const auto fine_distance = [&] {
    if (ctx.options.cache != nullptr) {
      return ctx.options.cache->impl().disk_distance.distance(tess.positions, tess.triangles,
                                                              centre, radius, 4.0 * radius, name);
    }
    return local_geodesic_distance(tess.positions, tess.triangles, centre, radius, 4.0 * radius,
                                   name);
  };
  if (budget <= 0 || near <= budget) {
    return fine_distance();
  }
  // Vertices scale with the resolution squared; edges inversely with it, and the radius must
  // still span kMinRadiusInCoarseEdges of them.
  std::vector<int> near_triangles;
  for (size_t t = 0; t < tess.triangles.size(); ++t) {
    if (within(tess.triangles[t][0])) {
      near_triangles.push_back(static_cast<int>(t));
    }
  }
  const double edge = mean_edge_length(tess, near_triangles);
  const int fewest =
      static_cast<int>(std::ceil(kMinRadiusInCoarseEdges * edge * tess.resolution / radius));
  const int resolution = std::max(
      fewest, static_cast<int>(std::floor(tess.resolution * std::sqrt(static_cast<double>(budget) /
                                                                      static_cast<double>(near)))));
  const TessellationOptions coarser{.resolution = resolution};
  if (resolution < 1 || tessellation_resolution(ctx.surface, coarser) >= tess.resolution) {
    return fine_distance();  // (n-gons under Catmull-Clark round an odd resolution up)
  }
  const LimitTessellation coarse = tessellate(ctx.surface, coarser);
  const FaceLocator locator(ctx.surface, coarse);
  const std::array<Eigen::Vector2d, 3> home_uv =
      tessellation_corner_uv(ctx.surface, tess, {centre.triangle}).front();
  const MeshLocation coarse_centre = locator.locate(
      tess.triangle_face[static_cast<size_t>(centre.triangle)], interpolate(home_uv, centre.bary));
  if (coarse_centre.triangle < 0) {
    return fine_distance();
  }
  const Eigen::VectorXd coarse_distance = local_geodesic_distance(
      coarse.positions, coarse.triangles, coarse_centre, radius, 4.0 * radius, name);
  const auto nv = static_cast<int>(tess.positions.size());
  Eigen::VectorXd distance(nv);
  tbb::parallel_for(tbb::blocked_range<int>(0, nv, 4096), [&](const tbb::blocked_range<int>& r) {
    for (int v = r.begin(); v != r.end(); ++v) {
      const SurfacePoint& p = tess.points[static_cast<size_t>(v)];
      const MeshLocation l = locator.locate(p.face, p.uv());
      if (l.triangle < 0) {
        distance[v] = 4.0 * radius;  // no coarse triangle in its face (cannot happen): outside
        continue;
      }
      const Eigen::Vector3i& c = coarse.triangles[static_cast<size_t>(l.triangle)];
      distance[v] = l.bary[0] * coarse_distance[c[0]] + l.bary[1] * coarse_distance[c[1]] +
                    l.bary[2] * coarse_distance[c[2]];
    }
  });
  return distance;
}

}  // namespace

Region disk_region(const RegionContext& ctx, const RegionSpec& spec) {
  const std::string& name = ctx.options.name;
  const double radius = spec.radius;
  if (!(radius > 0.0) || !std::isfinite(radius)) {
    throw InvalidInputError(name, "disk radius " + std::to_string(radius) + " must be positive");
  }
  const MeshLocation centre =
      ctx.project(spec.center, "disk centre", [&](const Eigen::Vector3d& q) {
        std::ostringstream text;
        text.precision(6);
        text << "disk:" << q.x() << ',' << q.y() << ',' << q.z() << ',' << radius;
        return text.str();
      });
  // Vertices beyond the disk's reach get a distance of 4 R: outside, far from the level set.
  const Eigen::VectorXd distance = disk_distance(ctx, centre, radius);
  // The level set phi = distance - R, cut exactly, in the disk's neighbourhood.
  DiskNeighbourhood part = disk_neighbourhood(ctx.tess, distance, radius);
  double edge = 0.0;
  const int levels = refinement_levels(ctx.tess, part, centre, radius, &edge);
  if (levels == 0) {
    return cut_disk(ctx, ctx.tess, part,
                    tessellation_corner_uv(ctx.surface, ctx.tess, part.triangles), centre, radius);
  }
  // A disk of few edges: its neighbourhood out to R + max(R, 2 edges) (the distance errs by about
  // an edge), refined one level at a time, each level's neighbourhood chosen by the distance on the
  // level before, so the work follows the disk's size in the finest edges.
  const auto reach = [&] { return radius + std::max(radius, 2.0 * edge); };
  std::vector<int> near = triangles_within(ctx.tess, centre, reach(), name);
  UvPart fine = gather(ctx.tess, tessellation_corner_uv(ctx.surface, ctx.tess, near), near, centre);
  for (int level = 1; level <= levels; ++level) {
    fine = subdivide(ctx.surface, fine);
    edge *= 0.5;
    if (level < levels) {
      near = triangles_within(fine.tess, fine.centre, reach(), name);
      std::vector<std::array<Eigen::Vector2d, 3>> near_uv;
      near_uv.reserve(near.size());
      for (const int t : near) {
        near_uv.push_back(fine.corner_uv[static_cast<size_t>(t)]);
      }
      fine = gather(fine.tess, std::move(near_uv), near, fine.centre);
    }
  }
  const Eigen::VectorXd fine_distance = local_geodesic_distance(
      fine.tess.positions, fine.tess.triangles, fine.centre, radius, 4.0 * radius, name);
  DiskNeighbourhood fine_part = disk_neighbourhood(fine.tess, fine_distance, radius);
  std::vector<std::array<Eigen::Vector2d, 3>> corner_uv;
  corner_uv.reserve(fine_part.triangles.size());
  for (const int t : fine_part.triangles) {
    corner_uv.push_back(fine.corner_uv[static_cast<size_t>(t)]);
  }
  return cut_disk(ctx, fine.tess, fine_part, std::move(corner_uv), fine.centre, radius);
}

}  // namespace elastic::regions_detail
