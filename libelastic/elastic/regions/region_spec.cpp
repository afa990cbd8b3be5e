#include "elastic/regions/region_spec.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>

#include "elastic/core/error.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/cut_mesh.h"
#include "elastic/regions/polygon_sides.h"
#include "elastic/regions/region_context.h"

namespace elastic::regions_detail {

RegionContext::RegionContext(const SurfaceProjector& p, const RegionOptions& o)
    : projector(p), surface(p.surface()), tess(p.tessellation()), options(o) {
  face_triangles.resize(static_cast<size_t>(surface.num_faces()));
  for (size_t t = 0; t < tess.triangles.size(); ++t) {
    face_triangles[static_cast<size_t>(tess.triangle_face[t])].push_back(static_cast<int>(t));
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Eigen::Vector3d& x : tess.positions) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  diagonal = tess.positions.empty() ? 0.0 : (hi - lo).norm();
}

const std::vector<std::array<Eigen::Vector2d, 3>>& RegionContext::corner_uv() const {
  if (corner_uv_.empty()) {
    corner_uv_ = tessellation_corner_uv(surface, tess);
  }
  return corner_uv_;
}

MeshLocation RegionContext::locate(const SurfacePoint& p) const {
  // Before any whole-surface cut, only the point's face needs its triangles' corner (u, v).
  const std::vector<int>& candidates = face_triangles[static_cast<size_t>(p.face)];
  const std::vector<std::array<Eigen::Vector2d, 3>> uv =
      corner_uv_.empty() ? tessellation_corner_uv(surface, tess, candidates)
                         : std::vector<std::array<Eigen::Vector2d, 3>>{};
  MeshLocation best = deepest_triangle(
      candidates,
      [&](size_t i) -> const auto& {
        return uv.empty() ? corner_uv_[static_cast<size_t>(candidates[i])] : uv[i];
      },
      p.uv());
  if (best.triangle < 0) {
    throw NumericalError(options.name, "internal: cannot locate a surface point");
  }
  Eigen::Vector3d b = best.bary.cwiseMax(0.0);
  for (int k = 0; k < 3; ++k) {
    b[k] = b[k] < 1e-9 ? 0.0 : b[k];
  }
  best.bary = b / b.sum();
  return best;
}

MeshLocation RegionContext::project(
    const Eigen::Vector3d& x, const std::string& what,
    const std::function<std::string(const Eigen::Vector3d&)>& suggest) const {
  if (!x.allFinite()) {
    throw InvalidInputError(options.name, what + " is not finite");
  }
  const ClosestPoint cp = projector.closest(x);
  if (cp.distance > options.max_point_distance * diagonal) {
    std::ostringstream msg;
    msg.precision(6);
    const Eigen::Vector3d& q = cp.position;
    msg << what << " (" << x.x() << ", " << x.y() << ", " << x.z() << ") is far from the surface ("
        << cp.distance << " away, more than " << options.max_point_distance
        << " of the bounding-box diagonal); the nearest surface point is (" << q.x() << ", "
        << q.y() << ", " << q.z() << ")";
    if (suggest) {
      msg << ": try " << suggest(q);
    }
    throw InvalidInputError(options.name, msg.str());
  }
  return locate(cp.point);
}

void throw_not_disk(const std::string& name) {
  throw InvalidInputError(name, "the region is not a disk (it holds a handle or a hole)");
}

}  // namespace elastic::regions_detail

namespace elastic {

RegionCache::RegionCache() : impl_(std::make_unique<Impl>()) {}
RegionCache::~RegionCache() = default;
RegionCache::RegionCache(RegionCache&&) noexcept = default;
RegionCache& RegionCache::operator=(RegionCache&&) noexcept = default;

namespace {

using regions_detail::Chart;
using regions_detail::CutMesh;
using regions_detail::kSnap;
using regions_detail::MeshLocation;
using regions_detail::PatchTopology;
using Context = regions_detail::RegionContext;

/// After a closed curve has been embedded: the side of it that is a disk (the smaller one by area
/// when both are).
Region pick_disk_side(const CutMesh& cut, const std::string& name) {
  const auto comps = cut.components();
  int best = -1;
  PatchTopology best_topo;
  int touching = 0;
  for (size_t c = 0; c < comps.size(); ++c) {
    bool adjacent = false;
    for (int t : comps[c]) {
      const Eigen::Vector3i& v = cut.triangles[static_cast<size_t>(t)];
      for (int k = 0; k < 3 && !adjacent; ++k) {
        adjacent = cut.is_curve_edge(v[k], v[(k + 1) % 3]);
      }
      if (adjacent) {
        break;
      }
    }
    if (!adjacent) {
      continue;
    }
    ++touching;
    PatchTopology topo = regions_detail::patch_topology(cut, comps[c]);
    if (!topo.is_disk()) {
      continue;
    }
    if (best < 0 || topo.area < best_topo.area) {
      best = static_cast<int>(c);
      best_topo = std::move(topo);
    }
  }
  if (best < 0 || touching < 2) {
    regions_detail::throw_not_disk(name);
  }
  return regions_detail::make_region_from_patch(cut, comps[static_cast<size_t>(best)], best_topo);
}

bool in_face(const CutMesh& cut, int v, int face) {
  for (int t : cut.vertex_triangles[static_cast<size_t>(v)]) {
    if (cut.face[static_cast<size_t>(t)] == face) {
      return true;
    }
  }
  return false;
}

/// A ptex face with triangles at both a and b, or -1 (then the walk reports the missing face).
int common_face(const CutMesh& cut, int a, int b) {
  for (int t : cut.vertex_triangles[static_cast<size_t>(a)]) {
    if (in_face(cut, b, cut.face[static_cast<size_t>(t)])) {
      return cut.face[static_cast<size_t>(t)];
    }
  }
  return -1;
}

Eigen::Vector2d coordinate_in_face(const CutMesh& cut, int v, int face) {
  for (int t : cut.vertex_triangles[static_cast<size_t>(v)]) {
    if (cut.face[static_cast<size_t>(t)] == face) {
      return cut.chart_coordinate(Chart::Ptex, t, v);
    }
  }
  return cut.points[static_cast<size_t>(v)].uv();
}

/// Embeds a closed chain of curve points (each a location in a tessellation triangle that also
/// holds the next point) and walks the straight segments between them in `chart`.
void embed_curve(CutMesh& cut, const std::vector<MeshLocation>& nodes, Chart chart,
                 const std::vector<Eigen::Vector2d>* chart_points) {
  std::vector<int> verts;
  std::vector<int> seg;  // tessellation triangle holding vertex i and i+1 (ptex chart)
  std::vector<Eigen::Vector2d> coords;
  for (size_t i = 0; i < nodes.size(); ++i) {
    const MeshLocation& n = nodes[i];
    int v = -1;
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    if (chart == Chart::Ptex) {
      // n.triangle is a tessellation triangle: its original corners, not the piece of it that
      // an earlier insertion left under that index.
      const Eigen::Vector2d uv =
          regions_detail::interpolate(cut.origin_uv[static_cast<size_t>(n.triangle)], n.bary);
      v = cut.insert_point(n.triangle, uv, kSnap);
    } else {
      // Texture chart: locate the polygon point among the current triangles (earlier insertions may
      // have split the one it was found in).
      const Eigen::Vector2d& p = (*chart_points)[i];
      int best_t = -1;
      double best_min = -std::numeric_limits<double>::infinity();
      Eigen::Vector3d best_b = Eigen::Vector3d::Zero();
      for (int t = 0; t < cut.num_triangles(); ++t) {
        const Eigen::Vector3d b =
            regions_detail::barycentric_2d(cut.tex[static_cast<size_t>(t)], p);
        if (!b.isZero() && b.minCoeff() > best_min) {
          best_min = b.minCoeff();
          best_t = t;
          best_b = b;
        }
      }
      best_b = best_b.cwiseMax(0.0);
      v = cut.insert_in_triangle(best_t, best_b / best_b.sum(), kSnap);
    }
    if (!verts.empty() && v == verts.back()) {
      seg.back() = n.triangle;  // merged: the next segment runs in this node's triangle
      continue;
    }
    // The last path may end on the first point (a trace that reaches it within the snap distance).
    if (i + 1 == nodes.size() && verts.size() > 1 && v == verts.front()) {
      break;
    }
    if (cut.on_curve[static_cast<size_t>(v)]) {
      cut.throw_crossing();
    }
    cut.on_curve[static_cast<size_t>(v)] = 1;
    verts.push_back(v);
    seg.push_back(n.triangle);
    // Chart coordinate of the new vertex: ptex (u, v) in the segment's face, or the texture
    // coordinate nearest the polygon's own point (several at a seam).
    double best = std::numeric_limits<double>::infinity();
    const Eigen::Vector2d want = chart_points ? (*chart_points)[i] : Eigen::Vector2d::Zero();
    for (int t : cut.vertex_triangles[static_cast<size_t>(v)]) {
      if (chart == Chart::Ptex) {
        if (cut.face[static_cast<size_t>(t)] != cut.face[static_cast<size_t>(n.triangle)]) {
          continue;
        }
        c = cut.chart_coordinate(chart, t, v);
        best = 0.0;
        break;
      }
      const Eigen::Vector2d cc = cut.chart_coordinate(chart, t, v);
      if ((cc - want).squaredNorm() < best) {
        best = (cc - want).squaredNorm();
        c = cc;
      }
    }
    coords.push_back(c);
  }
  if (verts.size() > 1 && verts.back() == verts.front()) {
    verts.pop_back();
    seg.pop_back();
    coords.pop_back();
  }
  if (verts.size() < 3) {
    throw InvalidInputError(cut.surface().name(),
                            "the curve is degenerate (fewer than 3 distinct points)");
  }
  for (size_t i = 0; i < verts.size(); ++i) {
    const size_t j = (i + 1) % verts.size();
    int face = chart == Chart::Ptex ? cut.face[static_cast<size_t>(seg[i])] : -1;
    Eigen::Vector2d from = coords[i];
    if (chart == Chart::Ptex && !in_face(cut, verts[j], face)) {
      // A snap moved the next point off the segment's ptex face (onto a vertex of the neighbour
      // face): walk in a face that holds both ends instead.
      face = common_face(cut, verts[i], verts[j]);
      from = coordinate_in_face(cut, verts[i], face);
    }
    cut.walk(verts[i], from, verts[j], chart, face, kSnap);
  }
}

Region points_region(const Context& ctx, const RegionSpec& spec) {
  const std::string& name = ctx.options.name;
  std::vector<MeshLocation> locs;
  std::vector<Eigen::Vector3d> where;
  for (size_t i = 0; i < spec.points.size(); ++i) {
    const MeshLocation loc = ctx.project(spec.points[i], "point " + std::to_string(i + 1));
    // Drop repeated points (consecutive, or the last equal to the first).
    const Eigen::Vector3d x = position_of(ctx.tess.positions, ctx.tess.triangles, loc);
    if (!where.empty() && (x - where.back()).norm() <= 1e-9 * ctx.diagonal) {
      continue;
    }
    where.push_back(x);
    locs.push_back(loc);
  }
  if (where.size() > 1 && (where.back() - where.front()).norm() <= 1e-9 * ctx.diagonal) {
    where.pop_back();
    locs.pop_back();
  }
  if (locs.size() < 3) {
    throw InvalidInputError(name,
                            "the curve needs at least 3 distinct points on the surface, got " +
                                std::to_string(locs.size()));
  }
  // The sides are exact polyhedral shortest paths on the tessellation (exact_geodesics.h explains
  // why not the heat method's traced paths), each searched in a band around it (polygon_sides.h).
  std::vector<MeshLocation> nodes;
  for (const regions_detail::PolygonSide& side :
       regions_detail::polygon_sides(ctx.tess.positions, ctx.tess.triangles, locs, name)) {
    for (const auto& node : side.path.nodes) {
      // Express the node in the triangle that holds the segment leaving it.
      MeshLocation m{node.segment_triangle, Eigen::Vector3d::Zero()};
      const Eigen::Vector3i& from = ctx.tess.triangles[static_cast<size_t>(node.location.triangle)];
      const Eigen::Vector3i& to = ctx.tess.triangles[static_cast<size_t>(node.segment_triangle)];
      for (int k = 0; k < 3; ++k) {
        for (int l = 0; l < 3; ++l) {
          if (to[l] == from[k]) {
            m.bary[l] += node.location.bary[k];
          }
        }
      }
      m.bary /= m.bary.sum();
      nodes.push_back(m);
    }
  }
  CutMesh cut = ctx.cut_mesh();
  embed_curve(cut, nodes, Chart::Ptex, nullptr);
  return pick_disk_side(cut, name);
}

Region boundary_region(const Context& ctx) {
  CutMesh cut = ctx.cut_mesh();
  std::vector<int> all(static_cast<size_t>(cut.num_triangles()));
  for (int t = 0; t < cut.num_triangles(); ++t) {
    all[static_cast<size_t>(t)] = t;
  }
  const PatchTopology topo = regions_detail::patch_topology(cut, all);
  if (topo.loops.size() != 1) {
    throw InvalidInputError(ctx.options.name,
                            "'boundary' needs a surface with exactly one boundary loop; " +
                                ctx.surface.name() + " has " + std::to_string(topo.loops.size()));
  }
  if (!topo.is_disk()) {
    regions_detail::throw_not_disk(ctx.options.name);
  }
  return regions_detail::make_region_from_patch(cut, all, topo);
}

bool segments_cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                    const Eigen::Vector2d& d) {
  auto orient = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    return (q.x() - p.x()) * (r.y() - p.y()) - (q.y() - p.y()) * (r.x() - p.x());
  };
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a),
               o4 = orient(c, d, b);
  return ((o1 > 0) != (o2 > 0) || o1 == 0.0 || o2 == 0.0) &&
         ((o3 > 0) != (o4 > 0) || o3 == 0.0 || o4 == 0.0);
}

Region uv_region(const Context& ctx, const RegionSpec& spec) {
  const std::string& name = ctx.options.name;
  if (!ctx.surface.control_mesh().has_texcoords()) {
    throw InvalidInputError(
        name, "uv: region on " + ctx.surface.name() + ", which has no texture coordinates");
  }
  std::vector<Eigen::Vector2d> poly;
  for (const Eigen::Vector2d& p : spec.uv_polygon) {
    if (!p.allFinite()) {
      throw InvalidInputError(name, "uv polygon point is not finite");
    }
    if (poly.empty() || (p - poly.back()).norm() > 1e-12) {
      poly.push_back(p);
    }
  }
  if (poly.size() > 1 && (poly.back() - poly.front()).norm() <= 1e-12) {
    poly.pop_back();
  }
  if (poly.size() < 3) {
    throw InvalidInputError(name, "the uv polygon needs at least 3 distinct points, got " +
                                      std::to_string(poly.size()));
  }
  const size_t n = poly.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      if (j == i + 1 || (i == 0 && j == n - 1)) {
        continue;  // neighbours share a corner
      }
      if (segments_cross(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n])) {
        throw InvalidInputError(name, "the curve crosses itself (uv polygon edges " +
                                          std::to_string(i + 1) + " and " + std::to_string(j + 1) +
                                          ")");
      }
    }
  }
  CutMesh cut = ctx.cut_mesh();
  cut.enable_texture_chart();
  std::vector<MeshLocation> nodes;
  for (const Eigen::Vector2d& p : poly) {
    MeshLocation best;
    double best_min = -1e-9;
    for (int t = 0; t < cut.num_triangles(); ++t) {
      const Eigen::Vector3d b = regions_detail::barycentric_2d(cut.tex[static_cast<size_t>(t)], p);
      if (b.isZero()) {
        continue;
      }
      if (b.minCoeff() > best_min) {
        best_min = b.minCoeff();
        best = MeshLocation{t, b.cwiseMax(0.0) / b.cwiseMax(0.0).sum()};
      }
    }
    if (best.triangle < 0) {
      std::ostringstream msg;
      msg << "uv polygon point (" << p.x() << ", " << p.y() << ") is outside the texture domain of "
          << ctx.surface.name();
      throw InvalidInputError(name, msg.str());
    }
    nodes.push_back(best);
  }
  embed_curve(cut, nodes, Chart::Texture, &poly);
  return pick_disk_side(cut, name);
}

/// Automatic anchor: the boundary point in the direction, from the region's centroid, of the world
/// axis least aligned with the region's mean normal (x before y before z on ties), projected onto
/// the plane perpendicular to that normal. Deterministic, independent of the boundary's vertex
/// numbering, and for two similarly placed regions it picks corresponding points.
double automatic_anchor(const Region& region) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero();
  double area = 0.0;
  for (const Eigen::Vector3i& t : region.triangles) {
    const Eigen::Vector3d& a = region.positions[static_cast<size_t>(t[0])];
    const Eigen::Vector3d& b = region.positions[static_cast<size_t>(t[1])];
    const Eigen::Vector3d& c = region.positions[static_cast<size_t>(t[2])];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    normal += n;
    area += 0.5 * n.norm();
    centroid += 0.5 * n.norm() * (a + b + c) / 3.0;
  }
  if (area > 0.0) {
    centroid /= area;
  }
  Eigen::Vector3d reference = Eigen::Vector3d::UnitX();
  if (normal.norm() > 1e-9 * area) {
    const Eigen::Vector3d nn = normal.normalized();
    int axis = 0;
    nn.cwiseAbs().minCoeff(&axis);  // first index on ties
    reference = Eigen::Vector3d::Unit(axis) - nn[axis] * nn;
    reference.normalize();
  }
  const SurfaceCurve curve = region.boundary_curve();
  double best = -std::numeric_limits<double>::infinity();
  int best_v = 0;
  for (int i = 0; i < curve.size(); ++i) {
    const Eigen::Vector3d d = curve.positions[static_cast<size_t>(i)] - centroid;
    const double norm = d.norm();
    const double score = norm > 0.0 ? d.dot(reference) / norm : -1.0;
    if (score > best + 1e-12) {
      best = score;
      best_v = i;
    }
  }
  const std::vector<double> cum = curve.arc_lengths();
  const double total = curve.length();
  return total > 0.0 ? cum[static_cast<size_t>(best_v)] / total : 0.0;
}

}  // namespace

Region make_region(const SurfaceProjector& projector, const RegionSpec& spec,
                   const RegionOptions& options) {
  const Context ctx(projector, options);
  Region region;
  switch (spec.kind) {
    case RegionSpec::Kind::Disk:
      region = regions_detail::disk_region(ctx, spec);
      break;
    case RegionSpec::Kind::Points:
      region = points_region(ctx, spec);
      break;
    case RegionSpec::Kind::Boundary:
      region = boundary_region(ctx);
      break;
    case RegionSpec::Kind::UvPolygon:
      region = uv_region(ctx, spec);
      break;
  }
  if (spec.anchor) {
    if (!spec.anchor->allFinite()) {
      throw InvalidInputError(options.name, "anchor is not finite");
    }
    region.anchor = region.boundary_curve().nearest_arc_parameter(*spec.anchor);
    region.anchor_given = true;
  } else {
    region.anchor = automatic_anchor(region);
  }
  return region;
}

}  // namespace elastic
