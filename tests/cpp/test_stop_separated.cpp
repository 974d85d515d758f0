// The stop for a separated specimen (runner.hpp watchLoadDrop, case keys stop_load_fraction and
// stop_load_transits) on prescribed history rows, without a mesh.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "case/case_params.hpp"
#include "run/runner.hpp"

using namespace enamel;

namespace {

Measurement row(double time, double load, double crackAdvance) {
  Measurement r;
  r.time = time;
  r.load = load;
  r.crackAdvance = crackAdvance;
  return r;
}

// The watch folded over rows; returns the index of the first row at which it reports separated, or -1.
int firstSeparatedRow(const std::vector<Measurement>& rows, double fraction, double hold) {
  LoadDropWatch w;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    w = watchLoadDrop(w, rows[i], fraction, hold);
    if (w.separated) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace

TEST(StopSeparated, LoadBelowTheFractionOfItsPeakForTheHoldAfterTheCrackStarted) {
  // load rises to 10, the crack starts at t = 4, the load falls to 0.3 (< 0.05 x 10) from t = 6 on
  std::vector<Measurement> rows;
  for (int i = 0; i <= 20; ++i) {
    const double t = i;
    const double load = t <= 4 ? 2.5 * t : (t < 6 ? 10 - 4.85 * (t - 4) : 0.3);
    rows.push_back(row(t, load, t >= 4 ? 0.1 * (t - 3) : 0.0));
  }
  EXPECT_EQ(firstSeparatedRow(rows, 0.05, 3.0), 9);  // below from t = 6; 6 + 3 = 9
  EXPECT_EQ(firstSeparatedRow(rows, 0.05, 0.0), 6);
  EXPECT_EQ(firstSeparatedRow(rows, 0.02, 3.0), -1);  // 0.3 is not below 0.2
  EXPECT_EQ(firstSeparatedRow(rows, 0.0, 3.0), -1);   // off
  EXPECT_EQ(firstSeparatedRow(rows, 0.05, 20.0), -1);  // not long enough
  LoadDropWatch w;
  for (const Measurement& r : rows) w = watchLoadDrop(w, r, 0.05, 3.0);
  EXPECT_EQ(w.peakLoad, 10.0);
  EXPECT_EQ(w.belowSince, 6.0);
}

TEST(StopSeparated, NotBeforeTheCrackStartsAndTheHoldRestartsWhenTheLoadRecovers) {
  // a low load before the crack has started (the ramp from rest) never counts
  std::vector<Measurement> rows = {row(0, 0, 0), row(1, 5, 0), row(2, 0.1, 0), row(3, 0.1, 0), row(4, 0.1, 0)};
  EXPECT_EQ(firstSeparatedRow(rows, 0.05, 1.0), -1);
  // below at t = 1, 2, back above at t = 3 (a reload), below again from t = 4: the hold counts from 4
  rows = {row(0, 10, 0.5), row(1, 0.1, 1), row(2, 0.1, 1), row(3, 2, 1), row(4, 0.1, 1.2), row(5, 0.1, 1.2),
          row(6, -0.2, 1.2), row(7, 0.1, 1.2)};
  EXPECT_EQ(firstSeparatedRow(rows, 0.05, 2.5), 7);
  EXPECT_EQ(firstSeparatedRow(rows, 0.05, 1.0), 2);
  // once reported it stays reported (a restart's fold over the rows read back gives the same answer)
  LoadDropWatch w;
  for (const Measurement& r : rows) w = watchLoadDrop(w, r, 0.05, 1.0);
  EXPECT_TRUE(w.separated);
}

TEST(StopSeparated, KeysDefaultOnAndCanBeSwitchedOff) {
  const CaseParams p = parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 7.1\n", "t", "ci", {});
  EXPECT_EQ(p.stop_load_fraction, 0.05);
  EXPECT_EQ(p.stop_load_transits, 1.0);
  EXPECT_EQ(parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 7.1\n", "t", "ci",
                      {"stop_load_fraction=0"}).stop_load_fraction, 0.0);
  EXPECT_THROW(parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 7.1\n", "t", "ci",
                         {"stop_load_fraction=1"}), CaseError);
  EXPECT_THROW(parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 7.1\n", "t", "ci",
                         {"stop_load_transits=0"}), CaseError);
}
