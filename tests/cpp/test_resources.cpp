// The run-time estimate (resources.hpp): the pure model's response to the keys that set a run's length and
// cost, and the block's time step against the one of the model the case builds.
#include "simulation/resources.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "case/case_params.hpp"
#include "integrators/integrators.hpp"
#include "simulation/simulation.hpp"

using namespace enamel;

namespace {

CaseParams caseAt(const std::string& preset, const std::vector<std::string>& sets = {}) {
  return parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n", "case.toml", preset, sets);
}

// c_d and dt of the theta30 case at the reduced preset (enamel-dem info), so the numbers are of a real size.
const StepScale kScale{0.65, 0.09};

}  // namespace

TEST(RunTimeEstimate, HalfRateTwinTakesAboutTwiceAsLong) {
  const TimeEstimate base = estimateRunTime(caseAt("reduced"), kScale);
  const TimeEstimate twin = estimateRunTime(caseAt("reduced", {"rate_factor=0.5"}), kScale);
  // the ramp lasts as long at either rate (it is h_s / c_d), so a little under 2x
  EXPECT_GT(twin.steps / base.steps, 1.8);
  EXPECT_LE(twin.steps / base.steps, 2.0);
  EXPECT_GT(twin.seconds / base.seconds, 1.8);
  EXPECT_DOUBLE_EQ(twin.uEnd, base.uEnd);
  EXPECT_DOUBLE_EQ(twin.secondsPerStep, base.secondsPerStep);
}

TEST(RunTimeEstimate, LargerSpecimenCostsMorePerStepAndInAll) {
  const TimeEstimate reduced = estimateRunTime(caseAt("reduced"), kScale);
  const TimeEstimate larger = estimateRunTime(caseAt("reduced", {"w_s_over_d=80", "h_s_over_d=80"}), kScale);
  EXPECT_GT(larger.secondsPerStep, 7 * reduced.secondsPerStep);  // 8x the DOF
  EXPECT_GT(larger.seconds, 7 * reduced.seconds);
  EXPECT_GT(larger.setupSeconds, reduced.setupSeconds);
}

TEST(RunTimeEstimate, StepsFollowTheStopCriteriaAndTheTimeStep) {
  const TimeEstimate base = estimateRunTime(caseAt("reduced"), kScale);
  const TimeEstimate longer = estimateRunTime(caseAt("reduced", {"stop_da_over_d=24"}), kScale);
  EXPECT_GT(longer.uEnd, 1.5 * base.uEnd);
  EXPECT_GT(longer.steps, 1.5 * base.steps);
  const TimeEstimate halfStep = estimateRunTime(caseAt("reduced"), {kScale.c_d, kScale.dt / 2});
  EXPECT_NEAR(halfStep.steps / base.steps, 2.0, 1e-3);
  EXPECT_DOUBLE_EQ(estimateRunTime(caseAt("reduced", {"stop_u_over_d=0.5"}), kScale).uEnd, 0.5);
  EXPECT_DOUBLE_EQ(estimateRunTime(caseAt("reduced", {"max_steps=1000"}), kScale).steps, 1000);
  // displacements scale with delta0: at half of it the run stops at half the displacement
  EXPECT_DOUBLE_EQ(estimateRunTime(caseAt("reduced", {"delta0_over_d=0.05"}), kScale).uEnd, 0.5 * base.uEnd);
}

TEST(RunTimeEstimate, StaticStartSkipsTheElasticStage) {
  const TimeEstimate fromRest = estimateRunTime(caseAt("converged", {"static_start=0"}), kScale);
  const TimeEstimate fromStatic = estimateRunTime(caseAt("converged"), kScale);  // static_start 0.95
  EXPECT_EQ(fromRest.uStart, 0);
  EXPECT_GT(fromStatic.uStart, 0);
  EXPECT_LT(fromStatic.uStart, fromStatic.uEnd);
  EXPECT_LT(fromStatic.steps, fromRest.steps);
  EXPECT_GT(fromStatic.setupSeconds, fromRest.setupSeconds);  // the static solve
}

TEST(RunTimeEstimate, PaperSchemeCostsMorePerStep) {
  const TimeEstimate lumped = estimateRunTime(caseAt("reduced"), kScale);
  const TimeEstimate paper = estimateRunTime(caseAt("reduced", {"integrator=\"paper\""}), kScale);
  EXPECT_GT(paper.secondsPerStep, 3 * lumped.secondsPerStep);
}

// The block's dt is the one of the model the case builds: exactly for `paper` (the element's frequency, the same
// h_e), and within 2% for `lumped` (omega_max, local: +1.2% here at 24 x 12 d against the 16 x 8 d block; -0.7% at
// 40 x 20 d and -1.0% at 80 x 80 d, docs/cluster.md).
TEST(StepScaleOfBlock, TimeStepIsTheFullModels) {
  for (const char* integrator : {"lumped", "paper"}) {
    const CaseParams p =
        caseAt("ci", {"w_s_over_d=24", "h_s_over_d=12", std::string("integrator=\"") + integrator + "\""});
    const StepScale block = stepScaleOfBlock(p);
    Simulation full(p);
    const double tolerance = std::string(integrator) == "paper" ? 1e-12 : 0.02;
    EXPECT_NEAR(block.dt / full.integrator->timeStep(), 1.0, tolerance) << integrator;
    EXPECT_DOUBLE_EQ(block.c_d, full.materials.c_d) << integrator;
  }
}

TEST(StepPlan, TheRunsPlanEndsAtTheEstimatesStepsAndTheCrackStartsBefore) {
  // The run's plan from its first state (step 0 at the start displacement) ends where estimateRunTime's steps do.
  for (const char* preset : {"ci", "converged"}) {
    const CaseParams p = caseAt(preset);
    const TimeEstimate t = estimateRunTime(p, kScale);
    Loading loading;
    loading.vApp = p.rate_factor * p.v_app_over_cd * kScale.c_d;
    loading.rampTime = p.ramp_transits * p.h_s_over_d / kScale.c_d;
    const StepPlan plan = planSteps(p, loading, kScale.dt, 0, loading.timeOfDisplacement(t.uStart));
    EXPECT_NEAR(plan.endStep, t.steps, 1.0) << preset;
    EXPECT_GT(plan.initiationStep, 0) << preset;
    EXPECT_LT(plan.initiationStep, 0.9 * plan.endStep) << preset;
    // step numbers of the run: the same plan from a later state
    const StepPlan later = planSteps(p, loading, kScale.dt, 1000, loading.timeOfDisplacement(t.uStart) + 1000 * kScale.dt);
    EXPECT_NEAR(later.endStep, plan.endStep, 1e-6 * plan.endStep) << preset;
    EXPECT_NEAR(later.initiationStep, plan.initiationStep, 1e-6 * plan.endStep) << preset;
  }
}
