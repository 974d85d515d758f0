// The progress line's estimate of the time left (runner.hpp: estimateTimeLeft, formatTimeLeft) and the
// quasi-static warning's row predicates, without a mesh.
#include <gtest/gtest.h>

#include <cmath>

#include "kernels/measurements.hpp"
#include "run/runner.hpp"

using enamel::estimateTimeLeft;
using enamel::formatTimeLeft;
using enamel::ProgressMarks;
using enamel::ProgressSample;
using enamel::StopTargets;
using enamel::TimeLeft;
using Basis = enamel::TimeLeft::Basis;

namespace {
// Marks of a piece that started at `start`, with the crack not yet moved.
ProgressMarks fromStart(const ProgressSample& start) { return ProgressMarks{start, start, start}; }
}  // namespace

TEST(Progress, BeforeTheCrackMovesTheLoadingGivesAnUpperBound) {
  // U went 0 -> 2 d in 100 s; the limit is 6 d: 4 d left = 200 s at most (the crack usually ends it sooner).
  const ProgressSample start{0, 0, 0, 0}, now{100, 1000, 0, 2};
  const TimeLeft t = estimateTimeLeft(fromStart(start), now, {30, 6, 0});
  EXPECT_DOUBLE_EQ(t.seconds, 200.0);
  EXPECT_EQ(t.basis, Basis::displacement);
  EXPECT_FALSE(t.stalled);
  EXPECT_EQ(formatTimeLeft(t), "<= 3 min (U limit)");
}

TEST(Progress, BeforeTheCrackMovesMaxStepsWinsWhenNearer) {
  const ProgressSample start{0, 0, 0, 0}, now{100, 1000, 0, 2};
  const TimeLeft t = estimateTimeLeft(fromStart(start), now, {30, 60, 4000});
  EXPECT_DOUBLE_EQ(t.seconds, 300.0);
  EXPECT_EQ(t.basis, Basis::steps);
  EXPECT_EQ(formatTimeLeft(t), "<= 5 min (max_steps)");
}

TEST(Progress, CrackAdvanceIsExtrapolatedFromWhereTheCrackStarted) {
  // The crack started at 10 h (not counted) and moved 3 d in the next 1000 s, the last time just now: 27 d
  // left = 9000 s, nearer than the displacement limit (U 5 -> 5.5 d since the start at 0 h: far).
  const ProgressSample start{0, 0, 0, 0}, crack{36000, 5e5, 0, 5}, now{37000, 5.2e5, 3, 5.5};
  const TimeLeft t = estimateTimeLeft({start, crack, now}, now, {30, 1000, 0});
  EXPECT_DOUBLE_EQ(t.seconds, 9000.0);
  EXPECT_EQ(t.basis, Basis::crack);
  EXPECT_EQ(formatTimeLeft(t), "2 h 30 min");
}

TEST(Progress, TheNearestCriterionWins) {
  // Crack: 27 d left at 3 d per 1000 s = 9000 s; displacement: 0.5 d left at 0.5 d per 1000 s = 1000 s.
  const ProgressSample start{0, 0, 0, 5}, now{1000, 2e4, 3, 5.5};
  const TimeLeft t = estimateTimeLeft({start, start, now}, now, {30, 6, 0});
  EXPECT_DOUBLE_EQ(t.seconds, 1000.0);
  EXPECT_EQ(t.basis, Basis::displacement);
}

TEST(Progress, AStalledCrackIsSaidAndTheLoadingGivesTheEstimate) {
  // The crack moved 4.9 d of 5 in 1000 s, the last time at 1000 s; at its average rate the last 0.1 d takes
  // ~20 s (or ~1000 s since the crack started, counting the silence). At 3000 s the crack has stood still for
  // 2000 s: stalled. The displacement (0 -> 3 d in 3000 s, limit 4 d) gives <= 1000 s.
  const ProgressSample start{0, 0, 0, 0}, lastMove{1000, 1e4, 4.9, 1}, now{3000, 3e4, 4.9, 3};
  const TimeLeft t = estimateTimeLeft({start, start, lastMove}, now, {5, 4, 0});
  EXPECT_TRUE(t.stalled);
  EXPECT_EQ(t.basis, Basis::displacement);
  EXPECT_DOUBLE_EQ(t.seconds, 1000.0);
  EXPECT_EQ(formatTimeLeft(t), "crack stalled, <= 17 min (U limit)");
  // The same crack 10 s after its last advance is not stalled: its own rate gives the estimate.
  const ProgressSample soon{1010, 1.01e4, 4.9, 1.01};
  const TimeLeft u = estimateTimeLeft({start, start, lastMove}, soon, {5, 4, 0});
  EXPECT_FALSE(u.stalled);
  EXPECT_EQ(u.basis, Basis::crack);
  EXPECT_NEAR(u.seconds, 1010 * 0.1 / 4.9, 1e-9);
}

TEST(Progress, AStalledCrackWithoutALoadingLimitSaysSo) {
  const ProgressSample start{0, 0, 0, 0}, lastMove{1000, 1e4, 4.9, 1}, now{3000, 3e4, 4.9, 3};
  const TimeLeft t = estimateTimeLeft({start, start, lastMove}, now, {5, 0, 0});
  EXPECT_TRUE(t.stalled);
  EXPECT_TRUE(std::isnan(t.seconds));
  EXPECT_EQ(formatTimeLeft(t), "crack stalled");
}

TEST(Progress, NoProgressSinceTheSampleGivesNoEstimateAndPastTargetsGiveZero) {
  const ProgressSample same{50, 100, 2, 3};
  const TimeLeft none = estimateTimeLeft(fromStart(same), same, {30, 60, 1000});
  EXPECT_TRUE(std::isnan(none.seconds));
  EXPECT_EQ(formatTimeLeft(none), "?");
  const ProgressSample start{0, 0, 0, 0}, now{10, 2000, 31, 1};
  EXPECT_DOUBLE_EQ(estimateTimeLeft({start, start, now}, now, {30, 0, 0}).seconds, 0.0);
}

TEST(QuasiStatic, TheRatioIsWatchedFromTheElasticStartWhateverTheCrackDoes) {
  enamel::Measurement r;
  r.kinetic = 0.2;
  r.strainBeams = 0.5;
  r.strainInterfaces = 0.5;
  EXPECT_DOUBLE_EQ(enamel::kineticOverStrain(r), 0.2);
  EXPECT_FALSE(enamel::pastElasticStart(r));  // elastic: the ratio says only how far the load has come
  r.brokenBeams = 3;                           // rods broke, the crack has not moved
  EXPECT_TRUE(enamel::pastElasticStart(r));
  r.brokenBeams = 0;
  r.inelasticInterfaces = 1;
  EXPECT_TRUE(enamel::pastElasticStart(r));
  r.inelasticInterfaces = 0;
  r.crackAdvance = 0.3;
  EXPECT_TRUE(enamel::pastElasticStart(r));
  EXPECT_DOUBLE_EQ(enamel::kineticOverStrain(enamel::Measurement{}), 0.0);  // no strain: no ratio
}

TEST(QuasiStatic, BeforeTheCrackGrowsOnlyTheMotionBeyondTheLoadingsCounts) {
  enamel::Measurement r;
  r.kinetic = 0.2;         // mostly the grips' steady motion: no inertia
  r.kineticBeyond = 0.01;  // beyond it
  r.strainBeams = 1;
  EXPECT_DOUBLE_EQ(enamel::quasiStaticRatio(r), 0.0);  // elastic
  r.inelasticInterfaces = 2;
  EXPECT_DOUBLE_EQ(enamel::quasiStaticRatio(r), 0.01);
  r.crackAdvance = 0.5;  // while the crack grows, kinetic / strain energy, or more
  EXPECT_DOUBLE_EQ(enamel::quasiStaticRatio(r), 0.2);
  r.kineticBeyond = 0.3;
  EXPECT_DOUBLE_EQ(enamel::quasiStaticRatio(r), 0.3);
}

TEST(EnergyBalance, TheErrorIsMeasuredAgainstTheWorkFloorUntilTheWorkExceedsIt) {
  const double floor = enamel::balanceWorkFloor(2.0, 1.5);
  EXPECT_DOUBLE_EQ(floor, 0.3);
  // The first rows: 1e-10 of work, 6.6e-11 of it unaccounted: -0.66 of the work, 2.2e-10 of the floor.
  EXPECT_NEAR(enamel::energyBalanceError(1e-10, 1.66e-10, floor), -6.6e-11 / 0.3, 1e-22);
  // Past the floor: the relative error of the balance.
  EXPECT_NEAR(enamel::energyBalanceError(10.0, 9.9, floor), 0.01, 1e-15);
  // Negative work is measured against its size.
  EXPECT_DOUBLE_EQ(enamel::energyBalanceError(-10.0, -9.0, floor), -0.1);
  EXPECT_DOUBLE_EQ(enamel::energyBalanceError(0.0, 0.0, 0.0), 0.0);
}
