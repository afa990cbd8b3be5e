// `disk:` regions (region_spec.h): the geodesic disk about a surface point, its boundary the
// level set of the heat-method distance (regions/heat_geodesics.h) at the radius, cut exactly
// into the tessellation near the disk.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/regions/cut_mesh.h"
#include "elastic/regions/heat_geodesics.h"
#include "elastic/regions/region_context.h"

namespace elastic::regions_detail {
namespace {

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

DiskNeighbourhood disk_neighbourhood(const LimitTessellation& tess, const Eigen::VectorXd& distance,
                                     double radius) {
  DiskNeighbourhood part;
  std::vector<int> local(tess.positions.size(), -1);
  for (size_t t = 0; t < tess.triangles.size(); ++t) {
    const Eigen::Vector3i& v = tess.triangles[t];
    if (distance[v[0]] < radius || distance[v[1]] < radius || distance[v[2]] < radius) {
      part.triangles.push_back(static_cast<int>(t));
      for (int k = 0; k < 3; ++k) {
        local[static_cast<size_t>(v[k])] = 0;
      }
    }
  }
  int next = 0;
  for (size_t v = 0; v < local.size(); ++v) {
    if (local[v] == 0) {
      local[v] = next++;
      part.tess.positions.push_back(tess.positions[v]);
      part.tess.points.push_back(tess.points[v]);
      part.phi.push_back(distance[static_cast<Eigen::Index>(v)] - radius);
    }
  }
  part.tess.resolution = tess.resolution;
  part.tess.triangles.reserve(part.triangles.size());
  part.tess.triangle_face.reserve(part.triangles.size());
  for (const int t : part.triangles) {
    const Eigen::Vector3i& v = tess.triangles[static_cast<size_t>(t)];
    part.tess.triangles.emplace_back(local[static_cast<size_t>(v[0])],
                                     local[static_cast<size_t>(v[1])],
                                     local[static_cast<size_t>(v[2])]);
    part.tess.triangle_face.push_back(tess.triangle_face[static_cast<size_t>(t)]);
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

// The component of the sub-level set that holds the centre (the discrete field may have far-away
// dips); refused when the disk is too small to hold a triangle of the cut there. `home` is the
// centre's triangle among the cut mesh's original triangles (-1: not among them).
int centre_component(const RegionContext& ctx, const CutMesh& cut,
                     const std::vector<std::vector<int>>& comps, const MeshLocation& centre,
                     int home_triangle, double radius) {
  for (size_t c = 0; c < comps.size(); ++c) {
    for (int t : comps[c]) {
      if (home_triangle >= 0 && cut.origin[static_cast<size_t>(t)] == home_triangle) {
        return static_cast<int>(c);
      }
    }
  }
  const Eigen::Vector3i& home = ctx.tess.triangles[static_cast<size_t>(centre.triangle)];
  double edge_sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    edge_sum += (ctx.tess.positions[static_cast<size_t>(home[(k + 1) % 3])] -
                 ctx.tess.positions[static_cast<size_t>(home[k])])
                    .norm();
  }
  throw InvalidInputError(ctx.options.name,
                          "the disk of radius " + std::to_string(radius) +
                              " is too small for the surface's tessellation (edges about " +
                              std::to_string(edge_sum / 3.0) + " long at the centre)");
}

}  // namespace

Region disk_region(const RegionContext& ctx, const RegionSpec& spec) {
  const std::string& name = ctx.options.name;
  if (!(spec.radius > 0.0) || !std::isfinite(spec.radius)) {
    throw InvalidInputError(name,
                            "disk radius " + std::to_string(spec.radius) + " must be positive");
  }
  const MeshLocation centre =
      ctx.project(spec.center, "disk centre", [&](const Eigen::Vector3d& q) {
        std::ostringstream text;
        text.precision(6);
        text << "disk:" << q.x() << ',' << q.y() << ',' << q.z() << ',' << spec.radius;
        return text.str();
      });
  // Vertices beyond the disk's reach get a distance of 4 R: outside, far from the level set.
  const Eigen::VectorXd distance = local_geodesic_distance(
      ctx.tess.positions, ctx.tess.triangles, centre, spec.radius, 4.0 * spec.radius, name);
  // The level set phi = distance - R, cut exactly, in the disk's neighbourhood.
  DiskNeighbourhood part = disk_neighbourhood(ctx.tess, distance, spec.radius);
  CutMesh cut(ctx.surface, part.tess, tessellation_corner_uv(ctx.surface, ctx.tess, part.triangles),
              name);
  std::vector<double>& phi = part.phi;
  const std::vector<double> raw = phi;
  cut_zero_level(mesh_edges(part.tess.triangles), cut, phi);
  const std::vector<char> inside = below_zero_level(cut, phi, raw);
  const auto comps = cut.components(&inside);
  const auto home = std::lower_bound(part.triangles.begin(), part.triangles.end(), centre.triangle);
  const int home_triangle = home != part.triangles.end() && *home == centre.triangle
                                ? static_cast<int>(home - part.triangles.begin())
                                : -1;
  const int chosen = centre_component(ctx, cut, comps, centre, home_triangle, spec.radius);
  PatchTopology topo = patch_topology(cut, comps[static_cast<size_t>(chosen)]);
  if (topo.loops.empty()) {
    throw InvalidInputError(name, "the disk of radius " + std::to_string(spec.radius) +
                                      " covers the whole closed surface");
  }
  if (!topo.is_disk()) {
    throw_not_disk(name);
  }
  return make_region_from_patch(cut, comps[static_cast<size_t>(chosen)], topo);
}

}  // namespace elastic::regions_detail
