#pragma once
// The time step's phase timers (`enamel-dem profile`, profile.hpp): the seconds each phase of the step took,
// booked by the step itself around the calls it makes for that phase (PhaseLaps), so that every phase is
// measured where the step runs it and none is derived as a difference. Filled only while a Simulation holds
// timers (Simulation::setTimers; a run holds none, and then each lap is one test of a null pointer, taken once
// per phase call: never inside a loop over nodes, interfaces or rod elements). Plain data and a clock.
#include <array>
#include <chrono>

namespace enamel {

/// The phases of a time step, both schemes', in the order the profile prints them (kStepPhases: their names).
enum class StepPhase : int {
  Advance,  // Simulation::step: the scheme's step (integrators.hpp Integrator::advance)
  // lumped (integrators/lumped.cpp)
  InterfaceSchedule,
  SlicePass,
  SliceInterfaces,
  SliceNodes,
  SliceWrites,
  SliceBarrier,
  RodDamping,
  GripsAndWork,
  ClockAndGrips,
  // paper (integrators/newmark.cpp)
  PaperPositions,
  PaperBoundaryConditions,
  PaperInterfaces,
  PaperRodForces,
  PaperAccelerations,
  PaperVelocities,
  PaperReactions,
  // Simulation::step, after the scheme's step
  InterfaceDissipation,
  DeletionCheck,
  Deletions,
  CrackMeasure,
  Count
};
inline constexpr int kStepPhaseCount = static_cast<int>(StepPhase::Count);

/// A phase's row of the profile: its name, its depth (0: a part of Simulation::step; 1: of the scheme's step;
/// 2: of the lumped slice pass, per thread) and the calls it times.
struct StepPhaseInfo {
  StepPhase phase;
  const char* name;
  int depth;
  const char* what;
};
inline constexpr std::array<StepPhaseInfo, kStepPhaseCount> kStepPhases = {{
    {StepPhase::Advance, "advance", 0, "the scheme's step (Integrator::advance)"},
    {StepPhase::InterfaceSchedule, "interface schedule", 1,
     "advanceInterfaceSchedule: each slice's drift of the displacements, which interfaces may be due"},
    {StepPhase::SlicePass, "slice pass", 1,
     "computeForcesAndAdvanceVelocities: the parallel pass over the slices, forces then velocities and positions"},
    {StepPhase::SliceInterfaces, "interfaces", 2,
     "per slice, mean over the threads: addInterfaceCorrectionsOfSliceScheduled, the law where the schedule makes an interface due and, "
     "off the elastic branch, its force beyond the elastic one"},
    {StepPhase::SliceNodes, "nodes", 2,
     "per slice, mean over the threads: advanceNodesOfSlice, per node K_I q, K q, K v, v_{n+1/2}, grip residuals, damping sums, "
     "q_{n+1} = q_n + dt v_{n+1/2}"},
    {StepPhase::SliceWrites, "slice writes", 2,
     "per slice, mean over the threads: SliceOutputs, v_{n+1/2} and q_{n+1} written over the old values (the waiting slices after the "
     "barrier)"},
    {StepPhase::SliceBarrier, "barrier", 2, "mean over the threads: waiting for the other threads at the pass's barrier"},
    {StepPhase::RodDamping, "rod damping", 1,
     "solveRodDampingOfStep (rod_damping implicit): the rods' s M + dt b K solved, q corrected, the slices' sums"},
    {StepPhase::GripsAndWork, "grips and work", 1,
     "computeReactions, addWorkOfGrips, addDampingWork: the grips' reactions and work, the damping work"},
    {StepPhase::ClockAndGrips, "clock and grips", 1,
     "moveOfStep, advanceClock, prescribeDisplacements, boundOfMove: t_{n+1}, q of the grips, the step's move"},
    {StepPhase::PaperPositions, "positions", 1, "predictVelocities, advancePositions: w, q_{n+1}"},
    {StepPhase::PaperBoundaryConditions, "boundary conditions", 1,
     "advanceClock, applyBoundaryConditions: t_{n+1}, q, v, a of the grips"},
    {StepPhase::PaperInterfaces, "interface forces", 1,
     "computeForcesForInterfaces: every interface by the law, its wrench on both nodes"},
    {StepPhase::PaperRodForces, "rod forces", 1, "computeForcesForBeams: K q, K w, M w (sparse products)"},
    {StepPhase::PaperAccelerations, "accelerations", 1, "solveAccelerations: H_ff a_f = r_f - H_fp a_p"},
    {StepPhase::PaperVelocities, "velocities", 1, "advanceVelocities, addDampingWork"},
    {StepPhase::PaperReactions, "reactions and work", 1, "computeReactions, addWorkOfGrips"},
    {StepPhase::InterfaceDissipation, "interface dissipation", 0,
     "bookInterfaceDissipation (mixed-mode law only; nothing to book otherwise)"},
    {StepPhase::DeletionCheck, "deletion check", 0, "checkRodStresses: the rod stress check as scheduled"},
    {StepPhase::Deletions, "deletions", 0,
     "deleteOverloadedBeams: the overloaded rod elements found and, where there are any, deleted"},
    {StepPhase::CrackMeasure, "crack measure", 0, "measureCrackAdvance, when something failed or broke"},
}};
constexpr bool stepPhasesInOrder() {
  for (int i = 0; i < kStepPhaseCount; ++i)
    if (static_cast<int>(kStepPhases[i].phase) != i) return false;
  return true;
}
static_assert(stepPhasesInOrder(), "kStepPhases lists the phases in the order of StepPhase");

/// Seconds booked to each phase and the laps that booked them, over the steps timed. A phase of the slice pass
/// (depth 2) holds the mean over the pass's threads of each thread's seconds, and all of their laps.
struct StepTimers {
  std::array<double, kStepPhaseCount> seconds{};
  std::array<long, kStepPhaseCount> laps{};
  long steps = 0;  // Simulation::step calls timed
};

/// Laps of a step's phases: lap(p) books the time since the last lap (or since the laps began) to phase p, so
/// that consecutive laps cover the calls between them with no gap. Does nothing without timers.
class PhaseLaps {
 public:
  using Clock = std::chrono::steady_clock;
  explicit PhaseLaps(StepTimers* timers) : timers_(timers) {
    if (timers_) last_ = Clock::now();
  }
  void lap(StepPhase p) {
    if (!timers_) return;
    const Clock::time_point now = Clock::now();
    timers_->seconds[static_cast<int>(p)] += std::chrono::duration<double>(now - last_).count();
    ++timers_->laps[static_cast<int>(p)];
    last_ = now;
  }

 private:
  StepTimers* timers_;
  Clock::time_point last_{};
};

/// to += share x (one thread's seconds), and its laps (the lumped slice pass: share = 1 / threads).
inline void addShareOfTimers(const StepTimers& thread, double share, StepTimers& to) {
  for (int i = 0; i < kStepPhaseCount; ++i) {
    to.seconds[i] += share * thread.seconds[i];
    to.laps[i] += thread.laps[i];
  }
}

}  // namespace enamel
