#pragma once
// What a case will need before the model is built: counts of the model from the case keys alone, the
// memory of a run from them (a case that cannot fit is refused with the
// memory needed and the memory available, before anything is allocated or written; cluster jobs ask for it),
// and one core's wall time of a whole run from the case keys and the time step of a small block of the case.
#include <string>

#include "case/case_params.hpp"
#include "data/state.hpp"

namespace enamel {

/// Counts of the model a case builds, from the geometry's own rules (docs/model.md), in double precision
/// so that an absurd case (h_e = 1e-9 d, a 2000 d specimen) gives a large number instead of an overflow.
struct ResourceEstimate {
  double slices = 0;       // w_s / h_e + 1
  double nodes = 0;        // slices x rods crossing a slice (2 plies x h_s cos theta / d)
  double dof = 0;          // 6 per node
  double interfaces = 0;   // about 3 per node (6 Voronoi neighbours, each shared)
  double memoryBytes = 0;  // peak resident memory of a run
};

/// Estimate from the case keys. Memory: the scheme's own, from its row of the integrators' registry
/// (IntegratorEntry::estimateCosts: bytes per node measured (VmHWM) at two sizes or more, its file gives the
/// measurements; a scheme with a factor adds its fill, which grows with the nodes of a slice), the static start's
/// factor and the executable (resources.cpp). Within ~10% of the measured peaks, on the high side.
ResourceEstimate estimateResources(const CaseParams& p);

/// The two numbers of the case's own model that the duration of a run needs (stepScaleOfBlock).
struct StepScale {
  double c_d = 0;  // transverse wave speed, c_r
  double dt = 0;   // the integrator's time step, d/c_r
};

/// One core's wall time of a whole run, and its parts (estimateRunTime).
struct TimeEstimate {
  double uStart = 0;          // applied displacement at the start, d: static_start x U_c (model), 0 from rest
  double uEnd = 0;            // applied displacement at the stop, d (model)
  double duration = 0;        // simulated time from the start to the stop, d/c_r
  double steps = 0;           // duration / dt, at most max_steps
  double secondsPerStep = 0;  // one core
  double setupSeconds = 0;    // the model, its operators, the integrator and the static start's solve
  double seconds = 0;         // setup + steps x secondsPerStep
};

/// One core's wall time of a whole run (a pure function of the case keys, c_d and dt; resources.cpp gives the
/// model and the measurements behind its constants, the scheme's registry row its seconds per step). The run's duration is that of the loading from the start
/// displacement to U_end = (U_i + k_a stop_da_over_d) (delta0 / 0.1 d) (at most stop_u_over_d), at v_app = rate_factor
/// x v_app_over_cd x c_d after the ramp; U_end is within about 0.6x-1.6x of the committed runs' (resources.cpp),
/// and an adaptive rate (rate_adapt_max > 1) is not counted (the estimate is then an upper bound).
TimeEstimate estimateRunTime(const CaseParams& p, const StepScale& s);

/// The steps at which a run is expected to reach the crack's start and its stop: estimateRunTime's displacements
/// (the crack starts at U_i (delta0 / 0.1 d), the run stops at U_end) on the run's own loading and time step.
/// Step numbers of the run (absolute, so a restart keeps them), from a state at `step` with loading clock `tau`;
/// with an adaptive rate (rate_adapt_max > 1) the loading runs ahead of the steps, so they are upper bounds.
/// The progress line's estimate of the time left rests on them (runner.hpp, estimateTimeLeft).
struct StepPlan {
  double initiationStep = NAN;  // the crack starts to move (NaN: no plan)
  double endStep = NAN;         // the run stops
};
StepPlan planSteps(const CaseParams& p, const Loading& loading, double dt, double step, double tau);

/// c_d and the integrator's dt of the case, measured without building its model: c_d by
/// measureTransverseModulus (which uses at most 24 x 12 d of the case), dt from the integrator built on a block
/// of at most 16 x 8 d of the case (same theta, h_e, physics and integrator; no reduced far field, no static
/// start). `paper`'s dt is the element's; `lumped`'s omega_max is that of the stiffest node group, local.
StepScale stepScaleOfBlock(const CaseParams& p);

/// The value in kB of the line "KEY: N kB" of a /proc file such as /proc/meminfo or /proc/self/status (NaN
/// where there is no such file or line).
double readProcKilobytes(const char* path, const char* key);

/// MemAvailable of /proc/meminfo in bytes (NaN where there is none).
double availableMemoryBytes();

/// Empty when the case fits in `available` bytes; otherwise one line saying the memory needed (and the
/// counts behind it) and the memory available.
std::string checkMemoryFits(const CaseParams& p, double available);

}  // namespace enamel
