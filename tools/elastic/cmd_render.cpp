// `elastic render`: ray-traced PNG previews of mesh files (render/render.h), and the built-in
// emblem (image/emblem.h).
#include <Eigen/Geometry>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "aim.h"
#include "cli_common.h"
#include "command.h"
#include "elastic/core/error.h"
#include "elastic/image/emblem.h"
#include "elastic/image/image.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/render/camera.h"
#include "elastic/render/render.h"
#include "job_file.h"
#include "map_job.h"

namespace elastic::cli {
namespace {

struct RenderArgs {
  std::vector<std::string> meshes;
  std::string out;
  std::string emblem;
  std::string size;  ///< "WxH" or "N"; empty: 800x600 (render) or 512 (emblem)
  std::string view;
  double azimuth = 0.0;
  double elevation = 0.0;
  bool angles = false;  ///< --azimuth or --elevation given
  std::string up = "auto";
  double fov = kFramingFov;
  std::string wireframe;
  bool heatmap = false;
  bool edges = false;
  int samples = 4;
  double adaptive = RenderOptions{}.adaptive_threshold;  ///< --adaptive
  int ao = 0;
  unsigned long seed = 1;
  bool transparent = false;
  int threads = 0;
  bool quiet = false;
  long long max_image_pixels = kDefaultMaxImagePixels;  ///< --max-image-pixels, for textures
};

/// "W", "WxH" (also "W*H" and "WXH") as positive pixel counts up to 16384.
Eigen::Vector2i parse_size(const std::string& text) {
  const size_t x = text.find_first_of("xX*");
  try {
    size_t used = 0;
    const int w = std::stoi(text.substr(0, x), &used);
    if (used != (x == std::string::npos ? text.size() : x)) {
      throw std::invalid_argument("w");
    }
    int h = w;
    if (x != std::string::npos) {
      const std::string rest = text.substr(x + 1);
      h = std::stoi(rest, &used);
      if (used != rest.size()) {
        throw std::invalid_argument("h");
      }
    }
    if (w < 1 || h < 1 || w > 16384 || h > 16384) {
      throw std::out_of_range("size");
    }
    return {w, h};
  } catch (const std::logic_error&) {
    throw UsageError("--size " + text + ": expected W or WxH, 1..16384 pixels");
  }
}

int write_emblem(const RenderArgs& args) {
  if (!args.meshes.empty()) {
    throw UsageError("--emblem takes no mesh files");
  }
  const Eigen::Vector2i size =
      args.size.empty() ? Eigen::Vector2i(512, 512) : parse_size(args.size);
  if (size.x() != size.y()) {
    throw UsageError("--size " + args.size + ": the emblem is square");
  }
  if (size.x() < 8 || size.x() > 8192) {
    throw UsageError("--size: the emblem is 8..8192 pixels");
  }
  require_extension(args.emblem, {".png"}, "--emblem");
  write_png(args.emblem, make_emblem(size.x()));  // transparent outside the ring
  if (!args.quiet) {
    std::cout << args.emblem << ": emblem " << size.x() << " x " << size.y() << '\n';
  }
  return kOk;
}

/// Reads a mesh for drawing: colours and materials as the file has them; texture files that cannot
/// be read become warnings (the faces then show their material colour).
SceneObject load_object(const std::string& path, const RenderArgs& args,
                        std::vector<std::string>& warnings) {
  MeshReadResult read = read_mesh(path);
  for (const std::string& w : read.warnings) {
    std::string line = path;
    line += ": ";
    line += w;
    warnings.push_back(std::move(line));
  }
  SceneObject object{std::move(read.mesh), {}};
  if (object.mesh.has_texcoords() && !object.mesh.materials.empty()) {
    MaterialTextures textures = load_material_textures(
        object.mesh, {.max_pixels = args.max_image_pixels, .limit_name = "--max-image-pixels"});
    warnings.insert(warnings.end(), textures.warnings.begin(), textures.warnings.end());
    object.look.textures = std::move(textures.images);
  }
  return object;
}

int run_render(const RenderArgs& args) {
  if (!args.emblem.empty()) {
    return write_emblem(args);
  }
  if (args.meshes.empty()) {
    throw UsageError("render: give at least one MESH (or --emblem OUT.png)");
  }
  require_flag(args.out, "--out");
  require_extension(args.out, {".png"}, "--out");
  const Eigen::Vector2i size =
      args.size.empty() ? Eigen::Vector2i(800, 600) : parse_size(args.size);

  std::vector<std::string> warnings;
  Scene scene;
  for (const std::string& path : args.meshes) {
    scene.objects.push_back(load_object(path, args, warnings));
    ObjectLook& look = scene.objects.back().look;
    if (args.heatmap) {
      if (!scene.objects.back().mesh.has_face_colors()) {
        throw InvalidInputError(path, "--heatmap: the mesh has no per-face colours");
      }
      look.colors = SurfaceColoring::FaceColors;
    }
    look.wireframe = args.edges;
  }
  if (!args.wireframe.empty()) {
    SceneObject grid = load_object(args.wireframe, args, warnings);
    grid.look.surface = false;
    grid.look.wireframe = true;
    scene.objects.push_back(std::move(grid));
  }
  print_warnings(warnings, args.quiet);

  // The view: --view, turned by the angles if given; else the angles; else the first mesh's
  // vector area when it mostly faces one way (an open region), else an oblique default.
  const Eigen::Vector3d up = resolve_up(args.up, scene.objects.front().mesh);
  Eigen::Vector3d view;
  if (!args.view.empty()) {
    view = parse_point(args.view, "--view");
    if (!(view.norm() > 0.0)) {
      throw UsageError("--view: the direction is zero");
    }
    if (args.angles) {
      view = orbit_view(view, args.azimuth, args.elevation, up);
    }
  } else if (args.angles) {
    view = view_from_angles(args.azimuth, args.elevation, up);
  } else {
    const PolygonMesh& first = scene.objects.front().mesh;
    const Eigen::Vector3d area = vector_area(first);
    double total = 0.0;
    for (int f = 0; f < first.num_faces(); ++f) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      const auto face = first.face(f);
      for (size_t i = 0; i < face.size(); ++i) {
        n += first.positions[face[i]].cross(first.positions[face[(i + 1) % face.size()]]);
      }
      total += 0.5 * n.norm();
    }
    view = area.norm() > 0.3 * total ? area : view_from_angles(30.0, 25.0, up);
  }
  std::vector<Eigen::Vector3d> points;
  for (const SceneObject& object : scene.objects) {
    points.insert(points.end(), object.mesh.positions.begin(), object.mesh.positions.end());
  }
  // Framed at the default angle, then zoomed: --fov below 35 magnifies, above shows more.
  Camera camera = frame_points(points, view, kFramingFov, size.x(), size.y(), 0.9, up);
  camera.fov_deg = args.fov;

  RenderOptions options;
  options.samples_per_pixel = args.samples;
  options.adaptive_threshold = args.adaptive;
  options.ambient_occlusion_samples = args.ao;
  options.seed = args.seed;
  options.transparent_background = args.transparent;
  options.threads = args.threads;
  const Image image = render(scene, camera, options);
  write_png(args.out, image);
  if (!args.quiet) {
    std::cout << args.out << ": " << size.x() << " x " << size.y() << ", " << args.meshes.size()
              << (args.meshes.size() == 1 ? " mesh" : " meshes")
              << (args.wireframe.empty() ? "" : " + wireframe") << '\n';
  }
  return kOk;
}

}  // namespace

ELASTIC_COMMAND(
    "render", "Ray-trace mesh files to a PNG preview, or write the built-in emblem",
    [](CLI::App& sub) {
      auto args = std::make_shared<RenderArgs>();
      sub.add_option("meshes", args->meshes,
                     "Mesh files (OBJ with MTL textures, PLY with vertex/face colours, OFF, STL)");
      sub.add_option("--out", args->out, "Output PNG (.png; other extensions are refused)");
      sub.add_option("--emblem", args->emblem,
                     "Write the built-in emblem to this PNG instead (no meshes)");
      sub.add_option("--size", args->size,
                     "Image size WxH (default 800x600; the emblem: N, default 512)");
      sub.add_option("--view", args->view,
                     "Direction from the scene towards the eye, X,Y,Z (default: where the first "
                     "mesh faces, or azimuth 30, elevation 25)");
      auto* azimuth = sub.add_option("--azimuth", args->azimuth,
                                     "Degrees about --up (turns --view when given)");
      auto* elevation = sub.add_option("--elevation", args->elevation,
                                       "Degrees above the horizon (raises --view when given)");
      sub.add_option("--up", args->up,
                     "Up axis: auto (guessed from the first mesh, as `elastic info`), x, y, z, -x, "
                     "-y, -z or X,Y,Z")
          ->capture_default_str();
      sub.add_option("--fov", args->fov,
                     "Vertical field of view in degrees: the camera is placed for 35, so a "
                     "smaller angle zooms in and a larger one out")
          ->check(CLI::Range(1.0, 170.0))
          ->capture_default_str();
      sub.add_option("--wireframe", args->wireframe,
                     "Mesh whose polygon edges are drawn over the others (e.g. a particle grid)");
      sub.add_flag("--heatmap", args->heatmap,
                   "Colour by per-face colours (e.g. a distortion PLY)");
      sub.add_flag("--edges", args->edges, "Also draw the meshes' own polygon edges");
      sub.add_option("--samples", args->samples, "Jittered rays per pixel (antialiasing)")
          ->check(CLI::Range(1, 256))
          ->capture_default_str();
      sub.add_option(
             "--adaptive", args->adaptive,
             "Adaptive antialiasing: a pixel gets all --samples rays only where its centre "
             "ray and a neighbour's differ in object or by more than this in a colour "
             "channel, or a wire passes near (0..1; 0: every pixel gets all; docs/render.md)")
          ->check(CLI::Range(0.0, 1.0))
          ->capture_default_str();
      sub.add_option("--ao", args->ao, "Ambient-occlusion rays per hit (0: off)")
          ->check(CLI::Range(0, 256))
          ->capture_default_str();
      sub.add_option("--seed", args->seed, "Seed of the jitter and occlusion rays")
          ->capture_default_str();
      sub.add_flag("--transparent", args->transparent, "Transparent background");
      sub.add_option("--threads", args->threads, "Threads (0: all); the image does not change")
          ->check(CLI::Range(0, 1024))
          ->capture_default_str();
      sub.add_option("--max-image-pixels", args->max_image_pixels,
                     "Skip textures with more pixels (width x height), checked before decoding")
          ->check(CLI::PositiveNumber)
          ->capture_default_str();
      sub.add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
      sub.footer(
          "Examples:\n"
          "  elastic shapes --out meshes --only cap\n"
          "  elastic render meshes/cap_quads.obj --out cap.png --size 640x480 \\\n"
          "      --azimuth 30 --elevation 40 --edges\n"
          "  elastic render target.obj --wireframe grid.ply --out grid.png   # grid over surface\n"
          "  elastic render distortion.ply --heatmap --out heat.png --view 0,0,1\n"
          "  elastic render --emblem emblem.png --size 256\n"
          "The camera looks at the centre of everything drawn from as near as it fits (10% "
          "margin);\n"
          "--view points from the scene towards the eye. The same inputs and --seed give the same "
          "PNG on any thread count.");
      return [args, azimuth, elevation] {
        args->angles = azimuth->count() > 0 || elevation->count() > 0;
        return run_render(*args);
      };
    });

}  // namespace elastic::cli
