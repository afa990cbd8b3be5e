#include "elastic/transfer/painted_surface.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <map>
#include <optional>
#include <utility>

#include "elastic/core/error.h"
#include "elastic/image/image.h"
#include "elastic/mesh/default_material.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/regions/surface_partition.h"
#include "elastic/regions/texture_coordinates.h"
#include "elastic/surface/limit_tessellation.h"

namespace elastic {

namespace {

using SegmentPoints = std::map<std::pair<int, int>, std::vector<int>>;

// Vertices: every vertex of the cut tessellation, then the refinement's new vertices; each region
// vertex knows its sample and each sample its vertex.
void add_vertices(PaintedSurface& out, SurfacePartition& part) {
  const TargetSamples& s = out.samples;
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
}

// The new vertices on each coarse boundary segment (a -> b along the inside's loop), in order.
// The refinement keeps the coarse vertices (indices < coarse) on the loop, 2^levels - 1 new ones
// between consecutive ones, at equal steps in (u, v).
SegmentPoints boundary_segment_points(const PaintedSurface& out, int coarse) {
  const TargetSamples& s = out.samples;
  SegmentPoints segment_points;
  if (s.levels == 0 || s.boundary.empty()) {
    return segment_points;
  }
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
  return segment_points;
}

void add_triangle(PaintedSurface& out, const Eigen::Vector3i& t, int face,
                  const std::array<Eigen::Vector2d, 3>& uv, bool inside) {
  out.triangles.push_back(t);
  out.triangle_face.push_back(face);
  out.triangle_uv.push_back(uv);
  out.triangle_inside.push_back(inside ? 1 : 0);
}

// One outside triangle (corners c at (u, v) `uv` in ptex face `face`): as it is, or, when refined
// boundary points lie on its edges, fanned from its (u, v) centroid through them.
void add_outside_triangle(PaintedSurface& out, const LimitSurface& target,
                          const SegmentPoints& segment_points, const Eigen::Vector3i& c,
                          const std::array<Eigen::Vector2d, 3>& uv, int face) {
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
    add_triangle(out, c, face, uv, false);
    return;
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
    add_triangle(out, Eigen::Vector3i(poly[k], poly[l], ci), face, {poly_uv[k], poly_uv[l], centre},
                 false);
  }
}

}  // namespace

int auto_target_resolution(const LimitSurface& target) {
  const int nearest =
      tessellation_resolution(target, {.resolution = 1, .target_triangles = kAutoTargetTriangles});
  return std::min(nearest, kAutoTargetMaxResolution);
}

PaintedSurface paint_surface(const LimitSurface& target, const Region& target_region,
                             const Mapping& mapping, const PaintedSurfaceOptions& options) {
  if (options.resolution < 0 || options.resolution > 1024) {
    throw InvalidInputError(options.name, "resolution " + std::to_string(options.resolution) +
                                              " is outside 1..1024 (0: auto)");
  }
  TessellationOptions tess_options;
  tess_options.resolution =
      options.resolution == 0 ? auto_target_resolution(target) : options.resolution;
  const LimitTessellation tess = tessellate(target, tess_options);
  PartitionOptions part_options;
  part_options.snap = options.snap;
  part_options.name = options.name;
  SurfacePartition part = partition_surface(target, tess, target_region, part_options);

  PaintedSurface out;
  out.surface = &target;
  out.resolution = tess.resolution;
  TargetSamplingOptions sampling = options.sampling;
  sampling.name = options.name;
  out.samples = sample_target(part.inside, mapping, sampling);
  const TargetSamples& s = out.samples;
  const int coarse = part.inside.num_vertices();
  add_vertices(out, part);
  const SegmentPoints segment_points = boundary_segment_points(out, coarse);
  for (size_t t = 0; t < part.outside_triangles.size(); ++t) {
    add_outside_triangle(out, target, segment_points, part.outside_triangles[t], part.outside_uv[t],
                         part.outside_face[t]);
  }
  for (int t = 0; t < s.num_triangles(); ++t) {
    const Eigen::Vector3i& c = s.triangles[static_cast<size_t>(t)];
    add_triangle(out,
                 Eigen::Vector3i(out.sample_vertex_index[static_cast<size_t>(c[0])],
                                 out.sample_vertex_index[static_cast<size_t>(c[1])],
                                 out.sample_vertex_index[static_cast<size_t>(c[2])]),
                 s.triangle_face[static_cast<size_t>(t)], s.triangle_uv[static_cast<size_t>(t)],
                 true);
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

/// The target's texture coordinates at the corners of painted triangles, pooled: one entry per
/// distinct value at a vertex (exact comparison: corners of one vertex in the same chart get the
/// same value from the same control corners up to round-off, which may leave a few duplicates,
/// harmless), so UV seams stay seams and the pool is about the vertex count.
class TargetUvPool {
 public:
  TargetUvPool(const PaintedSurface& painted, PolygonMesh& mesh)
      : painted_(painted), mesh_(mesh), at_vertex_(painted.positions.size()) {}

  /// The pool index of corner k of triangle t.
  int corner(int t, int k) {
    const Eigen::Vector2d& st =
        painted_.triangle_uv[static_cast<size_t>(t)][static_cast<size_t>(k)];
    const SurfacePoint p{painted_.triangle_face[static_cast<size_t>(t)], st.x(), st.y()};
    const Eigen::Vector2d uv = texture_coordinate(*painted_.surface, p);
    const int v = painted_.triangles[static_cast<size_t>(t)][k];
    std::vector<int>& seen = at_vertex_[static_cast<size_t>(v)];
    for (const int i : seen) {
      if (mesh_.texcoords[static_cast<size_t>(i)] == uv) {
        return i;
      }
    }
    const int i = static_cast<int>(mesh_.texcoords.size());
    mesh_.texcoords.push_back(uv);
    seen.push_back(i);
    return i;
  }

 private:
  const PaintedSurface& painted_;
  PolygonMesh& mesh_;
  std::vector<std::vector<int>> at_vertex_;
};

/// The target material of painted triangle t (-1: none).
int target_material(const PaintedSurface& painted, int t) {
  const PolygonMesh& control = painted.surface->control_mesh();
  if (control.face_materials.empty()) {
    return -1;
  }
  const int face = painted.surface->control_face(painted.triangle_face[static_cast<size_t>(t)]);
  return control.face_materials[static_cast<size_t>(face)];
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
    // Outside faces need a corner index too (every corner has one or none does); they are on the
    // default material, which has no texture, so this coordinate indexes nothing.
    mesh.texcoords.emplace_back(0.0, 0.0);
  }
  const int sample_base = static_cast<int>(mesh.texcoords.size());
  mesh.texcoords.insert(mesh.texcoords.end(), source_uv.begin(), source_uv.end());

  TargetUvPool pool(painted, mesh);
  for (int t = 0; t < painted.num_triangles(); ++t) {
    const Eigen::Vector3i& c = painted.triangles[static_cast<size_t>(t)];
    add_triangle_face(mesh, c);
    if (painted.triangle_inside[static_cast<size_t>(t)]) {
      for (int k = 0; k < 3; ++k) {
        mesh.corner_texcoords.push_back(sample_base +
                                        painted.vertex_sample[static_cast<size_t>(c[k])]);
      }
      mesh.face_materials.push_back(decal_index);
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      mesh.corner_texcoords.push_back(target_uv ? pool.corner(t, k) : 0);
    }
    mesh.face_materials.push_back(target_material(painted, t));
  }
  assign_default_material(mesh);
  return mesh;
}

PolygonMesh make_target_mesh(const PaintedSurface& painted,
                             std::span<const Eigen::Vector3d> positions) {
  const LimitSurface& target = *painted.surface;
  const PolygonMesh& control = target.control_mesh();
  if (!positions.empty() && positions.size() != painted.positions.size()) {
    throw InvalidInputError(target.name(), std::to_string(positions.size()) + " positions for " +
                                               std::to_string(painted.positions.size()) +
                                               " vertices of the painted target");
  }
  PolygonMesh mesh;
  if (positions.empty()) {
    mesh.positions = painted.positions;
  } else {
    mesh.positions.assign(positions.begin(), positions.end());
  }
  mesh.materials = control.materials;
  const bool target_uv = control.has_texcoords();
  TargetUvPool pool(painted, mesh);
  for (int t = 0; t < painted.num_triangles(); ++t) {
    add_triangle_face(mesh, painted.triangles[static_cast<size_t>(t)]);
    if (target_uv) {
      for (int k = 0; k < 3; ++k) {
        mesh.corner_texcoords.push_back(pool.corner(t, k));
      }
    }
    mesh.face_materials.push_back(target_material(painted, t));
  }
  assign_default_material(mesh);
  return mesh;
}

namespace {
/// The colour the region's faces have without the decal when it is one flat colour (every region
/// triangle on untextured materials of one Kd, or on none: the default grey); nullopt otherwise.
std::optional<Eigen::Vector3f> flat_region_color(const PaintedSurface& painted) {
  const PolygonMesh& control = painted.surface->control_mesh();
  if (control.has_vertex_colors()) {
    return std::nullopt;
  }
  std::optional<Eigen::Vector3d> color;
  for (int t = 0; t < painted.num_triangles(); ++t) {
    if (!painted.triangle_inside[static_cast<size_t>(t)]) {
      continue;
    }
    const int m = target_material(painted, t);
    const Material material =
        m >= 0 ? control.materials[static_cast<size_t>(m)] : default_material();
    if (!material.diffuse_texture.empty() || (color && *color != material.diffuse)) {
      return std::nullopt;
    }
    color = material.diffuse;
  }
  if (!color) {
    return std::nullopt;
  }
  return color->cast<float>();
}
}  // namespace

std::vector<std::filesystem::path> write_decal(OutputFolder& folder, const std::string& name,
                                               const PaintedSurface& painted,
                                               const ColorSource& source,
                                               const std::string& material_name) {
  const std::filesystem::path obj_name(name);
  const std::size_t before = folder.files().size();
  // Viewers differ in what a texel's alpha means (some OBJ importers ignore it and show the
  // transparent texels' colour, often black). Over a flat target colour the blend is known: write
  // the decal composited over it, opaque. Over a textured target the blend needs the target's
  // texture (that is the bake), so the image keeps its alpha.
  Image image = source.image();
  if (const std::optional<Eigen::Vector3f> under = flat_region_color(painted)) {
    for (Eigen::Vector4f& texel : image.pixels) {
      const float a = std::clamp(texel.w(), 0.0f, 1.0f);
      texel.head<3>() = a * texel.head<3>() + (1.0f - a) * *under;
      texel.w() = 1.0f;
    }
  }
  const std::filesystem::path png =
      folder.write_image(obj_name.stem().string() + "_decal.png", image);
  DecalOptions options;
  options.material_name = material_name;
  options.texture_path = png;
  const std::vector<std::filesystem::path> written =
      folder.write_obj(obj_name.string(), make_decal_mesh(painted, source, options));
  // obj, mtl, png, then the textures copied in for this OBJ.
  std::vector<std::filesystem::path> out = written;
  out.push_back(png);
  for (std::size_t k = before; k < folder.files().size(); ++k) {
    const std::filesystem::path& f = folder.files()[k];
    if (std::find(out.begin(), out.end(), f) == out.end()) {
      out.push_back(f);
    }
  }
  return out;
}

std::vector<std::filesystem::path> write_decal(const std::filesystem::path& obj,
                                               const PaintedSurface& painted,
                                               const ColorSource& source,
                                               const std::string& material_name) {
  const std::filesystem::path dir = obj.has_parent_path() ? obj.parent_path() : ".";
  OutputFolder folder(dir);
  return write_decal(folder, obj.filename().string(), painted, source, material_name);
}

TargetColor::TargetColor(const LimitSurface& target, const Eigen::Vector3f& fallback)
    : target_(&target), fallback_(fallback) {
  const PolygonMesh& control = target.control_mesh();
  images_.resize(control.materials.size());
  if (control.has_vertex_colors() || !control.has_texcoords()) {
    return;
  }
  for (size_t m = 0; m < control.materials.size(); ++m) {
    const std::filesystem::path& file = control.materials[m].diffuse_texture;
    if (file.empty()) {
      continue;
    }
    try {
      images_[m] = read_image(file);
    } catch (const Error&) {
      images_[m] = Image();  // unreadable: the material's Kd (documented)
    }
  }
}

Eigen::Vector3f TargetColor::operator()(const SurfacePoint& p) const {
  const PolygonMesh& control = target_->control_mesh();
  if (control.has_vertex_colors()) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto& [vertex, weight] : control_vertex_weights(*target_, p)) {
      c += weight * control.vertex_colors[static_cast<size_t>(vertex)].cast<double>();
    }
    return c.cast<float>();
  }
  if (control.face_materials.empty()) {
    return fallback_;
  }
  const int m = control.face_materials[static_cast<size_t>(target_->control_face(p.face))];
  if (m < 0) {
    return fallback_;
  }
  Eigen::Vector3f kd = control.materials[static_cast<size_t>(m)].diffuse.cast<float>();
  const Image& image = images_[static_cast<size_t>(m)];
  if (image.empty()) {
    return kd;
  }
  const Eigen::Vector4f texel = sample(image, texture_coordinate(*target_, p), ImageWrap::Repeat);
  return texel.w() * texel.head<3>() + (1.0f - texel.w()) * kd;
}

PolygonMesh make_colored_mesh(const PaintedSurface& painted, const ColorSource& source,
                              const Eigen::Vector3f& fallback) {
  const LimitSurface& target = *painted.surface;
  PolygonMesh mesh;
  mesh.positions = painted.positions;
  for (const Eigen::Vector3i& t : painted.triangles) {
    add_triangle_face(mesh, t);
  }
  const TargetColor own(target, fallback);
  const std::vector<Eigen::Vector4f> inside = transfer_colors(painted.samples, source);
  mesh.vertex_colors.resize(mesh.positions.size(), fallback);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.positions.size()),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t v = r.begin(); v != r.end(); ++v) {
                        const Eigen::Vector3f base = own(painted.points[v]);
                        const int j = painted.vertex_sample[v];
                        if (j < 0) {
                          mesh.vertex_colors[v] = base;
                          continue;
                        }
                        // Straight alpha over the target: a transparent texel shows the target's
                        // own colour.
                        const Eigen::Vector4f& c = inside[static_cast<size_t>(j)];
                        const float a = std::clamp(c.w(), 0.0f, 1.0f);
                        mesh.vertex_colors[v] = a * c.head<3>() + (1.0f - a) * base;
                      }
                    });
  return mesh;
}

}  // namespace elastic
