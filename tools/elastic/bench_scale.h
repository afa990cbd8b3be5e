#pragma once
// `elastic bench scale`: the whole `elastic map` (loading included) at several particle counts,
// beside CGAL's LSCM flattening of the same target grid (the relaxed particle grid on the target,
// quads split into triangles; only CGAL's parameterize call is timed), with the ratio of the two.

#include <CLI/CLI.hpp>
#include <functional>

namespace elastic::cli {

/// Adds `scale` to the `bench` command and returns the function that runs it.
std::function<int()> add_scale_subcommand(CLI::App& bench);

}  // namespace elastic::cli
