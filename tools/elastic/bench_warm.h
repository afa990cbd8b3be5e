#pragma once
// `elastic bench warm`: a target disk dragged over the surface in small steps (as a user drags it
// in a picker), each step mapped twice: cold (map_regions from scratch: sampling, both disk maps,
// the offset search, the relaxation) and warm (map_regions from the previous step's warm map:
// only the new target's disk map and the relaxation). Prints both times, their ratio and the two
// maps' energies per step, and the medians.

#include <CLI/CLI.hpp>
#include <functional>

namespace elastic::cli {

/// Adds `warm` to the `bench` command and returns the function that runs it.
std::function<int()> add_warm_subcommand(CLI::App& bench);

}  // namespace elastic::cli
