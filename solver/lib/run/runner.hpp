#pragma once
// The run loop: time steps, R-curve points, history, frames, stop criteria, quasi-static and stability
// checks, progress on stderr, and the result file (written whole and atomically, also during the run, under
// a name that says whether the run completed).
#include <exception>
#include <string>

#include "io/checkpoint.hpp"
#include "io/output.hpp"
#include "simulation/resources.hpp"
#include "simulation/simulation.hpp"

namespace enamel {

// Quasi-static and stability warnings (docs/solver.md, Time integration and checks), recorded in /meta/warnings;
// the failure bounds that stop a run are GuardBounds below. Python reads them from `enamel-dem constants`.
inline constexpr double kBalanceWarn = 0.02;  // |energy balance error| above this at any history row: warning
inline constexpr double kKineticWarn = 0.05;  // quasiStaticRatio above this: not quasi-static, warning

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

/// Where the rates of the estimate are measured from: this piece of the run, the crack's start in it, and the
/// crack's last advance.
struct ProgressMarks {
  ProgressSample piece;        // where this piece of the run started (the run's start or its restart)
  ProgressSample crackStart;   // where the crack started moving in this piece (at a restart: where it stood)
  ProgressSample lastAdvance;  // where the crack last advanced (the piece's start until it does)
};

/// The estimate of the time left and what it rests on.
struct TimeLeft {
  enum class Basis { none, steps, displacement, estimate, crack };
  double seconds = NAN;       // NaN: nothing to estimate from yet
  Basis basis = Basis::none;  // what gives it: a stop criterion that comes first, the run's estimate or the crack
  bool paused = false;        // the crack has moved and stands still for a while
  double crackAdvance = 0;    // Delta_a, d (said when paused)
};

/// A crack stands still for this long at least before it counts as paused (s of wall time).
inline constexpr double kPauseMinSeconds = 10;
/// ... and for longer than its average rate gives for this much advance (d), for the rest of it, or for half of
/// the advance it made in this piece (that is: longer than it took to make it).
inline constexpr double kPauseAdvance = 1;

/// Seconds left, from the run's own estimate (`plan`: the steps at which the crack starts and the run stops,
/// planSteps) and the rates measured in this piece of the run:
/// - the expected time: before the crack moves, the steps left to the plan's end at this piece's steps per second
///   (the crack's part of the plan in full once the run is past the plan's initiation, the crack being late);
///   once the crack moves, that part's share of the crack advance left (1 - Delta_a / stop), blended toward the
///   crack's own rate (the advance since it started in this piece, over the wall time since then) with the weight
///   of the advance made of what was left, so at the end the crack's rate alone;
/// - a paused crack (standing still for kPauseMinSeconds and longer than its average rate gives for
///   kPauseAdvance, the rest, or half its advance) is said, and expected to take at least the plan's share of
///   what is left and at least as long again as it has stood still;
/// - the stop criteria of the loading (stop_u_over_d, max_steps, extrapolated at their rates since the piece
///   started) replace the expected time when they come sooner.
/// Without a plan (NaN steps), the loading's limits alone until the crack moves: an upper bound. A pure function.
TimeLeft estimateTimeLeft(const ProgressMarks& marks, const ProgressSample& now, const StopTargets& stop,
                          const StepPlan& plan = {});

/// The progress line's ETA: "25 min (estimate)" (the run's estimate, the crack not yet moving), "12 min" (the
/// estimate corrected by the crack's rate), "<= 2 h 05 min (U limit)" or "<= 40 s (max_steps)" (a loading limit
/// comes first), each after "crack paused at Delta_a 3.20 d, estimate " (or ", ") while the crack is paused, and
/// "?" (no estimate yet).
std::string formatTimeLeft(const TimeLeft& t);

/// kinetic / strain energy of a history row (0 without strain energy).
double kineticOverStrain(const Measurement& r);

/// Whether a history row is past the elastic start of the run: an interface past delta0, a rod element broken or
/// the crack advanced. From then on the quasi-static warning watches the row, whatever the crack does.
bool pastElasticStart(const Measurement& r);

/// The quasi-static warning's ratio of a history row (warned above 0.05): the larger of kinetic / strain energy
/// while the crack grows and, from the elastic start on, the kinetic energy beyond the loading's own motion /
/// strain energy (Measurement::kineticBeyond). Proportional loading at a steady rate moves the nodes without
/// accelerating them: its kinetic energy grows as the rate squared and says nothing about inertia (kinetic /
/// strain up to 0.23 before the crack grows in a ci run whose adaptive rate reaches x8, at most 0.008 beyond the
/// loading's motion; up to 1.7 beyond it at rate_factor = 500).
/// 0 before the elastic start.
double quasiStaticRatio(const Measurement& r);

/// The exit status (exit_codes.hpp) for an error that ended a command: a bad case (its CaseError's code), a
/// checkpoint of another build or case 13, a damaged one 14, a full disk 15, a file that cannot be written 8, a
/// run directory another run holds 17, a
/// case the integrator refuses or a value out of range 7, anything else (a factorisation that failed) 11.
int exitCodeOf(const std::exception& e);

/// The blow-up guard's failure bounds (docs/solver.md, Time integration and checks): a history row beyond any of them fails the run.
struct GuardBounds {
  double Gamma = 1;       // Gamma_i, for messages
  /// |external work - (stored + kinetic + dissipated)| / max(|external work|, minWork): checked at every row,
  /// whatever the sign of the external work (a state whose work runs negative is not exempt).
  double balance = 0.25;
  double minWork = 0;     // balanceWorkFloor, 0.1 Gamma_i B d: below this much work the error is measured against it
  /// kinetic / strain energy while the crack grows (0.05 is the quasi-static warning). Ten times the largest
  /// ratio measured in a completed run: 0.322 (paper case theta30_s7.1_e10_cv0 at the ci preset;
  /// 0.299 at 80 x 80 d with the reduced far field, 0.156 at 100 x 100 d: docs/solver.md), so 3.2.
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
/// when it passes: a non-finite energy or J, the energy balance (energyBalanceError against b.minWork), kinetic /
/// strain energy (`kineticRatio`, 0 before the crack grows). A pure function of the row.
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
