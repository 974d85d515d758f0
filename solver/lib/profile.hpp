#pragma once
// Where a time step's time goes (`enamel-dem profile`, `make bench`): each kernel timed on its own over a
// number of steps of a built model, next to the bytes it has to move per step (a count of the arrays it
// reads and writes, each once per step) and a STREAM-like triad measured in the same process with the same
// threads, so that each kernel's achieved bandwidth can be held against what the machine can do.
// Measurement only: nothing here is called by a run.
#include <string>
#include <vector>

#include "simulation.hpp"

namespace enamel {

struct KernelTiming {
  std::string name;         // what was timed
  std::string what;         // the loop it is, in words
  double secondsPerStep = 0;
  double bytesPerStep = 0;  // the data it must move per step (profile.cpp: the count)
};

struct KernelProfile {
  int threads = 1;
  long steps = 0;           // steps timed per kernel
  double dof = 0;
  double triadBytesPerSecond = 0;  // a[i] = b[i] + s c[i] over three vectors far larger than the caches
  double stressComputedFraction = 0;  // rod elements the scheduled deletion check computed, per step, of all
  double interfaceEvaluatedFraction = 0;  // interfaces the step's law saw (InterfaceSchedule), per step, of all
  std::vector<KernelTiming> kernels;
};

/// Advance the simulation `warmup` steps, then time each kernel over `steps` steps: the whole step, the
/// integrator's advance, the interface forces alone, the rod stress check of every element (the step runs it as
/// scheduled: kernels.hpp StressCheckSchedule). The simulation is advanced by the
/// timed steps (a profile is a throw-away run). The `lumped` integrator only (IntegratorError otherwise).
KernelProfile profileKernels(Simulation& sim, long warmup, long steps);

/// The profile as a Markdown table (kernel, s/step, share of the step, bytes/step, GB/s, % of the triad)
/// with a header line naming the model size, threads and DOF-updates/s per core.
std::string formatProfileMarkdown(const KernelProfile& p);

}  // namespace enamel
