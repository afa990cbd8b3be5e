#pragma once
// The `elastic` tool's memory allocator, chosen at link time (tools/elastic/CMakeLists.txt).
//
// With jemalloc (ELASTIC_WITH_JEMALLOC, the default where libjemalloc is installed, never under the
// sanitizers) every arena is advised to use transparent huge pages. Why: a map touches its memory
// once and the kernel faults each fresh 4 KiB page in separately; on virtual machines a fault
// costs several microseconds, and the 5,775-particle grid.off -> hemisphere.off map took 22,600 of
// them (about a quarter of its wall time) under glibc's malloc. With 2 MiB pages it takes a few
// hundred. The whole configuration and what it was measured to gain and cost is in
// allocator.cpp. The library itself never chooses an allocator: a program that links it (the Python
// module, a user's tool) keeps its own.

#include <string>

namespace elastic::cli {

/// The allocator serving malloc, its huge-page option and the kernel's huge-page mode, e.g.
/// "jemalloc 5.3.0-0-g54eaed1... (thp:always), kernel thp: madvise" or "glibc malloc, kernel thp:
/// madvise": printed by `elastic version` and written into every benchmark's `machine`.
std::string allocator_description();

/// The process's largest resident set so far in MiB (VmHWM of /proc/self/status; 0 where that
/// cannot be read). Not getrusage's ru_maxrss: a process started by posix_spawn runs on its
/// parent's memory until its exec, and Linux keeps that memory's peak in ru_maxrss, so a map
/// spawned by `bench scale` reported the benchmark's own 10 GB at a million particles.
double peak_resident_mib();

}  // namespace elastic::cli
