// `elastic paste`: map the source region onto the target region (the `elastic map` flags), then
// carry the source's colour (and optionally height and geometric detail) across and write the
// outputs: the textured decal (OBJ + MTL + PNG), the per-vertex colour PLY, the target texture
// with the region baked in, the displaced mesh, the pasted detail. The paste itself is the
// library's (transfer/paste.h: paste, write_paste); this file turns flags into its options, and
// adds the staged output folder, the distortion report and heatmaps, the previews and the printing.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "aim.h"
#include "cli_common.h"
#include "command.h"
#include "compare_methods.h"
#include "elastic/core/error.h"
#include "elastic/core/staged_folder.h"
#include "elastic/image/image.h"
#include "elastic/mesh/default_material.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/metrics/heatmap.h"
#include "elastic/transfer/color_source.h"
#include "elastic/transfer/output_folder.h"
#include "elastic/transfer/painted_surface.h"
#include "elastic/transfer/paste.h"
#include "job_file.h"
#include "map_job.h"
#include "paste_preview.h"
#include "verdict.h"

namespace elastic::cli {
namespace {

struct PasteArgs {
  MapJob job;
  std::string out;                // --out DIR
  std::string color = "auto";     // --color auto|texture|vertex|none
  std::string texture;            // --texture IMAGE (the source's texture)
  int texture_resolution = 0;     // --texture-resolution N (0: off)
  long min_vertices = 100'000;    // --min-vertices
  double max_edge = 0.0;          // --max-edge L
  int resolution = 0;             // --target-tessellation N (old name --resolution; 0: auto)
  int max_levels = 8;             // --max-levels
  long max_vertices = 2'000'000;  // --max-vertices
  bool bake = false;              // --bake
  std::string bake_texture;       // --bake-texture IMAGE (default: the target's map_Kd)
  double feather = 0.0;           // --feather TEXELS
  double alpha = 1.0;             // --alpha A
  std::string height;             // --height IMAGE|luminance
  double height_scale = 0.1;      // --height-scale
  double height_zero = 0.0;       // --height-zero
  double falloff = 0.0;           // --falloff W
  std::string detail;             // --detail MESH
  double detail_scale = 1.0;      // --detail-scale
  bool preview = false;           // --preview
  int preview_size = 800;         // --preview-size N
  std::string up = "auto";        // --up: the previews' up axis
  long frames = 0;                // --frames K (every K-th relaxation iteration)
  std::string baseline = "none";  // --baseline lscm|arap|dcm|none
};

bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ec;
  if (std::filesystem::exists(a, ec) && std::filesystem::exists(b, ec)) {
    return std::filesystem::equivalent(a, b, ec);
  }
  return std::filesystem::weakly_canonical(a, ec) == std::filesystem::weakly_canonical(b, ec);
}

// Checks that need only the input files, before mapping: a colour source that exists, a target
// texture to bake into, readable height images and detail meshes.
void check_inputs(const PasteArgs& a) {
  if (a.color != "auto" && a.color != "texture" && a.color != "vertex" && a.color != "none") {
    throw UsageError("--color must be auto, texture, vertex or none, not '" + a.color + "'");
  }
  if (!(a.alpha >= 0.0 && a.alpha <= 1.0)) throw UsageError("--alpha must be in [0, 1]");
  if (!(a.feather >= 0.0)) throw UsageError("--feather must be >= 0 (texels)");
  if (!(a.max_edge >= 0.0)) throw UsageError("--max-edge must be >= 0");
  if (!a.texture.empty() && !std::filesystem::exists(a.texture)) {
    throw IoError(a.texture, "no such file (--texture)");
  }
  // Images are held to --max-image-pixels from their headers now, before any work.
  if (!a.texture.empty()) read_image_info(a.texture, image_read_options(a.job));
  if (a.color == "texture" && a.job.source_image.empty() && a.texture.empty()) {
    const PolygonMesh source = read_mesh(a.job.source).mesh;
    if (!source.has_texcoords()) {
      throw InvalidInputError(a.job.source,
                              "has no texture coordinates (needed for --color texture)");
    }
    if (first_diffuse_texture(source).empty()) {
      throw InvalidInputError(a.job.source,
                              "has no material texture (map_Kd); give one with --texture");
    }
  }
  if (a.color == "vertex" && !a.job.source.empty() && a.job.source_image.empty()) {
    if (!read_mesh(a.job.source).mesh.has_vertex_colors()) {
      throw InvalidInputError(a.job.source,
                              "has no per-vertex colours (needed for --color vertex)");
    }
  }
  if (a.bake) {
    const PolygonMesh target = read_mesh(a.job.target).mesh;
    if (!target.has_texcoords()) {
      throw InvalidInputError(a.job.target, "has no texture coordinates to bake into (--bake)");
    }
    const std::filesystem::path image = a.bake_texture.empty()
                                            ? first_diffuse_texture(target)
                                            : std::filesystem::path(a.bake_texture);
    if (image.empty()) {
      throw InvalidInputError(a.job.target,
                              "has no material texture (map_Kd) to bake into; give --bake-texture");
    }
    if (!std::filesystem::exists(image))
      throw IoError(image.string(), "no such file (bake texture)");
    read_image_info(image, image_read_options(a.job));
    if (same_file(image, std::filesystem::path(a.out) / "baked.png")) {
      throw UsageError("--out would overwrite the target's texture " + image.string() +
                       " with baked.png; choose another folder");
    }
  }
  if (!a.height.empty() && a.height != "luminance" && !std::filesystem::exists(a.height)) {
    throw IoError(a.height, "no such file (--height)");
  }
  if (!a.height.empty() && a.height != "luminance") {
    read_image_info(a.height, image_read_options(a.job));
  }
  if (!a.detail.empty() && !std::filesystem::exists(a.detail)) {
    throw IoError(a.detail, "no such file (--detail)");
  }
}

// The colour scale of the heatmaps, as the report records it (docs/file-formats.md).
nlohmann::json heatmap_scale_json(const HeatmapOptions& scale,
                                  const std::vector<std::string>& methods) {
  const auto rgb = [](const Eigen::Vector3f& c) {
    return nlohmann::json::array({c.x(), c.y(), c.z()});
  };
  const std::vector<Eigen::Vector3f> stops = heatmap_ramp_stops();
  return {{"metric", std::string(to_string(scale.metric))},
          {"min", scale.low.value_or(0.0)},
          {"max", scale.high.value_or(0.0)},
          {"percentile", scale.percentile},
          {"colors",
           {{"min", rgb(stops[0])},
            {"mid", rgb(stops[1])},
            {"max", rgb(stops[2])},
            {"fold", rgb(scale.fold_color)},
            {"excluded", rgb(scale.excluded_color)}}},
          {"methods", methods}};
}

// The library's paste options (transfer/paste.h) from the flags. `detail` is the --detail mesh
// (read by the caller), or null.
PasteOptions paste_options(const PasteArgs& a, const PolygonMesh* detail) {
  PasteOptions o;
  o.color = parse_paste_color(a.color, "--color");
  o.texture = a.texture;
  o.image_read = image_read_options(a.job);
  o.resolution = a.resolution;
  o.max_edge = a.max_edge;
  o.texture_resolution = a.texture_resolution;
  o.max_levels = a.max_levels;
  o.min_vertices = a.min_vertices;
  o.max_vertices = a.max_vertices;
  o.bake = a.bake;
  o.bake_texture = a.bake_texture;
  o.alpha = static_cast<float>(a.alpha);
  o.feather = a.feather;
  o.height = a.height.empty()          ? PasteHeight::None
             : a.height == "luminance" ? PasteHeight::Luminance
                                       : PasteHeight::Image;
  if (o.height == PasteHeight::Image) o.height_image = a.height;
  o.height_zero = a.height_zero;
  o.height_scale = a.height_scale;
  o.falloff = a.falloff;
  o.detail = detail;
  o.detail_name = a.detail;
  o.detail_scale = a.detail_scale;
  return o;
}

// The map job of a paste: the painted mesh's memory is checked with the map's before the map
// runs: the target tessellated at --target-tessellation N (N^2 vertices per control face; auto:
// the budget of auto_target_resolution, painted_surface.h), and the region refined to
// --min-vertices (to --max-vertices when --max-edge or --texture-resolution drive it).
MapJob paste_map_job(const PasteArgs& a) {
  MapJob job = a.job;
  const bool refined_by_edges = a.max_edge > 0.0 || a.texture_resolution > 0;
  job.extra_bytes = kPasteBytesPerVertex *
                    static_cast<double>(refined_by_edges ? a.max_vertices : a.min_vertices);
  // Auto: about kAutoTargetTriangles triangles (half as many vertices) over the whole target, or
  // the control mesh itself at one segment per edge when that is more.
  const int per_edge = a.resolution > 0 ? a.resolution : 1;
  if (a.resolution == 0) {
    job.extra_bytes += kPasteBytesPerVertex * 0.5 * static_cast<double>(kAutoTargetTriangles);
  }
  job.extra_bytes_per_target_face = kPasteBytesPerVertex * static_cast<double>(per_edge) * per_edge;
  job.extra_what = "--target-tessellation " +
                   (a.resolution > 0 ? std::to_string(a.resolution) : std::string("auto")) +
                   (refined_by_edges ? " --max-vertices " + std::to_string(a.max_vertices)
                                     : " --min-vertices " + std::to_string(a.min_vertices));
  return job;
}

// Relaxation frames for the preview's animation (positions every --frames iterations).
struct RelaxationFrames {
  std::vector<Eigen::Matrix3Xd> positions;
  std::vector<long> iterations;
  FrameCallback callback() {
    return [this](const RelaxationFrame& f) {
      constexpr size_t kMostFrames = 64;  // a contact sheet stays readable
      if (positions.size() < kMostFrames) {
        positions.push_back(*f.positions);
        iterations.push_back(f.iteration);
      }
    };
  }
};

// The report's "paste" block (docs/file-formats.md).
nlohmann::json paste_json(const PasteResult& pasted, double seconds) {
  const TargetSamples& samples = pasted.painted.samples;
  nlohmann::json paste;
  paste["target_tessellation"] = pasted.painted.resolution;
  paste["levels"] = samples.levels;
  paste["limited"] = samples.limited;
  paste["region_vertices"] = samples.num_vertices();
  paste["region_triangles"] = samples.num_triangles();
  paste["mesh_vertices"] = pasted.painted.num_vertices();
  paste["mesh_triangles"] = pasted.painted.num_triangles();
  paste["max_edge_length"] = samples.max_edge_length;
  paste["max_source_edge_length"] = samples.max_source_edge_length;
  paste["boundary_by_arc_length"] = samples.boundary_by_arc_length;
  paste["nudged"] = samples.nudged;
  paste["unresolved"] = samples.unresolved;
  const std::optional<ColorSource>& colors = pasted.colors;
  paste["color"] = !colors                                           ? "none"
                   : colors->kind() == ColorSourceKind::Texture      ? "texture"
                   : colors->kind() == ColorSourceKind::VertexColors ? "vertex"
                                                                     : "scalar";
  if (pasted.baked) {
    paste["texels_painted"] = pasted.baked->texels_painted;
    paste["texels_changed"] = pasted.baked->texels_changed;
  }
  if (pasted.displaced) paste["max_displacement"] = pasted.displaced->displacement.max_displacement;
  if (pasted.detail) {
    paste["detail_outside"] = pasted.detail->outside;
    paste["detail_dropped_faces"] = pasted.detail->dropped_faces;
  }
  paste["seconds"] = seconds;
  return paste;
}

// The methods the report, heatmaps and headline show: ElasticPaint and the --baseline, measured.
bool shown(const MethodMeasurement& m) {
  return m.ok && m.name != "naive";
}

// Distortion of the map (docs/metrics.md), and of a baseline on the same grid when asked, into
// the report; the distortion heatmap of Fig. 9 (symmetric Dirichlet per grid triangle, green =
// perfect) as PLY face and vertex colours, on one colour scale for every method measured (the
// preview's), recorded in the report. heatmap.ply is ElasticPaint's, heatmap_<baseline>.ply the
// baseline's. Returns the scale.
HeatmapOptions write_distortion(const std::vector<MethodMeasurement>& methods, OutputFolder& folder,
                                nlohmann::json& report) {
  nlohmann::json metrics = nlohmann::json::object();
  for (const MethodMeasurement& m : methods) metrics[m.name] = measurement_json(m);
  report["metrics"] = metrics;
  std::vector<const MapMetrics*> measured_metrics;
  std::vector<std::string> measured_names;
  for (const MethodMeasurement& m : methods) {
    if (!shown(m)) continue;
    measured_metrics.push_back(&m.metrics);
    measured_names.push_back(m.name);
  }
  HeatmapOptions heat_scale;
  if (measured_metrics.empty()) return heat_scale;
  heat_scale = shared_heatmap_scale(measured_metrics);
  for (const MethodMeasurement& m : methods) {
    if (!shown(m)) continue;
    const std::string name = m.name == "elastic" ? "heatmap.ply" : "heatmap_" + m.name + ".ply";
    folder.write_mesh(name, make_heatmap(m.positions, m.metrics, heat_scale).mesh);
  }
  report["heatmap"] = heatmap_scale_json(heat_scale, measured_names);
  return heat_scale;
}

// The preview pictures (--preview) and relaxation frames (--frames) into `stage`; returns the
// written files.
std::vector<std::filesystem::path> write_previews(const PasteArgs& a, const MapSession& session,
                                                  const PasteResult& pasted,
                                                  const std::vector<MethodMeasurement>& methods,
                                                  const HeatmapOptions& heat_scale,
                                                  const RelaxationFrames& frames,
                                                  const std::filesystem::path& stage) {
  const PaintedSurface& painted = pasted.painted;
  const MapResult& result = session.result;
  PolygonMesh surface, outside;
  surface.positions = painted.positions;
  outside.positions = painted.positions;
  for (int t = 0; t < painted.num_triangles(); ++t) {
    const Eigen::Vector3i& c = painted.triangles[static_cast<size_t>(t)];
    surface.add_face({c[0], c[1], c[2]});
    if (!painted.triangle_inside[static_cast<size_t>(t)]) outside.add_face({c[0], c[1], c[2]});
  }
  const PreviewWriter preview(session.target_region, std::move(surface), std::move(outside),
                              {.width = a.preview_size,
                               .height = a.preview_size,
                               .threads = a.job.threads,
                               .up = resolve_up(a.up, session.target.surface->control_mesh())});
  const ParticleGrid& grid = result.sampling.grid;
  std::vector<std::filesystem::path> files;
  if (a.preview) {
    const std::optional<ColorSource>& colors = pasted.colors;
    PolygonMesh shown_mesh =
        colors && colors->kind() == ColorSourceKind::Texture
            ? make_decal_mesh(painted, *colors, {.texture_path = stage / "painted_decal.png"})
        : colors ? make_colored_mesh(painted, *colors)
                 : PolygonMesh();
    // A height paste is shown displaced: the relief appears as shading, in preview.png under
    // the colours and in preview_height.png alone (plain grey).
    const std::vector<Eigen::Vector3d>* displaced =
        pasted.displaced ? &pasted.displaced->positions : nullptr;
    if (displaced && shown_mesh.positions.size() == displaced->size()) {
      shown_mesh.positions = *displaced;
    }
    if (shown_mesh.num_faces() > 0)
      files.push_back(preview.write_feature(stage / "preview.png", shown_mesh));
    if (displaced) {
      PolygonMesh relief;
      relief.positions = *displaced;
      for (const Eigen::Vector3i& c : painted.triangles) relief.add_face({c[0], c[1], c[2]});
      files.push_back(preview.write_feature(stage / "preview_height.png", relief));
    }
    files.push_back(preview.write_grids(stage / "preview_grid.png", grid,
                                        {&result.naive.positions, &result.relaxation.positions},
                                        {"naive map", "ElasticPaint"}));
    std::vector<const Eigen::Matrix3Xd*> positions;
    std::vector<const MapMetrics*> measured;
    std::vector<std::string> labels;
    for (const MethodMeasurement& m : methods) {
      if (!shown(m)) continue;
      positions.push_back(&m.positions);
      measured.push_back(&m.metrics);
      labels.push_back(m.name == "elastic" ? "ElasticPaint" : m.name);
    }
    if (!positions.empty()) {
      files.push_back(preview.write_heatmaps(stage / "preview_heatmap.png", positions, measured,
                                             labels, heat_scale));
    }
  }
  if (!frames.positions.empty()) {
    for (const auto& f :
         preview.write_frames(stage / "frames", grid, frames.positions, frames.iterations)) {
      files.push_back(f);
    }
  }
  return files;
}

// What the paste prints: the map's summary, the paste's line and files, and the headline
// (distortion against the baseline on the same grid).
void print_paste(const PasteArgs& a, const MapSession& session, const PasteResult& pasted,
                 const std::vector<MethodMeasurement>& methods,
                 const std::vector<std::filesystem::path>& files,
                 const std::filesystem::path& report_path, double seconds) {
  print_map_summary(a.job, session);
  if (!a.job.quiet) {
    const TargetSamples& samples = pasted.painted.samples;
    std::cout << "paste: " << samples.num_triangles() << " region triangles (" << samples.levels
              << " refinement levels) in " << pasted.painted.num_triangles() << " triangles, "
              << seconds << " s\n";
    for (const auto& f : files) std::cout << "  wrote " << f.string() << '\n';
    std::cout << "  report " << report_path.string() << '\n';
  }
  for (const MethodMeasurement& m : methods) {
    if (!shown(m)) continue;
    std::cout << (m.name == "elastic" ? "ElasticPaint" : m.name) << ": length energy "
              << m.metrics.length_energy << ", symmetric Dirichlet "
              << m.metrics.symmetric_dirichlet << ", stretch L2 " << m.metrics.stretch_l2
              << ", folds " << m.metrics.folds << ", " << m.seconds << " s\n";
  }
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int run_paste(const PasteArgs& a, const CLI::App& sub) {
  require_flag(a.out, "--out");
  require_flag(a.job.target, "--target");
  const auto start = std::chrono::steady_clock::now();
  const std::filesystem::path dir(a.out);
  check_inputs(a);
  // Every path is checked before any work. The files go to a staging folder beside --out and
  // appear there together at the end (core/staged_folder.h); a --report inside --out is part of
  // the set, one elsewhere is written after it.
  StagedFolder staged(dir, "--out");
  const std::filesystem::path stage = staged.staging();
  std::filesystem::path report_path = stage / "report.json";
  if (!a.job.report.empty()) {
    const std::filesystem::path wanted = std::filesystem::absolute(a.job.report).lexically_normal();
    report_path = wanted.parent_path() == staged.destination() ? stage / wanted.filename() : wanted;
    if (report_path == wanted) check_output_file(a.job.report, "--report");
  }

  RelaxationFrames frames;
  const std::unique_ptr<MapSession> session =
      run_map_job(paste_map_job(a), terminal_progress(a.job.quiet),
                  a.frames > 0 ? frames.callback() : FrameCallback(), a.frames);
  end_progress_line();
  nlohmann::json report = map_report(a.job, *session, job_of(sub));

  // The paste itself (transfer/paste.h). Every file goes through the folder, which keeps it
  // self-contained: textures are copied in and referenced by bare names, every OBJ face has a
  // material.
  const auto paste_start = std::chrono::steady_clock::now();
  const std::optional<PolygonMesh> detail =
      a.detail.empty() ? std::nullopt : std::optional<PolygonMesh>(read_mesh(a.detail).mesh);
  const PasteResult pasted =
      paste(*session->source.projector, session->source_region, *session->target.projector,
            session->target_region, session->result, paste_options(a, detail ? &*detail : nullptr));
  if (pasted.baked && same_file(dir / "baked.png", pasted.bake_input)) {
    throw UsageError("refusing to overwrite the input texture " + pasted.bake_input.string());
  }
  OutputFolder folder(stage);
  write_paste(folder, pasted);
  report["paste"] = paste_json(pasted, seconds_since(paste_start));

  CompareOptions compare;
  compare.baselines.clear();
  if (a.baseline != "none")
    compare.baselines.push_back(parse_baseline_kind(a.baseline, "--baseline"));
  const std::vector<MethodMeasurement> methods = compare_methods(*session, compare);
  const HeatmapOptions heat_scale = write_distortion(methods, folder, report);
  std::vector<std::filesystem::path> files = folder.files();
  if (a.preview || a.frames > 0) {
    for (auto& f : write_previews(a, *session, pasted, methods, heat_scale, frames, stage)) {
      files.push_back(std::move(f));
    }
  }

  // The report names the files where they will be (the set is moved into place below).
  for (auto& f : files) f = dir / staged.final_path(f).lexically_relative(staged.destination());
  nlohmann::json list = nlohmann::json::array();
  for (const auto& f : files) list.push_back(f.string());
  report["files"] = list;
  if (!folder.warnings().empty()) report["paste"]["warnings"] = folder.warnings();
  print_warnings(folder.warnings(), a.job.quiet);
  const bool report_in_set = report_path.parent_path() == stage;
  if (report_in_set) write_report(report_path.string(), report);
  staged.commit();
  if (report_in_set) {
    report_path = a.job.report.empty() ? dir / "report.json" : std::filesystem::path(a.job.report);
  } else {
    write_report(report_path.string(), report);
    report_path = a.job.report;
  }
  print_paste(a, *session, pasted, methods, files, report_path, seconds_since(start));
  return finish(judge_map(a.job, *session));
}

}  // namespace
}  // namespace elastic::cli

ELASTIC_COMMAND(
    "paste", "Map a source region onto a target region and paste its colour, height or detail",
    [](CLI::App& sub) {
      auto a = std::make_shared<elastic::cli::PasteArgs>();
      elastic::cli::add_map_flags(sub, a->job);
      sub.add_option("--out", a->out, "Output folder (required)");
      sub.add_option("--color", a->color, "Colour source: auto, texture, vertex or none");
      sub.add_option("--texture", a->texture, "The source's texture image (default: its map_Kd)");
      sub.add_option("--texture-resolution", a->texture_resolution,
                     "Refine the region to about one source texel of an N x N texture (0: off)");
      sub.add_option("--max-edge", a->max_edge, "Refine the region to edges at most this long");
      // --resolution: the name before 0.2, kept as an alias for one release (docs/cli.md).
      sub.add_option("--target-tessellation,--resolution", a->resolution,
                     "Tessellation of the painted target outside the region: segments per "
                     "control edge; 0: auto, about 262,144 triangles for the whole target and at "
                     "most 8 per edge (old name --resolution)")
          ->check(CLI::Range(0, 1024));
      sub.add_option("--max-levels", a->max_levels, "Most refinement levels")
          ->check(CLI::Range(0, 12));
      sub.add_option("--min-vertices", a->min_vertices,
                     "Refine the region to at least this many vertices (a smooth colour PLY)");
      sub.add_option("--max-vertices", a->max_vertices, "Most region vertices after refinement");
      sub.add_flag("--bake", a->bake, "Bake the colour into the target's own texture (baked.png)");
      sub.add_option("--bake-texture", a->bake_texture,
                     "Texture to bake into (default: the target's map_Kd); never overwritten");
      sub.add_option("--feather", a->feather, "Feathered edge of the bake, in texels");
      sub.add_option("--alpha", a->alpha, "Opacity of the baked colour, 0..1");
      sub.add_option("--height", a->height,
                     "Height image (looked up with the source's UVs) or 'luminance' of the colour");
      sub.add_option("--height-scale", a->height_scale, "Height units -> target length units");
      sub.add_option("--height-zero", a->height_zero, "The image value that means height 0");
      sub.add_option("--falloff", a->falloff, "Displacement ramps up over this distance inside");
      sub.add_option("--detail", a->detail, "Detail mesh over the source surface to paste");
      sub.add_option("--detail-scale", a->detail_scale, "Multiplies the detail's offsets");
      sub.add_flag("--preview", a->preview,
                   "Render preview.png (the feature), preview_grid.png (naive vs relaxed grid) "
                   "and preview_heatmap.png (distortion, beside --baseline)");
      sub.add_option("--preview-size", a->preview_size, "Preview pictures are N x N pixels")
          ->check(CLI::Range(64, 4096));
      sub.add_option("--up", a->up,
                     "Up axis of the previews: auto (guessed from the target, as `elastic info`), "
                     "x, y, z, -x, -y, -z or X,Y,Z");
      sub.add_option("--frames", a->frames,
                     "Render every K-th relaxation iteration to frames/ with a contact sheet")
          ->check(CLI::Range(0L, 1000000L));
      sub.add_option("--baseline", a->baseline,
                     "Also measure this baseline on the same grid (report, heatmap, headline)")
          ->check(CLI::IsMember({"none", "lscm", "arap", "dcm"}));
      sub.footer(
          "Example:\n  elastic paste --source-image logo.png --target meshes/cap_quads.obj "
          "--target-region disk:0,0,1,0.5 \\\n      --particles 2000 --out pasted/\n"
          "writes pasted/painted.obj (+ .mtl, painted_decal.png), pasted/colors.ply, "
          "pasted/heatmap.ply and pasted/report.json.\n"
          "\n"
          "Orientation: the feature's turn on the target is set by the boundary correspondence,\n"
          "which starts at an anchor on each region's boundary: the source anchor lands on the\n"
          "target anchor and the boundaries run counter-clockwise (seen from the normals) from\n"
          "there. Without anchors the turn is chosen for the least distortion (--boundary-offset\n"
          "auto), so it may not be upright. To fix it, give both anchors and --boundary-offset\n"
          "anchor; each anchor is the boundary point nearest X,Y,Z. E.g. to put the top edge\n"
          "of an image (on the plane z = 0, --image-width wide and centred at the origin: the\n"
          "middle of its top side is 0,1,0 for a square image of width 2) towards the top of\n"
          "a y-up target:\n"
          "  elastic paste --source-image logo.png --source-anchor 0,1,0 \\\n"
          "      --target ../shared/meshes/spot.obj --target-region disk:0.0197,0.452,0.741,0.25 "
          "\\\n"
          "      --target-anchor 0.0197,0.75,0.741 --boundary-offset anchor --out pasted/ "
          "--preview\n"
          "`elastic locate` and `elastic region --preview` find the points (docs/cli.md, aiming).\n"
          "\n"
          "Or place the image as a decal, no target region drawn: centre, up angle, scale\n"
          "(docs/transfer.md, placed decals):\n"
          "  elastic paste --source-image logo.png --image-width 0.3 \\\n"
          "      --target ../shared/meshes/spot.obj --target-place 0.356,-0.032,0.073,30,1 "
          "--out decal/ --preview");
      return [a, &sub] { return elastic::cli::run_paste(*a, sub); };
    });
