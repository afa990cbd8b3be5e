#pragma once
/// \file
/// Baking the transferred colour into the target's own texture.
///
/// The target has texture coordinates (its control mesh's, spread over the limit surface by
/// regions/texture_coordinates.h) and an image. Every refined region triangle (target_samples.h)
/// is rasterised in the target's texture space: a texel whose centre (u = (x + 0.5) / W,
/// v = 1 - (y + 0.5) / H, image/image.h) lies in the triangle (closed, so texels on shared edges
/// are not missed) takes the source colour at its barycentric position: for a texture source the
/// corners' source texture coordinates are interpolated and the source image is sampled there (so
/// a source texture is resampled per texel, not per vertex); for vertex colours or scalars the
/// corners' colours are interpolated. Each triangle's corners get target texture coordinates in
/// its own ptex face, so a region across a UV seam paints every island it covers.
///
/// Blending: out.rgb = (1 - w) in.rgb + w src.rgb with w = alpha * src.alpha * ramp, where ramp
/// rises linearly from 0 on the region's boundary to 1 at `feather` texels inside (distance in
/// texels to the nearest boundary segment in texture space; ramp = 1 when feather is 0). The alpha
/// channel of the target image is kept. Texels whose centre is outside every region triangle are
/// copied unchanged: the input image is never modified (the result is a new image).

#include <Eigen/Core>
#include <filesystem>
#include <string>

#include "elastic/image/image.h"
#include "elastic/transfer/color_source.h"
#include "elastic/transfer/painted_surface.h"
#include "elastic/transfer/target_samples.h"

namespace elastic {

struct BakeOptions {
  /// Opacity of the pasted colour, in [0, 1].
  float alpha = 1.0f;
  /// Width of the feathered edge in texels (0: a hard edge). >= 0.
  double feather = 0.0;
  /// Name used in error messages.
  std::string name = "bake";
};

struct BakeResult {
  Image image;              ///< the target image with the region painted
  long texels_painted = 0;  ///< texels with a centre inside the region
  long texels_changed = 0;  ///< of those, texels whose value changed
};

/// Paints the region (`samples`, on `target`) into a copy of `target_image`.
/// \throws InvalidInputError naming options.name when the target has no texture coordinates, the
///         image is empty, or alpha / feather are out of range.
BakeResult bake_texture(const TargetSamples& samples, const LimitSurface& target,
                        const ColorSource& source, const Image& target_image,
                        const BakeOptions& options = {});

/// The mesh that shows a bake: the painted target (make_target_mesh: its tessellation with the
/// target's own texture coordinates and materials), where every material whose map_Kd is
/// `input_texture` (the image that was baked into) now names `baked_texture`. When no material
/// names it (a texture of its own, e.g. `paste --bake-texture`), every face gets one material
/// "baked" (Kd 1, map_Kd `baked_texture`). Write it with OutputFolder::write_obj.
/// \throws InvalidInputError naming the target when it has no texture coordinates.
PolygonMesh make_baked_mesh(const PaintedSurface& painted,
                            const std::filesystem::path& baked_texture,
                            const std::filesystem::path& input_texture);

}  // namespace elastic
