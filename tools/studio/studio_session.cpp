#include "studio_session.h"

#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <utility>

#include "compare_methods.h"
#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"
#include "elastic/metrics/heatmap.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/region_spec.h"
#include "elastic/surface/limit_tessellation.h"
#include "job_file.h"
#include "verdict.h"

namespace elastic::cli {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Coordinates go to the page as JSON numbers rounded to float precision: 7 significant digits are
// far below a pixel and keep a 100k-vertex tessellation to a few MB.
double rounded(double x) {
  return static_cast<double>(static_cast<float>(x));
}

nlohmann::json flat(const Eigen::Matrix3Xd& m) {
  std::vector<double> out(static_cast<size_t>(m.size()));
  for (Eigen::Index i = 0; i < m.size(); ++i) {
    out[static_cast<size_t>(i)] = rounded(m.data()[i]);
  }
  return out;
}

nlohmann::json flat(const std::vector<Eigen::Vector3d>& points) {
  std::vector<double> out;
  out.reserve(points.size() * 3);
  for (const Eigen::Vector3d& p : points) {
    for (int k = 0; k < 3; ++k) {
      out.push_back(rounded(p[k]));
    }
  }
  return out;
}

nlohmann::json flat(const std::vector<Eigen::Vector3i>& triangles) {
  std::vector<int> out;
  out.reserve(triangles.size() * 3);
  for (const Eigen::Vector3i& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      out.push_back(t[k]);
    }
  }
  return out;
}

nlohmann::json vec3(const Eigen::Vector3d& p) {
  return {p.x(), p.y(), p.z()};
}

Eigen::Vector3d json_point(const nlohmann::json& j, const std::string& what) {
  if (!j.is_array() || j.size() != 3) {
    throw UsageError(what + ": expected [x, y, z]");
  }
  Eigen::Vector3d p;
  for (int k = 0; k < 3; ++k) {
    if (!j[k].is_number()) {
      throw UsageError(what + ": expected [x, y, z]");
    }
    p[k] = j[k].get<double>();
    if (!std::isfinite(p[k])) {
      throw UsageError(what + ": coordinates must be finite");
    }
  }
  return p;
}

// A budgeted live re-solve makes at least this many relaxation steps: each update moves the map
// towards its minimum, and the next one continues from there.
constexpr long kMinLiveIterations = 10;

std::string spec_number(double x) {
  std::ostringstream s;
  s.precision(9);
  s << x;
  return s.str();
}

// ";anchor=X,Y,Z" for a request's "anchor" (none when absent or null).
std::string anchor_suffix(const nlohmann::json& request, const std::string& flag) {
  if (!request.contains("anchor") || request.at("anchor").is_null()) {
    return {};
  }
  const Eigen::Vector3d a = json_point(request.at("anchor"), flag + ": anchor");
  return ";anchor=" + spec_number(a.x()) + "," + spec_number(a.y()) + "," + spec_number(a.z());
}

}  // namespace

Side parse_side(const std::string& text) {
  if (text == "source") {
    return Side::Source;
  }
  if (text == "target") {
    return Side::Target;
  }
  throw UsageError("side: expected 'source' or 'target', got '" + text + "'");
}

/// One loaded side: the surface the page draws and clicks on.
struct StudioSession::Loaded {
  std::string path;  // canonical
  bool image = false;
  LoadedSurface surface;
};

/// One background map: its progress (guarded by the session's mutex) and, when done, its session.
struct StudioSession::Run {
  long id = 0;
  std::atomic<bool> cancel{false};
  std::string status = "running";  // running | done | failed
  std::string stage = "start";
  std::string message;
  long iteration = 0, total = 0;
  double energy = 0.0, gradient = 0.0;
  long frame_id = 0;
  nlohmann::json frame;
  MapJob job;
  nlohmann::json job_json;
  std::unique_ptr<MapSession> session;
  nlohmann::json report;
  nlohmann::json verdict;
};

StudioSession::StudioSession(StudioSessionOptions options)
    : options_(std::move(options)),
      temp_dir_(std::filesystem::temp_directory_path() /
                ("elastic-studio-" + std::to_string(::getpid()))) {
  std::filesystem::create_directories(temp_dir_);
}

StudioSession::~StudioSession() {
  cancel();
  if (worker_.joinable()) {
    worker_.join();
  }
  std::error_code ignored;
  std::filesystem::remove_all(temp_dir_, ignored);
}

std::filesystem::path StudioSession::allowed_path(const std::string& path) const {
  namespace fs = std::filesystem;
  if (path.empty()) {
    throw UsageError("path: empty");
  }
  std::error_code error;
  fs::path canonical = fs::weakly_canonical(fs::absolute(path), error);
  if (error) {
    throw UsageError("'" + path + "': " + error.message());
  }
  for (const fs::path& root : options_.roots) {
    const auto mismatch =
        std::mismatch(root.begin(), root.end(), canonical.begin(), canonical.end());
    if (mismatch.first == root.end()) {
      return canonical;
    }
  }
  throw UsageError("'" + path + "' is outside the folders the studio serves (--root)");
}

nlohmann::json StudioSession::load(Side side, const std::string& path) {
  const std::filesystem::path file = allowed_path(path);
  auto loaded = std::make_unique<Loaded>();
  loaded->path = file.string();
  std::string ext = file.extension().string();
  for (char& c : ext) {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  loaded->image = side == Side::Source && (ext == ".png" || ext == ".jpg" || ext == ".jpeg" ||
                                           ext == ".bmp" || ext == ".tga");
  const MapJob defaults;
  std::string key;  // where run_map_job looks the surface up (for jobs with the default scheme)
  if (loaded->image) {
    // The plane `elastic map --source-image` builds.
    const ImagePlane plane =
        make_image_plane(file, {.width = defaults.image_width}, image_read_options(defaults));
    loaded->surface = surface_from_mesh(plane.mesh, loaded->path, defaults.scheme);
    key = image_surface_key(loaded->path, defaults.image_width, defaults.scheme);
  } else {
    loaded->surface = load_surface(loaded->path, defaults.scheme);
    key = mesh_surface_key(loaded->path, defaults.scheme);
  }
  const LimitTessellation& t = loaded->surface.projector->tessellation();
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : t.positions) {
    box.extend(p);
  }
  nlohmann::json answer = {{"side", side == Side::Source ? "source" : "target"},
                           {"path", loaded->path},
                           {"kind", loaded->image ? "image" : "mesh"},
                           {"warnings", loaded->surface.warnings},
                           {"vertices", t.positions.size()},
                           {"triangles", t.triangles.size()},
                           {"positions", flat(t.positions)},
                           {"indices", flat(t.triangles)},
                           {"diagonal", box.diagonal().norm()}};
  const PolygonMesh& mesh = *loaded->surface.mesh;
  for (const Material& material : mesh.materials) {
    if (!material.diffuse_texture.empty()) {
      answer["texture"] = material.diffuse_texture.string();
      break;
    }
  }
  if (loaded->image) {
    // The plane is the rectangle [-w/2, w/2] x [-h/2, h/2] at z = 0 carrying the image upright.
    std::vector<double> uv;
    uv.reserve(t.positions.size() * 2);
    for (const Eigen::Vector3d& p : t.positions) {
      uv.push_back(rounded((p.x() - box.min().x()) / box.sizes().x()));
      uv.push_back(rounded((p.y() - box.min().y()) / box.sizes().y()));
    }
    answer["uv"] = std::move(uv);
    answer["texture"] = loaded->path;
  }
  std::lock_guard lock(mutex_);
  cache_[key] = loaded->surface;
  (side == Side::Source ? source_ : target_) = std::move(loaded);
  return answer;
}

nlohmann::json StudioSession::snap(Side side, const Eigen::Vector3d& query) const {
  std::shared_ptr<SurfaceProjector> projector;
  {
    std::lock_guard lock(mutex_);
    const auto& loaded = side == Side::Source ? source_ : target_;
    if (!loaded) {
      throw UsageError("no surface loaded on that side");
    }
    projector = loaded->surface.projector;
  }
  const ClosestPoint c = projector->closest(query);
  return {{"position", vec3(c.position)}, {"normal", vec3(c.normal)}, {"distance", c.distance}};
}

nlohmann::json StudioSession::region(Side side, const nlohmann::json& request) {
  std::shared_ptr<SurfaceProjector> projector;
  std::string spec_text;
  const std::string flag = side == Side::Source ? "--source-region" : "--target-region";
  {
    std::lock_guard lock(mutex_);
    const auto& loaded = side == Side::Source ? source_ : target_;
    if (!loaded) {
      throw UsageError("no surface loaded on that side");
    }
    projector = loaded->surface.projector;
    if (request.contains("points")) {
      // A drawn polygon: the points file `points:FILE` names, in the work folder.
      const nlohmann::json& points = request.at("points");
      if (!points.is_array()) {
        throw UsageError(flag + ": points: expected [[x, y, z], ...]");
      }
      std::ostringstream text;
      text.precision(17);
      for (const nlohmann::json& p : points) {
        const Eigen::Vector3d x = json_point(p, flag + ": points");
        text << x.x() << ' ' << x.y() << ' ' << x.z() << '\n';
      }
      const std::filesystem::path file =
          options_.work_dir / (std::string(side == Side::Source ? "source" : "target") +
                               "-points-" + std::to_string(++points_files_) + ".txt");
      std::filesystem::create_directories(options_.work_dir);
      const std::string body = text.str();
      write_file_atomically(file, [&](std::ofstream& out) { out << body; });
      spec_text = "points:" + file.string();
    } else {
      spec_text = request.value("spec", std::string());
    }
  }
  spec_text += anchor_suffix(request, flag);
  const RegionSpec spec = parse_region_spec(spec_text, flag);
  const Region region = make_region(*projector, spec, {.name = flag});
  std::vector<Eigen::Vector3d> outline;
  outline.reserve(region.boundary.size());
  for (const int v : region.boundary) {
    outline.push_back(region.positions[static_cast<size_t>(v)]);
  }
  const SurfaceCurve curve = region.boundary_curve();
  return {{"spec", spec_text},
          {"outline", flat(outline)},
          {"area", region.area()},
          {"anchor", vec3(curve.locate(0.0).position)}};
}

}  // namespace elastic::cli

namespace elastic::cli {

std::string StudioSession::error_line(const std::exception& error) {
  // The prefixes main() gives the same exception types (tools/elastic/main.cpp).
  const bool known = dynamic_cast<const UsageError*>(&error) != nullptr ||
                     dynamic_cast<const Error*>(&error) != nullptr ||
                     dynamic_cast<const CLI::Error*>(&error) != nullptr;
  if (dynamic_cast<const std::bad_alloc*>(&error) != nullptr) {
    return "elastic: out of memory";
  }
  return std::string("elastic: ") + (known ? "" : "internal error: ") + one_line(error.what());
}

template <class F>
void StudioSession::update(F&& change) {
  {
    std::lock_guard lock(mutex_);
    change();
    ++version_;
  }
  changed_.notify_all();
}

nlohmann::json StudioSession::start_map(const nlohmann::json& request) {
  if (!request.is_object()) {
    throw UsageError("job: expected a JSON object of job-file keys");
  }
  nlohmann::json job_json = request;
  // Files the studio writes or that would go elsewhere are not the page's to choose.
  for (const char* key : {"report", "job", "out"}) {
    job_json.erase(key);
  }
  job_json["quiet"] = true;
  {
    std::lock_guard lock(mutex_);
    if (!job_json.contains("source") && !job_json.contains("source-image") && source_) {
      job_json[source_->image ? "source-image" : "source"] = source_->path;
    }
    if (!job_json.contains("target") && target_) {
      job_json["target"] = target_->path;
    }
  }
  for (const char* key : {"source", "source-image", "target"}) {
    if (job_json.contains(key) && job_json[key].is_string()) {
      job_json[key] = allowed_path(job_json[key].get<std::string>()).string();
    }
  }
  // The job is read exactly as `elastic map --job FILE` reads it: the same flags, checks and
  // messages, and job_of gives the file that repeats the run.
  auto run = std::make_shared<Run>();
  CLI::App app("Map a source region onto a target region", "map");
  app.option_defaults()->always_capture_default();
  add_map_flags(app, run->job);
  add_job_option(app);
  const std::filesystem::path request_file = temp_dir_ / "request.json";
  {
    std::lock_guard lock(start_mutex_);
    write_file_atomically(request_file, [&](std::ofstream& out) { out << job_json.dump(2); });
    try {
      std::vector<std::string> args = {request_file.string(), "--job"};  // CLI11 reads backwards
      app.parse(args);
    } catch (const CLI::ParseError& e) {
      throw UsageError(one_line(e.what()));
    }
    apply_job_file(app);
  }
  nlohmann::json effective = recorded_job(run->job, job_of(app));
  effective.erase("job");
  run->job_json = effective;

  std::lock_guard start(start_mutex_);
  cancel();
  if (worker_.joinable()) {
    worker_.join();
  }
  update([&] {
    run->id = next_run_++;
    run_ = run;
  });
  worker_ = std::thread([this, run] { run_map(run); });
  return {{"run", run->id}, {"job", effective}};
}

void StudioSession::cancel() {
  std::lock_guard lock(mutex_);
  if (run_) {
    run_->cancel = true;
  }
}

void StudioSession::run_map(const std::shared_ptr<Run>& run) {
  SurfaceCache cache;
  {
    std::lock_guard lock(mutex_);
    cache = cache_;
  }
  const ProgressCallback progress = [this, run](const Progress& p) {
    update([&] {
      run->stage = std::string(p.stage);
      run->iteration = p.iteration;
      run->total = p.total;
      run->energy = p.energy;
      run->gradient = p.gradient;
    });
    return !run->cancel.load();
  };
  const FrameCallback frame = [this, run](const RelaxationFrame& f) {
    nlohmann::json positions = flat(*f.positions);
    update([&] {
      run->frame = std::move(positions);
      ++run->frame_id;
    });
  };
  try {
    std::unique_ptr<MapSession> session =
        run_map_job(run->job, progress, frame, options_.frame_interval, &cache);
    const MapVerdict verdict = judge_map(run->job, *session);
    nlohmann::json report = map_report(run->job, *session, run->job_json);
    report["verdict"] = verdict.to_json();
    std::lock_guard warm(warm_mutex_);
    update([&] {
      run->verdict = verdict.to_json();
      run->report = std::move(report);
      run->session = std::move(session);
      if (run->cancel) {
        run->status = "failed";
        run->message = "elastic: cancelled";
        return;
      }
      run->status = "done";
      run->stage = "done";
      run->message = verdict.ok() ? std::string() : verdict.line();
      // Warm re-solves start over from this run.
      warm_previous_.reset();
      warm_regions_.clear();
      finished_ = run;
    });
  } catch (const std::exception& e) {
    const std::string line = error_line(e);
    update([&] {
      run->status = "failed";
      run->message = line;
    });
  }
}

nlohmann::json StudioSession::events(long since_version, long since_frame,
                                     double wait_seconds) const {
  std::unique_lock lock(mutex_);
  if (wait_seconds > 0.0) {
    changed_.wait_for(lock, std::chrono::duration<double>(wait_seconds),
                      [&] { return version_ > since_version; });
  }
  nlohmann::json j = {{"version", version_}, {"status", "idle"}};
  if (!run_) {
    return j;
  }
  const Run& r = *run_;
  j.update({{"run", r.id},
            {"status", r.status},
            {"stage", r.stage},
            {"iteration", r.iteration},
            {"total", r.total},
            {"energy", r.energy},
            {"gradient", r.gradient},
            {"message", r.message},
            {"frame_id", r.frame_id}});
  if (r.status == "done") {
    j["verdict"] = r.verdict;
  }
  if (r.frame_id > since_frame && !r.frame.is_null()) {
    j["frame"] = r.frame;
  }
  return j;
}

std::shared_ptr<StudioSession::Run> StudioSession::finished_run() const {
  std::lock_guard lock(mutex_);
  if (!finished_) {
    throw UsageError("no map has finished yet: run one first");
  }
  return finished_;
}

nlohmann::json StudioSession::result(const std::string& baseline) {
  const std::shared_ptr<Run> fin = finished_run();
  const MapSession& s = *fin->session;
  CompareOptions options;
  options.baselines.clear();
  if (baseline != "none") {
    options.baselines.push_back(parse_baseline_kind(baseline, "baseline"));
  }
  const std::vector<MethodMeasurement> measured = compare_methods(s, options);
  std::vector<const MethodMeasurement*> shown;
  for (const MethodMeasurement& m : measured) {
    if (m.name != "naive") {
      shown.push_back(&m);
    }
  }
  std::vector<const MapMetrics*> scale_of;
  for (const MethodMeasurement* m : shown) {
    if (m->ok) {
      scale_of.push_back(&m->metrics);
    }
  }
  const HeatmapOptions scale = shared_heatmap_scale(scale_of);
  nlohmann::json methods = nlohmann::json::array();
  for (const MethodMeasurement* m : shown) {
    nlohmann::json method = {{"name", m->name}, {"ok", m->ok}, {"error", m->error}};
    if (m->ok) {
      const HeatmapResult heat = make_heatmap(m->positions, m->metrics, scale);
      std::vector<double> colors;
      colors.reserve(heat.mesh.vertex_colors.size() * 3);
      for (const Eigen::Vector3f& c : heat.mesh.vertex_colors) {
        for (int k = 0; k < 3; ++k) {
          colors.push_back(rounded(c[k]));
        }
      }
      method["positions"] = flat(m->positions);
      method["colors"] = std::move(colors);
      method["metrics"] = measurement_json(*m);
      method["status"] = method_status(*m);
    }
    methods.push_back(std::move(method));
  }
  const ParticleGrid& grid = s.result.sampling.grid;
  nlohmann::json grid_json = {{"triangles", flat(measured.front().metrics.triangles)},
                              {"source", flat(grid.source_positions())},
                              {"particles", grid.num_particles()}};
  if (!grid.source_uv.empty()) {
    std::vector<double> uv;
    for (const Eigen::Vector2d& t : grid.source_uv) {
      uv.push_back(rounded(t.x()));
      uv.push_back(rounded(t.y()));
    }
    grid_json["uv"] = std::move(uv);
  }
  nlohmann::json stops = nlohmann::json::array();
  for (const Eigen::Vector3f& c : heatmap_ramp_stops()) {
    stops.push_back({c.x(), c.y(), c.z()});
  }
  return {{"run", fin->id},
          {"grid", std::move(grid_json)},
          {"methods", std::move(methods)},
          {"legend",
           {{"metric", std::string(to_string(scale.metric))},
            {"low", scale.low.value_or(0.0)},
            {"high", scale.high.value_or(1.0)},
            {"stops", stops}}},
          {"verdict", fin->verdict}};
}

nlohmann::json StudioSession::job() const {
  return finished_run()->job_json;
}

nlohmann::json StudioSession::report() const {
  return finished_run()->report;
}

nlohmann::json StudioSession::resolve(const nlohmann::json& request) {
  std::lock_guard warm(warm_mutex_);
  const std::shared_ptr<Run> fin = finished_run();
  const MapSession& s = *fin->session;
  if (s.decal) {
    throw UsageError("a placed decal (--target-place) is not re-solved live");
  }
  std::string spec_text = request.value("spec", std::string());
  spec_text += anchor_suffix(request, "--target-region");
  const auto start = Clock::now();
  // A live update while the user drags: the relaxation stops at the deadline (a Cancelled stop,
  // not converged) and the next update continues from where it stopped; the page asks for an
  // unbudgeted solve when the drag ends.
  const nlohmann::json* given =
      request.contains("budget_seconds") ? &request.at("budget_seconds") : nullptr;
  const double budget = given != nullptr && given->is_number() ? given->get<double>() : 0.0;
  if ((given != nullptr && !given->is_number()) || !std::isfinite(budget) || budget < 0.0) {
    throw UsageError("budget_seconds: expected a number of seconds >= 0");
  }
  const RegionSpec spec = parse_region_spec(spec_text, "--target-region");
  warm_regions_.push_back(
      make_region(*s.target.projector, spec,
                  {.name = "--target-region", .cache = budget > 0.0 ? &live_regions_ : nullptr}));
  const double seconds_region = seconds_since(start);
  const MapResult& previous = warm_previous_ ? *warm_previous_ : s.result;
  MapOptions options = make_map_options(fin->job);
  if (budget > 0.0) {
    // The budget counts from the request's start; the relaxation makes at least
    // kMinLiveIterations steps even when the region cut and its set-up took the budget.
    const auto deadline =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(budget));
    options.relaxation.progress = [deadline](const Progress& p) {
      return p.iteration < kMinLiveIterations || Clock::now() < deadline;
    };
    options.relaxation.untangle_steps = 0;
  }
  std::unique_ptr<MapResult> next;
  try {
    next = std::make_unique<MapResult>(map_regions(*s.source.projector, s.source_region,
                                                   *s.target.projector, warm_regions_.back(),
                                                   previous, options));
  } catch (...) {
    warm_regions_.pop_back();
    throw;
  }
  // The new result references only the newest region; older ones go once nothing needs them.
  warm_previous_ = std::move(next);
  while (warm_regions_.size() > 1) {
    warm_regions_.pop_front();
  }
  const RelaxationResult& r = warm_previous_->relaxation;
  const MapMetrics metrics = measure_placement(s, r.positions, r.points);
  std::vector<Eigen::Vector3d> outline;
  for (const int v : warm_regions_.back().boundary) {
    outline.push_back(warm_regions_.back().positions[static_cast<size_t>(v)]);
  }
  return {{"positions", flat(r.positions)},
          {"outline", flat(outline)},
          {"spec", spec_text},
          {"folds", metrics.folds},
          {"sigma_min", metrics.sigma_min},
          {"converged", r.converged},
          {"stop", std::string(to_string(r.reason))},
          {"iterations", r.iterations},
          {"seconds_region", seconds_region},
          {"seconds", seconds_since(start)}};
}

}  // namespace elastic::cli
