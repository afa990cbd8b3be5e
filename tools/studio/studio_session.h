#pragma once
// The state behind `elastic studio` (docs/studio.md), without any HTTP: the two loaded surfaces,
// snapping clicks to the limit surface, cutting a region's outline, running a map in the
// background (progress and relaxation frames for the page) and re-solving it warm-started while
// the user drags a region. The server (studio_server.h) turns requests into these calls and their
// answers into JSON; every method is safe to call from several request threads at once.
//
// Errors are the library's and the CLI's typed exceptions with the CLI's messages; the server
// sends them to the page as "elastic: <message>", the line the CLI would print.

#include <condition_variable>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>

#include "map_job.h"

namespace elastic::cli {

/// Which surface a request is about.
enum class Side { Source, Target };
/// "source" / "target". \throws UsageError for anything else.
Side parse_side(const std::string& text);

struct StudioSessionOptions {
  /// Folders whose files the page may load (meshes, images, points files); a path outside all of
  /// them is refused. Canonical absolute paths.
  std::vector<std::filesystem::path> roots;
  /// Where the studio writes the `points:` files of drawn polygons (inside a root).
  std::filesystem::path work_dir;
  /// The page receives every k-th relaxation configuration (>= 1).
  long frame_interval = 4;
};

class StudioSession {
 public:
  explicit StudioSession(StudioSessionOptions options);
  ~StudioSession();  ///< cancels and joins a running map
  StudioSession(const StudioSession&) = delete;
  StudioSession& operator=(const StudioSession&) = delete;

  /// Loads a mesh (or, for the source, an image: its plane) on one side, replacing what was there.
  /// Returns {"side", "path", "kind": "mesh"|"image", "warnings", "vertices", "triangles",
  /// "positions" (flat x,y,z), "indices" (flat), "uv" (image planes only), "diagonal"}: the
  /// limit tessellation the projector searches, which the page draws.
  /// \throws UsageError for a path outside the roots; IoError / InvalidInputError as the CLI.
  nlohmann::json load(Side side, const std::string& path);

  /// The closest limit-surface point to `query`: {"position", "normal", "distance"}.
  /// \throws UsageError when the side has no surface.
  nlohmann::json snap(Side side, const Eigen::Vector3d& query) const;

  /// Cuts the region of `spec` out of the side's surface: {"spec", "outline" (flat x,y,z of the
  /// boundary loop), "area", "anchor"}. A `points` spec given as
  /// {"points": [[x,y,z], ...]} is written to a points file in the work folder first; its spec
  /// then names that file. \throws InvalidInputError with make_region's message.
  nlohmann::json region(Side side, const nlohmann::json& request);

  /// Starts a cold map of `job` (job-file keys: "source-region", "particles", ...; "source" /
  /// "source-image" and "target" default to the loaded files) in the background, cancelling a
  /// running one. The job is validated here, as `elastic map --job` would, before anything
  /// starts. Returns {"run": id, "job": the effective job}.
  nlohmann::json start_map(const nlohmann::json& job);

  /// Cancels a running map (no-op when none runs).
  void cancel();

  /// The run's state: {"run", "status": "idle"|"running"|"done"|"failed", "stage", "iteration",
  /// "total", "energy", "gradient", "message", "version"}, and "frame" (flat target positions)
  /// when a frame newer than `since_frame` exists. Waits up to `wait_seconds` for a change newer
  /// than `since_version` (0: answers at once).
  nlohmann::json events(long since_version, long since_frame, double wait_seconds) const;

  /// The finished run: {"grid": {"triangles", "source", "uv"?}, "methods": [{"name", "positions",
  /// "colors", "metrics", "ok", "error"}...], "legend": {"metric", "low", "high", "stops"},
  /// "verdict", "report"}, with ElasticPaint first and `baseline` ("lscm", "arap", "dcm" or
  /// "none") beside it on the same grid and colour scale. \throws UsageError when no run finished.
  nlohmann::json result(const std::string& baseline);

  /// The last finished run's job file (what `elastic map --job` repeats) and report.
  nlohmann::json job() const;
  nlohmann::json report() const;

  /// Re-solves the last finished map for a new target region, warm-started from the previous
  /// solve (map_regions with `previous`): {"positions", "outline", "spec", "folds", "sigma_min",
  /// "converged", "stop", "iterations", "seconds", "seconds_region"}. Only the target region may
  /// change. With "budget_seconds" > 0 the relaxation stops at that time after the request began
  /// (a live update during a drag; the next continues from it), otherwise it converges.
  /// \throws UsageError when no run finished; InvalidInputError for a bad region.
  nlohmann::json resolve(const nlohmann::json& request);

  /// "elastic: <message>": the line the CLI prints for the same exception.
  static std::string error_line(const std::exception& error);

  /// A file the page may read (a mesh's texture image): the canonical path, checked against the
  /// roots. \throws UsageError naming the path otherwise.
  std::filesystem::path allowed_path(const std::string& path) const;

 private:
  struct Loaded;
  struct Run;
  void run_map(const std::shared_ptr<Run>& run);
  /// The last finished run. \throws UsageError when none finished yet.
  std::shared_ptr<Run> finished_run() const;
  /// Updates the run under the lock, bumps the version and wakes the waiting pages.
  template <class F>
  void update(F&& change);

  StudioSessionOptions options_;
  std::filesystem::path temp_dir_;  // the job requests parsed as job files (removed at the end)
  mutable std::mutex mutex_;        // guards everything below except the map thread's work
  mutable std::condition_variable changed_;
  std::unique_ptr<Loaded> source_, target_;
  SurfaceCache cache_;
  std::shared_ptr<Run> run_;  // the current (or last) run
  std::thread worker_;
  long next_run_ = 1;
  long version_ = 0;        // bumped on every change the page may wait for
  std::mutex start_mutex_;  // one start_map at a time (it joins the previous worker)
  long points_files_ = 0;
  // The last finished run and its warm re-solves (regions referenced by the results).
  std::shared_ptr<Run> finished_;
  std::mutex warm_mutex_;
  std::deque<Region> warm_regions_;
  std::unique_ptr<MapResult> warm_previous_;
  // The budgeted re-solves' disk cuts keep the heat method's factorisations of the neighbourhood
  // (RegionCache; the unbudgeted one at the drag's end cuts afresh, as the CLI does).
  RegionCache live_regions_;
};

}  // namespace elastic::cli
