#pragma once
/// \file
/// The painted target: the whole target limit surface as one triangle mesh, the region refined for
/// transfer and the rest kept, and the mesh outputs built on it: the textured decal (OBJ + MTL +
/// PNG) and the per-vertex colour mesh (PLY).
///
/// Design: our target geometry is the limit surface, not the control mesh, so the output is the
/// target's limit tessellation (`resolution` segments per control edge, limit_tessellation.h) cut
/// exactly along the region's boundary curve (regions/surface_partition.h). Outside the region the
/// triangles keep the control mesh's texture coordinates interpolated at their corners
/// (regions/texture_coordinates.h) and their control face's material; inside, the re-cut region is
/// refined and mapped to the source by sample_target (target_samples.h). Both sides share the
/// boundary vertices; an outside triangle that borders a refined boundary segment is fanned from
/// its (u, v) centroid (a new limit point) through the segment's new vertices, so the mesh has no
/// T-junctions and is watertight wherever the target tessellation is.
///
/// Colour is carried per vertex of the refined inside: the source point of each vertex (its
/// `Mapping::Location`) gives the colour (ColorSource::color) and, for a texture, the texture
/// coordinate into the source image (ColorSource::texcoord). Between vertices both are linear over
/// the refined triangles: texture coordinates per corner (the decal, exact to the source image's
/// resolution as far as the map is linear over a refined triangle), colours per vertex (the PLY,
/// resolution = the refinement's).

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "elastic/image/image.h"
#include "elastic/mesh/polygon_mesh.h"
#include "elastic/transfer/color_source.h"
#include "elastic/transfer/output_folder.h"
#include "elastic/transfer/target_samples.h"

namespace elastic {

/// The default tessellation of the painted target outside the region, so that a paste's output
/// grows with the region and not with the target: the resolution (segments per control edge) whose
/// whole-target tessellation has about kAutoTargetTriangles triangles, at most
/// kAutoTargetMaxResolution (a coarse control mesh gets a smooth limit surface, a dense one such as
/// a 70,000-triangle scan stays at 1 or 2 instead of 64 triangles per face).
constexpr long kAutoTargetTriangles = 1L << 18;
constexpr int kAutoTargetMaxResolution = 8;
int auto_target_resolution(const LimitSurface& target);

struct PaintedSurfaceOptions {
  /// Target tessellation: segments per control edge (TessellationOptions::resolution), 1..1024;
  /// 0: auto_target_resolution().
  int resolution = 0;
  /// Refinement of the region and how its vertices find their source (target_samples.h). Its
  /// `source_region` should be set to the mapped source region.
  TargetSamplingOptions sampling;
  /// Snap of curve points when cutting the tessellation (PartitionOptions::snap).
  double snap = 1e-6;
  /// Name used in error messages.
  std::string name = "target";
};

struct PaintedSurface {
  const LimitSurface* surface = nullptr;  ///< the target (not owned)
  int resolution = 0;  ///< the target's tessellation outside the region (segments per control edge)
  /// The refined region with its vertices' source locations. Its vertex j is vertex
  /// `sample_vertex_index[j]` of this mesh.
  TargetSamples samples;
  std::vector<int> sample_vertex_index;  ///< #samples.V index into positions

  std::vector<Eigen::Vector3d> positions;  ///< #V limit positions (both sides)
  std::vector<SurfacePoint> points;        ///< #V target surface points
  std::vector<int> vertex_sample;  ///< #V index into samples' vertices, -1 outside the region
  std::vector<Eigen::Vector3i> triangles;  ///< #T counter-clockwise; outside ones first
  std::vector<int> triangle_face;          ///< #T ptex face of each triangle
  std::vector<std::array<Eigen::Vector2d, 3>> triangle_uv;  ///< #T corners' (u,v) in that face
  std::vector<char> triangle_inside;                        ///< #T 1 for region triangles

  int num_vertices() const { return static_cast<int>(positions.size()); }
  int num_triangles() const { return static_cast<int>(triangles.size()); }
};

/// Tessellates the target, cuts it along `target_region` (which must lie on `target` and be the
/// region `mapping` was built to), refines the inside and maps it back (sample_target).
/// \throws InvalidInputError / NumericalError from partition_surface and sample_target, naming
///         options.name.
PaintedSurface paint_surface(const LimitSurface& target, const Region& target_region,
                             const Mapping& mapping, const PaintedSurfaceOptions& options = {});

/// The source colour at every vertex of the refined region (ColorSource::color at
/// samples.sources[i].point; `missing` where a vertex has no source).
std::vector<Eigen::Vector4f> transfer_colors(const TargetSamples& samples,
                                             const ColorSource& source,
                                             const Eigen::Vector4f& missing = {1, 0, 1, 1});

struct DecalOptions {
  /// Name of the new material of the region's faces.
  std::string material_name = "decal";
  /// The image file the decal material's map_Kd names (written by write_decal; any path here is
  /// stored in the mesh as given).
  std::filesystem::path texture_path;
};

/// The decal mesh: positions of `painted`; outside faces with the target's interpolated texture
/// coordinates (the single coordinate (0,0) when the target has none) and their control face's
/// material (copied from the target), or the default material (mesh/default_material.h) when
/// that face has none, so no outside face ever shows the decal's texture;
/// region faces with the source's texture coordinates at their corners and a new material
/// `material_name` whose map_Kd is `texture_path`.
/// \throws InvalidInputError naming the source when `source` is not a Texture source.
PolygonMesh make_decal_mesh(const PaintedSurface& painted, const ColorSource& source,
                            const DecalOptions& options = {});

/// The target mesh of `painted` without the feature: every triangle with the target's own
/// texture coordinates (interpolated at its corners in its ptex face; one pool entry per distinct
/// value at a vertex, so UV seams stay seams) when the target has them, and its control face's
/// material or the default one. `positions` (#V, e.g. displaced ones) replace painted.positions
/// when given. Used for the displaced and the baked outputs, which keep the target's look.
/// \throws InvalidInputError naming the target when `positions` has the wrong size.
PolygonMesh make_target_mesh(const PaintedSurface& painted,
                             std::span<const Eigen::Vector3d> positions = {});

/// Writes the decal into `folder` (output_folder.h): `<name>.obj` + `.mtl`, the decal image
/// `<name>_decal.png` and copies of the target's own textures, all referenced by bare names.
/// Viewers differ in what a texel's alpha means (some OBJ importers ignore it), so when every
/// region face is on an untextured material of one Kd (or on none: the default grey) and the target
/// has no vertex colours, the decal image is composited over that colour and written opaque; on a
/// textured target it keeps its alpha (the blend with the target's texture is the bake).
/// Returns the written paths (obj, mtl, decal png, then any copied textures).
/// \throws IoError when a file cannot be read or written; InvalidInputError as make_decal_mesh.
std::vector<std::filesystem::path> write_decal(OutputFolder& folder, const std::string& name,
                                               const PaintedSurface& painted,
                                               const ColorSource& source,
                                               const std::string& material_name = "decal");

/// The same into the folder of `obj` ("<stem>_decal.png" beside it).
std::vector<std::filesystem::path> write_decal(const std::filesystem::path& obj,
                                               const PaintedSurface& painted,
                                               const ColorSource& source,
                                               const std::string& material_name = "decal");

/// The target's own colour at a point of it (no feature): its control mesh's vertex colours
/// interpolated (control_vertex_weights); else the texture of the point's control-face material
/// at its texture coordinate (bilinear, repeating; a texel's alpha blends it over the material's
/// Kd, as render/render.h draws it); else that material's Kd; else `fallback`. Texture files that
/// cannot be read are treated as absent (the material's Kd). Holds a reference to the surface;
/// owns the images; queries are const and thread-safe.
class TargetColor {
 public:
  explicit TargetColor(const LimitSurface& target,
                       const Eigen::Vector3f& fallback = {0.8f, 0.8f, 0.8f});
  Eigen::Vector3f operator()(const SurfacePoint& p) const;

 private:
  const LimitSurface* target_;
  Eigen::Vector3f fallback_;
  std::vector<Image> images_;  // one per control material (empty: none or unreadable)
};

/// The per-vertex colour mesh: region vertices (boundary included) carry the source colour
/// blended over the target's own colour (TargetColor) by the source's alpha,
/// rgb = alpha src + (1 - alpha) own, so a transparent texel shows the target; the others the
/// target's own colour. `fallback` (default: the default material's grey, 0.8) colours a target
/// without vertex colours, texture or material. Vertices without a source stay magenta.
PolygonMesh make_colored_mesh(const PaintedSurface& painted, const ColorSource& source,
                              const Eigen::Vector3f& fallback = {0.8f, 0.8f, 0.8f});

}  // namespace elastic
