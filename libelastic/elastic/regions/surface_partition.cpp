#include "elastic/regions/surface_partition.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/regions/cut_mesh.h"

namespace elastic {
namespace {

using regions_detail::barycentric_2d;
using regions_detail::Chart;
using regions_detail::CutMesh;

// The tessellation triangle of ptex face `face` holding (u, v) (largest smallest barycentric).
int locate_in_face(const std::vector<std::vector<int>>& face_triangles,
                   const std::vector<std::array<Eigen::Vector2d, 3>>& corner_uv, int face,
                   const Eigen::Vector2d& uv) {
  int best = -1;
  double best_min = -std::numeric_limits<double>::infinity();
  for (int t : face_triangles[static_cast<size_t>(face)]) {
    const Eigen::Vector3d b = barycentric_2d(corner_uv[static_cast<size_t>(t)], uv);
    if (b.isZero()) {
      continue;
    }
    if (b.minCoeff() > best_min) {
      best_min = b.minCoeff();
      best = t;
    }
  }
  return best;
}

// The cut-mesh triangle (among those cut from tessellation triangle `origin`) holding (u, v).
int locate_in_children(const CutMesh& cut, int origin, const Eigen::Vector2d& uv) {
  int best = -1;
  double best_min = -std::numeric_limits<double>::infinity();
  for (int t : cut.children[static_cast<size_t>(origin)]) {
    const Eigen::Vector3d b = barycentric_2d(cut.uv[static_cast<size_t>(t)], uv);
    if (b.isZero()) {
      continue;
    }
    if (b.minCoeff() > best_min) {
      best_min = b.minCoeff();
      best = t;
    }
  }
  return best;
}

Eigen::Vector2d corner_uv_of(const Region& region, int t, int v) {
  const Eigen::Vector3i& tri = region.triangles[static_cast<size_t>(t)];
  for (int k = 0; k < 3; ++k) {
    if (tri[k] == v) {
      return region.triangle_uv[static_cast<size_t>(t)][static_cast<size_t>(k)];
    }
  }
  return region.points[static_cast<size_t>(v)].uv();
}

void check_partition_inputs(const LimitSurface& surface, const LimitTessellation& tess,
                            const Region& region, const std::string& name) {
  if (region.surface != &surface) {
    throw InvalidInputError(name, "the region does not lie on " + surface.name());
  }
  if (region.num_triangles() == 0 || region.boundary.size() < 3) {
    throw InvalidInputError(name, "the region is empty or has fewer than 3 boundary points");
  }
  if (tess.triangles.empty() || tess.triangle_face.size() != tess.triangles.size()) {
    throw InvalidInputError(name, "the tessellation is empty");
  }
  for (int f : tess.triangle_face) {
    if (f < 0 || f >= surface.num_faces()) {
      throw InvalidInputError(name, "the tessellation does not belong to " + surface.name());
    }
  }
}

/// Where the tessellation triangles are: per ptex face its triangles, per triangle its corners'
/// (u, v).
struct TessellationIndex {
  std::vector<std::array<Eigen::Vector2d, 3>> corner_uv;
  std::vector<std::vector<int>> face_triangles;

  TessellationIndex(const LimitSurface& surface, const LimitTessellation& tess)
      : corner_uv(regions_detail::tessellation_corner_uv(surface, tess)),
        face_triangles(static_cast<size_t>(surface.num_faces())) {
    for (size_t t = 0; t < tess.triangles.size(); ++t) {
      face_triangles[static_cast<size_t>(tess.triangle_face[t])].push_back(static_cast<int>(t));
    }
  }
  int locate(int face, const Eigen::Vector2d& uv) const {
    return locate_in_face(face_triangles, corner_uv, face, uv);
  }
};

// Embeds the region's boundary into the cut mesh: its points inserted (snapped), then the
// segments between consecutive ones walked across the tessellation. Each boundary segment k
// (boundary[k] -> boundary[k+1]) is an edge of one region triangle, whose ptex face the segment is
// straight in.
void embed_boundary(CutMesh& cut, const Region& region, const TessellationIndex& index, double snap,
                    const std::string& name) {
  const int n = static_cast<int>(region.boundary.size());
  const std::vector<BoundaryChord> chords = region.boundary_chords();
  struct Node {
    int vertex;
    int face;
    Eigen::Vector2d coord;  // (u, v) of the vertex in `face`
  };
  std::vector<Node> nodes;
  for (int k = 0; k < n; ++k) {
    const int a = region.boundary[static_cast<size_t>(k)];
    const BoundaryChord& chord = chords[static_cast<size_t>(k)];
    if (chord.triangle < 0 || chord.corner_to != (chord.corner_from + 1) % 3) {
      throw InvalidInputError(name, "the region's boundary is not a loop of its triangles' edges");
    }
    const int t = chord.triangle;
    const int face = region.triangle_face[static_cast<size_t>(t)];
    const Eigen::Vector2d uv = corner_uv_of(region, t, a);
    const int origin = index.locate(face, uv);
    if (origin < 0) {
      throw NumericalError(name, "cannot locate a boundary point on the surface");
    }
    const int v = cut.insert_point(origin, uv, snap);
    if (!nodes.empty() && nodes.back().vertex == v) {
      continue;  // merged by the snap
    }
    if (k + 1 == n && nodes.size() > 1 && nodes.front().vertex == v) {
      break;
    }
    if (cut.on_curve[static_cast<size_t>(v)]) {
      cut.throw_crossing();
    }
    cut.on_curve[static_cast<size_t>(v)] = 1;
    // Chart coordinate of the (possibly snapped) vertex in the segment's face.
    Eigen::Vector2d coord = uv;
    for (int ct : cut.vertex_triangles[static_cast<size_t>(v)]) {
      if (cut.face[static_cast<size_t>(ct)] == face) {
        coord = cut.chart_coordinate(Chart::Ptex, ct, v);
        break;
      }
    }
    nodes.push_back({v, face, coord});
  }
  if (nodes.size() < 3) {
    throw InvalidInputError(name,
                            "the boundary has fewer than 3 distinct points at this "
                            "tessellation's resolution");
  }
  for (size_t i = 0; i < nodes.size(); ++i) {
    const Node& a = nodes[i];
    const Node& b = nodes[(i + 1) % nodes.size()];
    cut.walk(a.vertex, a.coord, b.vertex, Chart::Ptex, a.face, snap);
  }
}

// A cut-mesh triangle inside the region: the one holding the centroid of the region's largest
// triangle (a point strictly inside the region, a third of that triangle's height away from its
// edges).
int interior_triangle(const CutMesh& cut, const Region& region, const TessellationIndex& index,
                      const std::string& name) {
  int largest = 0;
  double largest_area = -1.0;
  for (int t = 0; t < region.num_triangles(); ++t) {
    const Eigen::Vector3i& tri = region.triangles[static_cast<size_t>(t)];
    const Eigen::Vector3d& x = region.positions[static_cast<size_t>(tri[0])];
    const double area = (region.positions[static_cast<size_t>(tri[1])] - x)
                            .cross(region.positions[static_cast<size_t>(tri[2])] - x)
                            .norm();
    if (area > largest_area) {
      largest_area = area;
      largest = t;
    }
  }
  const auto& luv = region.triangle_uv[static_cast<size_t>(largest)];
  const Eigen::Vector2d centre = (luv[0] + luv[1] + luv[2]) / 3.0;
  const int centre_face = region.triangle_face[static_cast<size_t>(largest)];
  const int centre_origin = index.locate(centre_face, centre);
  const int centre_triangle =
      centre_origin < 0 ? -1 : locate_in_children(cut, centre_origin, centre);
  if (centre_triangle < 0) {
    throw NumericalError(name, "cannot locate the region's interior");
  }
  return centre_triangle;
}

// The partition from the inside component: the re-cut region (its anchor at the original one's
// position, its vertices' indices in the cut mesh), every vertex, and the outside triangles.
SurfacePartition assemble(const CutMesh& cut, const Region& region,
                          const std::vector<int>& component,
                          const regions_detail::PatchTopology& topo) {
  SurfacePartition out;
  out.inside = regions_detail::make_region_from_patch(cut, component, topo);
  // Anchor: the original anchor's position, found on the re-cut curve.
  {
    const SurfaceCurve original = region.boundary_curve();
    const SurfaceCurve::Location at = original.locate(0.0);
    out.inside.anchor = out.inside.boundary_curve().nearest_arc_parameter(at.position);
  }
  // make_region_from_patch copies the sorted triangles in order: triangle i of the region is the
  // i-th smallest triangle index of the component, corner by corner.
  {
    std::vector<int> sorted = component;
    std::sort(sorted.begin(), sorted.end());
    out.inside_vertices.assign(static_cast<size_t>(out.inside.num_vertices()), -1);
    for (size_t i = 0; i < sorted.size(); ++i) {
      const Eigen::Vector3i& from = cut.triangles[static_cast<size_t>(sorted[i])];
      const Eigen::Vector3i& to = out.inside.triangles[i];
      for (int k = 0; k < 3; ++k) {
        out.inside_vertices[static_cast<size_t>(to[k])] = from[k];
      }
    }
  }
  out.positions = cut.positions;
  out.points = cut.points;
  std::vector<char> in_inside(static_cast<size_t>(cut.num_triangles()), 0);
  for (int t : component) {
    in_inside[static_cast<size_t>(t)] = 1;
  }
  for (int t = 0; t < cut.num_triangles(); ++t) {
    if (in_inside[static_cast<size_t>(t)]) {
      continue;
    }
    out.outside_triangles.push_back(cut.triangles[static_cast<size_t>(t)]);
    out.outside_face.push_back(cut.face[static_cast<size_t>(t)]);
    out.outside_uv.push_back(cut.uv[static_cast<size_t>(t)]);
  }
  return out;
}

}  // namespace

SurfacePartition partition_surface(const LimitSurface& surface, const LimitTessellation& tess,
                                   const Region& region, const PartitionOptions& options) {
  const std::string& name = options.name;
  check_partition_inputs(surface, tess, region, name);
  const TessellationIndex index(surface, tess);
  CutMesh cut(surface, tess, index.corner_uv, name);
  embed_boundary(cut, region, index, options.snap, name);
  const int centre_triangle = interior_triangle(cut, region, index, name);

  const auto comps = cut.components();
  int inside = -1;
  for (size_t c = 0; c < comps.size() && inside < 0; ++c) {
    if (std::find(comps[c].begin(), comps[c].end(), centre_triangle) != comps[c].end()) {
      inside = static_cast<int>(c);
    }
  }
  const regions_detail::PatchTopology topo =
      regions_detail::patch_topology(cut, comps[static_cast<size_t>(inside)]);
  if (topo.loops.size() != 1) {
    throw NumericalError(name, "the embedded boundary does not bound a disk on this tessellation");
  }
  return assemble(cut, region, comps[static_cast<size_t>(inside)], topo);
}

}  // namespace elastic
