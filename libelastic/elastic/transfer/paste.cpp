#include "elastic/transfer/paste.h"

#include <chrono>
#include <string>
#include <utility>

#include "elastic/core/error.h"
#include "elastic/mesh/default_material.h"
#include "elastic/transfer/tangent_frames.h"
#include "elastic/transfer/target_samples.h"

namespace elastic {
namespace {

// Option checks before any work, naming the option.
void check_options(const PasteOptions& o) {
  const auto bad = [](const std::string& problem) { throw InvalidInputError("paste", problem); };
  if (!(o.alpha >= 0.0f && o.alpha <= 1.0f)) bad("alpha must be in [0, 1]");
  if (!(o.feather >= 0.0)) bad("feather must be >= 0 (texels)");
  if (!(o.max_edge >= 0.0)) bad("max_edge must be >= 0");
  if (o.texture_resolution < 0) bad("texture_resolution must be >= 0");
  if (o.height == PasteHeight::Image && o.height_image.empty()) {
    bad("a height image is asked for (PasteHeight::Image) and none is given");
  }
}

// The colour source the options ask for (nullopt for None, or Auto without colour).
std::optional<ColorSource> make_color_source(const PasteOptions& o, const LimitSurface& source) {
  const PolygonMesh& mesh = source.control_mesh();
  const bool texture_possible =
      mesh.has_texcoords() && (!o.texture.empty() || !first_diffuse_texture(mesh).empty());
  PasteColor kind = o.color;
  if (kind == PasteColor::Auto) {
    kind = texture_possible           ? PasteColor::Texture
           : mesh.has_vertex_colors() ? PasteColor::Vertex
                                      : PasteColor::None;
  }
  if (kind == PasteColor::Texture) return ColorSource::texture(source, o.texture, o.image_read);
  if (kind == PasteColor::Vertex) return ColorSource::vertex_colors(source);
  return std::nullopt;
}

// Step 1: the target tessellated at `resolution`, cut along the region, the region refined so
// that a source texel (or `max_edge`) is not averaged away.
PaintedSurface paint(const Region& source_region, const LimitSurface& target,
                     const Region& target_region, const MapResult& map, const PasteOptions& o) {
  PaintedSurfaceOptions options;
  options.resolution = o.resolution;
  options.name = target.name();
  TargetSamplingOptions& sampling = options.sampling;
  sampling.source_region = &source_region;
  sampling.source_particles = map.sampling.grid.source_positions();
  sampling.target_particles = map.relaxation.positions;
  sampling.max_edge = o.max_edge;
  sampling.max_levels = o.max_levels;
  sampling.max_vertices = o.max_vertices;
  sampling.min_vertices = o.min_vertices;
  if (o.texture_resolution > 0) {
    // About one source texel per refined edge: a texture of that size is not averaged away by
    // the per-vertex colours.
    sampling.max_source_edge =
        source_texel_length(source_region, o.texture_resolution, o.texture_resolution);
    if (sampling.max_source_edge == 0.0) {
      throw InvalidInputError(source_region.surface->name(),
                              "has no texture coordinates (texture_resolution)");
    }
  }
  return paint_surface(target, target_region, map.mapping, options);
}

// Step 3: the colour baked into a copy of the target's texture.
BakeResult bake(const PaintedSurface& painted, const LimitSurface& target,
                const ColorSource& colors, const std::filesystem::path& input,
                const PasteOptions& o) {
  BakeOptions options;
  options.alpha = o.alpha;
  options.feather = o.feather;
  options.name = input.string();
  return bake_texture(painted.samples, target, colors, read_image(input, o.image_read), options);
}

// Step 4: one height per region vertex, and the painted mesh displaced by them.
DisplacedPaintedSurface displace(const PaintedSurface& painted, const LimitSurface& source,
                                 const std::optional<ColorSource>& colors, const PasteOptions& o) {
  std::vector<double> heights;
  if (o.height == PasteHeight::Luminance) {
    if (!colors) throw InvalidInputError("height", "luminance needs a colour source");
    heights = sample_heights_from_colors(painted.samples, *colors, o.height_zero);
  } else {
    if (!source.control_mesh().has_texcoords()) {
      throw InvalidInputError(source.name(),
                              "has no texture coordinates to look up a height image");
    }
    HeightImageOptions image;
    image.zero_level = o.height_zero;
    heights = sample_heights_from_image(painted.samples, source,
                                        read_image(o.height_image, o.image_read), image);
  }
  DisplacementOptions options;
  options.scale = o.height_scale;
  options.falloff_width = o.falloff;
  return displace_painted_surface(painted, heights, options);
}

// Step 5: the detail mesh expressed over the source and carried through the map.
PasteDetailResult carry_detail(const SurfaceProjector& source, const LimitSurface& target,
                               const MapResult& map, const PasteOptions& o) {
  const DetailField field = extract_detail(source, *o.detail, {.name = o.detail_name});
  const MapDifferential differential(source.surface(), target, map);
  PasteDetailOptions options;
  options.scale = o.detail_scale;
  return paste_detail(field, map.mapping, differential, options);
}

}  // namespace

PasteColor parse_paste_color(std::string_view text, std::string_view input) {
  for (const auto& [name, kind] :
       {std::pair{"auto", PasteColor::Auto}, std::pair{"texture", PasteColor::Texture},
        std::pair{"vertex", PasteColor::Vertex}, std::pair{"none", PasteColor::None}}) {
    if (text == name) {
      return kind;
    }
  }
  throw InvalidInputError(std::string(input), "expected auto, texture, vertex or none, got '" +
                                                  std::string(text) + "'");
}

PasteResult paste(const SurfaceProjector& source, const Region& source_region,
                  const SurfaceProjector& target, const Region& target_region, const MapResult& map,
                  const PasteOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  check_options(options);
  const LimitSurface& source_surface = source.surface();
  const LimitSurface& target_surface = target.surface();
  PasteResult out;
  const auto step = [&](std::string_view stage) {
    out.cancelled = out.cancelled || !report_progress(options.progress, {.stage = stage});
    return !out.cancelled;
  };
  const auto finish = [&]() -> PasteResult {
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return std::move(out);
  };

  if (!step("paint")) return finish();
  out.colors = make_color_source(options, source_surface);
  out.painted = paint(source_region, target_surface, target_region, map, options);
  if (options.bake) {
    if (!out.colors) {
      throw InvalidInputError(source_surface.name(),
                              "has no colour to bake (no texture, no vertex colours)");
    }
    if (!step("bake")) return finish();
    out.bake_input = options.bake_texture.empty()
                         ? first_diffuse_texture(target_surface.control_mesh())
                         : options.bake_texture;
    out.baked = bake(out.painted, target_surface, *out.colors, out.bake_input, options);
  }
  if (options.height != PasteHeight::None) {
    if (!step("height")) return finish();
    out.displaced = displace(out.painted, source_surface, out.colors, options);
  }
  if (options.detail) {
    if (!step("detail")) return finish();
    out.detail = carry_detail(source, target_surface, map, options);
  }
  return finish();
}

std::vector<std::filesystem::path> write_paste(OutputFolder& folder, const PasteResult& pasted) {
  std::vector<std::filesystem::path> written;
  const auto add = [&](std::vector<std::filesystem::path> paths) {
    written.insert(written.end(), paths.begin(), paths.end());
  };
  if (pasted.colors) {
    if (pasted.colors->kind() == ColorSourceKind::Texture) {
      add(write_decal(folder, "painted.obj", pasted.painted, *pasted.colors));
    }
    written.push_back(
        folder.write_mesh("colors.ply", make_colored_mesh(pasted.painted, *pasted.colors)));
  }
  if (pasted.baked) {
    const std::filesystem::path image = folder.write_image("baked.png", pasted.baked->image);
    written.push_back(image);
    // The target with its own UVs and materials, the baked image in place of the input's.
    add(folder.write_obj("baked.obj", make_baked_mesh(pasted.painted, image, pasted.bake_input)));
  }
  if (pasted.displaced) {
    // The target's own UVs and materials (its texture copied in), on the displaced positions.
    add(folder.write_obj("displaced.obj",
                         make_target_mesh(pasted.painted, pasted.displaced->positions)));
  }
  if (pasted.detail) {
    add(folder.write_obj("detail.obj", pasted.detail->mesh));
  }
  return written;
}

}  // namespace elastic
