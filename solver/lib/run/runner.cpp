#include "run/runner.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "base/exit_codes.hpp"
#include "io/file_io.hpp"
#include "kernels/loading_rate.hpp"
#include "kernels/measurements.hpp"

namespace enamel {

namespace {
volatile std::sig_atomic_t gStopSignal = 0;

// The warning bounds kBalanceWarn and kKineticWarn: runner.hpp.
constexpr double kEdgeWarnDistance = 2.0;  // d: the inelastic zone this near the loaded edges: warning

std::string fmt(const char* f, double a, double b = 0, double c = 0, double d = 0, double e = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c, d, e);
  return buf;
}

// "42 s", "46 min", "3 h 05 min", "2.5 days".
std::string formatDuration(double seconds) {
  const long t = std::lround(seconds);
  char buf[64];
  if (t < 120) std::snprintf(buf, sizeof buf, "%ld s", t);
  else if (t < 3600) std::snprintf(buf, sizeof buf, "%ld min", (t + 30) / 60);
  else if (t < 86400) std::snprintf(buf, sizeof buf, "%ld h %02ld min", t / 3600, t % 3600 / 60);
  else std::snprintf(buf, sizeof buf, "%.1f days", t / 86400.0);
  return buf;
}
}  // namespace

namespace {
// Seconds to `target` at the rate the quantity went from `from` to `at` since the wall time `since`; NaN when
// the criterion is absent or the quantity has not progressed.
double extrapolate(const ProgressSample& now, double since, double from, double at, double target) {
  if (target <= 0 || !(at > from) || !(now.wall > since)) return NAN;
  return std::max(0.0, (now.wall - since) * (target - at) / (at - from));
}

// The plan's steps left (estimateTimeLeft); NaN without a plan.
double plannedStepsLeft(const StepPlan& plan, const ProgressSample& now, const StopTargets& stop) {
  if (std::isnan(plan.initiationStep) || std::isnan(plan.endStep)) return NAN;
  const double crackSteps = std::max(0.0, plan.endStep - plan.initiationStep);
  if (!(now.crackAdvance > 0)) return crackSteps + std::max(0.0, plan.initiationStep - now.step);
  const double done = stop.crackAdvance > 0 ? std::min(1.0, now.crackAdvance / stop.crackAdvance) : 1.0;
  return crackSteps * (1 - done);
}

// Whether the crack, having moved in this piece, stands still (estimateTimeLeft).
bool crackPaused(const ProgressMarks& marks, const ProgressSample& now, const StopTargets& stop) {
  const ProgressSample& c = marks.crackStart;
  const double moved = now.crackAdvance - c.crackAdvance;
  const double silence = now.wall - marks.lastAdvance.wall;
  if (!(moved > 0) || !(silence >= kPauseMinSeconds) || !(now.wall > c.wall)) return false;
  const double rest = stop.crackAdvance > 0 ? stop.crackAdvance - now.crackAdvance : INFINITY;
  return silence * moved / (now.wall - c.wall) > std::min({kPauseAdvance, rest, 0.5 * moved});
}
}  // namespace

TimeLeft estimateTimeLeft(const ProgressMarks& marks, const ProgressSample& now, const StopTargets& stop,
                          const StepPlan& plan) {
  TimeLeft best;
  auto consider = [&](double seconds, TimeLeft::Basis basis) {
    if (std::isnan(seconds) || (!std::isnan(best.seconds) && !(seconds < best.seconds))) return;
    best.seconds = seconds;
    best.basis = basis;
  };
  const ProgressSample& p = marks.piece;
  const ProgressSample& c = marks.crackStart;
  const double stepsPerSecond = now.wall > p.wall && now.step > p.step ? (now.step - p.step) / (now.wall - p.wall) : NAN;
  const double planned = plannedStepsLeft(plan, now, stop) / stepsPerSecond;  // NaN without a plan or a rate
  const double crack = extrapolate(now, c.wall, c.crackAdvance, now.crackAdvance, stop.crackAdvance);
  double expected = planned;
  if (!std::isnan(crack)) {  // blended toward the crack's rate with the share of the advance made
    const double left = stop.crackAdvance - c.crackAdvance;  // > 0 where the crack has a rate
    const double weight = std::clamp((now.crackAdvance - c.crackAdvance) / left, 0.0, 1.0);
    expected = std::isnan(planned) ? crack : (1 - weight) * planned + weight * crack;
  }
  best.paused = crackPaused(marks, now, stop);
  best.crackAdvance = now.crackAdvance;
  if (best.paused) expected = std::fmax(std::fmax(expected, planned), now.wall - marks.lastAdvance.wall);
  consider(expected, std::isnan(crack) ? TimeLeft::Basis::estimate : TimeLeft::Basis::crack);
  consider(extrapolate(now, p.wall, p.step, now.step, stop.steps), TimeLeft::Basis::steps);
  consider(extrapolate(now, p.wall, p.displacement, now.displacement, stop.displacement), TimeLeft::Basis::displacement);
  return best;
}

std::string formatTimeLeft(const TimeLeft& t) {
  using B = TimeLeft::Basis;
  const std::string paused = t.paused ? fmt("crack paused at Delta_a %.2f d", t.crackAdvance) : "";
  if (t.basis == B::none || std::isnan(t.seconds)) return t.paused ? paused : "?";
  const std::string d = formatDuration(t.seconds);
  const std::string prefix = t.paused ? paused + ", " : "";
  if (t.basis == B::displacement || t.basis == B::steps)
    return prefix + "<= " + d + (t.basis == B::displacement ? " (U limit)" : " (max_steps)");
  if (t.paused) return prefix + "estimate " + d;
  return t.basis == B::estimate ? d + " (estimate)" : d;
}

double kineticOverStrain(const Measurement& r) {
  const double strain = r.strainBeams + r.strainInterfaces;
  return strain > 0 ? r.kinetic / strain : 0.0;
}

bool pastElasticStart(const Measurement& r) {
  return r.inelasticInterfaces > 0 || r.brokenBeams > 0 || r.crackAdvance > 0;
}

double quasiStaticRatio(const Measurement& r) {
  if (!pastElasticStart(r)) return 0.0;
  const double strain = r.strainBeams + r.strainInterfaces;
  const double beyond = strain > 0 ? r.kineticBeyond / strain : 0.0;
  return std::max(beyond, r.crackAdvance > 0 ? kineticOverStrain(r) : 0.0);
}

LoadDropWatch watchLoadDrop(LoadDropWatch w, const Measurement& r, double fraction, double hold) {
  w.peakLoad = std::max(w.peakLoad, r.load);
  const bool below = fraction > 0 && r.crackAdvance > 0 && w.peakLoad > 0 && r.load < fraction * w.peakLoad;
  if (!below) w.belowSince = NAN;
  else if (std::isnan(w.belowSince)) w.belowSince = r.time;
  w.separated = w.separated || (below && r.time - w.belowSince >= hold);
  return w;
}

void requestStop(int signal) { gStopSignal = signal; }

namespace {

// Async-signal-safe pieces of the signal log line: only write(2), open(2), read(2), close(2).
void put(char*& at, const char* end, const char* text) {
  while (*text && at < end) *at++ = *text++;
}
void putNumber(char*& at, const char* end, long value) {
  char digits[24];
  int n = 0;
  unsigned long v = value < 0 ? 0UL - static_cast<unsigned long>(value) : static_cast<unsigned long>(value);
  do digits[n++] = static_cast<char>('0' + v % 10); while ((v /= 10) && n < 23);
  if (value < 0 && at < end) *at++ = '-';
  while (n > 0 && at < end) *at++ = digits[--n];
}

// SIGINT/SIGTERM: stop at the next step (requestStop), and say on stderr who sent it (pid, uid, its command
// name from /proc), so that a run ended on a cluster node can tell SLURM, make or a user apart.
void onStopSignal(int signal, siginfo_t* info, void*) {
  const int savedErrno = errno;
  requestStop(signal);
  char line[256];
  char* at = line;
  const char* end = line + sizeof line - 1;
  put(at, end, "enamel-dem: received signal ");
  putNumber(at, end, signal);
  put(at, end, " from pid ");
  putNumber(at, end, info ? info->si_pid : -1);
  put(at, end, " (uid ");
  putNumber(at, end, info ? static_cast<long>(info->si_uid) : -1);
  if (info && info->si_pid > 0) {
    char path[40] = "/proc/";
    char* p = path + 6;
    putNumber(p, path + sizeof path - 6, info->si_pid);
    put(p, path + sizeof path - 1, "/comm");
    *p = '\0';
    const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
    if (fd >= 0) {
      char comm[32];
      const ssize_t n = ::read(fd, comm, sizeof comm - 1);
      ::close(fd);
      if (n > 0) {
        put(at, end, ", ");
        for (ssize_t i = 0; i < n && comm[i] != '\n' && at < end; ++i) *at++ = comm[i];
      }
    }
  }
  put(at, end, "): stopping at the next step with a checkpoint\n");
  ssize_t ignored = ::write(STDERR_FILENO, line, static_cast<std::size_t>(at - line));
  (void)ignored;
  errno = savedErrno;
}

}  // namespace

void installStopHandlers() {
  struct sigaction sa = {};
  sa.sa_sigaction = onStopSignal;
  sa.sa_flags = SA_SIGINFO | SA_RESTART;
  sigemptyset(&sa.sa_mask);
  for (int s : {SIGINT, SIGTERM}) sigaction(s, &sa, nullptr);
}

GuardBounds guardBounds(double Gamma, double B) {
  GuardBounds b;
  b.Gamma = Gamma;
  b.minWork = balanceWorkFloor(Gamma, B);
  b.negativeJ = 1e-6 * Gamma;
  return b;
}

bool resistanceIsPhysical(double J, const GuardBounds& b) { return std::isfinite(J) && J >= -b.negativeJ; }

std::string blowUpCheck(const Measurement& r, double kineticRatio, const GuardBounds& b) {
  for (double x : {r.J, r.kinetic, r.strainBeams, r.strainInterfaces, r.damping, r.fracture, r.rodFracture,
                   r.external})
    if (!std::isfinite(x))
      return fmt("non-finite state at step %.0f (t = %g): J = %g, kinetic = %g, external work = %g; "
                 "the time step or the loading is unstable", double(r.step), r.time, r.J, r.kinetic, r.external);
  const double stored = r.kinetic + r.strainBeams + r.strainInterfaces + r.damping + r.fracture + r.rodFracture;
  const double balance = std::abs(energyBalanceError(r.external, stored, b.minWork));
  if (balance > b.balance)
    return fmt("energy balance error %.3g at step %.0f exceeds the bound %.2g (external work %.4g, stored, kinetic "
               "and dissipated %.4g): energy is created or lost; reduce dt_factor or the loading rate",
               balance, double(r.step), b.balance, r.external, stored);
  if (kineticRatio > b.kinetic)
    return fmt("kinetic / strain energy %.3g at step %.0f exceeds the failure bound %.2g (ten times the largest "
               "ratio of any completed run measured): the run is not quasi-static, it is blowing up",
               kineticRatio, double(r.step), b.kinetic);
  return "";
}

int exitCodeOf(const std::exception& e) {
  if (const auto* c = dynamic_cast<const CaseError*>(&e)) return c->exitCode;
  if (dynamic_cast<const CheckpointDamaged*>(&e)) return exit_code::checkpoint_damaged;
  if (dynamic_cast<const CheckpointError*>(&e)) return exit_code::checkpoint_invalid;
  if (dynamic_cast<const DirectoryLocked*>(&e)) return exit_code::output_locked;
  if (const auto* w = dynamic_cast<const WriteError*>(&e))
    return w->diskFull ? exit_code::disk_full : exit_code::output_unwritable;
  if (dynamic_cast<const IntegratorError*>(&e) || dynamic_cast<const std::invalid_argument*>(&e))
    return exit_code::out_of_range;
  return exit_code::run_failed;
}

namespace {

// One run's bookkeeping around the time steps: its record, clocks, next frame, and the named calls of the
// loop in runSimulation. Each call is defined once here.
class RunLoop {
 public:
  RunLoop(Simulation& sim, const RunOptions& opt)
      : sim_(sim), opt_(opt), p_(sim.params), start_(clock::now()), tty_(isatty(STDERR_FILENO)),
        frameTargets_(p_.frames_da_over_d),
        stopTargets_{p_.stop_da_over_d, p_.stop_u_over_d, double(p_.max_steps)},
        guard_(guardBounds(p_.Gamma(), sim.model.B)), burstInterfaces_(burstInterfacesOf(sim.model)),
        partialPath_(resultFileFor(opt.outDir, RunStatus::running)) {
    const double dt = sim.integrator->timeStep();
    historyEvery_ = p_.history_every > 0
        ? p_.history_every : std::max(1L, std::lround(0.05 * sim.model.h_s / sim.materials.c_d / dt));
    std::sort(frameTargets_.begin(), frameTargets_.end());
  }

  /// From rest (the first history row) or from the checkpoint; the result file written once at the start.
  void start() {
    if (opt_.restart) {
      readCheckpoint(opt_.checkpointPath, sim_, rec_);
      rec_.status = RunStatus::running;
      rec_.stopReason.clear();
      wallBefore_ = lastCheckpoint_ = rec_.wallSeconds;
      lastDa_ = rec_.rcurveDa.empty() ? 0.0 : rec_.rcurveDa.back();
      nextFrame_ = rec_.frames.size();  // frames are taken in the order of their sorted targets
      std::fprintf(stderr, "enamel-dem: resuming from checkpoint at step %ld (U/d %.4g, da/d %.3g, %s of wall time so far)\n",
                   sim_.state.step, sim_.state.appliedDisplacement, sim_.state.crackAdvance,
                   formatDuration(rec_.wallSeconds).c_str());
    } else {
      if (p_.static_start > 0) startFromStaticElastic();
      rec_.history.push_back(sim_.measure());
    }
    for (const Measurement& r : rec_.history) watchLoad(r);  // from rest: one row; a restart: every row read back
    save();
    // Progress rates are measured over this piece of the run, and the crack's from where it started; the run's
    // own estimate of its steps from where it stands.
    marks_.piece = marks_.crackStart = marks_.lastAdvance = sample();
    plan_ = planSteps(p_, sim_.materials.loading, sim_.integrator->timeStep(), double(sim_.state.step),
                      sim_.state.loadingTime);
    for (const Measurement& r : rec_.history)  // the restart's rows: their largest ratio (not in the checkpoint)
      rec_.maxQuasiStaticRatio = std::max(rec_.maxQuasiStaticRatio, quasiStaticRatio(r));
  }

  /// The static elastic start (case key static_start), timed, and a line on stderr saying what it did.
  void startFromStaticElastic() {
    const auto t0 = clock::now();
    rec_.staticStart = sim_.startFromStaticElastic(p_.static_start);
    StaticStart& st = rec_.staticStart;
    st.solveSeconds = std::chrono::duration<double>(clock::now() - t0).count();
    std::fprintf(stderr, "enamel-dem: static elastic start at U/d = %.6g, %g of the first-damage displacement "
                         "U_c/d = %.6g (%s), t = %.6g: skipped ~%.0f steps; static solve %.1f s%s\n",
                 st.displacement, st.fraction, st.firstDamageDisplacement,
                 st.limitedByRod ? "a rod element's strength" : "an interface's delta0", st.time,
                 st.time / sim_.integrator->timeStep(), st.solveSeconds,
                 st.mechanism ? " (the stiffness was singular: a part free to move without strain kept in place)" : "");
  }

  /// Fault injection for the tests of the failure path (RunOptions::injectNanAtStep): a NaN in one free
  /// displacement after that step, as a diverging run would produce.
  void injectFault() {
    if (sim_.state.step == opt_.injectNanAtStep) sim_.state.q[sim_.ops.freeDofs[sim_.ops.freeDofs.size() / 2]] = NAN;
  }

  /// An R-curve point (Delta a, J) each time the crack advanced, and the frames whose targets it passed; false
  /// (the run failed) when J is not finite or negative beyond round-off.
  bool recordRcurvePoint() {
    const State& s = sim_.state;
    if (!(s.crackAdvance > lastDa_)) return true;
    if (lastDa_ == 0) {  // the crack starts: its rate is measured from here, its first advance included
      marks_.crackStart = sample();
      marks_.crackStart.crackAdvance = 0;
    }
    marks_.lastAdvance = sample();
    lastDa_ = s.crackAdvance;
    rec_.rcurveDa.push_back(s.crackAdvance);
    const double J = sim_.computeJ();
    rec_.rcurveJ.push_back(J);
    while (nextFrame_ < frameTargets_.size() && s.crackAdvance >= frameTargets_[nextFrame_])
      rec_.frames.push_back(captureFrame(sim_, frameTargets_[nextFrame_++]));
    if (resistanceIsPhysical(J, guard_)) return true;
    return fail(fmt("R / Gamma_i = %.4g at Delta_a %.3g d (step %.0f) is ", J / p_.Gamma(), s.crackAdvance,
                    double(s.step)) +
                (std::isfinite(J) ? "negative beyond round-off" : "not finite") + ": the state is unsound");
  }

  /// Kinetic / strain energy while the crack grows: the blow-up guard's ratio (its bound was measured so).
  static double kineticRatioOf(const Measurement& r) { return r.crackAdvance > 0 ? kineticOverStrain(r) : 0.0; }

  bool historyDue() const { return sim_.state.step % historyEvery_ == 0; }

  Measurement recordHistory() {
    rec_.history.push_back(sim_.measure());
    watchLoad(rec_.history.back());
    return rec_.history.back();
  }

  /// The separated-specimen watch (watchLoadDrop) on one more history row.
  void watchLoad(const Measurement& r) {
    const double transit = sim_.model.h_s / sim_.materials.c_d;
    loadWatch_ = watchLoadDrop(loadWatch_, r, p_.stop_load_fraction, p_.stop_load_transits * transit);
  }

  /// The quasi-static and stability checks (docs/solver.md, Time integration and checks) on a history row: false when the run failed
  /// (blowUpCheck); warnings are recorded once each.
  bool checkBalance(const Measurement& r) {
    const State& s = sim_.state;
    const double kineticRatio = kineticRatioOf(r);
    const std::string blowUp = blowUpCheck(r, kineticRatio, guard_);
    if (!blowUp.empty()) return fail(blowUp);
    if (!rec_.warnedBalance && std::abs(r.balanceError) > kBalanceWarn) {  // against the work floor: any row
      rec_.warnedBalance = true;
      rec_.warnings.push_back(fmt("energy balance error %.3g at step %.0f above %.2g", r.balanceError, s.step,
                                  kBalanceWarn));
    }
    noteQuasiStatic(r);
    // A reduced far field holds only while the inelastic zone stays inside the full band: its lumped interfaces
    // cannot soften apart, and its rod elements stand for m slices each (far_field_rod_breaks = allow lets
    // them break whole, with a warning; interfaces past delta0 there always stop the run).
    const Model& m = sim_.model;
    const double bandEdge = m.fullHalfHeight - kEdgeWarnDistance;
    if (m.hasFarField() && r.inelasticReach > bandEdge) {
      const bool rodBreaksAllowed = p_.far_field_rod_breaks == FarFieldRodBreaks::allow;
      const double interfaceReach = rodBreaksAllowed ? sim_.inelasticInterfaceReach() : r.inelasticReach;
      if (interfaceReach > bandEdge || !rodBreaksAllowed)
        return fail(fmt(rodBreaksAllowed ? "interfaces past delta0 reached %.3g d from the crack plane at step %.0f "
                                           "(Delta_a %.3g d), "
                                         : "inelastic zone reached %.3g d from the crack plane at step %.0f (Delta_a %.3g d), ",
                        interfaceReach, s.step, s.crackAdvance) +
                    fmt("within %.2g d of the edge of the full band (full_half_height_over_d = %g): the reduced far "
                        "field (far_field_slices = %.0f) is no longer elastic there; rerun with a wider band",
                        kEdgeWarnDistance, m.fullHalfHeight, double(m.farFieldSlices)));
      if (!rec_.warnedFarFieldRod) {  // only rod elements out there, and allowed
        rec_.warnedFarFieldRod = true;
        rec_.warnings.push_back(fmt("a rod element broke %.3g d from the crack plane at step %.0f (Delta_a %.3g d), ",
                                    sim_.brokenRodReach(), s.step, s.crackAdvance) +
                                fmt("within %.2g d of the full band's edge or beyond it (full_half_height_over_d = %g): "
                                    "allowed (far_field_rod_breaks = allow), its far-field element of up to %.0f slices "
                                    "broke whole", kEdgeWarnDistance, m.fullHalfHeight, double(m.farFieldSlices)));
      }
    }
    // The inelastic zone near the loaded edges: the R-curve may depend on the specimen's height.
    const double halfHeight = 0.5 * sim_.model.h_s;
    if (!rec_.warnedEdge && r.inelasticReach > halfHeight - kEdgeWarnDistance) {
      rec_.warnedEdge = true;
      rec_.warnings.push_back(fmt("inelastic zone reached %.3g d from the crack plane at step %.0f (Delta_a %.3g d), "
                                  "within %.2g d of the loaded edges at h_s/2 = %.3g d: the specimen is not large "
                                  "against it, so the R-curve may depend on h_s_over_d (compare a taller specimen)",
                                  r.inelasticReach, s.step, s.crackAdvance, kEdgeWarnDistance, halfHeight));
    }
    return true;
  }

  /// A row's kinetic ratios into the run's maxima and its quasi-static warning: every row the loop checks, and the
  /// stop's own row (finish).
  void noteQuasiStatic(const Measurement& r) {
    rec_.maxKineticRatio = std::max(rec_.maxKineticRatio, kineticRatioOf(r));
    warnIfNotQuasiStatic(r);
  }

  /// The quasi-static warning, once: quasiStaticRatio above kKineticWarn at any row past the elastic start, whether
  /// the crack grows or not (rods breaking ahead of a crack that stands count too).
  void warnIfNotQuasiStatic(const Measurement& r) {
    const double ratio = quasiStaticRatio(r);
    rec_.maxQuasiStaticRatio = std::max(rec_.maxQuasiStaticRatio, ratio);
    if (rec_.warnedKinetic || !(ratio > kKineticWarn)) return;
    rec_.warnedKinetic = true;
    const bool growth = r.crackAdvance > 0 && kineticOverStrain(r) >= ratio;  // which measure gave the ratio
    rec_.warnings.push_back(std::string(growth ? "kinetic / strain energy" : "kinetic energy beyond the loading's "
                                                                             "motion / strain energy") +
                            fmt(" %.3g at step %.0f above %.2g: not quasi-static (Delta_a %.3g d, ", ratio,
                                double(r.step), kKineticWarn, r.crackAdvance) +
                            fmt("%.0f rod elements broken, %.0f interfaces past delta0)", r.brokenBeams,
                                r.inelasticInterfaces));
  }

  /// The adaptive loading rate (loading_rate.hpp), at each history row: with rate_adapt_rule = margin the
  /// forecast of the next failure event first (forecastEvents, kept in State; also when rate_adapt_max = 1,
  /// where it sets nothing); then, when rate_adapt_max > 1, the rule (nextRateMultiplier, or nextRateMultiplierByMargin
  /// with the forecast) on the interval since the previous row (energies at its end, rods deleted and interfaces
  /// failed during it) sets phi's next target, reached linearly over the next history interval.
  void controlLoadingRate() {
    const auto& h = rec_.history;
    const bool margin = p_.rate_adapt_rule == RateAdaptRule::margin;
    double rowsToEvent = NAN;
    if (margin) rowsToEvent = forecastNextEvent();
    if (!sim_.materials.loading.adaptive() || h.size() < 2) return;
    const Measurement& now = h.back();
    const Measurement& before = h[h.size() - 2];
    RateControlInput in;
    in.kinetic = now.kineticBeyond;
    in.strain = now.strainBeams + now.strainInterfaces;
    in.rodsDeleted = now.brokenBeams - before.brokenBeams;
    in.interfacesFailed = now.failedInterfaces - before.failedInterfaces;
    in.burstInterfaces = burstInterfaces_;
    in.rowsToEvent = rowsToEvent;
    in.rhoHigh = p_.rate_adapt_rho_high;
    State& s = sim_.state;
    const double phi = margin ? nextRateMultiplierByMargin(s.rateMultiplier, p_.rate_adapt_max, p_.rate_adapt_horizon, in)
                              : nextRateMultiplier(s.rateMultiplier, p_.rate_adapt_max, in);
    setRateMultiplierTarget(s, phi, historyEvery_);
  }

  /// The margin rule's forecast at this row (forecastEvents: each element's progress now against the last
  /// row's, rows of historyEvery_ steps at phi = 1); the progress and the forecast kept in State for the next
  /// row; returns the rows the rule reads (rowsToFirstEvent, with the last row's forecast).
  double forecastNextEvent() {
    State& s = sim_.state;
    EventProgress now = measureEventProgress(sim_.model, sim_.materials, s);
    const EventForecast f = forecastEvents(s.lastProgress, now, historyEvery_ * sim_.integrator->timeStep());
    s.lastProgress = std::move(now);
    const EventForecast last = s.lastForecast;
    s.lastForecast = f;
    return rowsToFirstEvent(last, f, p_.rate_adapt_horizon * p_.rate_adapt_max);
  }

  /// A progress line on stderr every 2 s: step, load, crack, R, this piece's steps/s and the time left.
  void reportProgress(const Measurement& r) {
    const double w = wall();
    if (!opt_.progress || !(w - lastProgress_ > 2.0)) return;
    lastProgress_ = w;
    const State& s = sim_.state;
    const ProgressSample now = sample();
    const std::string eta = formatTimeLeft(estimateTimeLeft(marks_, now, stopTargets_, plan_));
    const ProgressSample& piece = marks_.piece;
    const double rate = now.wall > piece.wall ? (now.step - piece.step) / (now.wall - piece.wall) : 0;
    std::fprintf(stderr, "%sstep %ld  t %.4g  U/d %.4g  da/d %.2f  R/Gamma %.3f  broken %d  rate x%.3g  %.1f steps/s  ETA %s%s",
                 tty_ ? "\r" : "", s.step, s.time, now.displacement, s.crackAdvance, r.J / p_.Gamma(),
                 s.brokenBeams(), s.rateMultiplier, rate, eta.c_str(),
                 tty_ ? "   " : "\n");
  }

  /// Rewrite the (partial) result file every writeIntervalSeconds.
  void saveIfDue() {
    if (wall() - lastWrite_ > opt_.writeIntervalSeconds) save();
  }

  /// The first stop criterion met after this step (rec.stopReason and status set), or false.
  bool findStopReason() {
    const State& s = sim_.state;
    const Model& m = sim_.model;
    const double U = s.appliedDisplacement;
    const double maxX = m.a0Eff + s.crackAdvance;
    if (s.crackAdvance >= p_.stop_da_over_d)
      rec_.stopReason = fmt("crack advance %.3g d reached stop_da_over_d = %g", s.crackAdvance, p_.stop_da_over_d);
    else if (maxX >= m.w_s - 2 * m.h_e)
      rec_.stopReason = fmt("separated: crack reached the far edge (x = %.3g d of w_s = %g d)", maxX, m.w_s);
    else if (loadWatch_.separated)
      rec_.stopReason = fmt("separated: the grip load stayed below stop_load_fraction = %g of its peak %.4g since t = %.6g "
                            "(stop_load_transits = %g transit times; Delta_a %.3g d)", p_.stop_load_fraction,
                            loadWatch_.peakLoad, loadWatch_.belowSince, p_.stop_load_transits, s.crackAdvance);
    else if (U >= p_.stop_u_over_d)
      rec_.stopReason = fmt("applied displacement %.4g d reached stop_u_over_d = %g", U, p_.stop_u_over_d);
    else if (p_.max_steps > 0 && s.step >= p_.max_steps)
      rec_.stopReason = fmt("step %.0f reached max_steps = %.0f", s.step, double(p_.max_steps));
    else if (gStopSignal)
      rec_.stopReason = fmt("interrupted by signal %.0f", gStopSignal);
    if (rec_.stopReason.empty()) return false;
    rec_.status = gStopSignal ? RunStatus::interrupted : RunStatus::completed;
    if (gStopSignal) checkpoint();  // the state after this step: a restart continues from here
    return true;
  }

  /// A checkpoint every checkpointIntervalSeconds of wall clock.
  void checkpointIfDue() {
    if (opt_.checkpointIntervalSeconds > 0 && wall() - lastCheckpoint_ > opt_.checkpointIntervalSeconds) checkpoint();
  }

  /// The last history row (its kinetic ratios noted as the loop's rows are) and frame, the result file under the
  /// name of its status (the partial one removed), and the checkpoint removed when the run completed.
  RunRecord finish() {
    if (opt_.progress && tty_) std::fprintf(stderr, "\n");
    if (rec_.status != RunStatus::failed || rec_.history.empty() || rec_.history.back().step != sim_.state.step) {
      rec_.history.push_back(sim_.measure());
      noteQuasiStatic(rec_.history.back());
    }
    if (rec_.status == RunStatus::completed) {  // the steps since the last checked row: a run blown up there is no result
      const std::string blowUp = blowUpCheck(rec_.history.back(), kineticRatioOf(rec_.history.back()), guard_);
      if (!blowUp.empty()) fail(blowUp);
    }
    rec_.frames.push_back(captureFrame(sim_, -1.0));
    save();
    if (resultFileFor(opt_.outDir, rec_.status) != partialPath_) std::remove(partialPath_.c_str());
    if (rec_.status == RunStatus::completed && !opt_.checkpointPath.empty()) std::remove(opt_.checkpointPath.c_str());
    return rec_;
  }

 private:
  using clock = std::chrono::steady_clock;

  double wall() const { return wallBefore_ + std::chrono::duration<double>(clock::now() - start_).count(); }
  ProgressSample sample() const {
    const State& s = sim_.state;
    return ProgressSample{wall(), double(s.step), s.crackAdvance, s.appliedDisplacement};
  }
  void save() {
    rec_.wallSeconds = wall();
    rec_.steps = sim_.state.step;
    writeResultFile(resultFileFor(opt_.outDir, rec_.status), sim_, rec_);
    lastWrite_ = rec_.wallSeconds;
  }
  void checkpoint() {
    if (opt_.checkpointPath.empty()) return;
    rec_.wallSeconds = wall();
    rec_.steps = sim_.state.step;
    writeCheckpoint(opt_.checkpointPath, sim_, rec_);
    lastCheckpoint_ = rec_.wallSeconds;
  }
  bool fail(const std::string& why) {
    rec_.status = RunStatus::failed;
    rec_.stopReason = why;
    return false;
  }

  Simulation& sim_;
  const RunOptions& opt_;
  const CaseParams& p_;
  const clock::time_point start_;
  const bool tty_;
  std::vector<double> frameTargets_;
  const StopTargets stopTargets_;
  const GuardBounds guard_;  // the blow-up guard's failure bounds
  const int burstInterfaces_;  // the rate controller's burst: more interfaces failed in one interval
  const std::string partialPath_;  // the result file while the run is in progress
  long historyEvery_ = 1;
  RunRecord rec_;
  double wallBefore_ = 0;  // wall time of the run before a restart
  double lastWrite_ = 0, lastProgress_ = 0, lastCheckpoint_ = 0, lastDa_ = 0;
  std::size_t nextFrame_ = 0;
  ProgressMarks marks_;  // where the progress line's rates are measured from
  StepPlan plan_;        // the run's own estimate of its steps (planSteps)
  LoadDropWatch loadWatch_;  // the separated-specimen stop
};

}  // namespace

RunRecord runSimulation(Simulation& sim, const RunOptions& opt) {
  RunLoop run(sim, opt);
  run.start();
  while (true) {
    sim.step();
    run.injectFault();
    if (!run.recordRcurvePoint()) break;
    if (run.historyDue()) {
      const Measurement r = run.recordHistory();
      if (!run.checkBalance(r)) break;
      run.controlLoadingRate();
      run.reportProgress(r);
      run.saveIfDue();
    }
    if (run.findStopReason()) break;
    run.checkpointIfDue();
  }
  return run.finish();
}

}  // namespace enamel
