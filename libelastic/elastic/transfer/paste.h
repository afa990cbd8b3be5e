#pragma once
/// \file
/// The paste (the paper's application, Figs. 1, 8, 9): what `elastic paste` does after the map,
/// as one call. Given a map of a source region onto a target region (mapping/map_regions.h), it
///
// clang-format off
///   1. paints the target: its limit tessellation cut along the region, the region refined until
///      a source texel or `max_edge` is not averaged away (paint_surface, painted_surface.h);
///   2. picks the colour source: the source's texture, its vertex colours, or none (ColorSource);
///   3. with `bake`, paints the colour into the target's own texture (bake_texture, bake.h);
///   4. with a height, displaces the region along the target normals by a height image looked up
///      with the source's texture coordinates, or by the colour's luminance (displacement.h);
///   5. with a detail mesh, carries it onto the target (geometric_detail.h);
// clang-format on
///
/// and write_paste() writes the results into an output folder (output_folder.h) under the names
/// `elastic paste` uses. The command line and C++ callers (and Python, once bound) paste through
/// these two calls; the command adds only its flags, the distortion report and the previews.
///
///     const MapResult map = map_regions(source, from, target, to, map_options);
///     const PasteResult pasted = paste(source, from, target, to, map, {.height = ...});
///     OutputFolder folder(out);
///     write_paste(folder, pasted);

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "elastic/core/progress.h"
#include "elastic/image/image.h"
#include "elastic/mapping/map_regions.h"
#include "elastic/mesh/polygon_mesh.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/region.h"
#include "elastic/transfer/bake.h"
#include "elastic/transfer/color_source.h"
#include "elastic/transfer/displacement.h"
#include "elastic/transfer/geometric_detail.h"
#include "elastic/transfer/output_folder.h"
#include "elastic/transfer/painted_surface.h"

namespace elastic {

/// What colour a paste carries.
enum class PasteColor {
  Auto,     ///< the source's texture when it has texture coordinates and an image, else its
            ///< vertex colours when it has them, else none
  Texture,  ///< the source's texture (`PasteOptions::texture`, or its material's map_Kd)
  Vertex,   ///< the source's per-vertex colours
  None      ///< no colour (a height or detail paste)
};

/// Where a paste's heights come from.
enum class PasteHeight {
  None,       ///< no displacement
  Image,      ///< `PasteOptions::height_image`, looked up with the source's texture coordinates
  Luminance,  ///< the luminance of the pasted colour (needs a colour source)
};

struct PasteOptions {
  /// The colour to carry.
  PasteColor color = PasteColor::Auto;
  /// The source's texture image (empty: the first material texture, map_Kd, of its mesh).
  std::filesystem::path texture;
  /// Limits for every image the paste reads (texture, bake texture, height image).
  ImageReadOptions image_read;

  /// The painted target outside the region: segments per control edge (1..1024); 0: about
  /// kAutoTargetTriangles triangles for the whole target, at most 8 per edge
  /// (auto_target_resolution in painted_surface.h).
  int resolution = 0;
  /// Refine the region until every target edge is at most this long (0: off).
  double max_edge = 0.0;
  /// Refine the region to about one source texel of an N x N texture (0: off): source edges of at
  /// most source_texel_length(source region, N, N).
  int texture_resolution = 0;
  /// Most refinement levels of the region.
  int max_levels = 8;
  /// Refine the region at least until it has this many vertices (a smooth colour PLY).
  long min_vertices = 100'000;
  /// Most region vertices after refinement.
  long max_vertices = 2'000'000;

  /// Bake the colour into the target's own texture (needs a colour and target texture
  /// coordinates).
  bool bake = false;
  /// The texture to bake into (empty: the target's first material texture, map_Kd). Never
  /// modified: the bake is a new image.
  std::filesystem::path bake_texture;
  /// Opacity of the baked colour, in [0, 1].
  float alpha = 1.0f;
  /// Feathered edge of the bake, in texels (0: a hard edge).
  double feather = 0.0;

  /// Where heights come from (none: no displacement).
  PasteHeight height = PasteHeight::None;
  /// The height image (PasteHeight::Image).
  std::filesystem::path height_image;
  /// The image value or luminance that means height 0.
  double height_zero = 0.0;
  /// Height units -> target length units.
  double height_scale = 0.1;
  /// The displacement ramps up from 0 on the region's boundary over this distance (0: no ramp).
  double falloff = 0.0;

  /// A detail mesh over the source surface to carry onto the target (null: none). Not owned.
  const PolygonMesh* detail = nullptr;
  /// The detail mesh's name in error messages (usually its file).
  std::string detail_name = "detail";
  /// Multiplies the detail's offsets.
  double detail_scale = 1.0;

  /// Called between the steps (stages "paint", "bake", "height", "detail"); returning false
  /// cancels (the result then says `cancelled`, with the steps done so far).
  ProgressCallback progress;
};

struct PasteResult {
  /// The painted target: its tessellation with the region refined, each region vertex with its
  /// source location (PaintedSurface::samples).
  PaintedSurface painted;
  /// The colour carried (empty: none).
  std::optional<ColorSource> colors;
  /// With `bake`: the target's texture with the region painted, and the image it was baked into.
  std::optional<BakeResult> baked;
  std::filesystem::path bake_input;
  /// With a height: the painted mesh with the region displaced.
  std::optional<DisplacedPaintedSurface> displaced;
  /// With a detail mesh: the detail on the target.
  std::optional<PasteDetailResult> detail;
  bool cancelled = false;  ///< the progress callback asked to stop
  double seconds = 0.0;    ///< the whole paste
};

/// Pastes from `source_region` (on `source`) onto `target_region` (on `target`) through `map`,
/// the map_regions result of these projectors and regions (which must outlive the result: its
/// colour source references the source surface, its painted surface the target).
/// \throws InvalidInputError when an option is out of range, a colour, texture or texture
///         coordinates the options ask for are missing (naming the surface), or a bake has no
///         colour; IoError / InvalidInputError from reading images; NumericalError from the steps.
/// "auto", "texture", "vertex" or "none" (the CLI's --color). \throws InvalidInputError naming
/// `input` for anything else.
PasteColor parse_paste_color(std::string_view text, std::string_view input = "color");

PasteResult paste(const SurfaceProjector& source, const Region& source_region,
                  const SurfaceProjector& target, const Region& target_region, const MapResult& map,
                  const PasteOptions& options = {});

/// Writes what `pasted` holds into `folder`, in this order: the textured decal `painted.obj`
/// (+ .mtl, painted_decal.png; a texture colour only), the per-vertex colour mesh `colors.ply`,
/// `baked.png` and `baked.obj` (the target showing it), `displaced.obj` (the target's own look on
/// the displaced positions), `detail.obj`. Returns the written paths (OutputFolder::files() has
/// them too, with the copied textures).
/// \throws IoError when a file cannot be written; InvalidInputError from the mesh builders.
std::vector<std::filesystem::path> write_paste(OutputFolder& folder, const PasteResult& pasted);

}  // namespace elastic
