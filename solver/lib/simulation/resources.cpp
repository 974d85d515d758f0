#include "simulation/resources.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "integrators/integrators.hpp"
#include "simulation/setup.hpp"
#include "simulation/simulation.hpp"

namespace enamel {

namespace {
constexpr double kPi = 3.14159265358979323846;
// Peak resident memory beyond the scheme's own (its registry row's estimateCosts, integrators.hpp), VmHWM
// (/meta/peak_memory_mb) measured on theta30, 20 steps, 1 thread: static_start > 0 adds the elastic stiffness's
// Cholesky factor (rods and interfaces; OpenBLAS): lumped 40 x 20 d 59 -> 130 MB, 200 x 200 d 1630 -> 7520 MB:
// ~14.2 kB per node + ~33 B per node of a slice. The constants round these up by ~10%.
constexpr double kStaticBytesPerNode = 15600;
constexpr double kStaticFillBytesPerNodeSliceNode = 36;
constexpr double kBaseBytes = 30e6;  // the executable, libraries and the transverse-modulus block

// The scheme's own costs (its row of the integrators' registry), from the counts.
SchemeCosts schemeCosts(const CaseParams& p, const ResourceEstimate& e) {
  return integratorEntry(p.integrator).estimateCosts(p, SchemeSizes{e.nodes, e.dof, e.nodes / e.slices});
}
}  // namespace

ResourceEstimate estimateResources(const CaseParams& p) {
  ResourceEstimate e;
  const double cosT = std::cos(p.theta_D * kPi / 180);
  e.slices = std::round(p.w_s_over_d / p.h_e_over_d) + 1;
  const double perSlice = 2 * p.h_s_over_d * cosT;
  e.nodes = e.slices * perSlice;
  e.dof = 6 * e.nodes;
  e.interfaces = 3 * e.nodes;
  e.memoryBytes = kBaseBytes + schemeCosts(p, e).memoryBytes;
  if (p.static_start > 0) e.memoryBytes += e.nodes * (kStaticBytesPerNode + kStaticFillBytesPerNodeSliceNode * perSlice);
  return e;
}

namespace {
// Time of a run (estimateRunTime). Measured one thread a run on this project's development machine (AMD EPYC,
// AVX-512; 2 cores under other builds and runs, load 10-16: wall times swing, so rates are CPU (user) seconds, and
// the constants take the slow side), with
//   /usr/bin/time enamel-dem run paper_cases/CASE.toml --preset P --set threads=1 [--set max_steps=N ...]
// and the run's /meta and /history.
// Applied displacement at the stop, at delta0 = 0.1 d (in linear kinematics every displacement scales with delta0,
// docs/model.md): U_end = U_i + k_a stop_da_over_d. U_i is where the crack starts to grow in the ci run of
// theta30_s21.4_e10_cv0 (16 x 8 d: Delta_a > 0 at U = 2.50 d; U_end 5.08 d at Delta_a 5.13 d, 0.52 d per d after
// it); k_a is that run's and the median of the 80 x 80 d square runs at G = 10 at the paper's rate (U_end
// 10.4-24.8 d at Delta_a = 30 d, median 16.5 d: (16.5 - 2.5) / 30 = 0.47). Against runs: ci (5.0 d) 0.60x-1.24x
// (U_end 4.04-8.39 d: theta0_s21.4_e10, theta15_s21.4_e5, theta30_s7.1/s21.4/s28.5_e10, cv 0), reduced 40 x 20 d
// to 12 d (8.5 d) 1.00x (theta30_s21.4_e10_cv0: 8.49 d); 80 x 80 d (17.5 d) 0.71x (theta30_s28.5_e10_cv0, 24.8 d)
// to 1.68x (theta0_s21.4_e10_cv0, 10.4 d); 100 x 100 d 1.0-1.2x (14.3-17.7 d); 200 x 200 d 1.26x (13.9 d). U_end
// at a given stop does not grow with h_s beyond 80 d (16.5 d at 80 d, 13.9 d at 200 d), so h_s is not in it.
constexpr double kUAtInitiation = 2.5;     // d
constexpr double kUPerCrackAdvance = 0.5;  // d per d of crack advance
// The static start's U_c (first damage, theta30_s21.4_e10_cv0): 0.272 d at h_s = 8 d, 0.529 at 20, 1.057 at 80
// (the ci, reduced and converged presets' sizes), 1.705 at 200 (the paper preset, `make bench-paper`'s static
// start): k_c sqrt(h_s / d) with
// k_c = 0.096-0.121; a low U_c skips less of the run, so k_c is on the low side of the larger sizes.
constexpr double kUcPerSqrtHeight = 0.11;
// Seconds per step: the scheme's own (its registry row's estimateCosts, integrators.hpp).
// Set-up (the model, operators, integrator, c_d's block), per DOF: 1.8e-5 s user at 80 x 80 d (a 1-step run).
// The static start's solve, per DOF and node of a slice: 82 s on 2 cores at 200 x 200 d (3.4e-7 core-s), 91 s
// wall at 80 x 80 d under load (2.9e-6).
constexpr double kSetupSecondsPerDof = 3e-5, kStaticSecondsPerDofSliceNode = 1e-6;
constexpr double kBlockWidth = 16, kBlockHeight = 8;  // d: the block of stepScaleOfBlock (the ci preset's size)
constexpr double kDefaultDelta0 = 0.1;                // d: the U_end and U_c measurements' delta0

// Applied displacement at the stop, d: (U_i + k_a stop_da_over_d) (delta0 / 0.1 d), at most stop_u_over_d.
double stopDisplacement(const CaseParams& p) {
  const double atDefaultDelta0 = kUAtInitiation + kUPerCrackAdvance * p.stop_da_over_d;
  return std::min(p.stop_u_over_d, atDefaultDelta0 * p.delta0_over_d / kDefaultDelta0);
}

// Applied displacement where the crack starts to move, d: U_i (delta0 / 0.1 d), at most the stop's.
double initiationDisplacement(const CaseParams& p) {
  return std::min(stopDisplacement(p), kUAtInitiation * p.delta0_over_d / kDefaultDelta0);
}

// Applied displacement at the start, d: static_start x U_c, U_c = k_c (delta0 / 0.1 d) sqrt(h_s / d) (0 from rest).
double startDisplacement(const CaseParams& p) {
  return p.static_start * kUcPerSqrtHeight * p.delta0_over_d / kDefaultDelta0 * std::sqrt(p.h_s_over_d);
}

double setupSeconds(const CaseParams& p, const ResourceEstimate& e) {
  const double staticSolve = p.static_start > 0 ? kStaticSecondsPerDofSliceNode * e.dof * e.nodes / e.slices : 0;
  return kSetupSecondsPerDof * e.dof + staticSolve;
}
}  // namespace

TimeEstimate estimateRunTime(const CaseParams& p, const StepScale& s) {
  TimeEstimate t;
  const ResourceEstimate e = estimateResources(p);
  Loading loading;
  loading.vApp = p.rate_factor * p.v_app_over_cd * s.c_d;
  loading.rampTime = p.ramp_transits * p.h_s_over_d / s.c_d;
  t.uEnd = stopDisplacement(p);
  t.uStart = std::min(startDisplacement(p), t.uEnd);
  t.duration = loading.timeOfDisplacement(t.uEnd) - loading.timeOfDisplacement(t.uStart);
  t.steps = std::ceil(t.duration / s.dt);
  if (p.max_steps > 0) t.steps = std::min(t.steps, static_cast<double>(p.max_steps));
  t.secondsPerStep = schemeCosts(p, e).secondsPerStep;
  t.setupSeconds = setupSeconds(p, e);
  t.seconds = t.setupSeconds + t.steps * t.secondsPerStep;
  return t;
}

StepPlan planSteps(const CaseParams& p, const Loading& loading, double dt, double step, double tau) {
  auto stepOf = [&](double U) { return step + (loading.timeOfDisplacement(U) - tau) / dt; };
  return StepPlan{stepOf(initiationDisplacement(p)), stepOf(stopDisplacement(p))};
}

StepScale stepScaleOfBlock(const CaseParams& p) {
  // the blocks are small unless h_e is: refuse one that cannot fit before building it (measureTransverseModulus's
  // is at most 24 x 12 d)
  CaseParams largest = p;
  largest.w_s_over_d = std::min(p.w_s_over_d, 24.0);
  largest.h_s_over_d = std::min(p.h_s_over_d, 12.0);
  largest.static_start = 0;
  const std::string why = checkMemoryFits(largest, availableMemoryBytes());
  if (!why.empty()) throw std::invalid_argument("the blocks that measure c_d and dt: " + why);
  StepScale s;
  s.c_d = std::sqrt(p.E_transverse_over_Er > 0 ? p.E_transverse_over_Er : measureTransverseModulus(p));
  CaseParams block = p;
  // the model's h_e is w_s / round(w_s / h_e) (geometry.cpp): the block keeps the case's, so its rod elements are
  // the case's (the same length, so the same element frequency)
  const double h_e = p.w_s_over_d / std::round(p.w_s_over_d / p.h_e_over_d);
  block.h_e_over_d = h_e;
  block.w_s_over_d = h_e * std::max(2.0, std::round(std::min(p.w_s_over_d, kBlockWidth) / h_e));
  block.h_s_over_d = std::min(p.h_s_over_d, kBlockHeight);
  block.far_field_slices = 1;
  block.static_start = 0;
  block.E_transverse_over_Er = s.c_d * s.c_d;  // the case's c_d (the block's own would differ a little)
  block.threads = 1;
  s.dt = Simulation(block).integrator->timeStep();
  return s;
}

double readProcKilobytes(const char* path, const char* key) {
  std::FILE* f = std::fopen(path, "r");
  if (!f) return NAN;
  const std::string format = std::string(key) + ": %lf kB";
  char line[256];
  double kb = NAN;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, format.c_str(), &kb) == 1) break;
  std::fclose(f);
  return kb;
}

double availableMemoryBytes() { return readProcKilobytes("/proc/meminfo", "MemAvailable") * 1024; }

std::string checkMemoryFits(const CaseParams& p, double available) {
  const ResourceEstimate e = estimateResources(p);
  if (!(e.memoryBytes > available)) return "";
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "the case needs about %.3g GB of memory (%.3g nodes, %.3g DOF, %.3g interfaces: w_s_over_d = %g, "
                "h_s_over_d = %g, h_e_over_d = %g, integrator %s) and %.3g GB are available",
                e.memoryBytes / 1e9, e.nodes, e.dof, e.interfaces, p.w_s_over_d, p.h_s_over_d, p.h_e_over_d,
                nameOf(p.integrator).c_str(), available / 1e9);
  return buf;
}

}  // namespace enamel
