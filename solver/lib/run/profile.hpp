#pragma once
// Where a time step's time goes (`enamel-dem profile`, `make bench`): the real step run a number of times on a
// built model with its phase timers on (step_timers.hpp: each phase timed around the calls the step makes for
// it), next to the bytes some phases have to move per step (a count of the arrays they read and write, each
// once per step) and a STREAM-like triad measured in the same process with the same threads, so that a phase's
// achieved bandwidth can be held against what the machine can do. Measurement only: nothing here is called by
// a run.
#include <cmath>
#include <string>
#include <vector>

#include "data/step_timers.hpp"
#include "simulation/simulation.hpp"

namespace enamel {

/// One phase of the step as the profile reports it (a row of kStepPhases that the step timed).
struct PhaseTiming {
  StepPhase phase;
  std::string what;          // the calls it times, with what the step did there
  double secondsPerStep = 0;
  double lapsPerStep = 0;    // laps booked to it per step (per slice and thread in the slice pass)
  double bytesPerStep = NAN; // the data it must move per step (profile.cpp: the count); NaN: not counted
};

struct StepProfile {
  std::string scheme;       // the integrator's name
  int threads = 1;
  long warmup = 0, steps = 0;  // steps run before timing, steps timed
  double dof = 0;
  double secondsPerStep = 0;   // the whole step, timed around each Simulation::step call
  double stepBytes = NAN;      // the data the whole step must move (NaN: not counted for this scheme)
  double triadBytesPerSecond = 0;  // a[i] = b[i] + s c[i] over three vectors far larger than the caches
  double clockReadSeconds = 0;     // one steady_clock::now(), as the timers read it
  double stressComputedFraction = 0;  // rod elements the scheduled deletion check computed, per step, of all
  double interfaceEvaluatedFraction = NAN;  // interfaces the lumped step's law saw (InterfaceSchedule), per step
  std::vector<PhaseTiming> phases;  // those the step timed, in the order of kStepPhases
  double displacementBefore = 0, displacementAfter = 0;  // the applied displacement U before and after the timed steps
  double phiBefore = 1, phiAfter = 1;                    // the loading rate's multiplier then (State::rateMultiplier)
};

/// Advance the simulation `warmup` steps, then `steps` more with its timers on (Simulation::setTimers), each
/// timed around its call; the timers are off again on return. The simulation is advanced by all of them (a
/// profile is a throw-away run). Either scheme.
StepProfile profileStep(Simulation& sim, long warmup, long steps);

/// The profile as a Markdown table (phase, ms/step, share of the step, laps/step, MB/step, GB/s, % of the
/// triad, what it times), the phases indented under the step and their parents, with a header line naming the
/// model size, threads, scheme, steps, ms/step and DOF-updates/s per core, and a line after it with the loading
/// over the timed steps (U/d and phi before and after: `enamel-dem profile --rate-multiplier` holds or ramps phi).
std::string formatProfileMarkdown(const StepProfile& p);

}  // namespace enamel
