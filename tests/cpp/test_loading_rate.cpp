// The adaptive loading rate (loading_rate.hpp) without a mesh: the rule nextRateMultiplier raises phi while the
// run is quiet, halves it on a rod deletion or a high kinetic ratio, holds in between and at its bounds, and never
// leaves [1, rate_adapt_max]; the loading clock ramps phi linearly to its target and integrates tau exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "kernels/loading_rate.hpp"

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

// rate_adapt_rho_high moves the high bound, and the low one with it (a quarter of it): a ratio above the default
// bound but below the case's is held, one below a quarter of the case's bound raises, one above it halves; the
// margin rule reads the same bounds. The default's low bound is the former constant 0.0025 exactly.
TEST(LoadingRate, TheCasesHighBoundMovesBothBounds) {
  auto at = [](double rho, double rhoHigh, double rows = NAN) {
    RateControlInput in = interval(rho);
    in.rhoHigh = rhoHigh;
    in.rowsToEvent = rows;
    return in;
  };
  EXPECT_DOUBLE_EQ(nextRateMultiplier(3.0, 8.0, at(0.02, kRateRhoHigh)), 1.5);   // the default halves at 0.02
  EXPECT_DOUBLE_EQ(nextRateMultiplier(3.0, 8.0, at(0.02, 0.04)), 3.0);           // 0.04 holds it
  EXPECT_DOUBLE_EQ(nextRateMultiplier(3.0, 8.0, at(0.009, kRateRhoHigh)), 3.0);   // the default holds at 0.009
  EXPECT_DOUBLE_EQ(nextRateMultiplier(3.0, 8.0, at(0.009, 0.04)), 3.75);         // below 0.01: raised
  EXPECT_DOUBLE_EQ(nextRateMultiplier(3.0, 8.0, at(0.041, 0.04)), 1.5);
  EXPECT_DOUBLE_EQ(nextRateMultiplierByMargin(3.0, 8.0, 10.0, at(0.02, kRateRhoHigh, 1000.0)), 1.5);
  EXPECT_DOUBLE_EQ(nextRateMultiplierByMargin(3.0, 8.0, 10.0, at(0.02, 0.04, 1000.0)), 3.0);
  EXPECT_DOUBLE_EQ(nextRateMultiplierByMargin(3.0, 8.0, 10.0, at(0.009, 0.04, 20.0)), 2.0);  // the forecast's 2
  EXPECT_EQ(kRateRhoLow, 0.0025);
  EXPECT_EQ(RateControlInput{}.rhoHigh, kRateRhoHigh);
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

// --- the margin rule (rate_adapt_rule = margin): its forecast and its rule, without a mesh ---

TEST(LoadingRateMargin, TimeToEventExtrapolatesTheLastRise) {
  EXPECT_DOUBLE_EQ(timeToEvent(0.5, 0.6, 2.0), 8.0);   // 0.4 left at 0.05 per unit of loading time
  EXPECT_EQ(timeToEvent(0.9, 1.0, 2.0), 0.0);          // at its event
  EXPECT_EQ(timeToEvent(0.5, 1.2, 2.0), 0.0);          // past it (a rod the deletion rule has not taken yet)
  EXPECT_EQ(timeToEvent(0.6, 0.6, 2.0), INFINITY);     // not rising
  EXPECT_EQ(timeToEvent(0.7, 0.6, 2.0), INFINITY);     // unloading
  EXPECT_EQ(timeToEvent(NAN, 0.6, 2.0), INFINITY);     // failed before, or never measured
  EXPECT_EQ(timeToEvent(0.5, NAN, 2.0), INFINITY);     // failed now
}

TEST(LoadingRateMargin, ForecastIsTheEarliestElementInRows) {
  EventProgress before{1.0, {0.2, 0.5, NAN}, {0.1, 0.30}};
  EventProgress now{3.0, {0.3, 0.5, NAN}, {0.1, 0.35}};
  const EventForecast f = forecastEvents(before, now, 0.5);  // rows of 0.5 loading time: dtau is 4 rows
  EXPECT_DOUBLE_EQ(f.rowsElapsed, 4.0);
  EXPECT_DOUBLE_EQ(f.rowsToRodBreak, 0.7 * 2.0 / 0.1 / 0.5);          // rod 0: 14 time units, 28 rows
  EXPECT_DOUBLE_EQ(f.rowsToInterfaceFailure, 0.65 * 2.0 / 0.05 / 0.5);  // interface 1: 52 rows
  EXPECT_DOUBLE_EQ(rowsToFirstEvent(EventForecast{}, f, 1e9), 28.0);  // no last forecast: no trend
  // nothing rising: +inf; no measurement before (the first row, or another size): NaN, and the rule's rows NaN
  EXPECT_EQ(forecastEvents(now, now, 0.5).rowsToRodBreak, INFINITY);
  const EventForecast first = forecastEvents(EventProgress{}, now, 0.5);
  EXPECT_TRUE(std::isnan(first.rowsToRodBreak) && std::isnan(first.rowsToInterfaceFailure));
  EXPECT_TRUE(std::isnan(rowsToFirstEvent(EventForecast{}, first, 1e9)));
  // rods that do not break: no rod vectors at either row, the interfaces alone decide
  EventProgress b2{1.0, {}, {0.1, 0.30}}, n2{3.0, {}, {0.1, 0.35}};
  EXPECT_DOUBLE_EQ(rowsToFirstEvent(EventForecast{}, forecastEvents(b2, n2, 0.5), 1e9), 52.0);
}

TEST(LoadingRateMargin, TrendTakesAnAcceleratingForecastWithinReach) {
  EXPECT_DOUBLE_EQ(trendedRows(100.0, 92.0, 8.0, 1e9), 92.0);       // fell by the loading covered: exact
  EXPECT_DOUBLE_EQ(trendedRows(100.0, 95.0, 8.0, 1e9), 95.0);       // fell less: as is
  EXPECT_DOUBLE_EQ(trendedRows(100.0, 40.0, 8.0, 1e9), 40.0 * 8.0 / 60.0);  // fell 60 in 8: ~5.3 rows
  EXPECT_DOUBLE_EQ(trendedRows(100.0, 40.0, 8.0, 40.0), 40.0);      // not within reach: as is
  EXPECT_DOUBLE_EQ(trendedRows(INFINITY, 40.0, 8.0, 1e9), 40.0);    // a new element rising: as is
  EXPECT_EQ(trendedRows(40.0, INFINITY, 8.0, 1e9), INFINITY);
  EXPECT_TRUE(std::isnan(trendedRows(40.0, NAN, 8.0, 1e9)));
  EXPECT_DOUBLE_EQ(trendedRows(NAN, 40.0, 8.0, 1e9), 40.0);
}

TEST(LoadingRateMargin, TargetIsRowsOverHorizonWithinOneAndTheMaximum) {
  EXPECT_DOUBLE_EQ(marginRateTarget(1000.0, 10.0, 8.0), 8.0);  // far from an event: the maximum
  EXPECT_DOUBLE_EQ(marginRateTarget(INFINITY, 10.0, 8.0), 8.0);
  EXPECT_DOUBLE_EQ(marginRateTarget(40.0, 10.0, 8.0), 4.0);
  EXPECT_DOUBLE_EQ(marginRateTarget(9.0, 10.0, 8.0), 1.0);     // within the horizon: 1
  EXPECT_DOUBLE_EQ(marginRateTarget(NAN, 10.0, 8.0), 1.0);     // no forecast: 1
  EXPECT_DOUBLE_EQ(marginRateTarget(1000.0, 10.0, 1.0), 1.0);  // off
}

TEST(LoadingRateMargin, RaisesFarFromAnEventAsTheEnergyRuleAllows) {
  RateControlInput in = interval(1e-4);
  in.rowsToEvent = 1e6;
  double phi = 1;
  for (int k = 0; k < 12; ++k) phi = nextRateMultiplierByMargin(phi, 8.0, 10.0, in);
  EXPECT_DOUBLE_EQ(phi, 8.0);  // x1.25 a row up to the maximum
  // the energy rule still halves on a deletion or high kinetic ratio, and holds on a burst, far from an event
  RateControlInput deleted = interval(1e-4, 1);
  deleted.rowsToEvent = 1e6;
  EXPECT_DOUBLE_EQ(nextRateMultiplierByMargin(8.0, 8.0, 10.0, deleted), 4.0);
  RateControlInput burst = interval(1e-4, 0, 9);
  burst.rowsToEvent = 1e6;
  EXPECT_DOUBLE_EQ(nextRateMultiplierByMargin(5.0, 8.0, 10.0, burst), 5.0);
}

TEST(LoadingRateMargin, ApproachingAnEventTheRateIsOneOverTheLastHorizon) {
  // An event 2000 rows of loading at v_app ahead, forecast exactly: each row the loading covers the mean phi
  // of its ramp. phi rises to the maximum, falls as rows / horizon, is set to 1 on every row within the
  // horizon and is 1 there from the second of them on (on the first it ends its ramp from just above 1).
  for (double phiMax : {4.0, 8.0, 16.0}) {
    const double horizon = 10.0;
    double rows = 2000.0, phi = 1.0;
    int steps = 0, rowsWithin = 0;
    double peak = 1;
    while (rows > 0) {
      RateControlInput in = interval(1e-4);
      in.rowsToEvent = rows;
      const double next = nextRateMultiplierByMargin(phi, phiMax, horizon, in);
      if (rows <= horizon) {
        EXPECT_EQ(next, 1.0) << "phi_max " << phiMax << ", " << rows << " rows before the event";
        if (rowsWithin > 0) EXPECT_EQ(phi, 1.0) << "phi_max " << phiMax << ", " << rows << " rows before the event";
        EXPECT_LT(phi, 1.0 + 1.0 / horizon + 1e-12);
        ++rowsWithin;
      }
      rows -= 0.5 * (phi + next);
      phi = next;
      peak = std::max(peak, phi);
      ++steps;
    }
    EXPECT_EQ(peak, phiMax);
    EXPECT_GE(rowsWithin, 9);                          // the last horizon at phi = 1
    EXPECT_LT(steps, 2000 / phiMax + 12 * horizon);    // far fewer rows than 2000
  }
}

TEST(LoadingRateMargin, ARodNearItsStrengthHoldsTheRateAtOne) {
  // a rod element at 0.999 of its strength, rising by 0.001 per row: one row from breaking
  EventProgress before{0.0, {0.998, 0.5}, {0.2}}, now{1.0, {0.999, 0.5}, {0.2}};
  const EventForecast f = forecastEvents(before, now, 1.0);
  EXPECT_NEAR(f.rowsToRodBreak, 1.0, 1e-9);
  RateControlInput in = interval(1e-4);
  in.rowsToEvent = rowsToFirstEvent(EventForecast{}, f, 80.0);
  EXPECT_EQ(nextRateMultiplierByMargin(1.0, 8.0, 10.0, in), 1.0);
  EXPECT_EQ(nextRateMultiplierByMargin(6.0, 8.0, 10.0, in), 1.0);  // from a high rate: down to 1 at once
  // a rod past its strength (not deleted yet) is 0 rows away whatever its rise
  EventProgress past{1.0, {1.0001, 0.5}, {0.2}};
  EXPECT_EQ(forecastEvents(now, past, 1.0).rowsToRodBreak, 0.0);
}

// --- the velocity correction at a change of phi (rate_adapt_velocity = quasi_static), without a mesh ---

TEST(LoadingRateVelocity, FactorIsTheChangeOfTheQuasiStaticRate) {
  EXPECT_DOUBLE_EQ(quasiStaticVelocityFactor(1.0, 1.5, 0.2, 4.0), 0.5 * 0.2 / 4.0);   // raised: the interior speeds up
  EXPECT_DOUBLE_EQ(quasiStaticVelocityFactor(2.0, 1.0, 0.2, 4.0), -1.0 * 0.2 / 4.0);  // lowered: it slows down
  EXPECT_EQ(quasiStaticVelocityFactor(2.0, 2.0, 0.2, 4.0), 0.0);                      // held: nothing
  EXPECT_EQ(quasiStaticVelocityFactor(1.0, 2.0, 0.2, 0.0), 0.0);                      // U = 0: no motion to follow
  EXPECT_EQ(quasiStaticVelocityFactor(1.0, 2.0, 0.2, -1.0), 0.0);
  EXPECT_EQ(quasiStaticVelocityFactor(1.0, 2.0, 0.2, NAN), 0.0);
}

TEST(LoadingRateVelocity, ARampOfTheClockMovesTheQuasiStaticVelocityWithPhi) {
  // One DOF at q = 3 moving with the loading, v = phi (U'/U) q, U'/U = 0.05 held: the clock ramps phi from 1 to 6
  // over 7 steps and back to 2 over 5; the factors of each step, added as c q, keep v = phi (U'/U) q at every step.
  const double rate = 0.05, q = 3.0;
  State s;
  double v = s.rateMultiplier * rate * q;
  Loading on;
  on.rateAdaptMax = 8;
  for (auto [target, steps] : {std::pair{6.0, 7L}, std::pair{2.0, 5L}}) {
    setRateMultiplierTarget(s, target, steps);
    for (long k = 0; k < steps; ++k) {
      const double before = s.rateMultiplier;
      advanceLoadingClock(on, 0.1, s);
      v += quasiStaticVelocityFactor(before, s.rateMultiplier, rate, 1.0) * q;
      EXPECT_NEAR(v, s.rateMultiplier * rate * q, 1e-14) << "target " << target << ", step " << k;
    }
    EXPECT_EQ(s.rateMultiplier, target);
  }
}
