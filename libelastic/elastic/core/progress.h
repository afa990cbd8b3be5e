#pragma once
/// \file
/// Progress reporting for long work. The library never prints: an algorithm that runs long takes a
/// `ProgressCallback` in its options and calls it now and then; a tool decides what to show.

#include <functional>
#include <string_view>

namespace elastic {

/// One progress report. Fields that do not apply to a stage are left at their defaults.
struct Progress {
  std::string_view stage;  ///< short name of the current stage, e.g. "tessellate", "relax"
  long iteration = 0;      ///< iteration or item index within the stage
  long total = 0;          ///< number of iterations or items when known, 0 when not
  double energy = 0.0;     ///< current objective value, when the stage minimises one
  double gradient = 0.0;   ///< current relative gradient norm, when the stage has one
};

/// Called with a report; return false to ask the algorithm to stop early (it then returns a result
/// whose status says it was cancelled). An empty callback means nobody listens.
using ProgressCallback = std::function<bool(const Progress&)>;

/// Calls `callback` if it is set; returns true when the work should go on.
inline bool report_progress(const ProgressCallback& callback, const Progress& progress) {
  return !callback || callback(progress);
}

}  // namespace elastic
