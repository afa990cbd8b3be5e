// `elastic info MESH`: mesh statistics, validation findings, and the limit surface's curvature
// statistics.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "command.h"
#include "elastic/core/atomic_file.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/mesh/mesh_validation.h"
#include "elastic/render/up_axis.h"
#include "elastic/surface/limit_surface.h"
#include "elastic/surface/limit_tessellation.h"

namespace elastic::cli {
namespace {

struct InfoArgs {
  std::string mesh;
  std::string scheme = "auto";
  int resolution = 8;
  std::string json;
  bool repair = true;
  bool quiet = false;
};

struct Stats {
  double min = 0, median = 0, max = 0, mean = 0;
};

Stats stats_of(std::vector<double> values) {
  Stats s;
  if (values.empty()) {
    return s;
  }
  std::sort(values.begin(), values.end());
  s.min = values.front();
  s.max = values.back();
  s.median = values[values.size() / 2];
  double sum = 0;
  for (double v : values) {
    sum += v;
  }
  s.mean = sum / static_cast<double>(values.size());
  return s;
}

nlohmann::json to_json(const Stats& s) {
  return {{"min", s.min}, {"median", s.median}, {"max", s.max}, {"mean", s.mean}};
}

// Curvature at every tessellation vertex; integrated Gaussian curvature by vertex areas (one third
// of the incident triangles' areas) to check Gauss-Bonnet on closed surfaces: integral K dA =
// 2 pi chi.
struct CurvatureSurvey {
  size_t vertices = 0;
  std::vector<double> k1, k2, mean, gauss, r;
  double total_area = 0, integral_gauss = 0;
  Eigen::Vector3d lo, hi;  // the tessellation's bounding box
};

CurvatureSurvey survey_curvature(const LimitSurface& surface, const LimitTessellation& tess) {
  CurvatureSurvey c;
  const size_t n = tess.positions.size();
  c.vertices = n;
  std::vector<double> k1(n), k2(n), mean(n), gauss(n), r(n);
  std::vector<double> area(n, 0.0);
  for (const Eigen::Vector3i& t : tess.triangles) {
    const double a = 0.5 * (tess.positions[t[1]] - tess.positions[t[0]])
                               .cross(tess.positions[t[2]] - tess.positions[t[0]])
                               .norm();
    for (int k = 0; k < 3; ++k) {
      area[t[k]] += a / 3.0;
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const SurfaceCurvature k = surface.curvature(tess.points[i]);
    k1[i] = k.k1;
    k2[i] = k.k2;
    mean[i] = k.mean;
    gauss[i] = k.gaussian;
    r[i] = std::sqrt(0.5 * (k.k1 * k.k1 + k.k2 * k.k2));  // the sampling weight of eq. 8
    c.total_area += area[i];
    c.integral_gauss += k.gaussian * area[i];
  }
  c.k1 = std::move(k1);
  c.k2 = std::move(k2);
  c.mean = std::move(mean);
  c.gauss = std::move(gauss);
  c.r = std::move(r);
  c.lo = tess.positions.front();
  c.hi = c.lo;
  for (const auto& p : tess.positions) {
    c.lo = c.lo.cwiseMin(p);
    c.hi = c.hi.cwiseMax(p);
  }
  return c;
}

// What info reports, gathered once for the JSON file and the printout.
struct InfoFacts {
  const InfoArgs* args = nullptr;
  const PolygonMesh* mesh = nullptr;
  MeshValidation before, v;
  std::vector<std::string> warnings;
  const char* scheme = "";
  int ptex_faces = 0;
  int isolation_level = 0;         // adaptive refinement depth at creases and corners
  int smooth_isolation_level = 0;  // ... and around smooth extraordinary vertices
  size_t tessellation_triangles = 0;
  CurvatureSurvey curvature;
  UpAxisGuess up;
  Eigen::AlignedBox3d control_box;
};

nlohmann::json info_report(const InfoFacts& f) {
  const MeshValidation& v = f.v;
  const CurvatureSurvey& c = f.curvature;
  const UpAxisGuess& up = f.up;
  const Eigen::AlignedBox3d& box = f.control_box;
  return {{"mesh", f.args->mesh},
          {"vertices", v.num_vertices},
          {"faces", v.num_faces},
          {"edges", v.num_edges},
          {"boundary_loops", v.num_boundary_loops},
          {"components", v.num_components},
          {"euler_characteristic", v.euler_characteristic},
          {"genus", v.genus},
          {"triangles_only", f.mesh->is_triangle_mesh()},
          {"quads_only", f.mesh->is_quad_mesh()},
          {"texcoords", f.mesh->has_texcoords()},
          {"findings_before_repair", f.before.describe()},
          {"bbox_min", {box.min().x(), box.min().y(), box.min().z()}},
          {"bbox_max", {box.max().x(), box.max().y(), box.max().z()}},
          {"up_axis",
           {{"axis", up.name()},
            {"confidence", to_string(up.confidence)},
            {"reason", up.reason},
            {"footprints", up.footprints},
            {"open_ends", up.open_ends},
            {"flat_ends", up.flat_ends}}},
          {"warnings", f.warnings},
          {"limit_surface",
           {{"scheme", f.scheme},
            {"ptex_faces", f.ptex_faces},
            {"isolation_level", f.isolation_level},
            {"smooth_isolation_level", f.smooth_isolation_level},
            {"tessellation_triangles", f.tessellation_triangles},
            {"area", c.total_area},
            {"bbox_min", {c.lo.x(), c.lo.y(), c.lo.z()}},
            {"bbox_max", {c.hi.x(), c.hi.y(), c.hi.z()}},
            {"k1", to_json(stats_of(c.k1))},
            {"k2", to_json(stats_of(c.k2))},
            {"mean_curvature", to_json(stats_of(c.mean))},
            {"gaussian_curvature", to_json(stats_of(c.gauss))},
            {"sampling_weight_r", to_json(stats_of(c.r))},
            {"integrated_gaussian_curvature", c.integral_gauss},
            {"gauss_bonnet_2pi_chi",
             v.is_closed() ? nlohmann::json(2.0 * std::numbers::pi * v.euler_characteristic)
                           : nlohmann::json(nullptr)}}}};
}

void print_info(const InfoFacts& f) {
  const MeshValidation& v = f.v;
  const CurvatureSurvey& c = f.curvature;
  const Eigen::AlignedBox3d& box = f.control_box;
  auto line = [](const char* name, const Stats& s) {
    std::cout << "  " << std::left << std::setw(22) << name << std::right << std::setprecision(4)
              << " min " << std::setw(10) << s.min << "  median " << std::setw(10) << s.median
              << "  max " << std::setw(10) << s.max << '\n';
  };
  std::cout << f.args->mesh << '\n'
            << "  " << v.num_vertices << " vertices, " << v.num_faces << " faces, " << v.num_edges
            << " edges, " << v.num_boundary_loops << " boundary loops, " << v.num_components
            << " component(s), chi = " << v.euler_characteristic << ", genus " << v.genus << '\n';
  if (!f.args->quiet) {
    for (const std::string& w : f.warnings) {
      std::cout << "  warning: " << w << '\n';
    }
  }
  const auto xyz = [](const Eigen::Vector3d& p) {
    std::ostringstream text;
    text << std::setprecision(6) << p.x() << ", " << p.y() << ", " << p.z();
    return text.str();
  };
  const Eigen::Vector3d size = box.sizes();
  std::cout << "  bounding box: min (" << xyz(box.min()) << "), max (" << xyz(box.max())
            << "), size " << xyz(size) << ", centre (" << xyz(box.center()) << ")\n"
            << "  up axis (guessed): " << f.up.name() << ", confidence "
            << to_string(f.up.confidence) << ": " << f.up.reason
            << "; previews take --up to overrule it\n";
  std::cout << "limit surface: " << f.scheme << ", " << f.ptex_faces
            << " ptex faces, isolated to depth " << f.isolation_level
            << " (smooth extraordinary vertices " << f.smooth_isolation_level << "), area "
            << std::setprecision(6) << c.total_area << ", curvature over " << c.vertices
            << " tessellation vertices:\n";
  line("k1", stats_of(c.k1));
  line("k2", stats_of(c.k2));
  line("mean curvature H", stats_of(c.mean));
  line("Gaussian curvature K", stats_of(c.gauss));
  line("sampling weight r", stats_of(c.r));
  std::cout << "  integral of K dA = " << std::setprecision(6) << c.integral_gauss;
  if (v.is_closed()) {
    std::cout << "  (Gauss-Bonnet: 2 pi chi = " << 2.0 * std::numbers::pi * v.euler_characteristic
              << ")";
  }
  std::cout << '\n';
}

int run_info(const InfoArgs& args) {
  MeshReadResult read = read_mesh(args.mesh);
  PolygonMesh& mesh = read.mesh;
  InfoFacts f;
  f.args = &args;
  f.mesh = &mesh;
  f.before = validate_mesh(mesh);
  f.warnings = read.warnings;
  if (args.repair) {
    SanitizeResult sanitized = sanitize_mesh(mesh, args.mesh);
    f.warnings.insert(f.warnings.end(), sanitized.warnings.begin(), sanitized.warnings.end());
  } else {
    require_valid_manifold(mesh, args.mesh);
  }
  f.v = validate_mesh(mesh);

  LimitSurfaceOptions options;
  options.name = args.mesh;
  if (args.scheme == "loop") {
    options.scheme = SubdivisionScheme::Loop;
  }
  if (args.scheme == "catmull-clark") {
    options.scheme = SubdivisionScheme::CatmullClark;
  }
  const LimitSurface surface(mesh, options);
  const LimitTessellation tess = tessellate(surface, {.resolution = args.resolution});
  f.curvature = survey_curvature(surface, tess);
  f.scheme = surface.scheme() == SubdivisionScheme::Loop ? "loop" : "catmull-clark";
  f.ptex_faces = surface.num_faces();
  f.isolation_level = options.isolation_level;
  f.smooth_isolation_level = surface.smooth_isolation_level();
  f.tessellation_triangles = tess.triangles.size();

  // Which way is up (render/up_axis.h: the side the model stands on, its open end, its height
  // field, or the +y convention, and how sure that is), from the control mesh.
  f.up = guess_up_axis(mesh);
  for (const Eigen::Vector3d& p : mesh.positions) {
    f.control_box.extend(p);
  }

  if (!args.json.empty()) {
    const nlohmann::json report = info_report(f);
    write_file_atomically(args.json, [&](std::ofstream& out) { out << report.dump(2) << '\n'; });
  }
  print_info(f);
  return kOk;
}

}  // namespace
}  // namespace elastic::cli

ELASTIC_COMMAND(
    "info", "Mesh statistics, validation and limit-surface curvature", [](CLI::App& sub) {
      auto args = std::make_shared<elastic::cli::InfoArgs>();
      sub.add_option("mesh", args->mesh, "Mesh file (OBJ, OFF, PLY, STL)")->required();
      sub.add_option("--scheme", args->scheme, "Subdivision scheme")
          ->check(CLI::IsMember({"auto", "loop", "catmull-clark"}));
      // --resolution: the name before 0.2, kept as an alias for one release (docs/cli.md).
      sub.add_option("--tessellation,--resolution", args->resolution,
                     "Limit-surface tessellation for the curvature statistics: segments per ptex "
                     "edge (old name --resolution)")
          ->check(CLI::Range(1, 256));
      // --json FILE: the name before 0.2, kept as an alias for one release (docs/cli.md); --json
      // on `locate` and `region` is a flag that prints JSON on stdout.
      sub.add_option("--report,--json", args->json,
                     "Also write the statistics as JSON to this file (old name --json)");
      sub.add_flag("!--no-repair", args->repair, "Fail on repairable defects instead of repairing");
      sub.add_flag("-q,--quiet", args->quiet, "No warnings: only results");
      sub.footer(
          "Example:\n  elastic info meshes/torus_quads.obj --report torus.json\n"
          "prints vertex/face counts, validation findings, the bounding box and the guessed up\n"
          "axis with its confidence (the end the model stands on, its open end, or +y),\n"
          "and the limit surface's principal, mean and Gaussian curvature statistics with a\n"
          "Gauss-Bonnet check on closed surfaces.");
      return [args] { return elastic::cli::run_info(*args); };
    });
