// The progress line's estimate of the time left (runner.hpp: estimateSecondsLeft), without a mesh.
#include <gtest/gtest.h>

#include <cmath>

#include "runner.hpp"

using enamel::estimateSecondsLeft;
using enamel::ProgressSample;
using enamel::StopTargets;

TEST(Progress, NoEstimateBeforeTheCrackStartsWithoutMaxSteps) {
  // Only the displacement limit is set, and it is a far safety net until the crack moves.
  const ProgressSample since{0, 0, 0, 0}, now{100, 1000, 0, 2};
  EXPECT_TRUE(std::isnan(estimateSecondsLeft(since, now, {30, 60, 0})));
}

TEST(Progress, MaxStepsGivesAnEstimateAtTheStepRate) {
  const ProgressSample since{0, 0, 0, 0}, now{100, 1000, 0, 2};
  EXPECT_DOUBLE_EQ(estimateSecondsLeft(since, now, {30, 60, 4000}), 300.0);
}

TEST(Progress, CrackAdvanceIsExtrapolatedFromWhereTheCrackStarted) {
  // The crack started at 10 h (not counted) and moved 3 d in the next 1000 s: 27 d left = 9000 s.
  const ProgressSample since{36000, 5e5, 0, 5}, now{37000, 5.2e5, 3, 5.5};
  const double left = estimateSecondsLeft(since, now, {30, 1000, 0});
  EXPECT_DOUBLE_EQ(left, 9000.0);
}

TEST(Progress, TheNearestCriterionWins) {
  // Crack: 27 d left at 3 d per 1000 s = 9000 s; displacement: 0.5 d left at 0.5 d per 1000 s = 1000 s.
  const ProgressSample since{0, 0, 0, 5}, now{1000, 2e4, 3, 5.5};
  EXPECT_DOUBLE_EQ(estimateSecondsLeft(since, now, {30, 6, 0}), 1000.0);
}

TEST(Progress, NoProgressSinceTheSampleGivesNoEstimateAndPastTargetsGiveZero) {
  const ProgressSample same{50, 100, 2, 3};
  EXPECT_TRUE(std::isnan(estimateSecondsLeft(same, same, {30, 60, 1000})));
  const ProgressSample since{0, 0, 0, 0}, now{10, 2000, 31, 1};
  EXPECT_DOUBLE_EQ(estimateSecondsLeft(since, now, {30, 0, 0}), 0.0);
}
