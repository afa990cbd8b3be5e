#include "paste_preview.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "aim.h"
#include "elastic/image/image.h"
#include "elastic/metrics/heatmap.h"
#include "elastic/render/compose.h"
#include "elastic/render/render.h"

namespace elastic::cli {
namespace {

constexpr double kFill = 0.6;  // the region fills 60% of the picture: its surroundings show

RenderOptions render_options(const PreviewSettings& settings) {
  RenderOptions options;
  options.threads = settings.threads;
  return options;
}

SceneObject surface_object(PolygonMesh mesh) {
  SceneObject object;
  object.mesh = std::move(mesh);
  object.look.colors = SurfaceColoring::Plain;
  return object;
}

SceneObject grid_object(const ParticleGrid& grid, const Eigen::Matrix3Xd& positions) {
  SceneObject object;
  object.mesh = to_polygon_mesh(grid, positions);
  object.look.surface = false;
  object.look.wireframe = true;
  object.look.wire_width_px = 1.0;
  return object;
}

}  // namespace

Camera region_camera(const Region& region, int width, int height, const Eigen::Vector3d& up) {
  return aim_camera(region.positions, region_figures(region).normal, up, kFramingFov, width, height,
                    kFill);
}

PreviewWriter::PreviewWriter(const Region& target_region, PolygonMesh target_surface,
                             PolygonMesh target_outside, const PreviewSettings& settings)
    : camera_(region_camera(target_region, settings.width, settings.height, settings.up)),
      small_camera_(region_camera(target_region, std::max(64, settings.width / 2),
                                  std::max(64, settings.height / 2), settings.up)),
      surface_(std::move(target_surface)),
      outside_(std::move(target_outside)),
      settings_(settings) {}

std::filesystem::path PreviewWriter::write_feature(const std::filesystem::path& png,
                                                   const PolygonMesh& painted) const {
  SceneObject object;
  object.mesh = painted;
  object.look.textures = load_material_textures(painted).images;
  Scene scene;
  scene.objects.push_back(std::move(object));
  write_png(png, render(scene, camera_, render_options(settings_)));
  return png;
}

std::filesystem::path PreviewWriter::write_grids(
    const std::filesystem::path& png, const ParticleGrid& grid,
    const std::vector<const Eigen::Matrix3Xd*>& positions,
    const std::vector<std::string>& labels) const {
  std::vector<Image> pictures;
  for (const Eigen::Matrix3Xd* p : positions) {
    Scene scene;
    scene.objects.push_back(surface_object(surface_));
    scene.objects.push_back(grid_object(grid, *p));
    pictures.push_back(render(scene, camera_, render_options(settings_)));
  }
  write_png(png, side_by_side(pictures, labels));
  return png;
}

std::filesystem::path PreviewWriter::write_heatmaps(
    const std::filesystem::path& png, const std::vector<const Eigen::Matrix3Xd*>& positions,
    const std::vector<const MapMetrics*>& metrics, const std::vector<std::string>& labels,
    const HeatmapOptions& scale) const {
  std::vector<Image> pictures;
  HeatmapResult heat;
  for (size_t k = 0; k < positions.size(); ++k) {
    heat = make_heatmap(*positions[k], *metrics[k], scale);
    Scene scene;
    if (outside_.num_faces() > 0) scene.objects.push_back(surface_object(outside_));
    SceneObject object;
    object.mesh = heat.mesh;
    object.look.colors = SurfaceColoring::FaceColors;
    scene.objects.push_back(std::move(object));
    pictures.push_back(render(scene, camera_, render_options(settings_)));
  }
  const Image row = side_by_side(pictures, labels);
  // The key under the pictures: the metric's name, its range on the shared scale, the colours
  // outside the ramp.
  std::string title(to_string(scale.metric));
  std::replace(title.begin(), title.end(), '_', ' ');
  ColorLegend legend;
  legend.title = title;
  legend.low = heat.low;
  legend.high = heat.high;
  legend.ramp = heatmap_ramp_stops();
  legend.swatches = {{"fold", scale.fold_color}, {"outside", scale.excluded_color}};
  ComposeOptions compose;
  compose.gap = 0;
  compose.text_scale = std::max(1, settings_.width / 160);
  const Image key = draw_legend(legend, row.width, compose);
  write_png(png, stack({row, key}, compose));
  return png;
}

std::vector<std::filesystem::path> PreviewWriter::write_frames(
    const std::filesystem::path& dir, const ParticleGrid& grid,
    const std::vector<Eigen::Matrix3Xd>& frames, const std::vector<long>& iterations) const {
  std::filesystem::create_directories(dir);
  std::vector<std::filesystem::path> written;
  std::vector<Image> pictures;
  std::vector<std::string> labels;
  for (size_t k = 0; k < frames.size(); ++k) {
    Scene scene;
    scene.objects.push_back(surface_object(surface_));
    scene.objects.push_back(grid_object(grid, frames[k]));
    Image picture = render(scene, small_camera_, render_options(settings_));
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04zu.png", k + 1);
    write_png(dir / name, picture);
    written.push_back(dir / name);
    pictures.push_back(std::move(picture));
    labels.push_back(std::to_string(iterations[k]));
  }
  if (!pictures.empty()) {
    const int columns =
        static_cast<int>(std::ceil(std::sqrt(static_cast<double>(pictures.size()))));
    write_png(dir / "contact_sheet.png", contact_sheet(pictures, columns, labels));
    written.push_back(dir / "contact_sheet.png");
  }
  return written;
}

}  // namespace elastic::cli
