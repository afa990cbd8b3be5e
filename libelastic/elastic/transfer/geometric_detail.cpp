#include "elastic/transfer/geometric_detail.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include "elastic/core/error.h"

namespace elastic {

DetailField extract_detail(const SurfaceProjector& base, const PolygonMesh& detail,
                           const DetailOptions& options) {
  const int n = detail.num_vertices();
  if (n == 0) {
    throw InvalidInputError(options.name, "the detail mesh has no vertices");
  }
  for (int i = 0; i < n; ++i) {
    if (!detail.positions[static_cast<size_t>(i)].allFinite()) {
      throw InvalidInputError(options.name,
                              "vertex " + std::to_string(i) + " has a non-finite position");
    }
  }
  DetailField field;
  field.mesh = detail;
  std::vector<ClosestPoint> closest(static_cast<size_t>(n));
  base.closest(detail.positions, closest);
  field.base_points.resize(static_cast<size_t>(n));
  field.base_positions.resize(static_cast<size_t>(n));
  field.local_offsets.resize(static_cast<size_t>(n));
  for (size_t i = 0; i < static_cast<size_t>(n); ++i) {
    field.base_points[i] = closest[i].point;
    field.base_positions[i] = closest[i].position;
    const TangentFrame frame = surface_frame(base.surface(), closest[i].point);
    const Eigen::Vector3d offset = detail.positions[i] - closest[i].position;
    field.local_offsets[i] = frame.to_local(offset);
    field.max_height = std::max(field.max_height, offset.norm());
    if (closest[i].on_boundary) {
      ++field.on_base_boundary;
    }
  }
  return field;
}

PasteDetailResult paste_detail(const DetailField& field, const Mapping& mapping,
                               const MapDifferential& differential,
                               const PasteDetailOptions& options) {
  if (!std::isfinite(options.scale)) {
    throw InvalidInputError(options.name, "scale is not finite");
  }
  const size_t n = field.base_points.size();
  if (field.mesh.positions.size() != n || field.local_offsets.size() != n) {
    throw InvalidInputError(options.name, "the detail field's arrays disagree with its mesh");
  }
  const LimitSurface& base = differential.source_surface();
  PasteDetailResult result;
  result.target_points.assign(n, SurfacePoint{});
  result.inside.assign(n, 0);
  std::vector<Eigen::Vector3d> pasted(n, Eigen::Vector3d::Zero());
  // Each vertex is independent: forward map of its base point, transport of its offset.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const Mapping::Location image = mapping.forward(field.base_points[i]);
      if (!image.inside) {
        continue;
      }
      // The offset back in world coordinates at the base point (x - b), then carried by T.
      const Eigen::Vector3d offset =
          surface_frame(base, field.base_points[i]).to_world(field.local_offsets[i]);
      const Eigen::Matrix3d t =
          differential.transport_forward(field.base_points[i], image, options.tangential);
      pasted[i] = image.position + options.scale * (t * offset);
      result.target_points[i] = image.point;
      result.inside[i] = 1;
    }
  });
  result.outside = static_cast<int>(std::count(result.inside.begin(), result.inside.end(), 0));

  // The output mesh: the detail's vertices at their pasted positions and the faces whose corners
  // all landed, with their corner texture coordinates, materials and colours.
  const PolygonMesh& in = field.mesh;
  PolygonMesh& out = result.mesh;
  out.positions = std::move(pasted);
  out.texcoords = in.texcoords;
  out.vertex_colors = in.vertex_colors;
  out.materials = in.materials;
  out.face_offsets.push_back(0);
  for (int f = 0; f < in.num_faces(); ++f) {
    const auto corners = in.face(f);
    const bool keep = std::all_of(corners.begin(), corners.end(), [&](int v) {
      return result.inside[static_cast<size_t>(v)] != 0;
    });
    if (!keep) {
      ++result.dropped_faces;
      continue;
    }
    for (int c = in.face_offsets[static_cast<size_t>(f)];
         c < in.face_offsets[static_cast<size_t>(f) + 1]; ++c) {
      out.face_vertices.push_back(in.face_vertices[static_cast<size_t>(c)]);
      if (in.has_texcoords()) {
        out.corner_texcoords.push_back(in.corner_texcoords[static_cast<size_t>(c)]);
      }
    }
    out.face_offsets.push_back(static_cast<int>(out.face_vertices.size()));
    if (!in.face_materials.empty()) {
      out.face_materials.push_back(in.face_materials[static_cast<size_t>(f)]);
    }
    if (in.has_face_colors()) {
      out.face_colors.push_back(in.face_colors[static_cast<size_t>(f)]);
    }
  }
  if (out.face_vertices.empty()) {
    out.face_offsets.clear();
  }
  return result;
}

namespace {

// Barycentric coordinates of the point of triangle (a, b, c) closest to p (Ericson, Real-Time
// Collision Detection §5.1.5, by Voronoi regions of the corners and edges).
Eigen::Vector3d closest_barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                    const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    return {1, 0, 0};
  }
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    return {0, 1, 0};
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return {1.0 - v, v, 0.0};
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    return {0, 0, 1};
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return {1.0 - w, 0.0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0.0, 1.0 - w, w};
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {1.0 - v - w, v, w};
}

// The detail's faces laid on the base through their vertices' base points, fan-triangulated, in a
// hashed uniform grid of cells (each triangle listed in every cell its bounding box, grown by the
// search radius, overlaps), so a query inspects one cell.
class Footprint {
 public:
  Footprint(const DetailField& field, double tolerance) : field_(field) {
    const PolygonMesh& mesh = field.mesh;
    double edge_sum = 0.0;
    long edges = 0;
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const auto corners = mesh.face(f);
      for (size_t k = 0; k < corners.size(); ++k) {
        edge_sum += (base(corners[k]) - base(corners[(k + 1) % corners.size()])).norm();
        ++edges;
      }
      for (size_t k = 1; k + 1 < corners.size(); ++k) {
        triangles_.push_back({corners[0], corners[k], corners[k + 1]});
      }
    }
    const double mean_edge = edges > 0 ? edge_sum / static_cast<double>(edges) : 0.0;
    radius_ = tolerance * mean_edge;
    cell_ = std::max(2.0 * mean_edge, 1e-12);
    for (size_t t = 0; t < triangles_.size(); ++t) {
      Eigen::Vector3d lo = base(triangles_[t][0]), hi = lo;
      for (int c = 1; c < 3; ++c) {
        lo = lo.cwiseMin(base(triangles_[t][c]));
        hi = hi.cwiseMax(base(triangles_[t][c]));
      }
      const Eigen::Vector3i a = cell_of(lo.array() - radius_), b = cell_of(hi.array() + radius_);
      for (int x = a.x(); x <= b.x(); ++x) {
        for (int y = a.y(); y <= b.y(); ++y) {
          for (int z = a.z(); z <= b.z(); ++z) {
            cells_[key({x, y, z})].push_back(static_cast<int>(t));
          }
        }
      }
    }
  }

  // The world offset x - b interpolated at p; false when p is off the footprint.
  bool offset_at(const Eigen::Vector3d& p, Eigen::Vector3d& offset) const {
    const auto it = cells_.find(key(cell_of(p)));
    if (it == cells_.end()) {
      return false;
    }
    double best = std::numeric_limits<double>::infinity();
    for (const int t : it->second) {
      const std::array<int, 3>& tri = triangles_[static_cast<size_t>(t)];
      const Eigen::Vector3d w = closest_barycentric(p, base(tri[0]), base(tri[1]), base(tri[2]));
      const Eigen::Vector3d q = w[0] * base(tri[0]) + w[1] * base(tri[1]) + w[2] * base(tri[2]);
      const double d = (p - q).norm();
      if (d < best) {
        best = d;
        offset =
            w[0] * world_offset(tri[0]) + w[1] * world_offset(tri[1]) + w[2] * world_offset(tri[2]);
      }
    }
    return best <= radius_;
  }

 private:
  const Eigen::Vector3d& base(int v) const { return field_.base_positions[static_cast<size_t>(v)]; }
  Eigen::Vector3d world_offset(int v) const {
    return field_.mesh.positions[static_cast<size_t>(v)] - base(v);
  }
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const {
    return (p / cell_).array().floor().cast<int>();
  }
  static std::int64_t key(const Eigen::Vector3i& c) {
    // 21 bits per axis: cells within +-1e6 of the origin are distinct.
    const auto part = [](int x) { return static_cast<std::int64_t>(x + (1 << 20)) & 0x1FFFFF; };
    return (part(c.x()) << 42) | (part(c.y()) << 21) | part(c.z());
  }

  const DetailField& field_;
  std::vector<std::array<int, 3>> triangles_;
  std::unordered_map<std::int64_t, std::vector<int>> cells_;
  double radius_ = 0.0;
  double cell_ = 1.0;
};

}  // namespace

DetailSamplesResult paste_detail_on_samples(const DetailField& field,
                                            const MapDifferential& differential,
                                            std::span<const SurfacePoint> target_points,
                                            std::span<const Eigen::Vector3d> target_positions,
                                            std::span<const Mapping::Location> sources,
                                            std::span<const char> pinned,
                                            const DetailSamplesOptions& options) {
  const size_t n = target_points.size();
  if (target_positions.size() != n || sources.size() != n ||
      (!pinned.empty() && pinned.size() != n)) {
    throw InvalidInputError(options.name,
                            "target points, positions, sources and pinned flags must "
                            "have one entry per sample (" +
                                std::to_string(n) + " target points)");
  }
  if (!std::isfinite(options.scale)) {
    throw InvalidInputError(options.name, "scale is not finite");
  }
  const Footprint footprint(field, options.footprint_tolerance);
  DetailSamplesResult result;
  result.positions.assign(target_positions.begin(), target_positions.end());
  result.covered.assign(n, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      if (!sources[i].inside || (!pinned.empty() && pinned[i])) {
        continue;
      }
      Eigen::Vector3d offset = Eigen::Vector3d::Zero();
      if (!footprint.offset_at(sources[i].position, offset)) {
        continue;
      }
      const Eigen::Matrix3d t = differential.transport(sources[i].point, target_points[i],
                                                       sources[i].triangle, options.tangential);
      result.positions[i] += options.scale * (t * offset);
      result.covered[i] = 1;
    }
  });
  for (size_t i = 0; i < n; ++i) {
    if (!sources[i].inside) {
      ++result.without_source;
    }
    if (result.covered[i]) {
      ++result.covered_count;
    }
    result.max_displacement =
        std::max(result.max_displacement, (result.positions[i] - target_positions[i]).norm());
  }
  return result;
}

}  // namespace elastic
