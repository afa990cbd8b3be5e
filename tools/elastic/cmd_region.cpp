// `elastic region MESH SPEC`: builds a region as `map` and `paste` would, reports its area,
// perimeter and geodesic radius, and with --preview renders the whole model with the region tinted
// and outlined, framed with its surroundings: a loop of seconds to aim a region.
#include <Eigen/Geometry>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "aim.h"
#include "cli_common.h"
#include "command.h"
#include "elastic/image/image.h"
#include "elastic/regions/region_spec.h"
#include "elastic/render/render.h"
#include "job_file.h"
#include "map_job.h"

namespace elastic::cli {
namespace {

struct RegionArgs {
  std::string mesh;
  std::string spec;
  std::string preview;  ///< --preview PNG
  int preview_size = 800;
  std::string up = "auto";
  double fov = kFramingFov;
  std::string anchor;  ///< --anchor X,Y,Z
  std::string scheme = "auto";
  int threads = 0;
  bool json = false;
  bool quiet = false;
};

nlohmann::json xyz(const Eigen::Vector3d& p) {
  return {p.x(), p.y(), p.z()};
}

/// "x,y,z" with 5 significant digits (ready to paste into a spec or --target-anchor).
std::string text(const Eigen::Vector3d& p) {
  std::ostringstream out;
  out << std::setprecision(5) << p.x() << ',' << p.y() << ',' << p.z();
  return out.str();
}

void render_preview(const RegionArgs& args, const LoadedSurface& loaded, const Region& region,
                    const RegionFigures& figures, const Eigen::Vector3d& up) {
  const LimitTessellation& tess = loaded.projector->tessellation();
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : tess.positions) box.extend(p);
  const double diagonal = box.diagonal().norm();

  Scene scene;
  SceneObject surface;
  surface.mesh.positions = tess.positions;
  for (const Eigen::Vector3i& t : tess.triangles) surface.mesh.add_face({t[0], t[1], t[2]});
  surface.look.colors = SurfaceColoring::Plain;
  scene.objects.push_back(std::move(surface));
  SceneObject tint;
  // Lifted by 0.2% of the diagonal: above the tessellation it lies on, too little to see.
  tint.mesh = lifted_region(region, 2e-3 * diagonal);
  tint.look.colors = SurfaceColoring::Plain;
  tint.look.plain_color = {0.98f, 0.62f, 0.25f};
  scene.objects.push_back(std::move(tint));
  SceneObject outline;
  outline.mesh = region_outline(region);
  outline.look.surface = false;
  outline.look.wireframe = true;
  outline.look.wire_color = {0.75f, 0.1f, 0.05f};
  outline.look.wire_width_px = std::max(2.0, args.preview_size / 250.0);
  scene.objects.push_back(std::move(outline));

  // The region fills 30% of the picture: the model around it shows where it is.
  const Camera camera = aim_camera(region.positions, figures.normal, up, args.fov,
                                   args.preview_size, args.preview_size, 0.3);
  RenderOptions options;
  options.threads = args.threads;
  write_png(args.preview, render(scene, camera, options));
}

int run_region(const RegionArgs& args) {
  if (!args.preview.empty()) require_extension(args.preview, {".png"}, "--preview");
  LoadedSurface loaded = load_surface(args.mesh, args.scheme);
  print_warnings(loaded.warnings, args.quiet);
  RegionSpec spec = parse_region_flag(args.spec, "SPEC");
  if (!args.anchor.empty()) spec.anchor = parse_point(args.anchor, "--anchor");
  const Region region = make_region(*loaded.projector, spec, {.name = "SPEC"});
  const RegionFigures figures = region_figures(region);
  std::string up_reason;
  const Eigen::Vector3d up = resolve_up(args.up, *loaded.mesh, &up_reason);
  if (!args.preview.empty()) render_preview(args, loaded, region, figures, up);

  if (args.json) {
    nlohmann::json out = {{"mesh", args.mesh},
                          {"region", args.spec},
                          {"area", figures.area},
                          {"perimeter", figures.perimeter},
                          {"geodesic_radius", figures.geodesic_radius},
                          {"vertices", region.num_vertices()},
                          {"triangles", region.num_triangles()},
                          {"boundary_vertices", region.boundary.size()},
                          {"centroid", xyz(figures.centroid)},
                          {"normal", xyz(figures.normal)},
                          {"anchor", xyz(figures.anchor)},
                          {"up", xyz(up)},
                          {"up_reason", up_reason}};
    if (!args.preview.empty()) out["preview"] = args.preview;
    std::cout << out.dump(2) << '\n';
    return kOk;
  }
  std::cout << std::setprecision(5) << args.spec << " on " << args.mesh << ":\n"
            << "  area " << figures.area << ", perimeter " << figures.perimeter
            << ", geodesic radius " << figures.geodesic_radius << '\n'
            << "  " << region.num_vertices() << " vertices, " << region.num_triangles()
            << " triangles, " << region.boundary.size() << " on the boundary\n"
            << "  centroid " << text(figures.centroid) << ", normal " << text(figures.normal)
            << ", anchor " << text(figures.anchor) << '\n'
            << "  up " << direction_name(up) << " (" << up_reason << ")\n";
  if (!args.preview.empty()) std::cout << "  wrote " << args.preview << '\n';
  return kOk;
}

}  // namespace
}  // namespace elastic::cli

ELASTIC_COMMAND(
    "region", "Build a region: its area, perimeter and geodesic radius, and a preview picture",
    [](CLI::App& sub) {
      using elastic::cli::kFramingFov;
      auto args = std::make_shared<elastic::cli::RegionArgs>();
      sub.add_option("mesh", args->mesh, "Mesh file (OBJ, OFF, PLY, STL)")->required();
      sub.add_option("spec", args->spec,
                     "Region: disk:X,Y,Z,R | points:FILE | boundary | uv:FILE (as --target-region)")
          ->required();
      sub.add_option("--preview", args->preview,
                     "Render the whole model with the region tinted and outlined to this PNG");
      sub.add_option("--preview-size", args->preview_size, "The preview is N x N pixels")
          ->check(CLI::Range(64, 4096));
      sub.add_option("--up", args->up,
                     "Up axis of the picture: auto (guessed, as `elastic info`), x, y, z, -x, -y, "
                     "-z or X,Y,Z");
      sub.add_option("--fov", args->fov,
                     "Vertical field of view in degrees: below 35 zooms in, above zooms out")
          ->check(CLI::Range(1.0, 170.0));
      sub.add_option("--anchor", args->anchor,
                     "X,Y,Z: start of the boundary correspondence (as --target-anchor)");
      sub.add_option("--scheme", args->scheme, "Subdivision scheme")
          ->check(CLI::IsMember({"auto", "loop", "catmull-clark"}));
      sub.add_option("--threads", args->threads, "Render threads (0: all)")
          ->check(CLI::Range(0, 1024));
      sub.add_flag("--json", args->json, "Print the figures as JSON instead of text");
      sub.add_flag("-q,--quiet", args->quiet, "No warnings: only results");
      sub.footer(
          "Example (aiming a region on spot, y-up):\n"
          "  elastic locate ../shared/meshes/spot.obj 0,0.6,0.8      # -> disk:... spec\n"
          "  elastic region ../shared/meshes/spot.obj disk:0.0197,0.452,0.741,0.25 \\\n"
          "      --preview region.png\n"
          "  elastic paste --source-image logo.png --target ../shared/meshes/spot.obj \\\n"
          "      --target-region disk:0.0197,0.452,0.741,0.25 --out pasted/ --preview\n"
          "The geodesic radius is the largest distance from the boundary inside the region, along "
          "its edges\n(for a disk:...,R about R).");
      return [args] { return elastic::cli::run_region(*args); };
    });
