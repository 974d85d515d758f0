// The integrators' registry (solver/lib/integrators/registry.cpp): one row per enumerator of IntegratorScheme (the
// `integrator` key's choices, choices.hpp), in order; each builds its own scheme, and a value without a row is
// refused with the list. The step's phase timers (step_timers.hpp): laps cover what lies between them, and a step
// with timers gives the same numbers as one without, its scheme's phases timed and no other's.
#include <gtest/gtest.h>
#include <omp.h>

#include <chrono>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "integrators/integrators.hpp"
#include "simulation/simulation.hpp"

using namespace enamel;

namespace {

CaseParams smallCase(const std::string& integrator) {
  // E_transverse given (not measured) to keep the set-up short.
  return parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\nE_transverse_over_Er = 0.1\n"
                   "w_s_over_d = 8\nh_s_over_d = 4\nintegrator = \"" + integrator + "\"\n",
                   "integrators", "", {});
}

}  // namespace

TEST(Integrators, RegistryHasOneRowPerIntegratorChoiceInOrder) {
  const auto& names = enumNames<IntegratorScheme>();
  ASSERT_EQ(integratorRegistry().size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i)
    EXPECT_EQ(nameOf(integratorRegistry()[i].scheme), names[i]) << "row " << i;
  std::string choices;
  for (const KeySpec& k : caseKeys())
    if (std::string(k.name) == "integrator") choices = k.choices;
  EXPECT_EQ(splitEnumNames(choices), names) << "the integrator key's choices are IntegratorScheme's names";
  EXPECT_EQ(smallCase("lumped").integrator, IntegratorScheme::lumped);
}

TEST(Integrators, EachRowEstimatesItsSchemesCostsGrowingWithTheModel) {
  // The estimates made before anything is built (resources.hpp) read a scheme's costs from its row alone.
  const SchemeSizes small{1000, 6000, 20}, large{8000, 48000, 80};
  for (const IntegratorEntry& e : integratorRegistry()) {
    ASSERT_NE(e.estimateCosts, nullptr) << nameOf(e.scheme);
    const CaseParams p = smallCase(nameOf(e.scheme));
    const SchemeCosts a = e.estimateCosts(p, small), b = e.estimateCosts(p, large);
    EXPECT_GT(a.memoryBytes, 0) << nameOf(e.scheme);
    EXPECT_GT(a.secondsPerStep, 0) << nameOf(e.scheme);
    EXPECT_GE(b.memoryBytes, 8 * a.memoryBytes) << nameOf(e.scheme);  // 8x the nodes, no less per node
    EXPECT_GE(b.secondsPerStep, 8 * a.secondsPerStep) << nameOf(e.scheme);
    EXPECT_EQ(&integratorEntry(e.scheme), &e);
  }
}

TEST(Integrators, EachRegisteredSchemeBuildsItselfAndOneWithoutARowIsRefused) {
  for (const IntegratorEntry& e : integratorRegistry()) {
    Simulation sim(smallCase(nameOf(e.scheme)));
    EXPECT_EQ(sim.integrator->name(), nameOf(e.scheme));
    EXPECT_GT(sim.integrator->timeStep(), 0);
    CaseParams other = sim.params;
    other.integrator = static_cast<IntegratorScheme>(enumNames<IntegratorScheme>().size());  // no row, no name
    try {
      makeIntegrator(other, sim.model, sim.materials, sim.ops);
      ADD_FAILURE() << "an integrator without a row was built";
    } catch (const IntegratorError& err) {
      std::string available;  // the registry's names, in its order
      for (const IntegratorEntry& r : integratorRegistry())
        available += (available.empty() ? "" : ", ") + nameOf(r.scheme);
      EXPECT_NE(std::string(err.what()).find("'?' is not available in this build (available: " + available + ")"),
                std::string::npos)
          << err.what();
    }
  }
}

// Laps book the time between them to their phases, one lap per call; without timers nothing is booked anywhere.
TEST(StepTimers, LapsBookTheTimeBetweenThem) {
  StepTimers t;
  const auto t0 = PhaseLaps::Clock::now();
  PhaseLaps laps(&t);
  std::this_thread::sleep_for(std::chrono::milliseconds(2));
  laps.lap(StepPhase::SliceNodes);
  laps.lap(StepPhase::SliceWrites);
  std::this_thread::sleep_for(std::chrono::milliseconds(1));
  laps.lap(StepPhase::SliceNodes);
  const double outside = std::chrono::duration<double>(PhaseLaps::Clock::now() - t0).count();
  const int nodes = static_cast<int>(StepPhase::SliceNodes), writes = static_cast<int>(StepPhase::SliceWrites);
  EXPECT_EQ(t.laps[nodes], 2);
  EXPECT_EQ(t.laps[writes], 1);
  EXPECT_GE(t.seconds[nodes], 3e-3);
  EXPECT_LE(t.seconds[nodes] + t.seconds[writes], outside);
  double others = 0;
  for (int i = 0; i < kStepPhaseCount; ++i)
    if (i != nodes && i != writes) others += t.seconds[i] + t.laps[i];
  EXPECT_EQ(others, 0.0);
  PhaseLaps none(nullptr);
  none.lap(StepPhase::SliceNodes);  // nowhere to book: nothing happens
  StepTimers sum;
  addShareOfTimers(t, 0.5, sum);
  EXPECT_EQ(sum.seconds[nodes], 0.5 * t.seconds[nodes]);
  EXPECT_EQ(sum.laps[nodes], 2);
}

// Both schemes, 2 threads: a run with timers is the run without them bit for bit; the timers hold every step,
// each phase of the scheme's step and of Simulation::step timed once per step (the lumped slice pass's phases per
// slice), none of the other scheme's; the parts of a phase take no longer than it (laps inside its lap).
TEST(StepTimers, TimedStepsAreTheStepsAndTimeTheirSchemesPhases) {
  using P = StepPhase;
  const std::vector<P> common = {P::Advance, P::InterfaceDissipation, P::DeletionCheck, P::Deletions, P::CrackMeasure};
  const std::vector<P> lumped = {P::InterfaceSchedule, P::SlicePass, P::SliceInterfaces, P::SliceNodes,
                                 P::SliceWrites, P::SliceBarrier, P::RodDamping, P::GripsAndWork, P::ClockAndGrips};
  const std::vector<P> paper = {P::PaperPositions, P::PaperBoundaryConditions, P::PaperInterfaces, P::PaperRodForces,
                                P::PaperAccelerations, P::PaperVelocities, P::PaperReactions};
  const int steps = 30;
  for (const std::string scheme : {"lumped", "paper"}) {
    Simulation plain(smallCase(scheme)), timed(smallCase(scheme));
    omp_set_num_threads(2);
    StepTimers t;
    timed.setTimers(&t);
    for (int n = 0; n < steps; ++n) plain.step(), timed.step();
    timed.setTimers(nullptr);
    timed.step(), plain.step();  // not timed
    EXPECT_EQ(timed.state.q, plain.state.q) << scheme;
    EXPECT_EQ(timed.state.v, plain.state.v) << scheme;
    EXPECT_EQ(timed.state.vHalf, plain.state.vHalf) << scheme;
    EXPECT_EQ(timed.state.lambdaMax, plain.state.lambdaMax) << scheme;
    EXPECT_EQ(timed.state.externalWork, plain.state.externalWork) << scheme;
    EXPECT_EQ(timed.state.dampingWork, plain.state.dampingWork) << scheme;
    EXPECT_EQ(t.steps, steps);
    std::vector<long> expected(kStepPhaseCount, 0);
    for (P p : common) expected[static_cast<int>(p)] = steps;
    for (P p : scheme == "lumped" ? lumped : paper) expected[static_cast<int>(p)] = steps;
    if (scheme == "lumped") {
      expected[static_cast<int>(P::GripsAndWork)] = 2 * steps;  // the grips' v_{n-1/2}, then their reactions and work
      for (P p : {P::SliceInterfaces, P::SliceNodes}) expected[static_cast<int>(p)] = steps * plain.model.numSlices;
      expected[static_cast<int>(P::SliceWrites)] = steps * (plain.model.numSlices + 2);  // and each thread's waiting slices
      expected[static_cast<int>(P::SliceBarrier)] = 2 * steps;
    }
    for (int i = 0; i < kStepPhaseCount; ++i) {
      EXPECT_EQ(t.laps[i], expected[i]) << scheme << ": " << kStepPhases[i].name;
      EXPECT_GE(t.seconds[i], 0.0) << kStepPhases[i].name;
    }
    double schemeParts = 0, sliceParts = 0;
    for (P p : scheme == "lumped" ? lumped : paper)
      (kStepPhases[static_cast<int>(p)].depth == 1 ? schemeParts : sliceParts) += t.seconds[static_cast<int>(p)];
    EXPECT_LE(schemeParts, t.seconds[static_cast<int>(P::Advance)]) << scheme;
    EXPECT_LE(sliceParts, t.seconds[static_cast<int>(P::SlicePass)] * (1 + 1e-12)) << scheme;
    EXPECT_GT(t.seconds[static_cast<int>(P::Advance)], 0.0);
  }
}
