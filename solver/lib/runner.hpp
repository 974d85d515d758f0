#pragma once
// The run loop: time steps, R-curve points, history, frames, stop criteria, quasi-static and stability
// checks, progress on stderr, and the result file (written whole and atomically, also during the run, under
// a name that says whether the run completed).
#include <exception>
#include <string>

#include "checkpoint.hpp"
#include "output.hpp"
#include "simulation.hpp"

namespace enamel {

struct RunOptions {
  std::string outDir;                // the run directory: result files (resultFileFor) go there
  bool progress = true;              // progress lines on stderr
  double writeIntervalSeconds = 30;  // rewrite the (partial) result file this often
  std::string checkpointPath;        // checkpoint file (empty: none)
  double checkpointIntervalSeconds = 0;  // write a checkpoint this often (wall clock; 0: only on SIGINT/SIGTERM)
  bool restart = false;              // continue from checkpointPath instead of starting from rest
  long injectNanAtStep = -1;         // tests of the failure path: a NaN in the state after this step (-1: none)
};

/// Run to a stop criterion. While it runs, the partial result is rewritten as DIR/result.partial.h5; at the
/// end the result is written under the name of its status (resultFileFor: result.h5 only when completed) and
/// the partial file removed. Never throws for a run that goes unstable: the record's status says
/// "failed" and stopReason says which quantity, at which step, with which value. With a checkpoint path,
/// checkpoints are written every checkpointIntervalSeconds and when a signal stops the run, and removed when
/// the run completes; `restart` continues from the last one (CheckpointError when there is none).
RunRecord runSimulation(Simulation& sim, const RunOptions& opt);

/// Where a run stands, for the progress line's estimate of the time left.
struct ProgressSample {
  double wall = 0;          // s
  double step = 0;
  double crackAdvance = 0;  // d
  double displacement = 0;  // U, d
};

/// The stop criteria the estimate aims at (a criterion <= 0 is absent).
struct StopTargets {
  double crackAdvance = 0;  // stop_da_over_d
  double displacement = 0;  // stop_u_over_d
  double steps = 0;         // max_steps
};

/// Seconds left to the nearest stop criterion, each extrapolated at the rate it progressed from `since` to
/// `now` (pass the sample where this piece of the run, or the crack, started: the time to initiation says
/// nothing about the crack's speed). The crack-advance criterion counts only once the crack has moved since
/// `since`. NaN when no criterion has progressed: before the crack starts only max_steps gives an estimate,
/// since the displacement limit is usually a far safety net.
double estimateSecondsLeft(const ProgressSample& since, const ProgressSample& now, const StopTargets& stop);

/// The exit status (exit_codes.hpp) for an error that ended a command: a bad case (its CaseError's code), a
/// checkpoint of another build or case 13, a damaged one 14, a full disk 15, a file that cannot be written 8, a
/// case the integrator refuses or a value out of range 7, anything else (a factorisation that failed) 11.
int exitCodeOf(const std::exception& e);

/// The blow-up guard's failure bounds (docs/solver.md, Time integration and checks): a history row beyond any of them fails the run.
struct GuardBounds {
  double Gamma = 1;       // Gamma_i, for messages
  /// |external work - (stored + kinetic + dissipated)| / max(|external work|, minWork): checked at every row,
  /// whatever the sign of the external work (a state whose work runs negative is not exempt).
  double balance = 0.25;
  double minWork = 0;     // 0.1 Gamma_i B d: below this much work the error is measured against it
  /// kinetic / strain energy while the crack grows (0.05 is the quasi-static warning). Ten times the largest
  /// ratio of any completed run measured by 2026-12-03: 0.322 (paper case theta30_s7.1_e10_cv0 at the ci preset;
  /// the committed records: 0.299 in studies/far_field record_cv03_m2_h22_allow, up to 0.156 in
  /// bench/experiments/check_100), so 3.2.
  double kinetic = 3.2;
  /// An R-curve point (J when the crack advanced) below -negativeJ: negative beyond round-off (1e-6 Gamma_i: J's
  /// terms round at ~1e-13 of Gamma_i). Only R-curve points: J of a history row may go below 0 in a sound run,
  /// e.g. in the rebound once the crack has nearly crossed the specimen (J / Gamma_i -0.156 measured at step
  /// 23840 of theta30_s21.4_e10_cv0 at the ci preset run on with stop_da_over_d=1e3, test_bench.py).
  double negativeJ = 0;
};
GuardBounds guardBounds(double Gamma, double B);

/// Whether J can be an R-curve point: finite and not negative beyond round-off.
bool resistanceIsPhysical(double J, const GuardBounds& b);

/// Why a history row shows a run that blew up, in one sentence naming the check, the step and the values; ""
/// when it passes: a non-finite energy or J, the energy balance, kinetic / strain energy (`kineticRatio`, 0
/// before the crack grows). A pure function of the row.
std::string blowUpCheck(const Measurement& r, double kineticRatio, const GuardBounds& b);

/// The stop for a separated specimen (case keys stop_load_fraction, stop_load_transits; docs/model.md, Loading,
/// damping, measurements): a fold over the history rows, so a restart rebuilds it from the rows it read back.
struct LoadDropWatch {
  double peakLoad = 0;      // the largest grip load of any row so far
  double belowSince = NAN;  // time of the first row of the current run of rows below fraction x peak with the
                            // crack started (NaN: the last row was not)
  bool separated = false;   // the load stayed below for `hold` or longer
};
/// The watch after one more row r: with fraction <= 0 it never reports separated.
LoadDropWatch watchLoadDrop(LoadDropWatch w, const Measurement& r, double fraction, double hold);

/// Ask a running simulation to stop at the next step (signal handlers call this).
void requestStop(int signal);

/// SIGINT and SIGTERM call requestStop, and each writes one line on stderr naming the signal and its sender
/// (pid, uid, command name: SA_SIGINFO).
void installStopHandlers();

}  // namespace enamel
