#include "runner.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <sstream>

namespace enamel {

namespace {
volatile std::sig_atomic_t gStopSignal = 0;

// Quasi-static and stability bounds (DESIGN section 4). Warnings are recorded in /meta/warnings;
// the failure bound stops the run.
constexpr double kBalanceWarn = 0.02;      // |energy balance error| above this: warning
constexpr double kBalanceFail = 0.25;      // ... above this: the run is unstable, stop
constexpr double kKineticWarn = 0.05;      // kinetic / strain energy above this: not quasi-static, warning
constexpr double kBalanceMinWork = 0.1;    // x Gamma_i B d: the balance error is checked once this much work was done

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

double estimateSecondsLeft(const ProgressSample& since, const ProgressSample& now, const StopTargets& stop) {
  const double elapsed = now.wall - since.wall;
  double left = NAN;
  auto aim = [&](double from, double at, double target) {
    if (target <= 0 || !(at > from)) return;
    const double t = std::max(0.0, elapsed * (target - at) / (at - from));
    left = std::isnan(left) ? t : std::min(left, t);
  };
  aim(since.step, now.step, stop.steps);
  aim(since.crackAdvance, now.crackAdvance, stop.crackAdvance);
  if (now.crackAdvance > 0) aim(since.displacement, now.displacement, stop.displacement);
  return left;
}

void requestStop(int signal) { gStopSignal = signal; }

RunRecord runSimulation(Simulation& sim, const RunOptions& opt) {
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  double wallBefore = 0;  // wall time of the run before a restart
  auto wall = [&] { return wallBefore + std::chrono::duration<double>(clock::now() - start).count(); };
  const CaseParams& p = sim.params;
  const double dt = sim.integrator->timeStep();
  const double Gamma = p.Gamma();
  const long historyEvery = p.history_every > 0
      ? p.history_every : std::max(1L, std::lround(0.05 * sim.model.h_s / sim.c_d / dt));
  const bool tty = isatty(STDERR_FILENO);

  RunRecord rec;
  std::size_t nextFrame = 0;
  std::vector<double> frameTargets = p.frames_da_over_d;
  std::sort(frameTargets.begin(), frameTargets.end());
  double lastWrite = 0, lastProgress = 0, lastDa = 0;
  bool& warnedBalance = rec.warnedBalance;
  bool& warnedKinetic = rec.warnedKinetic;
  double lastCheckpoint = 0;
  auto checkpoint = [&] {
    if (opt.checkpointPath.empty()) return;
    rec.wallSeconds = wall();
    rec.steps = sim.state.step;
    writeCheckpoint(opt.checkpointPath, sim, rec);
    lastCheckpoint = rec.wallSeconds;
  };
  const double minWork = kBalanceMinWork * Gamma * sim.model.B;
  const std::string partialPath = resultFileFor(opt.outDir, "running");
  auto save = [&] {
    rec.wallSeconds = wall();
    rec.steps = sim.state.step;
    writeResultFile(resultFileFor(opt.outDir, rec.status), sim, rec);
    lastWrite = rec.wallSeconds;
  };
  auto fail = [&](const std::string& why) {
    rec.status = "failed";
    rec.stopReason = why;
  };

  // Fault injection for the tests of the failure path: ENAMEL_INJECT_NAN_AT_STEP=N puts a NaN into one free
  // displacement after step N, as a diverging run would (tests/python/test_cli.py).
  const char* injectEnv = std::getenv("ENAMEL_INJECT_NAN_AT_STEP");
  const long injectAt = injectEnv ? std::atol(injectEnv) : -1;
  if (opt.restart) {
    readCheckpoint(opt.checkpointPath, sim, rec);
    rec.status = "running";
    rec.stopReason.clear();
    wallBefore = lastCheckpoint = rec.wallSeconds;
    lastDa = rec.rcurveDa.empty() ? 0.0 : rec.rcurveDa.back();
    nextFrame = rec.frames.size();  // frames are taken in the order of their sorted targets
    std::fprintf(stderr, "enamel-dem: resuming from checkpoint at step %ld (U/d %.4g, da/d %.3g, %s of wall time so far)\n",
                 sim.state.step, sim.state.appliedDisplacement, sim.state.crackAdvance,
                 formatDuration(rec.wallSeconds).c_str());
  } else {
    rec.history.push_back(sim.measure());
  }
  save();
  // Progress rates are measured over this piece of the run, and the crack's from where it started.
  auto sample = [&] {
    return ProgressSample{wall(), double(sim.state.step), sim.state.crackAdvance, sim.state.appliedDisplacement};
  };
  const ProgressSample pieceStart = sample();
  ProgressSample etaSince = pieceStart;
  const StopTargets stopTargets{p.stop_da_over_d, p.stop_u_over_d, double(p.max_steps)};
  while (true) {
    sim.step();
    if (sim.state.step == injectAt) sim.state.q[sim.freeDofs[sim.freeDofs.size() / 2]] = NAN;
    const State& s = sim.state;
    // R-curve point each time the crack advanced.
    if (s.crackAdvance > lastDa) {
      if (lastDa == 0) {  // the crack starts: its rate is measured from here, its first advance included
        etaSince = sample();
        etaSince.crackAdvance = 0;
      }
      lastDa = s.crackAdvance;
      rec.rcurveDa.push_back(s.crackAdvance);
      rec.rcurveJ.push_back(sim.computeJ());
      while (nextFrame < frameTargets.size() && s.crackAdvance >= frameTargets[nextFrame])
        rec.frames.push_back(captureFrame(sim, frameTargets[nextFrame++]));
    }
    // History, checks and progress every historyEvery steps.
    if (s.step % historyEvery == 0) {
      const Measurement r = sim.measure();
      rec.history.push_back(r);
      for (double x : {r.J, r.kinetic, r.strainBeams, r.strainInterfaces, r.external})
        if (!std::isfinite(x)) {
          fail(fmt("non-finite state at step %.0f (t = %g): J = %g, kinetic = %g, external work = %g; "
                   "the time step or the loading is unstable", s.step, s.time, r.J, r.kinetic, r.external));
          break;
        }
      if (rec.status == "failed") break;
      if (r.external > minWork && std::abs(r.balanceError) > kBalanceFail) {
        fail(fmt("energy balance error %.3g at step %.0f exceeds the bound %.2g (external work %.4g): "
                 "energy is created or lost; reduce dt_factor or the loading rate",
                 r.balanceError, s.step, kBalanceFail, r.external));
        break;
      }
      if (!warnedBalance && r.external > minWork && std::abs(r.balanceError) > kBalanceWarn) {
        warnedBalance = true;
        rec.warnings.push_back(fmt("energy balance error %.3g at step %.0f above %.2g", r.balanceError, s.step,
                                   kBalanceWarn));
      }
      const double strain = r.strainBeams + r.strainInterfaces;
      // Quasi-static check while the crack grows (before it, the ratio only says how far the load has come).
      const double kineticRatio = s.crackAdvance > 0 && strain > 0 ? r.kinetic / strain : 0.0;
      rec.maxKineticRatio = std::max(rec.maxKineticRatio, kineticRatio);
      if (!warnedKinetic && kineticRatio > kKineticWarn) {
        warnedKinetic = true;
        rec.warnings.push_back(fmt("kinetic / strain energy %.3g at step %.0f above %.2g: not quasi-static",
                                   kineticRatio, s.step, kKineticWarn));
      }
      const double w = wall();
      if (opt.progress && (w - lastProgress > 2.0)) {
        lastProgress = w;
        const ProgressSample now = sample();
        const double eta = estimateSecondsLeft(etaSince, now, stopTargets);
        const double rate = now.wall > pieceStart.wall ? (now.step - pieceStart.step) / (now.wall - pieceStart.wall) : 0;
        std::fprintf(stderr, "%sstep %ld  t %.4g  U/d %.4g  da/d %.2f  R/Gamma %.3f  broken %d  %.1f steps/s  ETA %s%s",
                     tty ? "\r" : "", s.step, s.time, now.displacement, s.crackAdvance, r.J / Gamma, s.brokenBeams,
                     rate, std::isfinite(eta) ? formatDuration(eta).c_str() : "?", tty ? "   " : "\n");
      }
      if (w - lastWrite > opt.writeIntervalSeconds) save();
    }
    // Stop criteria.
    const double U = s.appliedDisplacement;
    const double maxX = sim.model.a0 + s.crackAdvance;
    if (s.crackAdvance >= p.stop_da_over_d)
      rec.stopReason = fmt("crack advance %.3g d reached stop_da_over_d = %g", s.crackAdvance, p.stop_da_over_d);
    else if (maxX >= sim.model.w_s - 2 * sim.model.h_e)
      rec.stopReason = fmt("crack reached the far edge (x = %.3g d of w_s = %g d)", maxX, sim.model.w_s);
    else if (U >= p.stop_u_over_d)
      rec.stopReason = fmt("applied displacement %.4g d reached stop_u_over_d = %g", U, p.stop_u_over_d);
    else if (p.max_steps > 0 && s.step >= p.max_steps)
      rec.stopReason = fmt("step %.0f reached max_steps = %.0f", s.step, double(p.max_steps));
    else if (gStopSignal)
      rec.stopReason = fmt("interrupted by signal %.0f", gStopSignal);
    if (!rec.stopReason.empty()) {
      rec.status = gStopSignal ? "interrupted" : "completed";
      if (gStopSignal) checkpoint();  // the state after this step: a restart continues from here
      break;
    }
    if (opt.checkpointIntervalSeconds > 0 && wall() - lastCheckpoint > opt.checkpointIntervalSeconds) checkpoint();
  }
  if (opt.progress && tty) std::fprintf(stderr, "\n");
  if (rec.status != "failed" || rec.history.empty() || rec.history.back().step != sim.state.step)
    rec.history.push_back(sim.measure());
  rec.frames.push_back(captureFrame(sim, -1.0));
  save();
  if (resultFileFor(opt.outDir, rec.status) != partialPath) std::remove(partialPath.c_str());
  if (rec.status == "completed" && !opt.checkpointPath.empty()) std::remove(opt.checkpointPath.c_str());
  return rec;
}

}  // namespace enamel
