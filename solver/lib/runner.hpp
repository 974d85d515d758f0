#pragma once
// The run loop: time steps, R-curve points, history, frames, stop criteria, quasi-static and stability
// checks, progress on stderr, and the result file (written whole and atomically, also during the run).
#include <string>

#include "output.hpp"
#include "simulation.hpp"

namespace enamel {

struct RunOptions {
  std::string resultPath;            // result.h5 to write
  bool progress = true;              // progress lines on stderr
  double writeIntervalSeconds = 30;  // rewrite the (partial) result file this often
};

/// Run to a stop criterion. Never throws for a run that goes unstable: the record's status says
/// "failed" and stopReason says which quantity, at which step, with which value.
RunRecord runSimulation(Simulation& sim, const RunOptions& opt);

/// Ask a running simulation to stop at the next step (signal handlers call this).
void requestStop(int signal);

}  // namespace enamel
