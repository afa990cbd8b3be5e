#pragma once
// Shared pieces of the subcommands: loading a surface from a mesh file, a progress line on
// terminals.

#include <memory>
#include <string>
#include <vector>

#include "elastic/core/progress.h"
#include "elastic/mesh/polygon_mesh.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/region_spec.h"
#include "elastic/surface/limit_surface.h"

namespace elastic::cli {

/// A mesh file turned into a limit surface and its magnet. Heap-held so the references between them
/// stay valid when the struct moves; shared, so that copies (a cache of loaded surfaces, e.g. in
/// `bench robustness`) share one surface and projector, which are read-only once built.
struct LoadedSurface {
  std::string path;
  std::shared_ptr<PolygonMesh> mesh;
  std::shared_ptr<LimitSurface> surface;
  std::shared_ptr<SurfaceProjector> projector;
  std::vector<std::string> warnings;  ///< reader and repair warnings, for the user
};

/// Reads, sanitises (repairs what is safely repairable, rejects the rest), and builds the limit
/// surface and the projector. `scheme` is "auto", "loop" or "catmull-clark".
LoadedSurface load_surface(const std::string& path, const std::string& scheme = "auto");
/// The same for a mesh made in memory (e.g. the plane carrying a source image); `name` is for
/// messages.
LoadedSurface surface_from_mesh(PolygonMesh mesh, const std::string& name,
                                const std::string& scheme = "auto");
/// load_surface in two halves. The first reads and sanitises: where bad input is refused, in a
/// fraction of the time the limit surface takes (a map checks both meshes before building either
/// surface). `sanitised_mesh` is the same for a mesh already read (its reader's warnings given) or
/// made in memory.
LoadedSurface read_surface_mesh(const std::string& path);
LoadedSurface sanitised_mesh(PolygonMesh mesh, const std::string& name,
                             std::vector<std::string> warnings = {});
/// The second half: the limit surface and the projector of a sanitised mesh.
void build_limit_surface(LoadedSurface& loaded, const std::string& scheme = "auto");

/// A progress callback that redraws one status line on stderr when stderr is a terminal and `quiet`
/// is false; otherwise an empty callback (nothing goes into pipes or files).
ProgressCallback terminal_progress(bool quiet);
/// Ends the status line (if one was drawn).
void end_progress_line();

/// Memory estimates, checked before the work starts (docs/cli.md, "Limits"). The
/// per-item costs are peak resident sizes measured with /usr/bin/time on the shipped meshes,
/// rounded up: `map` about 3.1 KB per particle (grid, springs, solver history, multigrid), `sample`
/// about 1.0 KB, a paste's painted mesh about 1.0 KB per vertex.
inline constexpr double kMapBytesPerParticle = 3.5e3;
inline constexpr double kSampleBytesPerParticle = 1.2e3;
inline constexpr double kPasteBytesPerVertex = 1.2e3;
inline constexpr double kBaseBytes = 64e6;  ///< the tool, the meshes and their limit surfaces

/// The default of --max-memory, in MB: half the physical memory, at most 4096 (so that a run
/// that would take minutes and gigabytes is refused in a moment unless asked for).
long long default_max_memory_mb();

/// Throws InvalidInputError naming `what` (e.g. "--particles 5000000") when `bytes` is over
/// `max_memory_mb` (0: default_max_memory_mb()), giving the estimate, the limit and the flag that
/// raises it (--max-memory).
void check_memory(double bytes, const std::string& what, long long max_memory_mb);

/// Prints warnings to stderr ("elastic: warning: ...") unless quiet.
void print_warnings(const std::vector<std::string>& warnings, bool quiet);

/// A message on one line: newlines (CLI11 puts some in) become "; ", trailing ones are dropped.
std::string one_line(std::string text);

/// Parses a region flag's spec (parse_region_spec). A malformed spec is a usage error (exit 64)
/// naming `flag`; a `points:`/`uv:` file that is missing or malformed stays an IoError /
/// InvalidInputError naming the file (exit 66 / 65).
RegionSpec parse_region_flag(const std::string& text, const std::string& flag);

/// Output formats come from the file extension: \throws UsageError naming `flag` and the path when
/// `path`'s extension (case-insensitive) is not one of `extensions` (e.g. {".png"}).
void require_extension(const std::string& path, const std::vector<std::string>& extensions,
                       const std::string& flag);

}  // namespace elastic::cli
