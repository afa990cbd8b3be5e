#include "elastic/transfer/painted_surface.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <map>
#include <utility>

#include "elastic/core/error.h"
#include "elastic/image/image.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/regions/surface_partition.h"
#include "elastic/regions/texture_coordinates.h"
#include "elastic/surface/limit_tessellation.h"

namespace elastic {

PaintedSurface paint_surface(const LimitSurface& target, const Region& target_region,
                             const Mapping& mapping, const PaintedSurfaceOptions& options) {
  if (options.resolution < 1 || options.resolution > 1024) {
    throw InvalidInputError(
        options.name, "resolution " + std::to_string(options.resolution) + " is outside 1..1024");
  }
  TessellationOptions tess_options;
  tess_options.resolution = options.resolution;
  const LimitTessellation tess = tessellate(target, tess_options);
  PartitionOptions part_options;
  part_options.snap = options.snap;
  part_options.name = options.name;
  SurfacePartition part = partition_surface(target, tess, target_region, part_options);

  PaintedSurface out;
  out.surface = &target;
  TargetSamplingOptions sampling = options.sampling;
  sampling.name = options.name;
  out.samples = sample_target(part.inside, mapping, sampling);
  const TargetSamples& s = out.samples;

  // Vertices: every vertex of the cut tessellation, then the refinement's new vertices.
  out.positions = std::move(part.positions);
  out.points = std::move(part.points);
  out.vertex_sample.assign(out.positions.size(), -1);
  const int coarse = part.inside.num_vertices();
  out.sample_vertex_index.resize(static_cast<size_t>(s.num_vertices()));
  for (int j = 0; j < s.num_vertices(); ++j) {
    int g;
    if (j < coarse) {
      g = part.inside_vertices[static_cast<size_t>(j)];
    } else {
      g = static_cast<int>(out.positions.size());
      out.positions.push_back(s.positions[static_cast<size_t>(j)]);
      out.points.push_back(s.points[static_cast<size_t>(j)]);
      out.vertex_sample.push_back(-1);
    }
    out.sample_vertex_index[static_cast<size_t>(j)] = g;
    out.vertex_sample[static_cast<size_t>(g)] = j;
  }

  // The new vertices on each coarse boundary segment (a -> b along the inside's loop), in order.
  // The refinement keeps the coarse vertices (indices < coarse) on the loop, 2^levels - 1 new ones
  // between consecutive ones, at equal steps in (u, v).
  std::map<std::pair<int, int>, std::vector<int>> segment_points;
  if (s.levels > 0 && !s.boundary.empty()) {
    const size_t n = s.boundary.size();
    size_t first = 0;
    while (first < n && s.boundary[first] >= coarse) {
      ++first;
    }
    for (size_t k = 0; k < n && first < n; ++k) {
      const size_t i = (first + k) % n;
      if (s.boundary[i] >= coarse) {
        continue;
      }
      std::vector<int> between;
      size_t j = (i + 1) % n;
      while (s.boundary[j] >= coarse) {
        between.push_back(out.sample_vertex_index[static_cast<size_t>(s.boundary[j])]);
        j = (j + 1) % n;
      }
      const int a = out.sample_vertex_index[static_cast<size_t>(s.boundary[i])];
      const int b = out.sample_vertex_index[static_cast<size_t>(s.boundary[j])];
      if (!between.empty()) {
        segment_points[{a, b}] = std::move(between);
      }
    }
  }

  auto add = [&](const Eigen::Vector3i& t, int face, const std::array<Eigen::Vector2d, 3>& uv,
                 bool inside) {
    out.triangles.push_back(t);
    out.triangle_face.push_back(face);
    out.triangle_uv.push_back(uv);
    out.triangle_inside.push_back(inside ? 1 : 0);
  };
  for (size_t t = 0; t < part.outside_triangles.size(); ++t) {
    const Eigen::Vector3i& c = part.outside_triangles[t];
    const auto& uv = part.outside_uv[t];
    const int face = part.outside_face[t];
    // The polygon of the triangle with the refined boundary points on its edges. Edge (p, q) of an
    // outside triangle borders the region when (q, p) is a boundary segment of the inside.
    std::vector<int> poly;
    std::vector<Eigen::Vector2d> poly_uv;
    for (int k = 0; k < 3; ++k) {
      const int p = c[k], q = c[(k + 1) % 3];
      const Eigen::Vector2d& up = uv[static_cast<size_t>(k)];
      const Eigen::Vector2d& uq = uv[static_cast<size_t>((k + 1) % 3)];
      poly.push_back(p);
      poly_uv.push_back(up);
      const auto it = segment_points.find({q, p});
      if (it == segment_points.end()) {
        continue;
      }
      // Listed from q to p; the m-th from p is at fraction (m + 1) / (count + 1) of p -> q, since
      // the splits are at equal (u, v) steps and ptex faces meet by affine maps along edges.
      const std::vector<int>& between = it->second;
      const int count = static_cast<int>(between.size());
      for (int m = 0; m < count; ++m) {
        const double f = static_cast<double>(m + 1) / (count + 1);
        poly.push_back(between[static_cast<size_t>(count - 1 - m)]);
        poly_uv.push_back((1.0 - f) * up + f * uq);
      }
    }
    if (poly.size() == 3) {
      add(c, face, uv, false);
      continue;
    }
    // Fan from the (u, v) centroid: the polygon is the triangle with extra points on its edges, so
    // it is star-shaped from there and every fan triangle keeps the orientation.
    const Eigen::Vector2d centre = (uv[0] + uv[1] + uv[2]) / 3.0;
    const SurfacePoint cp{face, centre.x(), centre.y()};
    const int ci = static_cast<int>(out.positions.size());
    out.positions.push_back(target.position(cp));
    out.points.push_back(cp);
    out.vertex_sample.push_back(-1);
    for (size_t k = 0; k < poly.size(); ++k) {
      const size_t l = (k + 1) % poly.size();
      add(Eigen::Vector3i(poly[k], poly[l], ci), face, {poly_uv[k], poly_uv[l], centre}, false);
    }
  }
  for (int t = 0; t < s.num_triangles(); ++t) {
    const Eigen::Vector3i& c = s.triangles[static_cast<size_t>(t)];
    add(Eigen::Vector3i(out.sample_vertex_index[static_cast<size_t>(c[0])],
                        out.sample_vertex_index[static_cast<size_t>(c[1])],
                        out.sample_vertex_index[static_cast<size_t>(c[2])]),
        s.triangle_face[static_cast<size_t>(t)], s.triangle_uv[static_cast<size_t>(t)], true);
  }
  return out;
}

std::vector<Eigen::Vector4f> transfer_colors(const TargetSamples& samples,
                                             const ColorSource& source,
                                             const Eigen::Vector4f& missing) {
  std::vector<Eigen::Vector4f> colors(samples.sources.size(), missing);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, colors.size()),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        if (samples.sources[i].inside) {
                          colors[i] = source.color(samples.sources[i].point);
                        }
                      }
                    });
  return colors;
}

namespace {
void add_triangle_face(PolygonMesh& mesh, const Eigen::Vector3i& t) {
  mesh.add_face({t[0], t[1], t[2]});
}
}  // namespace

PolygonMesh make_decal_mesh(const PaintedSurface& painted, const ColorSource& source,
                            const DecalOptions& options) {
  if (source.kind() != ColorSourceKind::Texture) {
    throw InvalidInputError(source.surface().name(),
                            "a decal needs a texture source (a mesh with UVs and an image)");
  }
  const LimitSurface& target = *painted.surface;
  const PolygonMesh& control = target.control_mesh();
  PolygonMesh mesh;
  mesh.positions = painted.positions;
  mesh.materials = control.materials;
  Material decal;
  decal.name = options.material_name;
  decal.diffuse = Eigen::Vector3d::Ones();
  decal.diffuse_texture = options.texture_path;
  const int decal_index = static_cast<int>(mesh.materials.size());
  mesh.materials.push_back(decal);

  // Source texture coordinates of the refined region's vertices, one pool entry each.
  const TargetSamples& s = painted.samples;
  std::vector<Eigen::Vector2d> source_uv(s.sources.size(), Eigen::Vector2d::Zero());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, source_uv.size()),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        if (s.sources[i].inside) {
                          source_uv[i] = source.texcoord(s.sources[i].point);
                        }
                      }
                    });
  const bool target_uv = control.has_texcoords();
  if (!target_uv) {
    mesh.texcoords.emplace_back(0.0, 0.0);
  }
  const int sample_base = static_cast<int>(mesh.texcoords.size());
  mesh.texcoords.insert(mesh.texcoords.end(), source_uv.begin(), source_uv.end());

  for (int t = 0; t < painted.num_triangles(); ++t) {
    const Eigen::Vector3i& c = painted.triangles[static_cast<size_t>(t)];
    add_triangle_face(mesh, c);
    const int face = painted.triangle_face[static_cast<size_t>(t)];
    if (painted.triangle_inside[static_cast<size_t>(t)]) {
      for (int k = 0; k < 3; ++k) {
        mesh.corner_texcoords.push_back(sample_base +
                                        painted.vertex_sample[static_cast<size_t>(c[k])]);
      }
      mesh.face_materials.push_back(decal_index);
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      if (target_uv) {
        const Eigen::Vector2d& uv =
            painted.triangle_uv[static_cast<size_t>(t)][static_cast<size_t>(k)];
        mesh.corner_texcoords.push_back(static_cast<int>(mesh.texcoords.size()));
        mesh.texcoords.push_back(texture_coordinate(target, SurfacePoint{face, uv.x(), uv.y()}));
      } else {
        mesh.corner_texcoords.push_back(0);
      }
    }
    const int control_face = target.control_face(face);
    mesh.face_materials.push_back(control.face_materials.empty()
                                      ? -1
                                      : control.face_materials[static_cast<size_t>(control_face)]);
  }
  return mesh;
}

std::vector<std::filesystem::path> write_decal(const std::filesystem::path& obj,
                                               const PaintedSurface& painted,
                                               const ColorSource& source,
                                               const std::string& material_name) {
  std::filesystem::path png = obj;
  png.replace_filename(obj.stem().string() + "_decal.png");
  std::filesystem::path mtl = obj;
  mtl.replace_extension(".mtl");
  DecalOptions options;
  options.material_name = material_name;
  options.texture_path = png;
  const PolygonMesh mesh = make_decal_mesh(painted, source, options);
  write_png(png, source.image());
  write_mesh(obj, mesh);
  return {obj, mtl, png};
}

PolygonMesh make_colored_mesh(const PaintedSurface& painted, const ColorSource& source,
                              const Eigen::Vector3f& outside) {
  const LimitSurface& target = *painted.surface;
  const PolygonMesh& control = target.control_mesh();
  PolygonMesh mesh;
  mesh.positions = painted.positions;
  for (const Eigen::Vector3i& t : painted.triangles) {
    add_triangle_face(mesh, t);
  }
  const std::vector<Eigen::Vector4f> inside = transfer_colors(painted.samples, source);
  mesh.vertex_colors.resize(mesh.positions.size(), outside);
  for (int v = 0; v < painted.num_vertices(); ++v) {
    const int j = painted.vertex_sample[static_cast<size_t>(v)];
    if (j >= 0) {
      mesh.vertex_colors[static_cast<size_t>(v)] = inside[static_cast<size_t>(j)].head<3>();
    } else if (control.has_vertex_colors()) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (const auto& [vertex, weight] :
           control_vertex_weights(target, painted.points[static_cast<size_t>(v)])) {
        c += weight * control.vertex_colors[static_cast<size_t>(vertex)].cast<double>();
      }
      mesh.vertex_colors[static_cast<size_t>(v)] = c.cast<float>();
    }
  }
  return mesh;
}

}  // namespace elastic
