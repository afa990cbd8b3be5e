#include "elastic/transfer/geometric_detail.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "elastic/core/error.h"

namespace elastic {

DetailField extract_detail(const SurfaceProjector& base, const PolygonMesh& detail,
                           const DetailOptions& options) {
  const int n = detail.num_vertices();
  if (n == 0) throw InvalidInputError(options.name, "the detail mesh has no vertices");
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
    if (closest[i].on_boundary) ++field.on_base_boundary;
  }
  return field;
}

PasteDetailResult paste_detail(const DetailField& field, const Mapping& mapping,
                               const MapDifferential& differential,
                               const PasteDetailOptions& options) {
  if (!std::isfinite(options.scale)) throw InvalidInputError(options.name, "scale is not finite");
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
      if (!image.inside) continue;
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
      if (in.has_texcoords())
        out.corner_texcoords.push_back(in.corner_texcoords[static_cast<size_t>(c)]);
    }
    out.face_offsets.push_back(static_cast<int>(out.face_vertices.size()));
    if (!in.face_materials.empty())
      out.face_materials.push_back(in.face_materials[static_cast<size_t>(f)]);
    if (in.has_face_colors()) out.face_colors.push_back(in.face_colors[static_cast<size_t>(f)]);
  }
  if (out.face_vertices.empty()) out.face_offsets.clear();
  return result;
}

}  // namespace elastic
