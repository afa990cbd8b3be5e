// `elastic shapes`: writes the procedural test shapes (shapes/procedural_shapes.h) as mesh files,
// <name>_tris.<ext> and <name>_quads.<ext>, and prints one line per file written.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "command.h"
#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/mesh/mesh_validation.h"
#include "elastic/shapes/procedural_shapes.h"

namespace elastic::cli {
namespace {

struct ShapesArgs {
  std::string out = "meshes";
  int resolution = ShapeOptions{}.resolution;
  std::string faces = "both";
  std::string format = "obj";
  std::string only;  ///< comma-separated names, empty for all
  bool quiet = false;
};

std::vector<std::string> split_names(const std::string& list) {
  std::vector<std::string> names;
  size_t start = 0;
  while (start <= list.size()) {
    const size_t comma = std::min(list.find(',', start), list.size());
    names.push_back(list.substr(start, comma - start));
    start = comma + 1;
  }
  return names;
}

// CLI11 validator: every comma-separated name is a known shape (else a usage error naming it).
std::string check_names(const std::string& list) {
  for (const std::string& name : split_names(list)) {
    if (std::find(shape_names().begin(), shape_names().end(), name) == shape_names().end()) {
      return "unknown shape '" + name + "'";
    }
  }
  return {};
}

int run_shapes(const ShapesArgs& args) {
  const std::filesystem::path dir(args.out);
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    std::cerr << "elastic: " << args.out << ": cannot create the directory: " << error.message()
              << '\n';
    return kCantCreate;
  }

  std::vector<ShapeFaces> kinds;
  if (args.faces != "quad") kinds.push_back(ShapeFaces::Triangles);
  if (args.faces != "tri") kinds.push_back(ShapeFaces::Quads);
  const MeshFormat format = args.format == "off"   ? MeshFormat::Off
                            : args.format == "ply" ? MeshFormat::Ply
                                                   : MeshFormat::Obj;
  const std::vector<std::string> names = args.only.empty() ? shape_names() : split_names(args.only);

  for (const std::string& name : names) {
    for (ShapeFaces kind : kinds) {
      ShapeOptions options;
      options.faces = kind;
      options.resolution = args.resolution;
      const PolygonMesh mesh = make_shape(name, options);
      const std::filesystem::path path =
          dir / (name + (kind == ShapeFaces::Triangles ? "_tris." : "_quads.") + args.format);
      MeshWriteOptions write;
      write.format = format;
      try {
        write_mesh(path, mesh, write);
      } catch (const IoError& e) {  // an output that cannot be written is not a missing input
        std::cerr << "elastic: " << e.what() << '\n';
        return kCantCreate;
      }
      const MeshValidation check = validate_mesh(mesh);
      if (!args.quiet)
        std::cout << path.string() << ": " << name << ", V " << mesh.num_vertices() << ", F "
                  << mesh.num_faces() << ", boundary loops " << check.num_boundary_loops << '\n';
    }
  }
  return kOk;
}

}  // namespace

ELASTIC_COMMAND(
    "shapes",
    "Write the procedural test shapes (plane, cylinder, torus, vase, goblet, cap, sphere)",
    [](CLI::App& sub) {
      auto args = std::make_shared<ShapesArgs>();
      sub.add_option("--out", args->out, "Output directory (created if missing)")
          ->capture_default_str();
      // --resolution: the name before 0.2, kept as an alias for one release (docs/cli.md).
      sub.add_option("--segments,--resolution", args->resolution,
                     "Segments around the axis (per side for the plane; old name --resolution)")
          ->check(CLI::Range(3, 4096))
          ->capture_default_str();
      sub.add_option("--faces", args->faces, "Triangles, quads or both")
          ->check(CLI::IsMember({"tri", "quad", "both"}))
          ->capture_default_str();
      sub.add_option("--format", args->format, "File format")
          ->check(CLI::IsMember({"obj", "off", "ply"}))
          ->capture_default_str();
      sub.add_option("--only", args->only, "Comma-separated shape names (default: all)")
          ->check(check_names, "NAME,...");
      sub.add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
      sub.footer(
          "Example:\n  elastic shapes --out meshes --segments 32 --faces both\nwrites "
          "<shape>_tris.obj and <shape>_quads.obj for every shape into meshes/.");
      return [args] { return run_shapes(*args); };
    });

}  // namespace elastic::cli
