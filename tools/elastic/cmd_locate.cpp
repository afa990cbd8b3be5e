// `elastic locate MESH X,Y,Z`: the closest point of the limit surface to a point, its normal and a
// ready `disk:` spec, so that a region can be aimed without reading vertex coordinates by hand.
#include <Eigen/Geometry>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_common.h"
#include "command.h"
#include "job_file.h"
#include "map_job.h"

namespace elastic::cli {
namespace {

struct LocateArgs {
  std::string mesh;
  std::string point;
  double radius = 0.0;  ///< --radius of the suggested disk (0: a tenth of the box diagonal)
  std::string scheme = "auto";
  bool json = false;
  bool quiet = false;
};

/// "x,y,z" with 6 significant digits; coordinates below 1e-9 of `scale` (round-off of a zero)
/// are written as 0.
std::string point_text(const Eigen::Vector3d& p, double scale = 1.0) {
  std::ostringstream out;
  out << std::setprecision(6);
  for (int k = 0; k < 3; ++k) {
    out << (k > 0 ? "," : "") << (std::abs(p[k]) < 1e-9 * scale ? 0.0 : p[k]);
  }
  return out.str();
}

int run_locate(const LocateArgs& args) {
  const Eigen::Vector3d query = parse_point(args.point, "POINT");
  if (!(args.radius >= 0.0)) throw UsageError("--radius must be >= 0");
  LoadedSurface loaded = load_surface(args.mesh, args.scheme);
  print_warnings(loaded.warnings, args.quiet);
  const ClosestPoint cp = loaded.projector->closest(query);
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : loaded.projector->tessellation().positions) box.extend(p);
  const double radius = args.radius > 0.0 ? args.radius : 0.1 * box.diagonal().norm();
  std::ostringstream radius_text;
  radius_text << std::setprecision(4) << radius;
  const double scale = box.diagonal().norm();
  const std::string disk = "disk:" + point_text(cp.position, scale) + "," + radius_text.str();

  if (args.json) {
    const nlohmann::json out = {{"mesh", args.mesh},
                                {"query", {query.x(), query.y(), query.z()}},
                                {"point", {cp.position.x(), cp.position.y(), cp.position.z()}},
                                {"normal", {cp.normal.x(), cp.normal.y(), cp.normal.z()}},
                                {"distance", cp.distance},
                                {"on_boundary", cp.on_boundary},
                                {"ptex_face", cp.point.face},
                                {"ptex_uv", {cp.point.u, cp.point.v}},
                                {"radius", radius},
                                {"disk", disk}};
    std::cout << out.dump(2) << '\n';
    return kOk;
  }
  std::cout << std::setprecision(6)
            << "closest limit-surface point: " << point_text(cp.position, scale) << "  ("
            << cp.distance << " from " << point_text(query) << ")\n"
            << "normal: " << point_text(cp.normal) << '\n'
            << "ptex face " << cp.point.face << " at (u, v) = (" << cp.point.u << ", " << cp.point.v
            << ")" << (cp.on_boundary ? ", on the surface's boundary" : "") << '\n'
            << "region spec: " << disk << '\n';
  return kOk;
}

}  // namespace
}  // namespace elastic::cli

ELASTIC_COMMAND(
    "locate", "The closest limit-surface point to X,Y,Z, its normal and a ready disk: spec",
    [](CLI::App& sub) {
      auto args = std::make_shared<elastic::cli::LocateArgs>();
      sub.add_option("mesh", args->mesh, "Mesh file (OBJ, OFF, PLY, STL)")->required();
      sub.add_option("point", args->point, "The point X,Y,Z (e.g. read off `elastic info`'s box)")
          ->required();
      sub.add_option("--radius", args->radius,
                     "Radius of the suggested disk: spec (0: a tenth of the box diagonal)")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--scheme", args->scheme, "Subdivision scheme")
          ->check(CLI::IsMember({"auto", "loop", "catmull-clark"}));
      sub.add_flag("--json", args->json, "Print the answer as JSON instead of text");
      sub.add_flag("-q,--quiet", args->quiet, "No warnings: only results");
      sub.footer(
          "Example:\n  elastic locate ../shared/meshes/spot.obj 0,0.6,0.8\n"
          "prints the nearest point of the smooth (limit) surface, its unit normal, and a spec\n"
          "such as disk:0.0197,0.452,0.741,0.25 to pass to `elastic region` or --target-region.");
      return [args] { return elastic::cli::run_locate(*args); };
    });
