// The paste entry point (transfer/paste.h): map the built-in emblem onto a cap, then paste its
// colour and, as a relief, its luminance, and write the files `elastic paste` writes. Built and run
// by the test suite, quoted by docs/api.md.
#include <elastic/image/emblem.h>
#include <elastic/image/image.h>
#include <elastic/mapping/map_regions.h>
#include <elastic/regions/image_source.h>
#include <elastic/regions/region_spec.h>
#include <elastic/shapes/procedural_shapes.h>
#include <elastic/transfer/output_folder.h>
#include <elastic/transfer/paste.h>

#include <cstdio>
#include <filesystem>

int main() {
  using namespace elastic;
  const std::filesystem::path out =
      std::filesystem::temp_directory_path() / "elastic_example_relief";
  std::filesystem::create_directories(out);
  // [example]
  // The map: the emblem on its plane onto a geodesic disk of a cap.
  write_png(out / "emblem.png", make_emblem(128));
  const ImagePlane image =
      make_image_plane(out / "emblem.png", {.shape = ImageRegionShape::Ellipse});
  const LimitSurface plane(image.mesh);
  const SurfaceProjector source(plane);
  const Region from = make_region(source, image.region);
  const LimitSurface cap(make_cap());
  const SurfaceProjector target(cap);
  const Region to = make_region(target, parse_region_spec("boundary"));
  MapOptions map_options;
  map_options.sampling.layout.particles = 300;
  const MapResult map = map_regions(source, from, target, to, map_options);

  // The paste: the emblem's colour, and its luminance as a relief 0.05 deep.
  PasteOptions options;
  options.min_vertices = 5'000;
  options.height = PasteHeight::Luminance;
  options.height_scale = 0.05;
  const PasteResult pasted = paste(source, from, target, to, map, options);
  std::printf("%d region vertices, relief up to %.4f\n", pasted.painted.samples.num_vertices(),
              pasted.displaced->displacement.max_displacement);

  // The files `elastic paste` writes: painted.obj (+ .mtl, decal), colors.ply, displaced.obj.
  OutputFolder folder(out / "pasted");
  for (const auto& file : write_paste(folder, pasted)) {
    std::printf("wrote %s\n", file.string().c_str());
  }
  // [example]
  return pasted.displaced && pasted.displaced->displacement.max_displacement > 0.0 ? 0 : 1;
}
