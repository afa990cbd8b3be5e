#pragma once
// Pictures of a paste (`elastic paste --preview`): the target with the pasted feature, the particle
// grid over the target (naive and relaxed, side by side: the paper's Figs. 6 and 9), distortion
// heatmaps (ElasticPaint beside a baseline), and the relaxation as numbered frames with a contact
// sheet. The camera frames the target region with some of the model around it (aim.h), seen along
// its mean normal raised towards the up axis, with the picture's up along that axis.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"
#include "elastic/metrics/heatmap.h"
#include "elastic/metrics/map_metrics.h"
#include "elastic/particles/particle_grid.h"
#include "elastic/regions/region.h"
#include "elastic/render/camera.h"

namespace elastic::cli {

struct PreviewSettings {
  int width = 800;   ///< pixels
  int height = 800;  ///< pixels
  int threads = 0;   ///< render threads (0: all); the pictures do not depend on it
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< the model's up (--up, or guessed)
};

/// The camera for every picture of a paste: aim_camera (aim.h) on the region's vertices, which
/// fill 60% of the picture (the rest shows the model around them), seen along the region's mean
/// normal raised towards `up`.
Camera region_camera(const Region& region, int width, int height, const Eigen::Vector3d& up);

class PreviewWriter {
 public:
  /// `target_surface`: the whole target (under the grids); `target_outside`: the target without
  /// the region (around the heatmaps, which lie slightly under the smooth surface).
  PreviewWriter(const Region& target_region, PolygonMesh target_surface, PolygonMesh target_outside,
                const PreviewSettings& settings);

  /// The target with the feature: `painted` (a decal OBJ's mesh with materials, or a vertex-colour
  /// mesh); material textures are read from the mesh's map_Kd paths.
  std::filesystem::path write_feature(const std::filesystem::path& png,
                                      const PolygonMesh& painted) const;
  /// Grids over the target surface, one picture per entry, side by side with the labels.
  std::filesystem::path write_grids(const std::filesystem::path& png, const ParticleGrid& grid,
                                    const std::vector<const Eigen::Matrix3Xd*>& positions,
                                    const std::vector<std::string>& labels) const;
  /// Heatmaps of one per-triangle metric, one per method, side by side on the colour scale
  /// `scale` (shared_heatmap_scale of metrics/heatmap.h: perfect = green up to the largest of the
  /// methods' 95th percentiles = red), with a legend bar (the metric, its numbers, the fold and
  /// outside colours) under them.
  std::filesystem::path write_heatmaps(const std::filesystem::path& png,
                                       const std::vector<const Eigen::Matrix3Xd*>& positions,
                                       const std::vector<const MapMetrics*>& metrics,
                                       const std::vector<std::string>& labels,
                                       const HeatmapOptions& scale) const;
  /// Frames of the relaxation: frames/frame_0001.png ... and a labelled contact sheet.
  std::vector<std::filesystem::path> write_frames(const std::filesystem::path& dir,
                                                  const ParticleGrid& grid,
                                                  const std::vector<Eigen::Matrix3Xd>& frames,
                                                  const std::vector<long>& iterations) const;

 private:
  Camera camera_;
  Camera small_camera_;
  PolygonMesh surface_;
  PolygonMesh outside_;
  PreviewSettings settings_;
};

}  // namespace elastic::cli
