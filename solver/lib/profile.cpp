#include "profile.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <sstream>

#include "kernels.hpp"

namespace enamel {

namespace {

using clock = std::chrono::steady_clock;

constexpr int kRounds = 5;  // interleaved timing rounds per kernel (profileKernels)

// Seconds per call of f, over `steps` calls.
template <class F>
double secondsPerCall(long steps, F&& f) {
  const auto t0 = clock::now();
  for (long i = 0; i < steps; ++i) f();
  return std::chrono::duration<double>(clock::now() - t0).count() / std::max(1L, steps);
}

double median(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  return x[x.size() / 2];
}

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

// The bytes a kernel must move per step: every array it touches counted once per step (what it would cost if
// nothing stayed in cache between steps and everything within a slice did). 8 bytes per double, 4 per int.
struct ByteCounts {
  double interfaces, interfacesAlone, nodes, positions, stressCheck, stressSchedule;
};

std::string percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2g%%", 100.0 * fraction);
  return buf;
}

ByteCounts countBytes(const Model& m) {
  const double ni = m.numInterfaces(), nn = m.numNodes(), ne = m.numBeams();
  // K: one diagonal block per node, two off-diagonal per rod element; K_I: one diagonal block per node, two
  // off-diagonal per interface
  const double blocks = 2.0 * ne + nn + 2.0 * ni + nn;
  ByteCounts b;
  // per interface: its due drift (8); its compact geometry, its two nodes and its history only where due
  b.interfaces = ni * 8;
  // the same on their own: also q read and f written
  b.interfacesAlone = b.interfaces + nn * (48 + 48);
  // per node: q and v_{n-1/2} read, v_{n+1/2} and q_{n+1} written, 1/m and m (6 x 6 x 8), its grip flag (1);
  // K's and K_I's blocks (column and pair index, 8 per block + 4 per row of each)
  b.nodes = nn * 6 * 6 * 8 + nn + 8 * blocks + 8 * nn;
  // q read and written, v read
  b.positions = nn * 6 * 24;
  // per rod element: its nodes (8), rod (4), strength (8), broken flag (1), ratio written (8), and one node's q
  // (48: consecutive elements share the other)
  b.stressCheck = ne * (8 + 4 + 8 + 1 + 8 + 48);
  // the schedule's pass: per rod element its broken flag (1) and due drift (8)
  b.stressSchedule = ne * (1 + 8);
  return b;
}

}  // namespace

KernelProfile profileKernels(Simulation& sim, long warmup, long steps) {
  if (sim.params.integrator != IntegratorScheme::lumped || !sim.integrator->interfaceSchedule())
    throw IntegratorError("profile: integrator '" + sim.integrator->name() + "' is not profiled (allowed: " +
                          nameOf(IntegratorScheme::lumped) + ")");
  KernelProfile p;
  p.threads = threadCount();
  p.steps = steps;
  p.dof = sim.model.numDofs();
  for (long i = 0; i < warmup; ++i) sim.step();
  const ByteCounts bytes = countBytes(sim.model);
  const Model& m = sim.model;
  State& s = sim.state;
  VecX f, qMoved = s.q;
  std::vector<double> ratio, lambdaTrial;
  InterfaceSchedule schedule;  // the interfaces kernel's own: a copy of the step's
  long evaluated = 0;  // interfaces the step's law saw over the timed steps
  // Each kernel timed in kRounds interleaved rounds of steps / kRounds calls, the median round kept: all of
  // them see the machine in the same minutes (this machine's speed varies by up to 2x within an afternoon),
  // and "step - advance" is a difference of neighbours. A round of the whole step begins with one untimed step:
  // the kernels timed alone in between advance the clock, so the stress check's schedule starts afresh there
  // (every element computed once) and not in the timed calls.
  const long perRound = std::max(1L, steps / kRounds);
  std::vector<double> stepT, advanceT, interfacesT, checkT, positionsT;
  long computed = 0, timedSteps = 0;  // rod elements the scheduled deletion check computed over the timed steps
  for (int round = 0; round < kRounds; ++round) {
    sim.step();
    stepT.push_back(secondsPerCall(perRound, [&] {
      sim.step();
      computed += sim.stressCheckSchedule().computed;
      evaluated += sim.integrator->interfaceSchedule()->evaluated;
      ++timedSteps;
    }));
    advanceT.push_back(secondsPerCall(perRound, [&] { sim.integrator->advance(m, sim.materials, sim.ops, s); }));
    lambdaTrial = s.lambdaMax;  // the kernel's history updates go to a copy
    schedule = *sim.integrator->interfaceSchedule();  // the step's, as it stands
    const double qLargest = s.q.cwiseAbs().maxCoeff();
    interfacesT.push_back(secondsPerCall(perRound, [&] {
      // as if the step had moved q as far as the last one did
      advanceInterfaceSchedule(m, sim.materials.law, sim.ops, sim.integrator->lastStepMoveBound(),
                               qLargest, schedule);
      computeInterfaceCorrectionsScheduled(m, sim.materials.law, sim.ops, s.q, lambdaTrial, schedule, f);
    }));
    checkT.push_back(secondsPerCall(
        perRound, [&] { computeStressRatiosForBeams(m, sim.materials, s.q, s.beamBroken, ratio); }));
    qMoved = s.q;  // moved on a copy: the step's state (and its schedules' bounds) stay as they were
    positionsT.push_back(
        secondsPerCall(perRound, [&] { advancePositions(qMoved, s.vHalf, sim.integrator->timeStep()); }));
  }
  p.steps = perRound * kRounds;
  p.interfaceEvaluatedFraction =
      static_cast<double>(evaluated) / std::max(1.0, static_cast<double>(timedSteps) * m.numInterfaces());
  p.stressComputedFraction =
      static_cast<double>(computed) / std::max(1.0, static_cast<double>(timedSteps) * m.numBeams());
  const double step = median(stepT), advance = median(advanceT), interfaces = median(interfacesT),
               check = median(checkT), positions = median(positionsT);
  p.triadBytesPerSecond = measureTriad(3 * static_cast<long>(p.dof));
  p.kernels = {
      {"step", "the whole time step (integrator's advance, rod stress check, crack measure when something failed)",
       step, bytes.interfaces + bytes.nodes + bytes.stressSchedule + p.stressComputedFraction * bytes.stressCheck},
      {"advance", "the integrator's step: the slice pass (interfaces, then per node its velocity and position)",
       advance, bytes.interfaces + bytes.nodes},
      {"  interfaces", "per interface: nothing while the schedule says it is elastic (its force is K_I q, in the node rows); the law where it is due (the step: " +
       percent(p.interfaceEvaluatedFraction) + " of the interfaces per step), and off the elastic branch its force beyond the elastic one added to both nodes (alone, with f written)",
       interfaces, bytes.interfacesAlone},
      {"  nodes", "advance - interfaces: per node K rows (q and v), K_I rows (q: the elastic interfaces), v_{n+1/2}, grip residuals, damping sums, q_{n+1} = q_n + dt v_{n+1/2}",
       std::max(0.0, advance - interfaces), bytes.nodes},
      {"  (positions)", "alone, for comparison: q += dt v over all DOF as a pass of its own (the step does it in the node pass)",
       positions, bytes.positions},
      {"check and rest", "step - advance: the rod stress check as the step runs it (scheduled: " + percent(p.stressComputedFraction) +
       " of the rod elements computed per step), crack measure when something failed, bookkeeping",
       std::max(0.0, step - advance), bytes.stressSchedule + p.stressComputedFraction * bytes.stressCheck},
      {"(stress check, every element)", "alone, for comparison: per rod element 5 rows of K_local T u_e, sigma / sigma_ru (what the check cost before the schedule)",
       check, bytes.stressCheck},
  };
  return p;
}

std::string formatProfileMarkdown(const KernelProfile& p) {
  std::ostringstream o;
  char buf[512];
  const double step = p.kernels.empty() ? 0 : p.kernels.front().secondsPerStep;
  std::snprintf(buf, sizeof buf,
                "%.0f DOF, %d thread(s), %ld steps per kernel in %d interleaved rounds (median round): %.4g s/step, %.1f M DOF-updates/s per core; "
                "triad %.1f GB/s\n\n",
                p.dof, p.threads, p.steps, kRounds, step, p.dof / step / p.threads / 1e6, p.triadBytesPerSecond / 1e9);
  o << buf;
  o << "| kernel | s/step | share of step | MB/step | GB/s | % of triad | what |\n|---|---|---|---|---|---|---|\n";
  for (const KernelTiming& k : p.kernels) {
    const double gbs = k.secondsPerStep > 0 ? k.bytesPerStep / k.secondsPerStep / 1e9 : 0;
    std::snprintf(buf, sizeof buf, "| %s | %.4g | %.0f%% | %.1f | %.1f | %.0f%% | %s |\n", k.name.c_str(),
                  k.secondsPerStep, step > 0 ? 100 * k.secondsPerStep / step : 0, k.bytesPerStep / 1e6, gbs,
                  100 * gbs * 1e9 / p.triadBytesPerSecond, k.what.c_str());
    o << buf;
  }
  return o.str();
}

}  // namespace enamel
