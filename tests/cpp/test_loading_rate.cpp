// The adaptive loading rate (loading_rate.hpp) without a mesh: the rule nextRateMultiplier raises phi while the
// run is quiet, halves it on a rod deletion or a high kinetic ratio, holds in between and at its bounds, and never
// leaves [1, rate_adapt_max]; the loading clock ramps phi linearly to its target and integrates tau exactly.
#include <gtest/gtest.h>

#include <cmath>

#include "loading_rate.hpp"

using namespace enamel;

namespace {

// A control interval with kinetic / strain = rho, `deleted` rods deleted and `failed` interfaces failed
// (burst threshold 8).
RateControlInput interval(double rho, int deleted = 0, int failed = 0) {
  RateControlInput in;
  in.strain = 2.0;
  in.kinetic = rho * in.strain;
  in.rodsDeleted = deleted;
  in.interfacesFailed = failed;
  in.burstInterfaces = 8;
  return in;
}

}  // namespace

TEST(LoadingRate, RaisesWhenQuasiStaticAndQuiet) {
  EXPECT_DOUBLE_EQ(nextRateMultiplier(1.0, 8.0, interval(1e-4)), 1.25);
  EXPECT_DOUBLE_EQ(nextRateMultiplier(2.0, 8.0, interval(0.5 * kRateRhoLow, 0, 8)), 2.5);  // 8 failures: no burst
}

TEST(LoadingRate, HalvesOnADeletionOrAHighKineticRatio) {
  EXPECT_DOUBLE_EQ(nextRateMultiplier(4.0, 8.0, interval(1e-4, 1)), 2.0);  // quiet energies, but a rod broke
  EXPECT_DOUBLE_EQ(nextRateMultiplier(4.0, 8.0, interval(2 * kRateRhoHigh)), 2.0);
  EXPECT_DOUBLE_EQ(nextRateMultiplier(4.0, 8.0, RateControlInput{0, 0, 3, 0, 8}), 2.0);  // no strain yet, deleted
}

TEST(LoadingRate, HoldsBetweenTheBoundsOnABurstAndWithoutStrain) {
  EXPECT_DOUBLE_EQ(nextRateMultiplier(3.0, 8.0, interval(0.5 * (kRateRhoLow + kRateRhoHigh))), 3.0);
  EXPECT_DOUBLE_EQ(nextRateMultiplier(3.0, 8.0, interval(1e-4, 0, 9)), 3.0);  // 9 > 8 failures: a burst
  EXPECT_DOUBLE_EQ(nextRateMultiplier(3.0, 8.0, RateControlInput{}), 3.0);    // rho undefined
}

TEST(LoadingRate, NeverBelowOneNorAboveTheMaximum) {
  EXPECT_DOUBLE_EQ(nextRateMultiplier(8.0, 8.0, interval(1e-4)), 8.0);   // at the maximum: held there
  EXPECT_DOUBLE_EQ(nextRateMultiplier(7.0, 8.0, interval(1e-4)), 8.0);   // 8.75 capped
  EXPECT_DOUBLE_EQ(nextRateMultiplier(1.0, 8.0, interval(1.0, 5)), 1.0);  // at 1: not lower
  EXPECT_DOUBLE_EQ(nextRateMultiplier(1.5, 8.0, interval(1.0)), 1.0);    // 0.75 raised to 1
  EXPECT_DOUBLE_EQ(nextRateMultiplier(1.0, 1.0, interval(0.0)), 1.0);    // off: always 1
  // any sequence of intervals stays within [1, max]
  double phi = 1;
  for (int k = 0; k < 200; ++k) {
    phi = nextRateMultiplier(phi, 16.0, interval(k % 7 == 3 ? 0.02 : 1e-4, k % 11 == 5));
    ASSERT_GE(phi, 1.0);
    ASSERT_LE(phi, 16.0);
  }
}

TEST(LoadingRate, ClockRampsPhiLinearlyAndIntegratesTau) {
  Loading on;
  on.rateAdaptMax = 8;
  State s;
  const double dt = 0.1;
  setRateMultiplierTarget(s, 2.0, 4);  // phi 1 -> 2 over 4 steps: 1.25, 1.5, 1.75, 2
  for (int k = 1; k <= 6; ++k) {
    const LoadingClock mid = loadingClockAt(s, 0.5 * dt, dt);
    const double phiBefore = s.rateMultiplier, tauBefore = s.loadingTime;
    s.time += dt;
    advanceLoadingClock(on, dt, s);
    const double expected = std::min(2.0, 1.0 + 0.25 * k);
    EXPECT_NEAR(s.rateMultiplier, expected, 1e-15) << "step " << k;
    EXPECT_NEAR(mid.phi, 0.5 * (phiBefore + s.rateMultiplier), 1e-15);
    EXPECT_NEAR(s.loadingTime - tauBefore, dt * 0.5 * (phiBefore + s.rateMultiplier), 1e-15);
  }
  EXPECT_EQ(s.rateMultiplier, 2.0);  // the target exactly
  EXPECT_EQ(s.rateRampSteps, 0);
  // tau = int phi dt = 0.1 (1.125 + 1.375 + 1.625 + 1.875) + 2 x 0.2
  EXPECT_NEAR(s.loadingTime, 0.6 + 0.4, 1e-14);

  Loading off;  // rate_adapt_max = 1: tau is t itself
  State t;
  setRateMultiplierTarget(t, 1.0, 4);
  for (int k = 0; k < 3; ++k) {
    t.time += 0.3;
    advanceLoadingClock(off, 0.3, t);
    EXPECT_EQ(t.loadingTime, t.time);
    EXPECT_EQ(t.rateMultiplier, 1.0);
  }
}
