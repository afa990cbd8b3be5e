// The whole job through the C++ API: paste the built-in emblem from a plane onto the belly of a
// vase, measure the map against LSCM on the same grid, write the textured decal (OBJ + MTL + PNG)
// and render a preview. Built and run by the test suite, quoted by docs/api.md.
#include <elastic/baselines/baseline_map.h>
#include <elastic/image/emblem.h>
#include <elastic/image/image.h>
#include <elastic/mapping/map_regions.h>
#include <elastic/metrics/map_metrics.h>
#include <elastic/regions/image_source.h>
#include <elastic/regions/region_spec.h>
#include <elastic/render/camera.h>
#include <elastic/render/render.h>
#include <elastic/shapes/procedural_shapes.h>
#include <elastic/transfer/painted_surface.h>

#include <cstdio>
#include <filesystem>
#include <utility>

int main() {
  using namespace elastic;
  const std::filesystem::path out =
      std::filesystem::temp_directory_path() / "elastic_example_paste";
  std::filesystem::create_directories(out);
  // [example]
  // 1. The source: an image on a plane (here the built-in emblem), its region the inscribed
  //    ellipse. The plane's texture coordinates index the image.
  write_png(out / "emblem.png", make_emblem(256));
  const ImagePlane image =
      make_image_plane(out / "emblem.png", {.shape = ImageRegionShape::Ellipse});
  const LimitSurface plane(image.mesh);
  const SurfaceProjector source(plane);
  const Region from = make_region(source, image.region);

  // 2. The target: a geodesic disk on the vase's belly.
  const LimitSurface vase(make_vase());
  const SurfaceProjector target(vase);
  const Region to = make_region(target, parse_region_spec("disk:0.55,0,0.45,0.45"));

  // 3. Map with least distortion.
  MapOptions options;
  options.sampling.layout.particles = 800;
  const MapResult result = map_regions(source, from, target, to, options);
  const ParticleGrid& grid = result.sampling.grid;

  // 4. Measure it, and LSCM composed through the plane on the same grid (docs/metrics.md).
  MapMetricsOptions measure;
  measure.rest_scale = result.rest_scale;
  measure.target_normals = surface_normals(vase, result.relaxation.points);
  const MapMetrics elastic = measure_map(grid, result.relaxation.positions, measure);
  const BaselineResult lscm = map_baseline(grid, source, from, target, to, {});
  measure.target_normals = surface_normals(vase, lscm.points, lscm.outside);
  measure.outside = lscm.outside;
  const MapMetrics baseline = measure_map(grid, lscm.positions, measure);
  std::printf(
      "%d particles; length energy %.4f (LSCM %.4f), symmetric Dirichlet %.4f (LSCM %.4f)\n",
      grid.num_particles(), elastic.length_energy, baseline.length_energy,
      elastic.symmetric_dirichlet, baseline.symmetric_dirichlet);

  // 5. Paint: the vase's limit surface with the region refined and textured by the emblem.
  PaintedSurfaceOptions paint;
  paint.sampling.source_region = &from;
  paint.sampling.max_levels = 2;
  const PaintedSurface painted = paint_surface(vase, to, result.mapping, paint);
  const ColorSource emblem = ColorSource::texture(plane, out / "emblem.png");
  for (const auto& file : write_decal(out / "vase.obj", painted, emblem)) {
    std::printf("wrote %s\n", file.string().c_str());
  }

  // 6. A preview, framed on the region and seen along its mean normal.
  SceneObject object;
  object.mesh = make_decal_mesh(painted, emblem, {.texture_path = out / "emblem.png"});
  object.look.colors = SurfaceColoring::Texture;
  object.look.textures = load_material_textures(object.mesh).images;  // one per material
  Scene scene;
  scene.objects.push_back(std::move(object));
  const Camera camera = frame_points(to.positions, Eigen::Vector3d(1, 0, 0.2), 35.0, 320, 320, 0.8);
  write_png(out / "preview.png", render(scene, camera));
  // [example]
  return elastic.folds == 0 && result.relaxation.converged ? 0 : 1;
}
