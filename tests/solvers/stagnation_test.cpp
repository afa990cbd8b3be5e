// The L-BFGS solver's stagnation stop (solvers/stagnation.h) on made-up histories: it must stop a
// run whose energy and gradient both stand still, and leave alone one that makes either kind of
// progress, above all one converging slowly near its minimum (energy changes quadratically
// small, gradient still falling).

#include "elastic/solvers/stagnation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace elastic::solver_detail {
namespace {

// Feeds `n` iterates; the index of the first that reports stagnation, or -1.
template <class History>
long first_stop(StagnationMonitor& monitor, long n, const History& history) {
  for (long k = 0; k < n; ++k) {
    const auto [energy, gradient] = history(k);
    if (monitor.stagnated(energy, gradient)) {
      return k;
    }
  }
  return -1;
}

TEST(Stagnation, StopsWhenEnergyAndGradientStandStill) {
  // The camel-ear case: 288.309 falling by 3e-9 of itself per 100 iterations, gradient fixed.
  StagnationMonitor monitor(100, 1e-8);
  const long stop = first_stop(monitor, 1000, [](long k) {
    return std::pair{288.309033 - 7.7e-9 * static_cast<double>(k), 102239.0};
  });
  EXPECT_EQ(stop, 100);  // as soon as a whole window is there
}

TEST(Stagnation, SlowConvergenceWithAFallingGradientGoesOn) {
  // Energy settled to 1e-12 of itself per iteration while the gradient falls 2% per iteration
  // (fandisk's disk onto the pawn's in its last hundreds of iterations).
  StagnationMonitor monitor(100, 1e-8);
  EXPECT_EQ(first_stop(monitor, 2000,
                       [](long k) {
                         return std::pair{3.2433e-4 * (1.0 + 1e-12 * std::exp(-0.01 * k)),
                                          3e-5 * std::pow(0.98, static_cast<double>(k))};
                       }),
            -1);
}

TEST(Stagnation, FallingEnergyWithAStuckGradientGoesOn) {
  // The slide with particles held at a kink: the gradient stays, the energy still falls 1e-4
  // of itself per iteration.
  StagnationMonitor monitor(100, 1e-8);
  EXPECT_EQ(first_stop(monitor, 2000,
                       [](long k) {
                         return std::pair{std::pow(1.0 - 1e-4, static_cast<double>(k)), 2.2};
                       }),
            -1);
}

TEST(Stagnation, AnOscillatingGradientCountsItsBestOnly) {
  // A gradient that jumps up and down without its minimum improving is no progress.
  StagnationMonitor monitor(100, 1e-8);
  const long stop = first_stop(monitor, 1000, [](long k) {
    return std::pair{1.0, k % 2 == 0 ? 1.0 : 5.0};
  });
  EXPECT_EQ(stop, 100);
}

}  // namespace
}  // namespace elastic::solver_detail
