#pragma once
/// \file
/// `StagnationMonitor`: whether an iteration still gets anywhere (StopReason::Stagnated,
/// relaxation.h). The L-BFGS solver (lbfgs_solver.cpp) feeds it every iterate's energy and
/// tangential gradient norm and stops, not converged, when the last `window` iterations lowered
/// the energy by less than `energy_tolerance` of itself *and* did not lower the smallest gradient
/// norm seen so far by 10%. Either kind of progress keeps it going: a run converging slowly near
/// its minimum barely moves the energy (quadratically small changes) but still lowers the gradient.

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <utility>

#include "elastic/solvers/relaxation.h"

namespace elastic::solver_detail {

class StagnationMonitor {
 public:
  explicit StagnationMonitor(long window = kStagnationWindow,
                             double energy_tolerance = kStagnationEnergy)
      : window_(window), energy_tolerance_(energy_tolerance) {}

  /// Records one iterate; true when the window shows no progress of either kind (above).
  bool stagnated(double energy, double gradient_norm) {
    best_gradient_ = std::min(best_gradient_, gradient_norm);
    recent_.emplace_back(energy, best_gradient_);
    if (static_cast<long>(recent_.size()) <= window_) {
      return false;
    }
    recent_.pop_front();
    const auto& [old_energy, old_gradient] = recent_.front();
    return old_energy - energy <= energy_tolerance_ * std::abs(energy) &&
           best_gradient_ >= 0.9 * old_gradient;
  }

 private:
  long window_;
  double energy_tolerance_;
  double best_gradient_ = std::numeric_limits<double>::infinity();
  std::deque<std::pair<double, double>> recent_;  ///< (energy, best gradient) per iterate
};

}  // namespace elastic::solver_detail
