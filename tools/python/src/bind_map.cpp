// The map for Python: elastic.map_regions (every option of `elastic map` as a keyword), the Map it
// returns (particles, metrics, forward and inverse for arrays of surface points, the LSCM/ARAP/DCM
// baselines on its grid) and Map.paste, which writes the files `elastic paste` writes.
#include <pybind11/stl.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>

#include "arrays.h"
#include "elastic/baselines/baseline_map.h"
#include "elastic/core/staged_folder.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/transfer/output_folder.h"
#include "elastic/transfer/paste.h"
#include "session.h"

namespace elastic::python {

namespace {

// The range of `particles` (the CLI's --particles).
constexpr long kMinParticles = 16;
constexpr long kMaxParticles = 5'000'000;

template <typename T>
T parsed(const std::string& text, const char* name,
         T (*parse)(std::string_view, std::string_view)) {
  return parse(text, name);
}

struct MapKeywords {
  long particles = 1000;
  std::string solver = "lbfgs", energy = "robust", rest_scale = "auto", boundary = "auto";
  std::string boundary_offset = "auto", preconditioner = "multigrid";
  py::object angular_stiffness;
  int subdivide = 0, threads = 0;
  double jitter = 0.0;
  unsigned long seed = 0;
  long max_iterations = 0;
  double curvature_radius = AdaptiveSamplingOptions{}.curvature_radius;
  double distortion_weight = 0.0;
  bool distortion_guard = true;
  std::string newton = "auto";
  long coarse_start = MapOptions{}.coarse_start_above;
};

// The MapOptions of `elastic map` for the same flags (tools/elastic/map_job.cpp).
MapOptions map_options(const MapKeywords& k) {
  if (k.particles < kMinParticles || k.particles > kMaxParticles) {
    throw py::value_error("particles: " + std::to_string(k.particles) + " is outside [" +
                          std::to_string(kMinParticles) + ", " + std::to_string(kMaxParticles) +
                          "]");
  }
  if (k.solver != "lbfgs" && k.solver != "explicit") {
    throw py::value_error("solver: expected 'lbfgs' or 'explicit', got '" + k.solver + "'");
  }
  if (k.boundary_offset != "auto" && k.boundary_offset != "anchor") {
    throw py::value_error("boundary_offset: expected 'auto' or 'anchor', got '" +
                          k.boundary_offset + "'");
  }
  if (k.coarse_start < 0 || k.coarse_start > kMaxParticles) {
    throw py::value_error("coarse_start: expected a particle count in [0, " +
                          std::to_string(kMaxParticles) + "], got " +
                          std::to_string(k.coarse_start));
  }
  if (k.subdivide < 0 || k.subdivide > 4 || k.threads < 0 || k.max_iterations < 0) {
    throw py::value_error("subdivide (0..4), threads and max_iterations (>= 0) out of range");
  }
  if (!(k.jitter >= 0.0 && k.jitter <= 1.0)) {
    throw py::value_error("jitter: expected a fraction in [0, 1], got " + std::to_string(k.jitter));
  }
  if (k.seed != 0 && k.jitter == 0.0) {
    throw py::value_error("seed: chooses the random start of jitter, which is 0: give jitter");
  }
  if (!(k.curvature_radius >= 0.0 && k.curvature_radius <= 100.0)) {
    throw py::value_error("curvature_radius: expected grid spacings in [0, 100], got " +
                          std::to_string(k.curvature_radius));
  }
  MapOptions options;
  options.sampling.layout.particles = k.particles;
  options.sampling.layout.name = "source_region";
  options.sampling.sampling.seed = k.seed;
  options.sampling.sampling.jitter = k.jitter;
  options.sampling.sampling.curvature_radius = k.curvature_radius;
  options.rest_scale = parse_rest_scale(k.rest_scale, "rest_scale");
  options.relaxation.solver = k.solver == "explicit" ? SolverKind::Faithful : SolverKind::Fast;
  options.relaxation.energy = parse_energy_kind(k.energy, "energy");
  options.choose_offset = k.boundary_offset == "auto";
  options.relaxation.boundary = k.boundary == "auto" ? auto_boundary_mode(k.subdivide)
                                                     : parse_boundary_mode(k.boundary, "boundary");
  options.relaxation.lbfgs.preconditioner =
      parse_preconditioner(k.preconditioner, "preconditioner");
  options.relaxation.lbfgs.newton.mode = parse_newton_mode(k.newton, "newton");
  options.coarse_start_above = static_cast<int>(k.coarse_start);
  options.relaxation.threads = k.threads;
  options.relaxation.max_iterations = k.max_iterations;
  if (!k.angular_stiffness.is_none()) {
    const double ca = k.angular_stiffness.cast<double>();
    if (!(ca >= 0.0 && ca <= 100.0)) {
      throw py::value_error("angular_stiffness: expected C_a / C in [0, 100], got " +
                            std::to_string(ca));
    }
    options.relaxation.angular_stiffness = ca;
  }
  if (!(k.distortion_weight >= 0.0 && k.distortion_weight <= 100.0)) {
    throw py::value_error("distortion_weight: expected lambda / C in [0, 100], got " +
                          std::to_string(k.distortion_weight));
  }
  options.relaxation.distortion_stiffness = k.distortion_weight;
  options.distortion_guard = k.distortion_guard;
  options.subdivisions = k.subdivide;
  return options;
}

// Runs `work` in a TBB arena of `threads` threads (0: all) without the GIL; then raises the
// listener's error (Ctrl-C, the callback's exception), else `work`'s.
void run_released(int threads, PythonProgress& listener, const std::function<void()>& work) {
  std::exception_ptr failure;
  {
    const py::gil_scoped_release release;
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    try {
      arena.execute(work);
    } catch (...) {
      failure = std::current_exception();
    }
  }
  listener.rethrow();  // Ctrl-C or the callback's own exception wins over "cancelled"
  if (failure) {
    std::rethrow_exception(failure);
  }
}

// The map's and the naive map's metrics, as `elastic map` reports them.
void measure_state(MapState& state) {
  state.metrics =
      measure_on_target(state, state.result.relaxation.positions, state.result.relaxation.points);
  state.naive_metrics =
      measure_on_target(state, state.result.naive.positions, state.result.naive.points);
}

std::shared_ptr<MapState> run_map(const std::shared_ptr<RegionState>& source_region,
                                  const std::shared_ptr<RegionState>& target_region,
                                  const MapKeywords& keywords, const py::object& progress,
                                  const std::shared_ptr<MapState>& previous = nullptr) {
  if (previous && previous->decal) {
    throw py::value_error("previous: a placed decal cannot warm-start map_regions");
  }
  MapOptions options = map_options(keywords);
  PythonProgress listener(progress);
  options.progress = listener.callback();
  options.relaxation.progress = options.progress;
  auto state = std::make_shared<MapState>();
  state->source = source_region->surface;
  state->target = target_region->surface;
  state->source_region = source_region;
  state->target_region = target_region;
  run_released(keywords.threads, listener, [&] {
    // A warm start reads the previous map (and its target region, which it holds) only here.
    state->result = previous
                        ? map_regions(*state->source->projector, source_region->region,
                                      *state->target->projector, target_region->region,
                                      previous->result, options)
                        : map_regions(*state->source->projector, source_region->region,
                                      *state->target->projector, target_region->region, options);
    measure_state(*state);
  });
  return state;
}

// Mapping::forward or inverse for arrays of surface points: one parallel pass without the GIL that
// reads the input arrays and writes the output arrays in place (no intermediate per-point
// vectors: at a million points their allocation and first touch cost a third of the mapping).
py::dict map_points(const MapState& m, const py::handle& face, const py::handle& uv, bool forward) {
  const Int32Array faces = int_rows(face, "face", 0);
  const Float64Array params = float_rows(uv, "uv", 2);
  const py::ssize_t n = faces.shape(0);
  if (params.shape(0) != n) {
    throw py::value_error("face and uv: expected the same number of points, got " +
                          std::to_string(n) + " and " + std::to_string(params.shape(0)));
  }
  const LimitSurface& surface = forward ? *m.source->surface : *m.target->surface;
  const std::int32_t* f = faces.data();
  for (py::ssize_t i = 0; i < n; ++i) {
    if (f[i] < 0 || f[i] >= surface.num_faces()) {
      throw py::value_error("face: entry " + std::to_string(i) + " is " + std::to_string(f[i]) +
                            ", outside [0, " + std::to_string(surface.num_faces()) + ")");
    }
  }
  py::array_t<bool> inside(n);
  Int32Array out_face = new_ints(n);
  Float64Array out_uv = new_rows(n, 2), position = new_rows(n, 3);
  const double* in_uv = params.data();
  bool* in = inside.mutable_data();
  std::int32_t* of = out_face.mutable_data();
  double* ouv = out_uv.mutable_data();
  auto* p = reinterpret_cast<Eigen::Vector3d*>(position.mutable_data());
  {
    const py::gil_scoped_release release;
    const Mapping& mapping = m.result.mapping;
    tbb::parallel_for(
        tbb::blocked_range<py::ssize_t>(0, n, 1024), [&](const tbb::blocked_range<py::ssize_t>& r) {
          for (py::ssize_t i = r.begin(); i != r.end(); ++i) {
            const SurfacePoint point{f[i], in_uv[2 * i], in_uv[2 * i + 1]};
            const Mapping::Location l = forward ? mapping.forward(point) : mapping.inverse(point);
            in[i] = l.inside;
            of[i] = l.inside ? l.point.face : -1;
            ouv[2 * i] = l.inside ? l.point.u : 0.0;
            ouv[2 * i + 1] = l.inside ? l.point.v : 0.0;
            p[i] = l.inside ? l.position
                            : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
          }
        });
  }
  py::dict out;
  out["face"] = out_face;
  out["uv"] = out_uv;
  out["inside"] = inside;
  out["position"] = position;
  return out;
}

// Tangent vectors at source points carried to the target by the map's differential (J v, or its
// rotation part for directions), with the mapped points.
py::dict transport_vectors(MapState& m, const py::handle& face, const py::handle& uv,
                           const py::handle& vectors, const std::string& mode) {
  VectorTransport transport = VectorTransport::Stretch;
  if (mode == "rotation") {
    transport = VectorTransport::Rotation;
  } else if (mode != "stretch") {
    throw py::value_error("mode: expected 'stretch' or 'rotation', got '" + mode + "'");
  }
  const std::vector<SurfacePoint> points = surface_points(face, uv);
  const Float64Array v = float_rows(vectors, "vectors", 3);
  if (v.shape(0) != static_cast<py::ssize_t>(points.size())) {
    throw py::value_error("vectors: expected one per point (" + std::to_string(points.size()) +
                          "), got " + std::to_string(v.shape(0)));
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].face < 0 || points[i].face >= m.source->surface->num_faces()) {
      throw py::value_error("face: entry " + std::to_string(i) + " is outside the source's faces");
    }
  }
  const auto in = as_vectors(v);
  const auto n = static_cast<py::ssize_t>(points.size());
  py::array_t<bool> inside(n);
  Float64Array out = new_rows(n, 3), position = new_rows(n, 3);
  bool* ok = inside.mutable_data();
  auto* o = reinterpret_cast<Eigen::Vector3d*>(out.mutable_data());
  auto* p = reinterpret_cast<Eigen::Vector3d*>(position.mutable_data());
  {
    const py::gil_scoped_release release;
    std::call_once(m.differential_once, [&] {
      m.differential =
          std::make_unique<MapDifferential>(*m.source->surface, *m.target->surface, m.result);
    });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          const Mapping::Location l = m.result.mapping.forward(points[i]);
                          ok[i] = l.inside;
                          const double nan = std::numeric_limits<double>::quiet_NaN();
                          p[i] = l.inside ? l.position : Eigen::Vector3d::Constant(nan);
                          o[i] = l.inside ? Eigen::Vector3d(m.differential->transport_forward(
                                                                points[i], l, transport) *
                                                            in[i])
                                          : Eigen::Vector3d::Constant(nan);
                        }
                      });
  }
  py::dict result;
  result["inside"] = inside;
  result["position"] = position;
  result["vectors"] = out;
  return result;
}

py::dict baseline(const MapState& m, const std::string& kind) {
  BaselineOptions options;
  options.kind = parse_baseline_kind(kind, "kind");
  options.target_offset = m.result.boundary_offset;
  BaselineResult result;
  MapMetrics metrics;
  {
    const py::gil_scoped_release release;
    result = map_baseline(m.result.sampling.grid, *m.source->projector, m.source_region->region,
                          *m.target->projector, m.target_region->region, options);
    metrics = measure_on_target(m, result.positions, result.points, result.outside);
  }
  py::dict out;
  out["kind"] = std::string(to_string(result.kind));
  out["positions"] = rows_of(result.positions);
  py::array_t<bool> outside(static_cast<py::ssize_t>(result.outside.size()));
  std::copy(result.outside.begin(), result.outside.end(), outside.mutable_data());
  out["outside"] = outside;
  out["metrics"] = metrics_dict(metrics);
  out["seconds"] = result.seconds;
  return out;
}

std::vector<std::string> paste_files(const MapState& m, const std::string& out,
                                     const std::string& color, const py::object& texture, bool bake,
                                     const py::object& height, double height_scale,
                                     const py::object& detail, double detail_scale,
                                     const py::object& progress) {
  PasteOptions options;
  options.color = parse_paste_color(color, "color");
  if (!texture.is_none()) {
    options.texture = texture.cast<std::string>();
  }
  // As the CLI's --height: None, "luminance" (of the pasted colour), or a height image's path.
  if (!height.is_none()) {
    const std::string h = height.cast<std::string>();
    options.height = h == "luminance" ? PasteHeight::Luminance : PasteHeight::Image;
    if (options.height == PasteHeight::Image) {
      options.height_image = h;
    }
  }
  options.bake = bake;
  options.height_scale = height_scale;
  std::optional<PolygonMesh> detail_mesh;
  if (!detail.is_none()) {
    if (py::isinstance<py::str>(detail)) {
      const std::string path = detail.cast<std::string>();
      detail_mesh = read_mesh(path).mesh;
      options.detail_name = path;
    } else {
      detail_mesh = detail.cast<const PolygonMesh&>();
    }
    options.detail = &*detail_mesh;
    options.detail_scale = detail_scale;
  }
  PythonProgress listener(progress);
  options.progress = listener.callback();
  std::vector<std::string> written;
  std::exception_ptr failure;
  {
    const py::gil_scoped_release release;
    try {
      // Staged like `elastic paste --out`: the files appear together, or not at all.
      StagedFolder staged(out, "out");
      const PasteResult pasted =
          paste(*m.source->projector, m.source_region->region, *m.target->projector,
                m.target_region->region, m.result, options);
      if (!pasted.cancelled) {
        OutputFolder folder(staged.staging());
        for (const auto& f : write_paste(folder, pasted)) {
          written.push_back(
              (staged.destination() / f.lexically_relative(staged.staging())).string());
        }
        staged.commit();
      }
    } catch (...) {
      failure = std::current_exception();
    }
  }
  listener.rethrow();
  if (failure) {
    std::rethrow_exception(failure);
  }
  if (listener.stopped()) {
    throw py::value_error("paste: stopped by the progress callback; nothing was written");
  }
  return written;
}

}  // namespace

MapMetrics measure_on_target(const MapState& map, const Eigen::Matrix3Xd& positions,
                             const std::vector<SurfacePoint>& points, std::vector<char> outside) {
  return elastic::measure_on_target(map.result.sampling.grid, *map.target->surface,
                                    map.result.rest_scale, positions, points, std::move(outside));
}

py::dict metrics_dict(const MapMetrics& m) {
  py::dict out;
  out["length_energy"] = m.length_energy;
  out["angle_error_mean_deg"] = m.angle_error_mean_deg;
  out["angle_error_max_deg"] = m.angle_error_max_deg;
  out["stretch_l2"] = m.stretch_l2;
  out["stretch_linf"] = m.stretch_linf;
  out["inverse_stretch_l2"] = m.inverse_stretch_l2;
  out["inverse_stretch_linf"] = m.inverse_stretch_linf;
  out["area_distortion"] = m.area_distortion;
  out["conformal_distortion"] = m.conformal_distortion;
  out["symmetric_dirichlet"] = m.symmetric_dirichlet;
  out["folds"] = m.folds;
  out["sigma_min"] = m.sigma_min;
  out["degenerate"] = m.degenerate;
  out["outside"] = m.outside;
  out["measured_triangles"] = m.measured_triangles;
  return out;
}

// place_decal: map_decal with the keywords of `elastic map --target-place` (tools/elastic).
std::shared_ptr<MapState> run_decal(const std::shared_ptr<RegionState>& source_region,
                                    const std::shared_ptr<SurfaceState>& target,
                                    const DecalPlacement& placement, const MapKeywords& keywords,
                                    const py::object& progress) {
  if (keywords.subdivide != 0 || keywords.boundary != "auto" || keywords.rest_scale != "auto") {
    throw py::value_error(
        "place_decal: a placed decal's boundary is free and its size is its scale");
  }
  const MapOptions options = map_options(keywords);
  MapDecalOptions decal;
  decal.sampling = options.sampling;
  decal.relaxation = options.relaxation;
  decal.name = "place_decal";
  PythonProgress listener(progress);
  decal.progress = listener.callback();
  decal.relaxation.progress = decal.progress;
  auto state = std::make_shared<MapState>();
  state->source = source_region->surface;
  state->target = target;
  state->source_region = source_region;
  run_released(keywords.threads, listener, [&] {
    MapDecalResult placed = map_decal(*state->source->projector, source_region->region,
                                      *target->projector, placement, decal);
    state->result = std::move(placed.map);
    state->decal = std::move(placed.geometry);
    state->placed_region = std::move(placed.target_region);
    measure_state(*state);
  });
  auto region = std::make_shared<RegionState>();
  region->surface = target;
  region->region = *state->placed_region;
  state->target_region = std::move(region);
  return state;
}

py::object decal_dict(const MapState& s) {
  if (!s.decal) {
    return py::none();
  }
  const DecalGeometry& g = *s.decal;
  const auto vec = [](const Eigen::Vector3d& v) { return py::make_tuple(v.x(), v.y(), v.z()); };
  py::dict d;
  d["point"] = vec(g.placement.point);
  d["angle_deg"] = g.placement.angle_degrees;
  d["scale"] = g.placement.scale;
  d["centre"] = vec(g.target_centre_position);
  d["up"] = vec(g.target_frame.up);
  d["normal"] = vec(g.target_frame.normal);
  d["source_centre"] = vec(g.source_centre);
  d["source_radius"] = g.source_radius;
  d["turned_deg"] = g.turned_degrees;
  d["target_area"] = s.placed_region ? s.placed_region->area() : 0.0;
  return d;
}

void bind_map(py::module_& m) {
  m.def(
      "place_decal",
      [](const std::shared_ptr<RegionState>& source_region,
         const std::shared_ptr<SurfaceState>& target, const std::array<double, 3>& point,
         double angle, double scale, long particles, const std::string& solver,
         const std::string& energy, int threads, double jitter, unsigned long seed,
         long max_iterations, double curvature_radius, const py::object& progress) {
        const DecalPlacement placement{
            .point = {point[0], point[1], point[2]}, .angle_degrees = angle, .scale = scale};
        MapKeywords k;
        k.angular_stiffness = py::none();  // the energy's default
        k.particles = particles;
        k.solver = solver;
        k.energy = energy;
        k.threads = threads;
        k.jitter = jitter;
        k.seed = seed;
        k.max_iterations = max_iterations;
        k.curvature_radius = curvature_radius;
        return run_decal(source_region, target, placement, k, progress);
      },
      py::arg("source_region"), py::arg("target"), py::arg("point"), py::kw_only(),
      py::arg("angle") = 0.0, py::arg("scale") = 1.0, py::arg("particles") = 1000,
      py::arg("solver") = "lbfgs", py::arg("energy") = "robust", py::arg("threads") = 0,
      py::arg("jitter") = 0.0, py::arg("seed") = 0, py::arg("max_iterations") = 0,
      py::arg("curvature_radius") = AdaptiveSamplingOptions{}.curvature_radius,
      py::arg("progress") = py::none(),
      "Places source_region on the target Surface as a decal with a free boundary, as `elastic "
      "map --target-place X,Y,Z,ANGLE,SCALE` (docs/transfer.md): its centre at the target point "
      "closest to `point`, its up `angle` degrees counter-clockwise from the world +Y projected "
      "on the surface, `scale` times its own size. -> Map (Map.decal says where it went; paste() "
      "paints the region cut along its relaxed boundary). A decal that runs off the "
      "surface or overlaps itself raises ValueError saying how much smaller it must be.");

  m.def(
      "map_regions",
      [](const std::shared_ptr<RegionState>& source_region,
         const std::shared_ptr<RegionState>& target_region, long particles,
         const std::string& solver, const std::string& energy, const std::string& rest_scale,
         const std::string& boundary, const std::string& boundary_offset,
         const std::string& preconditioner, const py::object& angular_stiffness, int subdivide,
         int threads, double jitter, unsigned long seed, long max_iterations,
         double curvature_radius, double distortion_weight, bool distortion_guard,
         const std::string& newton, long coarse_start, const py::object& progress,
         const std::shared_ptr<MapState>& previous) {
        const MapKeywords k{particles,
                            solver,
                            energy,
                            rest_scale,
                            boundary,
                            boundary_offset,
                            preconditioner,
                            angular_stiffness,
                            subdivide,
                            threads,
                            jitter,
                            seed,
                            max_iterations,
                            curvature_radius,
                            distortion_weight,
                            distortion_guard,
                            newton,
                            coarse_start};
        return run_map(source_region, target_region, k, progress, previous);
      },
      py::arg("source_region"), py::arg("target_region"), py::kw_only(),
      py::arg("particles") = 1000, py::arg("solver") = "lbfgs", py::arg("energy") = "robust",
      py::arg("rest_scale") = "auto", py::arg("boundary") = "auto",
      py::arg("boundary_offset") = "auto", py::arg("preconditioner") = "multigrid",
      py::arg("angular_stiffness") = py::none(), py::arg("subdivide") = 0, py::arg("threads") = 0,
      py::arg("jitter") = 0.0, py::arg("seed") = 0, py::arg("max_iterations") = 0,
      py::arg("curvature_radius") = AdaptiveSamplingOptions{}.curvature_radius,
      py::arg("distortion_weight") = 0.0, py::arg("distortion_guard") = true,
      py::arg("newton") = "auto", py::arg("coarse_start") = MapOptions{}.coarse_start_above,
      py::arg("progress") = py::none(), py::arg("previous") = nullptr,
      "Maps source_region onto target_region (each a Region of its Surface) with the particle "
      "system: the keywords are the flags of `elastic map` (docs/cli.md) with underscores. "
      "progress: called as progress(stage, iteration, total, energy, gradient); return False to "
      "stop. Runs without the GIL; Ctrl-C raises KeyboardInterrupt. previous: a Map of the same "
      "source_region object to warm-start from (its grid and boundary turn are kept, its relaxed "
      "placement carried onto target_region; the sampling keywords are then not used; "
      "docs/api.md). "
      "-> Map. A map that did not "
      "converge or has folds is returned (check Map.ok), as `elastic map` writes its report "
      "before exiting 70.");

  py::class_<MapState, std::shared_ptr<MapState>>(
      m, "Map",
      "A relaxed map between two regions: its particles on both surfaces, its distortion "
      "(docs/metrics.md), and forward/inverse queries.")
      .def_property_readonly(
          "ok",
          [](const MapState& s) { return s.result.relaxation.converged && s.metrics.folds == 0; },
          "The verdict of `elastic map`: converged and fold-free.")
      .def_property_readonly("decal", &decal_dict,
                             "A placed decal's placement (place_decal; None for map_regions): "
                             "point, angle_deg, scale, centre, up, normal, source_centre, "
                             "source_radius, turned_deg, target_area, as the report's 'decal'.")
      .def_property_readonly(
          "converged", [](const MapState& s) { return s.result.relaxation.converged; },
          "Whether the solver's stop is a convergence (the report's 'converged').")
      .def_property_readonly(
          "reason",
          [](const MapState& s) { return std::string(to_string(s.result.relaxation.reason)); },
          "The solver's stop reason, as in the CLI report.")
      .def_property_readonly(
          "iterations", [](const MapState& s) { return s.result.relaxation.iterations; },
          "Solver iterations (L-BFGS) or time steps (explicit).")
      .def_property_readonly(
          "folds", [](const MapState& s) { return s.metrics.folds; },
          "Folded faces of the final map (docs/metrics.md), the report's 'folds'.")
      .def_property_readonly(
          "sigma_min", [](const MapState& s) { return s.metrics.sigma_min; },
          "Worst signed sigma_min over the grid triangles, divided by the rest scale.")
      .def_property_readonly(
          "rest_scale", [](const MapState& s) { return s.result.rest_scale; },
          "sigma, the factor on the source's rest lengths (the report's rest_scale.factor).")
      .def_property_readonly(
          "energy",
          [](const MapState& s) {
            const RelaxationResult& x = s.result.relaxation;
            py::dict e;
            e["length"] = x.length_energy;
            e["angle"] = x.angular_energy;
            e["barrier"] = x.barrier_energy;
            e["distortion"] = x.distortion_energy;
            e["initial"] = x.initial_energy;
            return e;
          },
          "The solver's final energies (the report's 'energy').")
      .def_property_readonly(
          "seconds",
          [](const MapState& s) {
            const MapResult& r = s.result;
            py::dict d;
            d["sampling"] = r.seconds_sampling;
            d["naive_map"] = r.seconds_naive;
            d["coarse_start"] = r.seconds_coarse;
            d["solver_setup"] = r.relaxation.setup_seconds;
            d["solve"] = r.relaxation.solve_seconds;
            d["mapping"] = r.seconds_mapping;
            return d;
          },
          "Wall seconds of the map's stages.")
      .def_property_readonly(
          "num_particles", [](const MapState& s) { return s.result.sampling.grid.num_particles(); },
          "P, the number of particles.")
      .def_property_readonly(
          "source_positions",
          [](const MapState& s) {
            const ParticleGrid& g = s.result.sampling.grid;
            Float64Array out = new_rows(g.num_particles(), 3);
            auto rows = out.mutable_unchecked<2>();
            for (int i = 0; i < g.num_particles(); ++i) {
              const auto& p = g.mesh.point(GridMesh::VertexHandle(i));
              for (int c = 0; c < 3; ++c) {
                rows(i, c) = p[c];
              }
            }
            return out;
          },
          "(P, 3) float64 particles on the source.")
      .def_property_readonly(
          "source_points",
          [](const MapState& s) { return points_dict(s.result.sampling.grid.source_points); },
          "The particles as source surface points: dict 'face', 'uv'.")
      .def_property_readonly(
          "target_positions",
          [](const MapState& s) { return rows_of(s.result.relaxation.positions); },
          "(P, 3) float64 particles on the target (the relaxed map).")
      .def_property_readonly(
          "target_points",
          [](const MapState& s) { return points_dict(s.result.relaxation.points); },
          "The particles as target surface points: dict 'face', 'uv'.")
      .def_property_readonly(
          "naive_positions", [](const MapState& s) { return rows_of(s.result.naive.positions); },
          "(P, 3) float64 start of the relaxation (the composed disk maps).")
      .def_property_readonly(
          "triangles", [](const MapState& s) { return triangles_of(s.metrics.triangles); },
          "(T, 3) int32 grid triangles (each quad split once), as the metrics use them.")
      .def_property_readonly(
          "boundary",
          [](const MapState& s) {
            const auto& loop = s.result.sampling.grid.boundary_loop;
            Int32Array out = new_ints(static_cast<py::ssize_t>(loop.size()));
            std::copy(loop.begin(), loop.end(), out.mutable_data());
            return out;
          },
          "(B,) int32 boundary particles in order.")
      .def(
          "metrics", [](const MapState& s) { return metrics_dict(s.metrics); },
          "Distortion of the final map (docs/metrics.md): length energy, angle error, stretch, "
          "area and conformal distortion, symmetric Dirichlet, folds, sigma_min.")
      .def(
          "naive_metrics", [](const MapState& s) { return metrics_dict(s.naive_metrics); },
          "The same for the naive start.")
      .def(
          "per_triangle",
          [](const MapState& s, const std::string& name) {
            const std::vector<double>& v =
                s.metrics.per_triangle.values(parse_triangle_metric(name, "name"));
            Float64Array out = new_rows(static_cast<py::ssize_t>(v.size()), 0);
            std::copy(v.begin(), v.end(), out.mutable_data());
            return out;
          },
          py::arg("name"),
          "(T,) float64 values of one metric per grid triangle ('angle_error_deg', 'stretch_l2', "
          "'stretch_linf', 'inverse_stretch_l2', 'area_distortion', 'conformal_distortion', "
          "'symmetric_dirichlet'); NaN for excluded triangles.")
      .def(
          "forward",
          [](const MapState& s, const py::handle& face, const py::handle& uv) {
            return map_points(s, face, uv, true);
          },
          py::arg("face"), py::arg("uv"),
          "Source surface points -> target: dict 'inside' (N,) bool, 'face', 'uv', 'position' "
          "(NaN outside the mapped region).")
      .def(
          "inverse",
          [](const MapState& s, const py::handle& face, const py::handle& uv) {
            return map_points(s, face, uv, false);
          },
          py::arg("face"), py::arg("uv"), "Target surface points -> source, as forward.")
      .def("baseline", &baseline, py::arg("kind") = "lscm",
           "A baseline map ('lscm', 'arap' or 'dcm', CGAL) of the same grid, as `elastic compare` "
           "runs it -> dict 'positions', 'outside', 'metrics', 'seconds'.")
      .def("paste", &paste_files, py::arg("out"), py::kw_only(), py::arg("color") = "auto",
           py::arg("texture") = py::none(), py::arg("bake") = false, py::arg("height") = py::none(),
           py::arg("height_scale") = 0.1, py::arg("detail") = py::none(),
           py::arg("detail_scale") = 1.0, py::arg("progress") = py::none(),
           "Pastes the source's colour (and height) onto the target through the map and writes "
           "the files of `elastic paste` (painted OBJ/MTL and textures, colours PLY, baked and "
           "displaced meshes when asked; height: None, 'luminance' or a height image's path, as "
           "--height; detail: a mesh or path whose geometric detail over the "
           "source is carried onto the target, as --detail) into the folder `out`, all together "
           "or none. -> the paths written.")
      .def("transport_vectors", &transport_vectors, py::arg("face"), py::arg("uv"),
           py::arg("vectors"), py::arg("mode") = "stretch",
           "Carries (N, 3) vectors at source surface points to the target by the map's "
           "differential: 'stretch' (J v: they stretch and shear with the paste) or 'rotation' "
           "(directions, lengths kept) -> dict 'inside' (N,) bool, 'position' and 'vectors' "
           "(N, 3), NaN outside.")
      .def("__repr__", [](const MapState& s) {
        return "<elastic.Map " + std::to_string(s.result.sampling.grid.num_particles()) +
               " particles, " + (s.result.relaxation.converged ? "converged" : "not converged") +
               ", " + std::to_string(s.metrics.folds) + " folds>";
      });
}

}  // namespace elastic::python
