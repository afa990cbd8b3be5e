#include "verdict.h"

#include <iostream>
#include <vector>

#include "command.h"

namespace elastic::cli {
namespace {

std::string join_choices(const std::vector<std::string>& items) {
  std::string out;
  for (size_t k = 0; k < items.size(); ++k) {
    if (k > 0) out += k + 1 == items.size() ? " or " : ", ";
    out += items[k];
  }
  return out;
}

}  // namespace

int MapVerdict::exit_code() const {
  return ok() ? kOk : kNumerical;
}

std::string MapVerdict::line() const {
  if (ok()) return {};
  return "elastic: the map failed: " + failure + "; try " + advice;
}

nlohmann::json MapVerdict::to_json() const {
  return {{"ok", ok()},     {"exit", exit_code()},    {"converged", converged}, {"reason", reason},
          {"folds", folds}, {"sigma_min", sigma_min}, {"failure", failure},     {"advice", advice}};
}

MapVerdict judge_map(const MapJob& job, const MapSession& session) {
  const RelaxationResult& x = session.result.relaxation;
  MapVerdict v;
  v.converged = x.converged;
  v.reason = std::string(to_string(x.reason));
  v.folds = session.metrics.folds;
  v.sigma_min = session.metrics.sigma_min;
  if (v.ok()) return v;

  std::vector<std::string> failed;
  if (!v.converged) failed.push_back("not converged (" + v.reason + ")");
  if (v.folds != 0) {
    failed.push_back(std::to_string(v.folds) + (v.folds == 1 ? " folded face" : " folded faces"));
  }
  v.failure = failed.size() == 2 ? failed[0] + " and " + failed[1] : failed[0];

  // Suggestions that apply to this job: a larger budget when the budget ran out; for a rectangle
  // image its inscribed ellipse (corners are the hardest boundary); the robust energy instead of
  // the paper's; the area rest scale unless in use (it spreads compression instead of buckling);
  // the other boundary mode.
  std::vector<std::string> advice;
  if (x.reason == StopReason::MaxIterations) {
    advice.push_back(job.max_iterations > 0
                         ? "--max-iterations above " + std::to_string(job.max_iterations)
                         : "a larger --max-iterations");
  }
  if (!job.source_image.empty() && job.source_region != "ellipse") {
    advice.push_back("--source-region ellipse");
  }
  if (job.energy == "paper") advice.push_back("--energy robust");
  if (!job.target_place.empty()) {
    advice.push_back("a smaller SCALE in --target-place");  // a free boundary: no curve to change
  } else {
    if (job.rest_scale != "area") advice.push_back("--rest-scale area");
    advice.push_back(job.boundary == "fixed" ? "--boundary slide" : "--boundary fixed");
  }
  v.advice = join_choices(advice);
  return v;
}

int finish(const MapVerdict& verdict) {
  if (!verdict.ok()) std::cerr << verdict.line() << '\n';
  return verdict.exit_code();
}

}  // namespace elastic::cli
