// The progress line's estimate of the time left (runner.hpp: estimateTimeLeft, formatTimeLeft) on crafted
// samples and plans, and the quasi-static warning's row predicates, without a mesh.
#include <gtest/gtest.h>

#include <cmath>

#include "kernels/measurements.hpp"
#include "run/runner.hpp"

using enamel::estimateTimeLeft;
using enamel::formatTimeLeft;
using enamel::ProgressMarks;
using enamel::ProgressSample;
using enamel::StepPlan;
using enamel::StopTargets;
using enamel::TimeLeft;
using Basis = enamel::TimeLeft::Basis;

namespace {
// Marks of a piece that started at `start`, with the crack not yet moved.
ProgressMarks fromStart(const ProgressSample& start) { return ProgressMarks{start, start, start}; }

// A plan (planSteps): the crack starts at step 5000, the run stops at step 20000 (15000 steps of crack growth).
const StepPlan kPlan{5000, 20000};
}  // namespace

TEST(Progress, TheFirstLineGivesTheEstimatesRemainingTime) {
  // 1000 steps in 10 s: 100 steps/s; 19000 steps to the plan's end = 190 s. The U limit (1000 d) is far.
  const ProgressSample start{0, 0, 0, 0}, now{10, 1000, 0, 0.5};
  const TimeLeft t = estimateTimeLeft(fromStart(start), now, {5, 1000, 0}, kPlan);
  EXPECT_DOUBLE_EQ(t.seconds, 190.0);
  EXPECT_EQ(t.basis, Basis::estimate);
  EXPECT_FALSE(t.paused);
  EXPECT_EQ(formatTimeLeft(t), "3 min (estimate)");
}

TEST(Progress, ACrackLaterThanThePlanLeavesItsWholeGrowthToCome) {
  // Step 8000 is past the plan's start of the crack (5000), which has not moved: its 15000 steps are still to
  // come, at 100 steps/s.
  const ProgressSample start{0, 0, 0, 0}, now{80, 8000, 0, 3};
  const TimeLeft t = estimateTimeLeft(fromStart(start), now, {5, 1000, 0}, kPlan);
  EXPECT_DOUBLE_EQ(t.seconds, 150.0);
  EXPECT_EQ(t.basis, Basis::estimate);
}

TEST(Progress, AMovingCrackBlendsThePlanTowardItsOwnRate) {
  // 10 steps/s. The crack started at 100 s and is at 2.5 d of 5 at 200 s: the plan's half of its 15000 steps
  // left is 750 s, the crack's rate gives 100 s; half the advance is made: 425 s.
  const ProgressSample start{0, 0, 0, 0}, crack{100, 1000, 0, 2.5}, now{200, 2000, 2.5, 3};
  const TimeLeft t = estimateTimeLeft({start, crack, now}, now, {5, 1000, 0}, kPlan);
  EXPECT_DOUBLE_EQ(t.seconds, 425.0);
  EXPECT_EQ(t.basis, Basis::crack);
  EXPECT_EQ(formatTimeLeft(t), "7 min");
  // At 4 d of 5 (0.8 of the advance made): 0.8 x 25 s + 0.2 x 300 s.
  const ProgressSample later{200, 2000, 4, 3};
  EXPECT_DOUBLE_EQ(estimateTimeLeft({start, crack, later}, later, {5, 1000, 0}, kPlan).seconds, 80.0);
}

TEST(Progress, APausedCrackIsSaidAndGivesTheEstimateNotSeconds) {
  // The crack ran 4.9 d of 5 in 50 s (from 100 s to 150 s) and stands still at 300 s: its average rate gives
  // 4 s for the last 0.1 d, but it has stood still for 150 s: paused, and expected to take at least as long again.
  const ProgressSample start{0, 0, 0, 0}, crack{100, 1000, 0, 2.5}, lastMove{150, 1500, 4.9, 2.8},
      now{300, 3000, 4.9, 3.5};
  const TimeLeft t = estimateTimeLeft({start, crack, lastMove}, now, {5, 1000, 0}, kPlan);
  EXPECT_TRUE(t.paused);
  EXPECT_EQ(t.basis, Basis::crack);
  EXPECT_DOUBLE_EQ(t.seconds, 150.0);
  EXPECT_EQ(formatTimeLeft(t), "crack paused at Delta_a 4.90 d, estimate 3 min");
  // Paused at 2.5 d of 5: the plan's share of the rest (7500 steps at 10 steps/s) is the estimate.
  const ProgressSample halfway{150, 1500, 2.5, 2.8}, stillHalfway{300, 3000, 2.5, 3.5};
  const TimeLeft u = estimateTimeLeft({start, crack, halfway}, stillHalfway, {5, 1000, 0}, kPlan);
  EXPECT_TRUE(u.paused);
  EXPECT_DOUBLE_EQ(u.seconds, 750.0);
  EXPECT_EQ(formatTimeLeft(u), "crack paused at Delta_a 2.50 d, estimate 13 min");
}

TEST(Progress, ABriefStandstillIsNoPause) {
  // 5 s without an advance is under kPauseMinSeconds. 60 s after a crack that moved 2.5 d in 50 s is a pause
  // (its average rate since it started, 2.5 d in 110 s, gives 1.4 d for 60 s: more than kPauseAdvance); 60 s after
  // one that moved 0.3 d in 200 s is not (0.07 d, under half its advance).
  const ProgressSample start{0, 0, 0, 0}, crack{100, 1000, 0, 2.5};
  const ProgressSample moved{150, 1500, 2.5, 2.8}, soon{155, 1550, 2.5, 2.8}, minute{210, 2100, 2.5, 2.9};
  EXPECT_FALSE(estimateTimeLeft({start, crack, moved}, soon, {5, 1000, 0}, kPlan).paused);
  EXPECT_TRUE(estimateTimeLeft({start, crack, moved}, minute, {5, 1000, 0}, kPlan).paused);
  const ProgressSample slow{300, 3000, 0.3, 3}, slowMinute{360, 3600, 0.3, 3.1};
  EXPECT_FALSE(estimateTimeLeft({start, crack, slow}, slowMinute, {5, 1000, 0}, kPlan).paused);
}

TEST(Progress, AtARestartThePlanGivesTheRestUntilTheCrackMovesAgain) {
  // The piece started at step 10000 with the crack at 2 d of 5 (it had moved before the restart): the plan's
  // 3/5 of 15000 steps at 100 steps/s.
  const ProgressSample restart{0, 10000, 2, 3}, now{10, 11000, 2, 3.1};
  const TimeLeft t = estimateTimeLeft(fromStart(restart), now, {5, 1000, 0}, kPlan);
  EXPECT_DOUBLE_EQ(t.seconds, 90.0);
  EXPECT_EQ(t.basis, Basis::estimate);
  EXPECT_FALSE(t.paused);
}

TEST(Progress, AStopCriterionOfTheLoadingThatComesFirstWins) {
  // The estimate gives 190 s; U goes 0 -> 0.5 d in 10 s and stops at 1 d: <= 10 s; max_steps 1500: <= 5 s.
  const ProgressSample start{0, 0, 0, 0}, now{10, 1000, 0, 0.5};
  const TimeLeft u = estimateTimeLeft(fromStart(start), now, {5, 1, 0}, kPlan);
  EXPECT_DOUBLE_EQ(u.seconds, 10.0);
  EXPECT_EQ(formatTimeLeft(u), "<= 10 s (U limit)");
  const TimeLeft s = estimateTimeLeft(fromStart(start), now, {5, 1, 1500}, kPlan);
  EXPECT_DOUBLE_EQ(s.seconds, 5.0);
  EXPECT_EQ(formatTimeLeft(s), "<= 5 s (max_steps)");
  // A paused crack says so before the limit.
  const ProgressSample crack{100, 1000, 0, 2.5}, lastMove{150, 1500, 4.9, 2.8}, later{300, 3000, 4.9, 3.5};
  EXPECT_EQ(formatTimeLeft(estimateTimeLeft({start, crack, lastMove}, later, {5, 4, 0}, kPlan)),
            "crack paused at Delta_a 4.90 d, <= 43 s (U limit)");
}

TEST(Progress, WithoutAPlanTheLoadingGivesAnUpperBoundUntilTheCrackMoves) {
  // U went 0 -> 2 d in 100 s; the limit is 6 d: 4 d left = 200 s at most (the crack usually ends it sooner).
  const ProgressSample start{0, 0, 0, 0}, now{100, 1000, 0, 2};
  const TimeLeft t = estimateTimeLeft(fromStart(start), now, {30, 6, 0});
  EXPECT_DOUBLE_EQ(t.seconds, 200.0);
  EXPECT_EQ(t.basis, Basis::displacement);
  EXPECT_EQ(formatTimeLeft(t), "<= 3 min (U limit)");
  // Once it moves, its own rate: 27 d left at 3 d per 1000 s since it started.
  const ProgressSample crack{36000, 5e5, 0, 5}, moving{37000, 5.2e5, 3, 5.5};
  const TimeLeft c = estimateTimeLeft({start, crack, moving}, moving, {30, 1000, 0});
  EXPECT_DOUBLE_EQ(c.seconds, 9000.0);
  EXPECT_EQ(formatTimeLeft(c), "2 h 30 min");
}

TEST(Progress, NoProgressSinceTheSampleGivesNoEstimateAndPastTargetsGiveZero) {
  const ProgressSample same{50, 100, 2, 3};
  const TimeLeft none = estimateTimeLeft(fromStart(same), same, {30, 60, 1000}, kPlan);
  EXPECT_TRUE(std::isnan(none.seconds));
  EXPECT_EQ(formatTimeLeft(none), "?");
  const ProgressSample start{0, 0, 0, 0}, now{10, 2000, 31, 1};
  EXPECT_DOUBLE_EQ(estimateTimeLeft({start, start, now}, now, {30, 0, 0}, kPlan).seconds, 0.0);
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
