// enamel-dem: the command-line front end. A thin layer: parse the command line and the case, then call
// the library (geometry, simulation, runner). Every failure class has its own exit status (exit_codes.hpp).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "base/exit_codes.hpp"
#include "base/version.hpp"
#include "case/case_params.hpp"
#include "geometry/geometry.hpp"
#include "integrators/integrators.hpp"
#include "io/file_io.hpp"
#include "kernels/loading_rate.hpp"
#include "laws/beam.hpp"
#include "run/profile.hpp"
#include "run/runner.hpp"
#include "run/shared_constants.hpp"
#include "simulation/resources.hpp"
#include "simulation/simulation.hpp"

namespace fs = std::filesystem;
using namespace enamel;

namespace {

int fail(int code, const std::string& message) {
  std::fprintf(stderr, "enamel-dem: error: %s\n", message.c_str());
  return code;
}

struct CaseArgs {
  std::string casePath;
  std::string preset;
  std::vector<std::string> sets;
  void addTo(CLI::App* cmd) {
    cmd->add_option("case", casePath, "case file (TOML); 'enamel-dem keys' lists every key")->required();
    cmd->add_option("--preset,-p", preset,
                    "size preset: ci | reduced | converged | paper (specimen size, mesh, loading rate, stop criterion); "
                    "precedence: key defaults < preset < case file < --set");
    cmd->add_option("--set,-s", sets, "override one key, as key=value (TOML value), repeatable");
  }
};

// Refuse a case whose run cannot fit in this machine's memory, before anything is allocated or written.
int checkMemory(const CaseParams& p) {
  const std::string why = checkMemoryFits(p, availableMemoryBytes());
  return why.empty() ? exit_code::ok : fail(exit_code::out_of_range, p.sourceName + ": " + why);
}

int runInfo(const CaseArgs& args, bool estimateOnly) {
  const CaseParams p = loadCase(args.casePath, args.preset, args.sets);
  if (estimateOnly) {  // machine-readable, without building the model (cluster job scripts use it)
    const ResourceEstimate e = estimateResources(p);
    std::printf("nodes %.0f\ndof %.0f\ninterfaces %.0f\nmemory_mb %.0f\n", e.nodes, e.dof, e.interfaces,
                std::ceil(e.memoryBytes / 1048576));
    const StepScale s = stepScaleOfBlock(p);
    const TimeEstimate t = estimateRunTime(p, s);
    std::printf("c_d %.6g\ndt %.6g\nu_start %.6g\nu_end %.6g\nduration %.6g\nsteps %.0f\nseconds_per_step %.6g\n"
                "setup_seconds %.0f\nseconds %.0f\n", s.c_d, s.dt, t.uStart, t.uEnd, t.duration, t.steps,
                t.secondsPerStep, std::ceil(t.setupSeconds), std::ceil(t.seconds));
    return exit_code::ok;
  }
  if (int rc = checkMemory(p)) return rc;
  Simulation sim(p);
  const Model& m = sim.model;
  const Materials& mat = sim.materials;
  int byTag[4] = {0, 0, 0, 0};
  for (auto t : m.ifaceTag) ++byTag[t];
  const double wAxial = beam::closedFormAxialOmegaMax(mat.section, m.beamLength);
  const double wBend = beam::closedFormBendingOmegaMax(mat.section, m.beamLength, mat.section.Iy);
  std::printf("case               %s%s%s\n", p.sourceName.c_str(), p.presetName.empty() ? "" : "  preset ",
              p.presetName.c_str());
  std::printf("theta_D            %g deg   Er/kd %g   sigma_ru/sigma0 %g   cv %g\n", p.theta_D, p.Er_over_kd,
              p.sigma_ru_over_sigma0, p.cv);
  std::printf("specimen           w_s %g d x h_s %g d, z-period B %.4f d, pre-crack a0 %g d\n", m.w_s, m.h_s, m.B, m.a0);
  std::printf("pre-crack tip      a0_eff %.6g d = (K + 1/4) h_e, K = %d (cut through slice K)", m.a0Eff,
              m.precrackLastSlice);
  if (m.theta > 0) std::printf(", a crisscross at x = %.6g d (crisscross_at_tip %s)", m.xCrisscross, nameOf(p.crisscross_at_tip).c_str());
  std::printf("\n");
  std::printf("slices             %d (h_e %.4f d)\n", m.numSlices, m.h_e);
  std::printf("rods               %d\n", m.numRods());
  std::printf("nodes              %d\n", m.numNodes());
  std::printf("DOF                %d (6 per node), %zu prescribed\n", m.numDofs(), sim.ops.prescribedDofs.size());
  std::printf("beam elements      %d (+%d cut by the pre-crack), length %.4f d\n", m.numBeams(), m.precrackBeams,
              m.beamLength);
  std::printf("interfaces         %d (+%d cut by the pre-crack)\n", m.numInterfaces(), m.precrackInterfaces);
  if (m.hasFarField()) {
    int longBeams = 0;
    for (int e = 0; e < m.numBeams(); ++e) longBeams += m.beamSpan[e] > 1;
    std::printf("reduced far field  a node every %d slices beyond |y - h_s/2| = %g d: %d rod elements longer than "
                "one slice\n", m.farFieldSlices, m.fullHalfHeight, longBeams);
  }
  for (int t = 0; t < 4; ++t) std::printf("  %-30s %d\n", interfaceTagName(t), byTag[t]);
  std::printf("element frequency  omega_max %.4g c_r/d: %s governs (bending %.4g, axial %.4g)\n",
              mat.omegaMaxElement, wBend > wAxial ? "bending" : "axial", wBend, wAxial);
  std::printf("time step          dt %.4g d/c_r (integrator %s)\n", sim.integrator->timeStep(),
              sim.integrator->describe().c_str());
  std::printf("transverse modulus E_transverse %.4g E_r, c_d %.4g c_r%s\n", mat.E_transverse, mat.c_d,
              p.E_transverse_over_Er > 0 ? " (given)" : " (measured)");
  std::printf("damping            zeta %g at w_min %.4g: a %.4g, b %.4g\n", p.zeta, mat.omegaMin, mat.dampA, mat.dampB);
  std::printf("loading            v_app %.4g d c_r/d, ramp %.4g d/c_r\n", mat.loading.vApp, mat.loading.rampTime);
  std::printf("memory estimate    %.0f MB (%s)\n", estimateResources(p).memoryBytes / 1048576,
              "enamel-dem info --estimate; a run refuses a case that needs more than is available");
  return exit_code::ok;
}

// Time the step's phases on the case's model (profile.hpp) and print the table; writes nothing else. With
// rateMultiplier > 0 the loading clock runs at that phi from the start (the adaptive rate held, no controller), or
// ramps from it to rateTarget over the warm-up and timed steps, as a run's controller ramps it between rows.
int runProfile(const CaseArgs& args, long warmup, long steps, double rateMultiplier, double rateTarget) {
  const CaseParams p = loadCase(args.casePath, args.preset, args.sets);
  const double phiMax = std::max(rateMultiplier, rateTarget);
  if (phiMax > p.rate_adapt_max) {
    char msg[256];
    std::snprintf(msg, sizeof msg, "--rate-multiplier / --rate-target = %g is above rate_adapt_max = %g; allowed: "
                  "[1, rate_adapt_max] (add --set rate_adapt_max=%g)", phiMax, p.rate_adapt_max, phiMax);
    return fail(exit_code::usage, msg);
  }
  if (int rc = checkMemory(p)) return rc;
  Simulation sim(p);
  if (rateMultiplier > 0) {
    sim.state.rateMultiplier = sim.state.rateMultiplierTarget = rateMultiplier;
    if (rateTarget > 0) setRateMultiplierTarget(sim.state, rateTarget, warmup + steps);
  }
  std::printf("%s", formatProfileMarkdown(profileStep(sim, warmup, steps)).c_str());
  return exit_code::ok;
}

// The output directory, created if needed and locked for this run's whole life (DirectoryLock), before anything
// else is written to it: a second run into it is refused (or waits up to --lock-wait s) and changes nothing.
int lockOutput(const std::string& dir, double waitSeconds, std::unique_ptr<DirectoryLock>& lock) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return fail(exit_code::output_unwritable, "cannot create output directory '" + dir + "': " + ec.message());
  try {
    lock = std::make_unique<DirectoryLock>(dir, 0.0);
  } catch (const DirectoryLocked&) {
    if (!(waitSeconds > 0)) throw;
    std::fprintf(stderr, "enamel-dem: run directory '%s' is in use (%s): waiting up to %g s for it\n", dir.c_str(),
                 directoryLockHolder(dir).c_str(), waitSeconds);
    lock = std::make_unique<DirectoryLock>(dir, waitSeconds);
  }
  if (!lock->why().empty())
    std::fprintf(stderr, "enamel-dem: warning: %s%s\n", lock->why().c_str(),
                 lock->held() ? "" : ": running without the lock, a second run into this directory is not refused");
  return exit_code::ok;
}

// Output directory: created if needed, must be writable, and must not hold a result unless --force.
int prepareOutput(const std::string& dir, bool force, std::string& resultPath) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return fail(exit_code::output_unwritable, "cannot create output directory '" + dir + "': " + ec.message());
  resultPath = (fs::path(dir) / "result.h5").string();
  if (fs::exists(resultPath) && !force)
    return fail(exit_code::output_exists,
                "'" + resultPath + "' exists; use --force to overwrite it (nothing was changed)");
  const std::string probe = (fs::path(dir) / ".write-test").string();
  {
    std::ofstream f(probe);
    if (!f) return fail(exit_code::output_unwritable, "output directory '" + dir + "' is not writable");
  }
  fs::remove(probe, ec);
  return exit_code::ok;
}

// A run starts (or continues): the results of earlier runs in DIR are stale. result.h5 must only ever be the
// file of a run that completed with these inputs, so it goes now, not when this run ends.
void removeStaleResults(const std::string& dir) {
  std::error_code ec;
  for (RunStatus status : {RunStatus::completed, RunStatus::failed}) fs::remove(resultFileFor(dir, status), ec);
}

struct RunFlags {
  std::string outDir;
  bool force = false, quiet = false, restart = false, resume = false;
  double checkpointEvery = -1;  // < 0: the case key checkpoint_interval_s
  double lockWait = 0;          // s to wait for another run's lock on the output directory
};

int runRun(const CaseArgs& args, RunFlags flags) {
  std::string& outDir = flags.outDir;
  const CaseParams p = loadCase(args.casePath, args.preset, args.sets);
  if (outDir.empty())
    outDir = (fs::path("runs") / (p.presetName.empty() ? "default" : p.presetName) / fs::path(p.sourceName).stem())
                 .string();
  std::string resultPath;
  const std::string checkpointPath = (fs::path(outDir) / "checkpoint.bin").string();
  if (flags.restart && !fs::exists(checkpointPath))
    return fail(exit_code::missing_file, "--restart: no checkpoint '" + checkpointPath +
                                             "' (a run writes one every checkpoint_interval_s and on SIGINT/SIGTERM)");
  if (int rc = checkMemory(p)) return rc;
  std::unique_ptr<DirectoryLock> lock;  // held until the run returns: the kernel drops it if the process dies
  if (int rc = lockOutput(outDir, flags.lockWait, lock)) return rc;
  if (flags.restart) checkCheckpoint(checkpointPath, p);  // a bad one is refused before anything is changed
  bool restart = flags.restart;
  if (flags.resume) {  // continue when the checkpoint is this build's and this case's, else start over, saying why
    std::string why = "no checkpoint " + checkpointPath;
    if (fs::exists(checkpointPath)) try {
        checkCheckpoint(checkpointPath, p);
        restart = true;
      } catch (const CheckpointDamaged&) {
        throw;  // a damaged file is refused, not replaced: the message says to delete it
      } catch (const CheckpointError& e) {
        why = e.what();
      }
    if (!restart) std::fprintf(stderr, "enamel-dem: starting from step 0: %s\n", why.c_str());
  }
  if (int rc = prepareOutput(outDir, flags.force || restart, resultPath)) return rc;
  removeStaleResults(outDir);
  Simulation sim(p);
  installStopHandlers();
  std::signal(SIGXFSZ, SIG_IGN);  // a file-size limit (ulimit -f) fails the write (EFBIG), it does not kill the run
  if (!flags.quiet)
    std::fprintf(stderr, "enamel-dem: %s: %d DOF, %d interfaces, dt %.3g, integrator %s -> %s\n",
                 p.sourceName.c_str(), sim.model.numDofs(), sim.model.numInterfaces(), sim.integrator->timeStep(),
                 sim.integrator->name().c_str(), resultPath.c_str());
  RunOptions opt;
  opt.outDir = outDir;
  opt.progress = !flags.quiet;
  opt.checkpointPath = checkpointPath;
  opt.checkpointIntervalSeconds = flags.checkpointEvery >= 0 ? flags.checkpointEvery : p.checkpoint_interval_s;
  opt.restart = restart;
  // Fault injection for the tests of the failure path (tests/python/test_cli.py).
  if (const char* inject = std::getenv("ENAMEL_INJECT_NAN_AT_STEP")) opt.injectNanAtStep = std::atol(inject);
  const RunRecord rec = runSimulation(sim, opt);
  const RcurveSummary s = [&] {
    std::vector<double> R;
    for (double J : rec.rcurveJ) R.push_back(J / p.Gamma());
    return summariseRcurve(rec.rcurveDa, R);
  }();
  std::fprintf(stderr, "enamel-dem: %s: %s after %ld steps, %.1f s: %s\n", p.sourceName.c_str(), nameOf(rec.status).c_str(),
               rec.steps, rec.wallSeconds, rec.stopReason.c_str());
  std::fprintf(stderr, "enamel-dem: R_init/Gamma %.4g  R_ss/Gamma %.4g  da_max/d %.3g  broken rods %d  energy balance %.3g\n",
               s.R_init, s.R_ss, s.daMax, sim.state.brokenBeams(),
               rec.history.empty() ? 0.0 : rec.history.back().balanceError);
  for (const auto& w : rec.warnings) std::fprintf(stderr, "enamel-dem: warning: %s\n", w.c_str());
  if (rec.status == RunStatus::failed)
    return fail(exit_code::run_unstable,
                rec.stopReason + " (partial result kept in " + resultFileFor(outDir, rec.status) + ")");
  if (rec.status == RunStatus::interrupted) {
    std::fprintf(stderr, "enamel-dem: partial result in %s; continue with --resume (or --restart)\n",
                 resultFileFor(outDir, rec.status).c_str());
    return exit_code::interrupted;
  }
  return exit_code::ok;
}

/// `enamel-dem run`: the case's arguments and the run's own flags.
CLI::App* addRunCommand(CLI::App& app, CaseArgs& runArgs, RunFlags& flags) {
  CLI::App* run = app.add_subcommand("run", "run one case to its stop criterion and write DIR/result.h5 (while it "
                                            "runs, and when interrupted: DIR/result.partial.h5; failed: "
                                            "DIR/result.failed.h5)");
  runArgs.addTo(run);
  run->add_option("--out,-o", flags.outDir, "output directory (default runs/<preset>/<case name>)");
  run->add_flag("--force", flags.force, "overwrite an existing result.h5");
  run->add_flag("--quiet,-q", flags.quiet, "no progress lines");
  run->add_flag("--restart", flags.restart,
                "continue from DIR/checkpoint.bin (same case, --preset and --set as the first run); the result "
                "is the same as an uninterrupted run's, bit for bit at the same thread count");
  run->add_flag("--resume", flags.resume,
                "continue from DIR/checkpoint.bin when it was written by this build for this case, otherwise "
                "start from step 0 (says which on stderr): what the pipeline passes, so a killed run continues");
  run->add_option("--checkpoint-every", flags.checkpointEvery,
                  "write DIR/checkpoint.bin every this many wall-clock seconds (default: the case key "
                  "checkpoint_interval_s; a checkpoint is always written on SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  run->add_option("--lock-wait", flags.lockWait,
                  "while another live run holds DIR (its lock DIR/.lock), wait up to this many seconds for it to "
                  "end (default 0: refused at once, exit status 17, nothing changed)")
      ->check(CLI::NonNegativeNumber);
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"enamel-dem: discrete element fracture of decussating crossply microstructures (tooth enamel),\n"
               "after Pro & Barthelat 2020, J. Mech. Phys. Solids. Normalised units: d = E_r = rho_r = 1."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string(ENAMEL_VERSION) + " (" + enamel::kGitHash + ")");

  CaseArgs infoArgs, runArgs;
  CLI::App* info = app.add_subcommand("info", "print the model built from a case: counts of rods, nodes, beam "
                                              "elements, interfaces by tag, DOF, governing element frequency, dt");
  infoArgs.addTo(info);
  bool estimateOnly = false;
  info->add_flag("--estimate", estimateOnly,
                 "print only the estimated counts, peak memory and one core's wall time of the whole run (lines "
                 "'nodes N', 'dof N', 'interfaces N', 'memory_mb N', then 'c_d', 'dt', 'u_start', 'u_end', "
                 "'duration', 'steps', 'seconds_per_step', 'setup_seconds', 'seconds'), without building the model "
                 "(c_d and dt from a block of at most 16 x 8 d of the case)");

  RunFlags flags;
  CLI::App* run = addRunCommand(app, runArgs, flags);

  CaseArgs profileArgs;
  long profileWarmup = 200, profileSteps = 100;
  CLI::App* profile = app.add_subcommand(
      "profile", "run the time step on the case's model with its phase timers on and print a Markdown table: each "
                 "phase's ms/step and share of the step, bytes moved per step and achieved GB/s next to a triad "
                 "measured in the same run");
  profileArgs.addTo(profile);
  profile->add_option("--warmup", profileWarmup, "steps run before timing")->check(CLI::NonNegativeNumber);
  profile->add_option("--steps", profileSteps, "steps timed")->check(CLI::PositiveNumber);
  double profilePhi = 0, profilePhiTarget = 0;
  profile->add_option("--rate-multiplier", profilePhi,
                      "run the loading clock at this phi from the start (the adaptive rate held; needs rate_adapt_max "
                      ">= it)")->check(CLI::Range(1.0, 1e6));
  profile->add_option("--rate-target", profilePhiTarget,
                      "ramp phi from --rate-multiplier to this over the warm-up and timed steps (as a run's controller "
                      "ramps it between rows)")->check(CLI::Range(1.0, 1e6))->needs("--rate-multiplier");

  CLI::App* keys = app.add_subcommand("keys", "list every case key: meaning, unit, default, allowed range (Markdown)");
  bool constantsJson = false;
  CLI::App* constants = app.add_subcommand(
      "constants", "print the numbers the Python side shares with the solver: exit statuses, warning bounds, the "
                   "result file's seal and names, the adaptive loading rate's bounds, the case keys' choices (TOML)");
  constants->add_flag("--json", constantsJson, "print them as one JSON object (what enamel_results/constants.py reads)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return exit_code::usage;
  }

  try {
    if (*keys) { std::cout << formatKeysMarkdown(); return exit_code::ok; }
    if (*constants) { std::cout << (constantsJson ? sharedConstantsJson() : sharedConstantsToml()); return exit_code::ok; }
    if (*info) return runInfo(infoArgs, estimateOnly);
    if (*run) return runRun(runArgs, flags);
    if (*profile) return runProfile(profileArgs, profileWarmup, profileSteps, profilePhi, profilePhiTarget);
  } catch (const std::exception& e) {
    return fail(exitCodeOf(e), e.what());
  }
  return exit_code::usage;
}
