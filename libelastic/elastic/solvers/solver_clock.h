#pragma once
/// \file
/// The solvers' timer: seconds on a steady clock, for RelaxationResult's timings. Internal to the
/// solvers (solver_detail).

#include <chrono>

namespace elastic::solver_detail {

/// Ticks of the steady clock now (a start for seconds_since).
inline long long now_ticks() {
  return std::chrono::steady_clock::now().time_since_epoch().count();
}

/// Seconds since `start_ticks` (now_ticks()) on the steady clock.
inline double seconds_since(long long start_ticks) {
  const auto elapsed = std::chrono::steady_clock::now().time_since_epoch().count() - start_ticks;
  return std::chrono::duration<double>(std::chrono::steady_clock::duration(elapsed)).count();
}

}  // namespace elastic::solver_detail
