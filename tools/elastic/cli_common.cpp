#include "cli_common.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>

#include "elastic/mesh/mesh_io.h"
#include "elastic/mesh/mesh_validation.h"

namespace elastic::cli {

namespace {
bool g_line_open = false;
}

LoadedSurface load_surface(const std::string& path, const std::string& scheme) {
  MeshReadResult read = read_mesh(path);
  LoadedSurface loaded = surface_from_mesh(std::move(read.mesh), path, scheme);
  loaded.warnings.insert(loaded.warnings.begin(), read.warnings.begin(), read.warnings.end());
  return loaded;
}

LoadedSurface surface_from_mesh(PolygonMesh mesh, const std::string& path,
                                const std::string& scheme) {
  LoadedSurface loaded;
  loaded.path = path;
  loaded.mesh = std::make_unique<PolygonMesh>(std::move(mesh));
  SanitizeResult sanitized = sanitize_mesh(*loaded.mesh, path);
  loaded.warnings.insert(loaded.warnings.end(), sanitized.warnings.begin(),
                         sanitized.warnings.end());
  LimitSurfaceOptions options;
  options.name = path;
  if (scheme == "loop") options.scheme = SubdivisionScheme::Loop;
  if (scheme == "catmull-clark") options.scheme = SubdivisionScheme::CatmullClark;
  loaded.surface = std::make_unique<LimitSurface>(*loaded.mesh, options);
  loaded.projector = std::make_unique<SurfaceProjector>(*loaded.surface);
  return loaded;
}

ProgressCallback terminal_progress(bool quiet) {
  if (quiet || !::isatty(STDERR_FILENO)) return {};
  auto start = std::chrono::steady_clock::now();
  return [start](const Progress& p) {
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (p.iteration > 0 || p.energy != 0.0) {
      std::fprintf(stderr, "\r\033[K%-10.*s it %6ld  E %.6e  |Pg|/|Pg0| %.2e  %6.2fs",
                   static_cast<int>(p.stage.size()), p.stage.data(), p.iteration, p.energy,
                   p.gradient, seconds);
    } else {
      std::fprintf(stderr, "\r\033[K%-10.*s ...  %6.2fs", static_cast<int>(p.stage.size()),
                   p.stage.data(), seconds);
    }
    g_line_open = true;
    return true;
  };
}

void end_progress_line() {
  if (g_line_open) {
    std::fputs("\r\033[K", stderr);
    g_line_open = false;
  }
}

void print_warnings(const std::vector<std::string>& warnings, bool quiet) {
  if (quiet) return;
  for (const std::string& w : warnings) std::cerr << "elastic: warning: " << w << '\n';
}

}  // namespace elastic::cli
