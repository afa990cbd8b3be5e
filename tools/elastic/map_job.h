#pragma once
// The job shared by `elastic map`, `paste` and `compare`: the flags that choose the source and the
// target regions and how the map is computed, loading the inputs, running map_regions, and the
// JSON report of `elastic map` (docs/getting-started.md lists its keys).
//
//   auto job = std::make_shared<MapJob>();
//   add_map_flags(sub, *job);                       // in the ELASTIC_COMMAND setup
//   ...
//   const std::unique_ptr<MapSession> s = run_map_job(*job);   // in the run function
//   nlohmann::json report = map_report(*job, *s, job_of(sub));

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "cli_common.h"
#include "elastic/mapping/map_decal.h"
#include "elastic/mapping/map_regions.h"
#include "elastic/metrics/map_metrics.h"
#include "elastic/regions/image_source.h"
#include "elastic/regions/region.h"

namespace elastic::cli {

struct MapJob {
  std::string source;                      ///< --source MESH
  std::string source_image;                ///< --source-image IMAGE (a plane carrying the image)
  double image_width = 2.0;                ///< --image-width: physical width of the image's plane
  std::string source_region = "boundary";  ///< --source-region SPEC
  std::string source_anchor;               ///< --source-anchor X,Y,Z
  std::string target;                      ///< --target MESH (required)
  std::string target_region = "boundary";  ///< --target-region SPEC
  std::string target_anchor;               ///< --target-anchor X,Y,Z
  /// --target-place X,Y,Z[,ANGLE_DEG[,SCALE]]: a decal with a free boundary instead of a drawn
  /// target region (mapping/map_decal.h)
  std::string target_place;
  long particles = 1000;                     ///< --particles N
  std::string solver = "lbfgs";              ///< --solver lbfgs|explicit
  std::string preconditioner = "multigrid";  ///< --preconditioner multigrid|direct (lbfgs)
  std::string newton = "auto";               ///< --newton auto|on|off (lbfgs)
  std::string rest_scale = "auto";           ///< --rest-scale auto|boundary|area|none
  std::string energy = "robust";             ///< --energy robust|paper
  std::string angular_stiffness = "auto";    ///< --angular-stiffness auto|C_a / C
  double distortion_weight = 0.0;            ///< --distortion-weight lambda / C (robust energy)
  std::string distortion_guard = "on";       ///< --distortion-guard on|off
  std::string boundary_offset = "auto";      ///< --boundary-offset auto|anchor
  std::string boundary = "auto";             ///< --boundary auto|fixed|slide
  std::string scheme = "auto";               ///< --scheme auto|loop|catmull-clark
  int subdivide = 0;                         ///< --subdivide K: refinement levels after the map
  /// --coarse-start N: grids of more than N particles start from a coarser grid's map (0: never)
  long coarse_start = MapOptions{}.coarse_start_above;
  /// --coarse-hold N: such a grid above N particles holds its sliding boundary where the coarse
  /// map slid it
  long coarse_hold = MapOptions{}.coarse_hold_above;
  int threads = 0;      ///< --threads N (0: all)
  double jitter = 0.0;  ///< --jitter F: random start of the sampling
  /// --curvature-radius S: the sampling's curvature averaged over S grid spacings (0: pointwise)
  double curvature_radius = AdaptiveSamplingOptions{}.curvature_radius;
  unsigned long seed = 0;   ///< --seed S: seed of the --jitter
  long max_iterations = 0;  ///< --max-iterations (0: the solver's default)
  std::string report;       ///< --report FILE
  bool quiet = false;       ///< --quiet

  /// --max-memory MB: the most memory the run may be estimated to need (0: the default,
  /// default_max_memory_mb()).
  long long max_memory_mb = 0;
  /// Memory a command needs beyond the map (a paste's painted mesh): fixed bytes, and bytes per
  /// face of the target's control mesh; checked with the map's estimate before any surface is
  /// built (the per-face part as soon as the target's control mesh is read, before the source).
  double extra_bytes = 0.0;
  double extra_bytes_per_target_face = 0.0;
  std::string extra_what;  ///< what the extra is, for the message (e.g. "--resolution 8")

  /// --max-image-pixels: the most pixels any image the job reads may have (checked from headers)
  long long max_image_pixels = kDefaultMaxImagePixels;
};

/// The limits every image the job reads is held to (--max-image-pixels).
inline ImageReadOptions image_read_options(const MapJob& job) {
  return {.max_pixels = job.max_image_pixels, .limit_name = "--max-image-pixels"};
}

/// Adds the MapJob flags to a subcommand (--report and --quiet included).
void add_map_flags(CLI::App& sub, MapJob& job);

/// Everything a map run loaded and computed. Heap-held and not movable: the regions reference the
/// surfaces, and the MapResult's Mapping references the projectors, regions and disk maps.
struct MapSession {
  std::optional<ImagePlane> image;  ///< when the source is an image
  LoadedSurface source;
  LoadedSurface target;
  Region source_region;
  /// The target region: drawn (--target-region), or for a placed decal (--target-place) a copy
  /// of the region cut along its relaxed boundary.
  Region target_region;
  MapResult result;
  /// A placed decal: its placement and frames, and the cut region the Mapping references.
  std::optional<DecalGeometry> decal;
  std::unique_ptr<Region> placed_region;
  /// The final map (result.relaxation) and the naive map measured on the grid by docs/metrics.md:
  /// the one fold count (`folds`) every report and summary shows, and the verdict's.
  MapMetrics metrics;
  MapMetrics naive_metrics;
  double seconds_loading = 0.0;  ///< reading, repairing, limit surfaces, projectors, regions
  double seconds_total = 0.0;    ///< the whole run_map_job
  MapSession() = default;
  MapSession(const MapSession&) = delete;
  MapSession& operator=(const MapSession&) = delete;
};

/// The MapOptions a job asks for (what run_map_job passes to map_regions), for commands that
/// repeat the map (e.g. `bench` timing several runs).
MapOptions make_map_options(const MapJob& job, const ProgressCallback& progress = {});

/// Loaded surfaces by file (or image) and scheme, for commands that map many jobs on the same
/// meshes (`bench robustness`): each is read, repaired and prepared once.
using SurfaceCache = std::map<std::string, LoadedSurface>;
/// The cache key of a mesh file's surface, and of an image's plane (which does not depend on the
/// image's region: the rectangle and the ellipse are cut from the same plane).
std::string mesh_surface_key(const std::string& path, const std::string& scheme);
std::string image_surface_key(const std::string& path, double width, const std::string& scheme);

/// Validates the job, loads the surfaces and regions, and maps. Progress goes to `progress`
/// (stage and solver iterations). \throws UsageError / InvalidInputError / IoError naming the flag
/// or file; NumericalError when a stage fails.
/// `frame` (optional) receives every `frame_interval`-th configuration of the relaxation. With a
/// `cache`, surfaces already in it are reused and new ones are added.
std::unique_ptr<MapSession> run_map_job(const MapJob& job, const ProgressCallback& progress = {},
                                        const FrameCallback& frame = {}, long frame_interval = 1,
                                        SurfaceCache* cache = nullptr);

/// The report of `elastic map` (keys in docs/getting-started.md) with `job` recorded under "job".
nlohmann::json map_report(const MapJob& job, const MapSession& session,
                          const nlohmann::json& job_json);

/// Writes `report` to `path` atomically (pretty JSON), if `path` is not empty.
void write_report(const std::string& path, const nlohmann::json& report);

/// The two-line summary `elastic map` prints.
void print_map_summary(const MapJob& job, const MapSession& session);

/// Measures a placement of the session's particles on the target (docs/metrics.md) with the
/// session's rest scale and the target's limit-surface normals; particles flagged in `outside` or
/// without a valid surface point are left out.
MapMetrics measure_placement(const MapSession& session, const Eigen::Matrix3Xd& positions,
                             const std::vector<SurfacePoint>& points,
                             std::vector<char> outside = {});

/// The range of --particles on every subcommand that samples (sample, map, paste, compare, bench).
inline constexpr long kMinParticles = 16;
inline constexpr long kMaxParticles = 5'000'000;
/// \throws UsageError naming --particles outside [kMinParticles, kMaxParticles] (exit 64).
void check_particles(long particles);

/// The source region a job uses: its --source-region, except for an image source, whose region is
/// "rectangle" unless "ellipse" is given. Reports record this one.
std::string effective_source_region(const MapJob& job);
/// `job_json` (job_of) with "source-region" as effective_source_region.
nlohmann::json recorded_job(const MapJob& job, nlohmann::json job_json);

/// Parses "X,Y,Z" (finite numbers). \throws UsageError naming `flag` (a malformed flag value).
Eigen::Vector3d parse_point(const std::string& text, const std::string& flag);

}  // namespace elastic::cli
