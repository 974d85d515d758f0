#include "run/profile.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <sstream>

namespace enamel {

namespace {

using clock = std::chrono::steady_clock;

// a[i] = b[i] + s c[i] (STREAM's triad, 24 bytes per element) over vectors of at least 2^23 doubles (64 MB
// each: far larger than any cache), the best of 10 passes, with this run's threads.
double measureTriad(long n) {
  n = std::max(n, 1L << 23);
  std::vector<double> a(n), b(n, 1.0), c(n, 2.0);
  const double s = 0.5;
  double best = 1e30;
  for (int pass = 0; pass < 10; ++pass) {
    const auto t0 = clock::now();
    double* pa = a.data();
    const double* pb = b.data();
    const double* pc = c.data();
#pragma omp parallel for schedule(static)
    for (long i = 0; i < n; ++i) pa[i] = pb[i] + s * pc[i];
    best = std::min(best, std::chrono::duration<double>(clock::now() - t0).count());
  }
  return 24.0 * static_cast<double>(n) / best;
}

// One steady_clock::now() (what a lap reads), the best of 20 rounds of 1000 back-to-back reads.
double measureClockRead() {
  double best = 1e30;
  for (int round = 0; round < 20; ++round) {
    const auto t0 = clock::now();
    clock::time_point last = t0;
    for (int i = 0; i < 1000; ++i) last = clock::now();
    best = std::min(best, std::chrono::duration<double>(last - t0).count() / 1000);
  }
  return best;
}

// The bytes a phase must move per step: every array it touches counted once per step (what it would cost if
// nothing stayed in cache between steps and everything within a slice did). 8 bytes per double, 4 per int.
// Counted for the lumped slice pass and for the deletion check; NaN for the phases not counted.
double bytesOfPhase(StepPhase phase, const Model& m, double stressComputedFraction, bool stressScheduled) {
  const double ni = m.numInterfaces(), nn = m.numNodes(), ne = m.numBeams();
  // K: one diagonal block per node, two off-diagonal per rod element; K_I: one diagonal block per node, two
  // off-diagonal per interface
  const double blocks = 2.0 * ne + nn + 2.0 * ni + nn;
  // per interface: its due drift (8); its compact geometry, its two nodes and its history only where due
  const double interfaces = ni * 8;
  // per node: q and v_{n-1/2} read, v_{n+1/2} and q_{n+1} written, 1/m and m (6 x 6 x 8), its grip flag (1);
  // K's and K_I's blocks (column and pair index, 8 per block + 4 per row of each)
  const double nodes = nn * 6 * 6 * 8 + nn + 8 * blocks + 8 * nn;
  switch (phase) {
    case StepPhase::SlicePass: return interfaces + nodes;
    case StepPhase::SliceInterfaces: return interfaces;
    case StepPhase::SliceNodes: return nodes;
    case StepPhase::DeletionCheck:
      // per rod element computed: its nodes (8), rod (4), strength (8), broken flag (1), ratio written (8), and
      // one node's q (48: consecutive elements share the other); the schedule's pass: per rod element its
      // broken flag (1) and due drift (8)
      return stressComputedFraction * ne * (8 + 4 + 8 + 1 + 8 + 48) + (stressScheduled ? ne * (1 + 8) : 0.0);
    default: return NAN;
  }
}

std::string percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, fraction >= 0.1 ? "%.0f%%" : "%.2g%%", 100.0 * fraction);
  return buf;
}

// The phases the step timed, per step, with their byte counts and what the step did there.
std::vector<PhaseTiming> phasesOf(const StepTimers& t, const StepProfile& p, const Model& m, bool stressScheduled) {
  std::vector<PhaseTiming> out;
  for (const StepPhaseInfo& info : kStepPhases) {
    const int i = static_cast<int>(info.phase);
    if (t.laps[i] == 0) continue;  // the other scheme's
    PhaseTiming r{info.phase, info.what, t.seconds[i] / t.steps, static_cast<double>(t.laps[i]) / t.steps,
                  bytesOfPhase(info.phase, m, p.stressComputedFraction, stressScheduled)};
    if (info.phase == StepPhase::SliceInterfaces)
      r.what += " (the step: the law saw " + percent(p.interfaceEvaluatedFraction) + " of the interfaces per step)";
    if (info.phase == StepPhase::DeletionCheck)
      r.what += " (" + percent(p.stressComputedFraction) + " of the rod elements computed per step)";
    out.push_back(r);
  }
  return out;
}

}  // namespace

StepProfile profileStep(Simulation& sim, long warmup, long steps) {
  StepProfile p;
  p.scheme = sim.integrator->name();
  p.threads = threadCount();
  p.warmup = warmup;
  p.steps = steps;
  p.dof = sim.model.numDofs();
  for (long i = 0; i < warmup; ++i) sim.step();
  StepTimers timers;
  sim.setTimers(&timers);
  long computed = 0, evaluated = 0;  // rod elements the deletion check computed, interfaces the law saw
  double seconds = 0;
  p.displacementBefore = sim.state.appliedDisplacement;
  p.phiBefore = sim.state.rateMultiplier;
  for (long i = 0; i < steps; ++i) {
    const auto t0 = clock::now();
    sim.step();
    seconds += std::chrono::duration<double>(clock::now() - t0).count();
    computed += sim.stressCheckSchedule().computed;
    if (const InterfaceSchedule* schedule = sim.integrator->interfaceSchedule()) evaluated += schedule->evaluated;
  }
  sim.setTimers(nullptr);
  p.displacementAfter = sim.state.appliedDisplacement;
  p.phiAfter = sim.state.rateMultiplier;
  const Model& m = sim.model;
  p.secondsPerStep = seconds / steps;
  p.stressComputedFraction = sim.materials.rodsBreakable ? static_cast<double>(computed) / (steps * std::max(1, m.numBeams())) : 0.0;
  const bool scheduled = std::isfinite(sim.integrator->lastStepMoveBound());
  if (sim.integrator->interfaceSchedule())
    p.interfaceEvaluatedFraction = static_cast<double>(evaluated) / (steps * std::max(1, m.numInterfaces()));
  p.phases = phasesOf(timers, p, m, scheduled);
  if (scheduled)  // the lumped step: its slice pass and deletion check
    p.stepBytes = bytesOfPhase(StepPhase::SlicePass, m, 0, false) +
                  bytesOfPhase(StepPhase::DeletionCheck, m, p.stressComputedFraction, true);
  p.triadBytesPerSecond = measureTriad(3 * static_cast<long>(p.dof));
  p.clockReadSeconds = measureClockRead();
  return p;
}

namespace {

// One row of the table; `depth` levels of indentation under the step.
std::string profileRow(const std::string& name, int depth, double seconds, double stepSeconds, double laps,
                       double bytes, double triad, const std::string& what) {
  char buf[1024];
  const std::string indented = std::string(2 * depth, ' ') + name;
  char lapsText[32] = "-", bytesText[96] = "- | - | -";
  if (laps > 0) std::snprintf(lapsText, sizeof lapsText, "%.4g", laps);
  if (std::isfinite(bytes)) {
    const double gbs = seconds > 0 ? bytes / seconds / 1e9 : 0;
    std::snprintf(bytesText, sizeof bytesText, "%.1f | %.1f | %.0f%%", bytes / 1e6, gbs, 100 * gbs * 1e9 / triad);
  }
  std::snprintf(buf, sizeof buf, "| %s | %.4g | %.0f%% | %s | %s | %s |\n", indented.c_str(), 1e3 * seconds,
                stepSeconds > 0 ? 100 * seconds / stepSeconds : 0, lapsText, bytesText, what.c_str());
  return buf;
}

}  // namespace

std::string formatProfileMarkdown(const StepProfile& p) {
  std::ostringstream o;
  char buf[512];
  double laps = 0;
  for (const PhaseTiming& t : p.phases) laps += t.lapsPerStep;
  const double step = p.secondsPerStep;
  std::snprintf(buf, sizeof buf,
                "%.0f DOF, %d thread(s), scheme %s, %ld steps timed after %ld warm-up steps: %.4g ms/step, %.1f M "
                "DOF-updates/s per core; triad %.1f GB/s; timers: %.4g laps per step, a clock read %.0f ns\n\n",
                p.dof, p.threads, p.scheme.c_str(), p.steps, p.warmup, 1e3 * step, p.dof / step / p.threads / 1e6,
                p.triadBytesPerSecond / 1e9, laps, 1e9 * p.clockReadSeconds);
  o << buf;
  o << "| phase | ms/step | share of step | laps/step | MB/step | GB/s | % of triad | what |\n"
       "|---|---|---|---|---|---|---|---|\n";
  o << profileRow("step", 0, step, step, 0, p.stepBytes, p.triadBytesPerSecond,
                  "Simulation::step, timed around each call; the phases below are its parts, each timed around the "
                  "calls the step makes for it");
  for (const PhaseTiming& t : p.phases)
    o << profileRow(kStepPhases[static_cast<int>(t.phase)].name, 1 + kStepPhases[static_cast<int>(t.phase)].depth,
                    t.secondsPerStep, step, t.lapsPerStep, t.bytesPerStep, p.triadBytesPerSecond, t.what);
  std::snprintf(buf, sizeof buf, "\nloading over the timed steps: U/d %.6g -> %.6g, phi %.4g -> %.4g\n",
                p.displacementBefore, p.displacementAfter, p.phiBefore, p.phiAfter);
  o << buf;
  return o.str();
}

}  // namespace enamel
