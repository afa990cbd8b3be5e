#include "cli_common.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/mesh/mesh_validation.h"
#include "job_file.h"

namespace elastic::cli {

namespace {
bool g_line_open = false;
}

LoadedSurface load_surface(const std::string& path, const std::string& scheme) {
  LoadedSurface loaded = read_surface_mesh(path);
  build_limit_surface(loaded, scheme);
  return loaded;
}

LoadedSurface surface_from_mesh(PolygonMesh mesh, const std::string& path,
                                const std::string& scheme) {
  LoadedSurface loaded = sanitised_mesh(std::move(mesh), path);
  build_limit_surface(loaded, scheme);
  return loaded;
}

LoadedSurface read_surface_mesh(const std::string& path) {
  MeshReadResult read = read_mesh(path);
  return sanitised_mesh(std::move(read.mesh), path, std::move(read.warnings));
}

LoadedSurface sanitised_mesh(PolygonMesh mesh, const std::string& path,
                             std::vector<std::string> warnings) {
  LoadedSurface loaded;
  loaded.path = path;
  loaded.warnings = std::move(warnings);
  loaded.mesh = std::make_shared<PolygonMesh>(std::move(mesh));
  SanitizeResult sanitized = sanitize_mesh(*loaded.mesh, path);
  loaded.warnings.insert(loaded.warnings.end(), sanitized.warnings.begin(),
                         sanitized.warnings.end());
  return loaded;
}

void build_limit_surface(LoadedSurface& loaded, const std::string& scheme) {
  LimitSurfaceOptions options;
  options.name = loaded.path;
  if (scheme == "loop") {
    options.scheme = SubdivisionScheme::Loop;
  }
  if (scheme == "catmull-clark") {
    options.scheme = SubdivisionScheme::CatmullClark;
  }
  loaded.surface = std::make_shared<LimitSurface>(*loaded.mesh, options);
  loaded.projector = std::make_shared<SurfaceProjector>(*loaded.surface);
}

namespace {

/// How far a stage has come, in [0, 1], or a negative value when nothing tells. Stages with a known
/// count use it; a minimisation uses its relative gradient, which falls from 1 towards the
/// tolerance roughly geometrically, so log(g) / log(tolerance) grows about linearly in time.
double stage_fraction(const Progress& p, double gradient_tolerance) {
  if (p.total > 0) {
    return std::clamp(static_cast<double>(p.iteration) / p.total, 0.0, 1.0);
  }
  if (p.gradient > 0.0 && p.gradient < 1.0) {
    return std::clamp(std::log(p.gradient) / std::log(gradient_tolerance), 0.0, 1.0);
  }
  return -1.0;
}

}  // namespace

ProgressCallback terminal_progress(bool quiet) {
  if (quiet || !::isatty(STDERR_FILENO)) {
    return {};
  }
  using Clock = std::chrono::steady_clock;
  struct State {
    Clock::time_point start = Clock::now();
    Clock::time_point stage_start = Clock::now();
    Clock::time_point last_draw;
    std::string stage;
  };
  auto state = std::make_shared<State>();
  return [state](const Progress& p) {
    const Clock::time_point now = Clock::now();
    if (p.stage != state->stage) {
      state->stage = std::string(p.stage);
      state->stage_start = now;
    } else if (now - state->last_draw < std::chrono::milliseconds(50)) {
      return true;  // at most 20 redraws a second
    }
    state->last_draw = now;
    const double seconds = std::chrono::duration<double>(now - state->start).count();
    const double in_stage = std::chrono::duration<double>(now - state->stage_start).count();
    constexpr double kGradientTolerance = 1e-6;  // the solvers' default relative tolerance
    const double fraction = stage_fraction(p, kGradientTolerance);
    // [#########...........]: the stage's progress when it can be known.
    constexpr int kWidth = 20;
    std::string bar;
    if (fraction >= 0.0) {
      const auto filled =
          static_cast<size_t>(std::clamp(fraction * kWidth + 0.5, 0.0, 1.0 * kWidth));
      bar.push_back('[');
      bar.append(filled, '#');
      bar.append(static_cast<size_t>(kWidth) - filled, '.');
      bar.append("] ");
    }
    std::string left;
    if (fraction > 0.05 && in_stage > 0.5) {
      char text[32];
      std::snprintf(text, sizeof text, "  ~%.0fs left", in_stage * (1.0 - fraction) / fraction);
      left = text;
    }
    if (p.iteration > 0 || p.energy != 0.0) {
      std::fprintf(stderr, "\r\033[K%-18.*s %sit %5ld  E %.4e  grad %.1e  %6.1fs%s",
                   static_cast<int>(p.stage.size()), p.stage.data(), bar.c_str(), p.iteration,
                   p.energy, p.gradient, seconds, left.c_str());
    } else {
      std::fprintf(stderr, "\r\033[K%-18.*s %s...  %6.1fs", static_cast<int>(p.stage.size()),
                   p.stage.data(), bar.c_str(), seconds);
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

long long default_max_memory_mb() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page_size = ::sysconf(_SC_PAGESIZE);
  constexpr long long kMostDefault = 4096;
  if (pages <= 0 || page_size <= 0) {
    return kMostDefault;
  }
  const long long half = static_cast<long long>(pages) / 2 * page_size / (1024LL * 1024);
  return std::clamp(half, 1LL, kMostDefault);
}

void check_memory(double bytes, const std::string& what, long long max_memory_mb) {
  const long long limit = max_memory_mb > 0 ? max_memory_mb : default_max_memory_mb();
  const double mb = bytes / (1024.0 * 1024.0);
  if (mb <= static_cast<double>(limit)) {
    return;
  }
  char text[256];
  std::snprintf(text, sizeof text,
                "needs about %.0f MB of memory, more than the limit of %lld MB%s; raise it with "
                "--max-memory %.0f",
                mb, limit,
                max_memory_mb > 0 ? ""
                                  : " (the default: half the physical memory, "
                                    "at most 4096 MB)",
                std::ceil(mb * 1.1));
  throw InvalidInputError(what, text);
}

std::string one_line(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) {
    text.pop_back();
  }
  for (size_t at = text.find('\n'); at != std::string::npos; at = text.find('\n', at)) {
    text.replace(at, 1, "; ");
  }
  return text;
}

void print_warnings(const std::vector<std::string>& warnings, bool quiet) {
  if (quiet) {
    return;
  }
  for (const std::string& w : warnings) {
    std::cerr << "elastic: warning: " << w << '\n';
  }
}

RegionSpec parse_region_flag(const std::string& text, const std::string& flag) {
  try {
    return parse_region_spec(text, flag);
  } catch (const InvalidInputError& e) {
    if (e.input() == flag) {
      throw UsageError(e.what());
    }
    throw;
  }
}

void require_extension(const std::string& path, const std::vector<std::string>& extensions,
                       const std::string& flag) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::string allowed;
  for (const std::string& e : extensions) {
    if (extension == e) {
      return;
    }
    allowed += (allowed.empty() ? "" : " or ") + e;
  }
  throw UsageError(flag + " " + path + ": this output is written as " + allowed +
                   " only; name the file with that extension");
}

}  // namespace elastic::cli
